//! Noisy SISO consistency (Boulet & Francis 1998, Sec. IV-B): the interconnection `V(jω)` of
//! eqs. (13)–(14), the lower LFT `F_L(V, φ⁻¹)` of eq. (15), and the envelope of the smallest
//! `|r(jω_i)|` with `μ_Γ{F_L[V(jω_i), φ_i⁻¹]} > 1` (Theorem 4), found by a bracketed search on
//! `|r|` that Proposition 1 (monotonicity in `|r|`) makes valid.
//!
//! Both factorizations are covered: the scalar one (`n = 1`, `C = 1`) and the special one
//! (`n` modes, `C` of size `1×n`).  The input factor `J` (a scalar here) is kept where the
//! model has it, `g = C·M̃⁻¹·Ñ·J`: it multiplies the input of `Ñ + rΔ̃_N`, so it appears in
//! `V₁₂` and `V₂₂` (for `J = 1` this is exactly eq. (14)).  This equals dividing the datum by
//! `J` and the noise radius by `|J|`, as Theorem 3 does with `Φ̂ = ΦJ⁻¹`.

use crate::model::FactorsAt;
use crate::mu::{
    mu_full_scalar_low_rank, mu_full_scalar_structured, FullPlusScalar, LowRank, MuSettings,
    MuStatus,
};
use nalgebra::DMatrix;
use num_complex::Complex64;

mod envelope;

pub use envelope::{
    noisy_envelope, noisy_envelope_report, DatumProgressFn, EnvelopeOptions, NoisyReport,
};

/// Why a datum cannot be processed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoisyFailure {
    /// The model or the data are not SISO.
    NotSiso,
    /// `M̃(jω)` is singular.
    MSingular,
    /// `J(jω) = 0`.
    JSingular,
    /// A6: `φ = 0` (or not finite).
    A6,
    /// A7: `φ − V₂₂ = 0` (the datum equals the nominal model).
    A7,
}

impl NoisyFailure {
    /// A one-line explanation with what to do.
    pub fn message(&self) -> &'static str {
        match self {
            Self::NotSiso => "the noisy test (Theorem 4) is for SISO data and models; select a channel",
            Self::MSingular => "M̃(jω) is singular: the factorization is not valid at this frequency; check the model ([model] entries, or the [physical] parameters)",
            Self::JSingular => "J(jω) = 0: choose an input factor J without zeros on the jω-axis",
            Self::A6 => "assumption A6 fails: the datum φ is zero or not finite; remove this datum",
            Self::A7 => "assumption A7 fails: φ − C·M̃⁻¹·Ñ·J = 0 (the datum equals the nominal model); remove this datum",
        }
    }
}

/// Relative threshold under which `|φ − V₂₂|` counts as zero (A7), as for A5 in Theorem 3.
const A7_RTOL: f64 = 1e-13;

/// `M̃⁻¹(jω)`: dense, or its diagonal when `M̃` is diagonal (a `[physical]` model, one row
/// per mode: no `n × n` matrix per datum).
enum Minv {
    Dense(DMatrix<Complex64>),
    Diagonal(Vec<Complex64>),
}

impl Minv {
    fn size(&self) -> usize {
        match self {
            Self::Dense(m) => m.nrows(),
            Self::Diagonal(d) => d.len(),
        }
    }
}

/// The pieces of `V` that do not depend on `r` or `L_a`.
struct Parts {
    minv: Minv,
    minv_nj: DMatrix<Complex64>,
    c_minv: DMatrix<Complex64>,
    v22: Complex64,
    j: Complex64,
}

fn parts(at: &FactorsAt) -> std::result::Result<Parts, NoisyFailure> {
    let n = at.m.nrows();
    if at.c.nrows() != 1 || at.n.ncols() != 1 || at.j.len() != 1 || at.c.ncols() != n {
        return Err(NoisyFailure::NotSiso);
    }
    let j = at.j[0];
    if !(j.norm() > 0.0 && j.is_finite()) {
        return Err(NoisyFailure::JSingular);
    }
    if at.m_singular() {
        return Err(NoisyFailure::MSingular);
    }
    if crate::system::linalg::diagonal_fast_path(&at.m) {
        // The same divisions as `m_solve`'s diagonal path, without the identity columns.
        let mut minv = Vec::with_capacity(n);
        let mut minv_nj = DMatrix::zeros(n, 1);
        let mut c_minv = DMatrix::zeros(1, n);
        let one = Complex64::new(1.0, 0.0);
        for i in 0..n {
            let d = at.m[(i, i)];
            if d == Complex64::default() {
                return Err(NoisyFailure::MSingular);
            }
            let inv = one / d;
            minv.push(inv);
            minv_nj[(i, 0)] = (at.n[(i, 0)] * j) / d;
            c_minv[(0, i)] = at.c[(0, i)] * inv;
        }
        let v22 = (&at.c * &minv_nj)[(0, 0)];
        return Ok(Parts {
            minv: Minv::Diagonal(minv),
            minv_nj,
            c_minv,
            v22,
            j,
        });
    }
    let mut rhs = DMatrix::zeros(n, n + 1);
    rhs.view_mut((0, 0), (n, 1)).copy_from(&(&at.n * j));
    rhs.view_mut((0, 1), (n, n)).fill_with_identity();
    let sol = at.m_solve(&rhs).ok_or(NoisyFailure::MSingular)?;
    let minv_nj = sol.columns(0, 1).into_owned();
    let minv = sol.columns(1, n).into_owned();
    let c_minv = &at.c * &minv;
    let v22 = (&at.c * &minv_nj)[(0, 0)];
    Ok(Parts {
        minv: Minv::Dense(minv),
        minv_nj,
        c_minv,
        v22,
        j,
    })
}

/// `V(jω)` of eq. (14), `(n+3)×(n+2)`, partitioned with `V₁₁` `(n+2)×(n+1)`:
/// `V₁₁ = [0; r·M̃⁻¹ 0; 0]`, `V₁₂ = [r·J; r·M̃⁻¹ÑJ; 1]`, `V₂₁ = [C·M̃⁻¹  L_a]`,
/// `V₂₂ = C·M̃⁻¹·Ñ·J` (`J = 1` gives the paper's eq. (14)).
pub fn v_matrix(
    at: &FactorsAt,
    r: Complex64,
    la: f64,
) -> std::result::Result<DMatrix<Complex64>, NoisyFailure> {
    Ok(v_of_parts(&parts(at)?, r, la))
}

/// [`v_matrix`] from its `r`-free [`Parts`].
fn v_of_parts(p: &Parts, r: Complex64, la: f64) -> DMatrix<Complex64> {
    let n = p.minv.size();
    let mut v = DMatrix::zeros(n + 3, n + 2);
    match &p.minv {
        Minv::Dense(m) => v.view_mut((1, 0), (n, n)).copy_from(&(m * r)),
        Minv::Diagonal(d) => {
            for (i, di) in d.iter().enumerate() {
                v[(1 + i, i)] = di * r;
            }
        }
    }
    v[(0, n + 1)] = r * p.j;
    v.view_mut((1, n + 1), (n, 1)).copy_from(&(&p.minv_nj * r));
    v[(n + 1, n + 1)] = Complex64::new(1.0, 0.0);
    v.view_mut((n + 2, 0), (1, n)).copy_from(&p.c_minv);
    v[(n + 2, n)] = Complex64::new(la, 0.0);
    v[(n + 2, n + 1)] = p.v22;
    v
}

/// `F_L(V, φ⁻¹) = V₁₁ + V₁₂(φ − V₂₂)⁻¹V₂₁` (eq. (15) and Lemma 1), `(n+2)×(n+1)`, for a
/// `V` from [`v_matrix`].  Checks A6 (`φ ≠ 0`) and A7 (`φ − V₂₂ ≠ 0`).
pub fn lower_lft(
    v: &DMatrix<Complex64>,
    phi: Complex64,
) -> std::result::Result<DMatrix<Complex64>, NoisyFailure> {
    let (rows, cols) = (v.nrows() - 1, v.ncols() - 1);
    let k = lft_denominator(phi, v[(rows, cols)])?;
    let v11 = v.view((0, 0), (rows, cols));
    let v12 = v.view((0, cols), (rows, 1));
    let v21 = v.view((rows, 0), (1, cols));
    Ok(v11 + (v12 * v21) / k)
}

/// `φ − V₂₂`, after A6 (`φ ≠ 0`) and A7 (`φ − V₂₂ ≠ 0`).
fn lft_denominator(phi: Complex64, v22: Complex64) -> std::result::Result<Complex64, NoisyFailure> {
    if !(phi.norm() > 0.0 && phi.is_finite()) {
        return Err(NoisyFailure::A6);
    }
    let k = phi - v22;
    if k.norm().is_nan() || k.norm() <= A7_RTOL * phi.norm().max(v22.norm()) {
        return Err(NoisyFailure::A7);
    }
    Ok(k)
}

/// `F_L[V(jω), φ⁻¹]` at `r` and `L_a` (eqs. (14)–(15)): the matrix whose `μ_Γ` decides
/// consistency (Theorem 4).
pub fn gamma_lft(
    at: &FactorsAt,
    phi: Complex64,
    r: Complex64,
    la: f64,
) -> std::result::Result<DMatrix<Complex64>, NoisyFailure> {
    lower_lft(&v_matrix(at, r, la)?, phi)
}

/// Settings of the search on `|r|`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BisectionSettings {
    /// Stop when the bracket on `|r|`, or the Newton step, is smaller than `rel_tol·|r|`.
    pub rel_tol: f64,
    /// Maximum number of `μ` evaluations per datum (besides the one at the A1 limit).
    pub max_iter: usize,
    /// Settings of each `μ` computation.
    pub mu: MuSettings,
}

impl BisectionSettings {
    /// Checks every field, the μ settings included; the error names the first bad one.
    pub fn validate(&self) -> std::result::Result<(), crate::settings::InvalidSetting> {
        crate::settings::Checker::new("BisectionSettings")
            .fraction("rel_tol", self.rel_tol)
            .at_least("max_iter", self.max_iter, 1, "must be at least 1")
            .finish()?;
        self.mu.validate()
    }
}

impl Default for BisectionSettings {
    fn default() -> Self {
        Self {
            rel_tol: 1e-10,
            max_iter: 100,
            mu: MuSettings::default(),
        }
    }
}

/// Result at one datum.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NoisyDatum {
    /// Smallest `|r|` with `μ_Γ > 1`: 0 when the datum is within the noise of the nominal
    /// model, `inf` when even `|r| → σ_min(M̃)` does not explain it.
    pub r_min: f64,
    /// `σ_min(M̃(jω))`, the A1 limit.
    pub a1_limit: f64,
    /// `μ_Γ` at `|r| = 0`, i.e. `L_a/|φ − V₂₂|`.
    pub mu_at_zero: f64,
    /// `μ_Γ` at `|r| = σ_min(M̃)`.
    pub mu_at_a1: f64,
    /// Number of `μ` computations.
    pub mu_evaluations: usize,
    /// Total number of matrix decompositions inside those `μ` computations.
    pub decompositions: usize,
    /// Largest relative gap of the `μ` bounds met in the search.
    pub worst_mu_gap: f64,
    /// Worst `μ` status met (`Converged` unless something went wrong).
    pub mu_status: MuStatus,
    /// True when the search hit `max_iter` before the tolerance.
    pub hit_iteration_cap: bool,
}

fn status_rank(s: MuStatus) -> u8 {
    match s {
        MuStatus::Converged => 0,
        MuStatus::GapAboveTolerance => 1,
        MuStatus::SvdFailed => 2,
        MuStatus::NonFinite => 3,
    }
}

/// `F_L(V(1), φ⁻¹) = E + a·bᴴ` when `M̃(jω)` is diagonal (a `[physical]` model, one row per
/// mode): `E = V₁₁ = [0; M̃⁻¹ 0; 0]` has one entry per mode, `a = V₁₂`,
/// `bᴴ = V₂₁/(φ − V₂₂)` (eqs. (14)–(15)).  `None` for a full `M̃`.
fn low_rank(p: &Parts, phi: Complex64, la: f64) -> Option<LowRank> {
    let Minv::Diagonal(minv) = &p.minv else {
        return None;
    };
    let n = minv.len();
    let k = phi - p.v22;
    let mut a = nalgebra::DVector::zeros(n + 2);
    a[0] = p.j;
    a.rows_mut(1, n).copy_from(&p.minv_nj.column(0));
    a[n + 1] = Complex64::new(1.0, 0.0);
    let mut b = nalgebra::DVector::zeros(n + 1);
    for j in 0..n {
        b[j] = (p.c_minv[(0, j)] / k).conj();
    }
    b[n] = Complex64::new(la, 0.0) / k.conj();
    Some(LowRank {
        entries: (0..n).map(|i| (i + 1, i, minv[i])).collect(),
        a,
        b,
    })
}

/// The smallest `|r|` consistent with the noisy datum `φ` and noise radius `L_a` (Theorem 4).
///
/// `M(|r|) = diag(|r|·I_{n+1}, 1)·M(1)`, since only the rows of `V₁₁`, `V₁₂` feeding `Δ̃` carry
/// `r` and its phase is absorbed into `Δ̃`.  `μ(0) = L_a/|φ − V₂₂|`; if it exceeds 1 the
/// answer is 0.  Otherwise `μ` is evaluated at the A1 limit `σ_min(M̃)`; if it is at most 1
/// the answer is `inf`.  Otherwise the crossing `μ(|r|) = 1` is bracketed in
/// `[0, σ_min(M̃)]`: every evaluation moves one end of the bracket (`μ > 1`: upper end,
/// else lower end), which is valid because `μ` is continuous and nondecreasing in `|r|`
/// (Proposition 1).  The next point is a Newton step on `ln μ` against `ln |r|`, whose slope
/// is [`MuBounds::row_share`](crate::mu::MuBounds::row_share), when it falls inside the
/// bracket, and the bracket midpoint otherwise (bisection).  The search stops when the
/// bracket is narrower than `settings.rel_tol·|r|` or the Newton step is smaller than that
/// (quadratic convergence: the remaining error is far below the step).  Each `μ` is
/// warm-started at the previous optimal `ln d`.
pub fn r_min_noisy(
    at: &FactorsAt,
    phi: Complex64,
    la: f64,
    settings: &BisectionSettings,
) -> std::result::Result<NoisyDatum, NoisyFailure> {
    // The parts serve both M(1) and its low-rank description: one solve with M̃ per datum.
    let p = parts(at)?;
    let k = lft_denominator(phi, p.v22)?;
    // M(1) = F_L(V(1), φ⁻¹) is formed only when a step needs it: never on the O(n) path of
    // a diagonal M̃, whose description `E + a·bᴴ` comes from the same parts (issue 34: the
    // O(n²) copies per datum and per μ made Theorem 4 on 1000 modes take half a minute).
    let m1_cell = std::cell::OnceCell::new();
    let m1 = || {
        m1_cell.get_or_init(|| {
            lower_lft(&v_of_parts(&p, Complex64::new(1.0, 0.0), la), phi)
                .expect("A6 and A7 were checked")
        })
    };
    let n = at.m.nrows();
    let a1 = at.a1_limit();
    let s = FullPlusScalar::gamma(n);
    // M(1)'s entry (n+1, n) is V₁₂[n+1]·V₂₁[n]/(φ − V₂₂) = 1·L_a/(φ − V₂₂).
    let mu0 = (Complex64::new(la, 0.0) / k).norm();
    let mut out = NoisyDatum {
        r_min: 0.0,
        a1_limit: a1,
        mu_at_zero: mu0,
        mu_at_a1: f64::NAN,
        mu_evaluations: 0,
        decompositions: 0,
        worst_mu_gap: 0.0,
        mu_status: MuStatus::Converged,
        hit_iteration_cap: false,
    };
    if mu0 > 1.0 {
        return Ok(out);
    }
    let mut hint: Option<f64> = None;
    let structure = low_rank(&p, phi, la).filter(|lr| lr.fits(s.rows, s.cols));
    let mut lr = structure.clone();
    // M(ρ) = diag(ρ·I_{n+1}, 1)·M(1).
    let dense_at = |rho: f64| {
        let m1 = m1();
        let mut scaled = m1.clone();
        for i in 0..=n {
            for j in 0..=n {
                scaled[(i, j)] = m1[(i, j)] * rho;
            }
        }
        scaled
    };
    // μ(ρ) and d ln μ/d ln ρ.
    let mut mu_of = |rho: f64, out: &mut NoisyDatum| -> (f64, f64) {
        let b = match (&structure, &mut lr) {
            (Some(base), Some(lr)) => {
                // The rows feeding Δ̃ scale with ρ: E and a₀..aₙ.
                for (e, e0) in lr.entries.iter_mut().zip(&base.entries) {
                    e.2 = e0.2 * rho;
                }
                for i in 0..=n {
                    lr.a[i] = base.a[i] * rho;
                }
                mu_full_scalar_structured(lr, &|| dense_at(rho), s, &settings.mu, hint)
            }
            _ => mu_full_scalar_low_rank(&dense_at(rho), s, &settings.mu, hint, None),
        }
        .expect("shape of F_L matches Γ");
        out.mu_evaluations += 1;
        out.decompositions += b.evaluations;
        out.worst_mu_gap = out.worst_mu_gap.max(b.rel_gap);
        if status_rank(b.status) > status_rank(out.mu_status) {
            out.mu_status = b.status;
        }
        if b.log_d.is_finite() {
            hint = Some(b.log_d);
        }
        (b.upper, b.row_share)
    };
    let (mu_hi, share_hi) = mu_of(a1, &mut out);
    out.mu_at_a1 = mu_hi;
    if mu_hi.is_nan() || mu_hi <= 1.0 {
        out.r_min = f64::INFINITY;
        return Ok(out);
    }
    // Bracket [lo, hi] with μ(lo) ≤ 1 < μ(hi).
    let (mut lo, mut hi) = (0.0, a1);
    let (mut rho, mut mu, mut share) = (a1, mu_hi, share_hi);
    let mut iters = 0;
    loop {
        let newton = rho * (-mu.ln() / share).exp();
        let tol = settings.rel_tol * hi;
        if share > 0.0 && newton.is_finite() && (newton - rho).abs() <= tol {
            out.r_min = newton.clamp(lo, hi);
            break;
        }
        if hi - lo <= tol {
            out.r_min = hi;
            break;
        }
        if iters >= settings.max_iter {
            out.hit_iteration_cap = true;
            out.r_min = hi;
            break;
        }
        let next = if share > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        (mu, share) = mu_of(next, &mut out);
        rho = next;
        iters += 1;
        if mu > 1.0 {
            hi = rho;
        } else if mu == 1.0 {
            out.r_min = rho;
            break;
        } else {
            lo = rho;
        }
    }
    Ok(out)
}

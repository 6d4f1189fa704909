//! Structured singular value `μ` for one full complex block plus one complex scalar block.
//!
//! The structure is the set `Γ` of eq. (16) of Boulet & Francis (1998),
//! `Δ_s = diag(Δ̃, w̃)` with `Δ̃` a full complex `q×k` block and `w̃` a complex scalar;
//! `μ_Γ(M)` is defined by eq. (17): the inverse of the smallest `‖Δ_s‖` with
//! `det(I − M·Δ_s) = 0`, or 0 when no such `Δ_s` exists.  `M` is `(k+1)×(q+1)`: its first
//! `k` rows feed `Δ̃`, its last row feeds `w̃`; its first `q` columns come from `Δ̃`, its last
//! column from `w̃`.  For the noisy SISO test, `q = n`, `k = n + 1` (`Δ̃ ∈ ℂ^{n×(n+1)}`).
//!
//! **Upper bound.**  With `D_l = diag(I_k, d)`, `D_r = diag(I_q, d)` (so `D_r·Δ_s = Δ_s·D_l`),
//! `μ_Γ(M) ≤ σ̄(D_l M D_r⁻¹) = σ̄([[M₁₁, M₁₂/d], [d·M₂₁, M₂₂]])` for every `d > 0`.  With two
//! blocks, one of them scalar (`2S + F ≤ 3`), the infimum over `d` equals `μ` (Packard and
//! Doyle 1993; a non-square full block is made square by zero padding, which changes
//! neither side).  `σ̄` is convex in `t = ln d` (Sezginer and Overton 1990) with derivative
//! `dσ̄/dt = σ̄·(|y_last|² − |x_last|²)` for the top singular pair `M_d x = σ̄ y`; the search
//! is a safeguarded Newton search (analytic second derivative, bisection fallback) for the
//! root of the sign-monotone `h(t) = |y_last|² − |x_last|²`.
//!
//! **Lower bound.**  Every vector `x ≠ 0` gives `μ ≥ min(‖(Mx)₁‖/‖x₁‖, |(Mx)₂|/|x₂|)` with a
//! certificate `Δ̃ = x₁z₁*/‖z₁‖²`, `w̃ = x₂/z₂` (`z = Mx`): then `M·Δ_s·z = z`, so
//! `I − MΔ_s` is singular, and `‖Δ_s‖` is the inverse of the bound.  Each evaluation of the
//! search feeds its top right singular vector (unscaled) to this bound; at the optimal `d`,
//! `h = 0` makes both ratios equal `σ̄`, closing the gap.  Degenerate cases (optimum at
//! `d → 0` or `∞`, repeated `σ̄`) have their own candidates; see [`mu_full_scalar`].
//!
//! What is here: [`mu_full_scalar`] (and [`mu_full_scalar_from`], warm-started) on the
//! structure [`FullPlusScalar`] with [`MuSettings`], giving [`MuBounds`] and a [`MuStatus`];
//! [`mu_two_scalar`], the closed form for two complex scalar blocks.

mod low_rank;
mod search;
pub(crate) mod two_scalar;

pub use low_rank::LowRank;

pub use two_scalar::mu_two_scalar;

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector, SVD};
use num_complex::Complex64;
use search::{newton_search, Dense, Search};

/// Block sizes of the structure `Γ = {diag(Δ̃, w̃)}` (eq. (16)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FullPlusScalar {
    /// Rows `q` of the full block `Δ̃` (the number of columns of `M` driven by `Δ̃`).
    pub rows: usize,
    /// Columns `k` of the full block `Δ̃` (the number of rows of `M` feeding `Δ̃`).
    pub cols: usize,
}

impl FullPlusScalar {
    /// The structure `Γ` of eq. (16) for `n` modes: `Δ̃ ∈ ℂ^{n×(n+1)}`, `M ∈ ℂ^{(n+2)×(n+1)}`.
    pub fn gamma(n: usize) -> Self {
        Self {
            rows: n,
            cols: n + 1,
        }
    }

    /// Shape `(rows, cols)` of `M`.
    pub fn m_shape(&self) -> (usize, usize) {
        (self.cols + 1, self.rows + 1)
    }

    /// Shape `(rows, cols)` of `Δ_s`.
    pub fn delta_shape(&self) -> (usize, usize) {
        (self.rows + 1, self.cols + 1)
    }
}

/// Settings of the `μ` computation.  All loops are capped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuSettings {
    /// Target relative gap `(upper − lower)/upper`; the search stops as soon as it is met.
    pub rel_gap: f64,
    /// Maximum number of singular value decompositions in the search over `ln d`.
    pub max_evals: usize,
    /// The search over `t = ln d` stays within `t₀ ± log_d_range` (`t₀` the starting point).
    pub log_d_range: f64,
    /// Iteration cap of each matrix decomposition (Hermitian eigenproblem or SVD).
    pub svd_max_iter: usize,
}

impl MuSettings {
    /// Checks every field; the error names the first bad one ([`crate::settings`]).
    pub fn validate(&self) -> std::result::Result<(), crate::settings::InvalidSetting> {
        crate::settings::Checker::new("MuSettings")
            .fraction("rel_gap", self.rel_gap)
            .at_least("max_evals", self.max_evals, 1, "must be at least 1")
            .positive("log_d_range", self.log_d_range)
            .at_least("svd_max_iter", self.svd_max_iter, 1, "must be at least 1")
            .finish()
    }
}

impl Default for MuSettings {
    fn default() -> Self {
        Self {
            rel_gap: 1e-10,
            max_evals: 80,
            log_d_range: 60.0,
            svd_max_iter: 2000,
        }
    }
}

/// How the computation ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MuStatus {
    /// The relative gap is at most `MuSettings::rel_gap`.
    Converged,
    /// The iteration cap was reached first; both bounds are valid, the gap is reported.
    GapAboveTolerance,
    /// A decomposition (eigen or SVD) did not converge within its cap; the bounds found so
    /// far are reported.
    SvdFailed,
    /// `M` has a non-finite entry; the bounds are NaN.
    NonFinite,
}

/// Bounds on `μ_Γ(M)` with the lower-bound certificate.
#[derive(Debug, Clone)]
pub struct MuBounds {
    /// Upper bound `σ̄(D_l M D_r⁻¹)` at the best `d` found (equals `μ` at the optimum).
    pub upper: f64,
    /// Lower bound `1/‖Δ_s‖` of the certificate.
    pub lower: f64,
    /// `(upper − lower)/upper` (0 when `upper = 0`).
    pub rel_gap: f64,
    /// `ln d` at the best upper bound (`±∞` when the optimum is at `d → 0` or `∞`).
    pub log_d: f64,
    /// Sensitivity `d ln μ / d ln s` when the first `k` rows of `M` (those feeding `Δ̃`) are
    /// scaled by `s`: `‖y₁‖²` of the top left singular vector at the optimal `d` (envelope
    /// theorem; exact where `σ̄` is simple).  In `[0, 1]`; NaN when unknown.
    pub row_share: f64,
    /// Number of matrix decompositions performed.
    pub evaluations: usize,
    /// How the computation ended.
    pub status: MuStatus,
    /// The vector `x` (columns of `M`) generating the certificate; `None` when `μ = 0`.
    pub witness: Option<DVector<Complex64>>,
    structure: FullPlusScalar,
}

impl MuBounds {
    /// The certificate `Δ_s = diag(Δ̃, w̃)` (`(q+1)×(k+1)`) built from the witness `x`:
    /// `z = Mx`, `Δ̃ = x₁z₁*/‖z₁‖²`, `w̃ = x₂/z₂`, so that `(I − MΔ_s)z = 0` and
    /// `‖Δ_s‖ = 1/lower`.  `None` when `μ = 0` (no `Δ_s` makes `I − MΔ_s` singular).
    pub fn certificate(&self, m: &DMatrix<Complex64>) -> Option<DMatrix<Complex64>> {
        let x = self.witness.as_ref()?;
        let s = self.structure;
        let (q, k) = (s.rows, s.cols);
        let z = m * x;
        let (dr, dc) = s.delta_shape();
        let mut delta = DMatrix::zeros(dr, dc);
        let z1 = z.rows(0, k);
        let z1n = z1.norm_squared();
        if z1n > 0.0 {
            for i in 0..q {
                for j in 0..k {
                    delta[(i, j)] = x[i] * z1[j].conj() / z1n;
                }
            }
        }
        if z[k].norm() > 0.0 {
            delta[(q, k)] = x[q] / z[k];
        }
        Some(delta)
    }
}

/// The lower bound `min(‖z₁‖/‖x₁‖, |z₂|/|x₂|)` of a vector `x` (`z = Mx`); a zero part of
/// `x` imposes nothing.
fn lower_of(x: &DVector<Complex64>, z: &DVector<Complex64>, q: usize, k: usize) -> f64 {
    let x1 = x.rows(0, q).norm();
    let x2 = x[q].norm();
    let r1 = if x1 > 0.0 {
        z.rows(0, k).norm() / x1
    } else {
        f64::INFINITY
    };
    let r2 = if x2 > 0.0 {
        z[k].norm() / x2
    } else {
        f64::INFINITY
    };
    let lb = r1.min(r2);
    if lb.is_finite() {
        lb
    } else {
        0.0
    }
}

/// Bounds on `μ_Γ(M)` for `Γ = {diag(Δ̃, w̃)}`, `Δ̃` full `s.rows × s.cols` (eqs. (16)–(17)).
///
/// Algorithm: (i) if `M₁₂ = 0` or `M₂₁ = 0`, `det(I − MΔ_s)` factors and
/// `μ = max(σ̄(M₁₁), |M₂₂|)` exactly; (ii) otherwise a safeguarded Newton search for
/// `h(t) = 0`, `t = ln d`, started at the balancing point `t₀ = ½·ln(‖M₁₂‖/‖M₂₁‖)` (or
/// `log_d_hint`), bisecting a bracket once one is known and growing it by doubling steps
/// before; every evaluation updates the upper bound (`σ̄` at that `d`) and the lower bound
/// (its singular vector); the search stops as soon as the relative gap is at most
/// `settings.rel_gap`; (iii) if it is not met within the caps, a rebalanced witness, the
/// repeated-`σ̄` combination, `|M₂₂|` and `σ̄(M₁₁)` are tried.
///
/// Errors only on a shape mismatch; numerical trouble is reported in [`MuBounds::status`].
pub fn mu_full_scalar(
    m: &DMatrix<Complex64>,
    s: FullPlusScalar,
    settings: &MuSettings,
) -> Result<MuBounds> {
    mu_full_scalar_from(m, s, settings, None)
}

/// As [`mu_full_scalar`], starting the search over `ln d` at `log_d_hint` when it is finite
/// (a warm start, e.g. from a previous `μ` of a nearby matrix).
pub fn mu_full_scalar_from(
    m: &DMatrix<Complex64>,
    s: FullPlusScalar,
    settings: &MuSettings,
    log_d_hint: Option<f64>,
) -> Result<MuBounds> {
    mu_full_scalar_low_rank(m, s, settings, log_d_hint, None)
}

/// As [`mu_full_scalar_from`], with `M = E + a·bᴴ` described by `low_rank` ([`LowRank`]:
/// `E` with at most one nonzero per row and column in `M₁₁`): each step of the search over
/// `ln d` then costs O(n) instead of a dense eigenproblem, falling back to it where the
/// structured eigenvector fails its residual test.  A description that does not match `m`
/// (shape, or an entry off by more than rounding) is ignored.  The lower bound is always
/// evaluated on `m` itself, so it stays a certificate whatever path found the witness.
pub fn mu_full_scalar_low_rank(
    m: &DMatrix<Complex64>,
    s: FullPlusScalar,
    settings: &MuSettings,
    log_d_hint: Option<f64>,
    low_rank: Option<&LowRank>,
) -> Result<MuBounds> {
    check_structure(m, s)?;
    let low_rank = low_rank.filter(|lr| lr.fits(s.rows, s.cols) && lr.matches(m));
    if m.iter().any(|v| !v.is_finite()) {
        return Ok(Outcome::non_finite().bounds(s));
    }
    let (q, k) = (s.rows, s.cols);
    let n12 = m.view((0, q), (k, 1)).norm();
    let n21 = m.view((k, 0), (1, q)).norm();
    let search = Search::new(Dense::given(m), q, k, settings, low_rank);
    Ok(run_search(search, n12, n21, log_d_hint).bounds(s))
}

/// As [`mu_full_scalar_low_rank`] for a caller that built `M = E + a·bᴴ` and its
/// [`LowRank`] description from the same parts and checked them against each other once
/// ([`LowRank::matches`] on an unscaled copy): the dense `M` is not formed (the O(n²) copy
/// per evaluation that made Theorem 4 on a 1000-mode model take half a minute, issue 34)
/// unless a step falls back to the dense eigenproblem, where `dense` builds it. The lower
/// bound is evaluated through `low_rank` (`M·x` in O(n)), which describes `M` exactly.
/// A description that does not fit the structure sends the whole computation to the dense
/// path.
pub fn mu_full_scalar_structured(
    low_rank: &LowRank,
    dense: &dyn Fn() -> DMatrix<Complex64>,
    s: FullPlusScalar,
    settings: &MuSettings,
    log_d_hint: Option<f64>,
) -> Result<MuBounds> {
    let (q, k) = (s.rows, s.cols);
    if q == 0 || k == 0 || !low_rank.fits(q, k) {
        return mu_full_scalar_low_rank(&dense(), s, settings, log_d_hint, None);
    }
    let finite = |v: &Complex64| v.is_finite();
    let (amax, bmax) = (low_rank.a.camax(), low_rank.b.camax());
    if !(low_rank.a.iter().all(finite)
        && low_rank.b.iter().all(finite)
        && low_rank.entries.iter().all(|e| e.2.is_finite())
        && (amax * bmax).is_finite())
    {
        return Ok(Outcome::non_finite().bounds(s));
    }
    // Column q of M is a·conj(b_q) (E has no entry there), row k is a_k·bᴴ (nor there).
    let n12 = low_rank.a.rows(0, k).norm() * low_rank.b[q].norm();
    let n21 = low_rank.a[k].norm() * low_rank.b.rows(0, q).norm();
    let search = Search::new(Dense::lazy(dense), q, k, settings, Some(low_rank));
    Ok(run_search(search, n12, n21, log_d_hint).bounds(s))
}

/// The search of [`mu_full_scalar_low_rank`] once `‖M₁₂‖` and `‖M₂₁‖` are known.
fn run_search(mut search: Search<'_>, n12: f64, n21: f64, log_d_hint: Option<f64>) -> Outcome {
    let q = search.q;
    // |M₂₂| with witness e_last (Δ̃ = 0).
    let mut e_last = DVector::zeros(q + 1);
    e_last[q] = Complex64::new(1.0, 0.0);
    search.offer(e_last);
    if n12 == 0.0 || n21 == 0.0 {
        block_triangular(&mut search, n12)
    } else {
        let t0 = log_d_hint
            .filter(|t| t.is_finite())
            .unwrap_or(0.5 * (n12 / n21).ln());
        scaled_search(&mut search, t0)
    }
}

/// The sizes of `M` against the structure `diag(Δ̃ q×k, w̃)`.
fn check_structure(m: &DMatrix<Complex64>, s: FullPlusScalar) -> Result<()> {
    if s.rows == 0 || s.cols == 0 {
        return Err(Error::Invalid(format!(
            "μ structure: the full block must be at least 1×1, got {}×{}",
            s.rows, s.cols
        )));
    }
    if m.shape() != s.m_shape() {
        return Err(Error::Invalid(format!(
            "μ: M is {}×{} but the structure diag(Δ̃ {}×{}, w̃) needs {}×{}",
            m.nrows(),
            m.ncols(),
            s.rows,
            s.cols,
            s.m_shape().0,
            s.m_shape().1
        )));
    }
    Ok(())
}

/// What a μ computation found, before it is tied to its structure.
struct Outcome {
    upper: f64,
    lower: f64,
    log_d: f64,
    evals: usize,
    status: MuStatus,
    witness: Option<DVector<Complex64>>,
    row_share: f64,
}

impl Outcome {
    fn non_finite() -> Self {
        Self {
            upper: f64::NAN,
            lower: f64::NAN,
            log_d: f64::NAN,
            evals: 0,
            status: MuStatus::NonFinite,
            witness: None,
            row_share: f64::NAN,
        }
    }

    fn bounds(self, structure: FullPlusScalar) -> MuBounds {
        MuBounds {
            upper: self.upper,
            lower: self.lower,
            row_share: self.row_share,
            rel_gap: if self.upper > 0.0 {
                (self.upper - self.lower) / self.upper
            } else {
                0.0
            },
            log_d: self.log_d,
            evaluations: self.evals,
            status: self.status,
            witness: self.witness,
            structure,
        }
    }
}

/// `σ̄(M₁₁)`, offering its top right singular vector (padded with a zero) as a witness.
fn sigma11(search: &mut Search) -> Option<f64> {
    let (m, q, k) = (search.m.get(), search.q, search.k);
    let m11 = m.view((0, 0), (k, q)).into_owned();
    let svd = SVD::try_new_unordered(
        m11,
        false,
        true,
        5.0 * f64::EPSILON,
        search.settings.svd_max_iter,
    )?;
    let vt = svd.v_t.as_ref()?;
    let (imax, &sv) = svd
        .singular_values
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    let x = DVector::from_fn(q + 1, |j, _| {
        if j < q {
            vt[(imax, j)].conj()
        } else {
            Complex64::default()
        }
    });
    search.offer(x);
    Some(sv)
}

/// `M₁₂ = 0` or `M₂₁ = 0`: block triangular, `det(I − MΔ_s) = det(I − M₁₁Δ̃)·(1 − M₂₂w̃)`,
/// so `μ = max(σ̄(M₁₁), |M₂₂|)` exactly, at `d → 0` or `d → ∞`.
fn block_triangular(search: &mut Search, n12: f64) -> Outcome {
    let m22 = search.m.get()[(search.k, search.q)].norm();
    let Some(s11) = sigma11(search) else {
        return Outcome {
            upper: f64::NAN,
            lower: search.lower,
            log_d: f64::NAN,
            evals: 1,
            status: MuStatus::SvdFailed,
            witness: search.witness.take(),
            row_share: f64::NAN,
        };
    };
    let upper = s11.max(m22);
    Outcome {
        upper,
        lower: if upper > 0.0 { search.lower } else { 0.0 },
        log_d: if n12 == 0.0 {
            f64::NEG_INFINITY
        } else {
            f64::INFINITY
        },
        evals: 1,
        status: MuStatus::Converged,
        witness: if upper > 0.0 {
            search.witness.take()
        } else {
            None
        },
        // μ = σ̄(M₁₁) scales with the rows, μ = |M₂₂| does not.
        row_share: if s11 > m22 { 1.0 } else { 0.0 },
    }
}

/// The general case: the Newton search over `t = ln d` from `t0`, then the balanced and
/// kink candidates and `σ̄(M₁₁)` while the gap is above the tolerance.
fn scaled_search(search: &mut Search, t0: f64) -> Outcome {
    newton_search(search, t0);
    if !search.gap_ok() && !search.svd_failed {
        search.balance_candidate();
    }
    if !search.gap_ok() && !search.svd_failed {
        search.kink_candidate();
        if !search.gap_ok() {
            sigma11(search);
        }
    }
    let status = if search.gap_ok() {
        MuStatus::Converged
    } else if search.svd_failed {
        MuStatus::SvdFailed
    } else {
        MuStatus::GapAboveTolerance
    };
    Outcome {
        upper: search.upper,
        lower: search.lower,
        log_d: search.t_upper,
        evals: search.evals,
        status,
        witness: search.witness.take(),
        row_share: search.share_upper,
    }
}

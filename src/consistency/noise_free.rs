//! Noise-free consistency at one frequency (Boulet & Francis 1998, Sec. IV-A).
//!
//! * Standard factorization, Theorem 2: the minimum-norm solution of `ΔW = U` (eq. (7)),
//!   `Δ_i = U_i (W_i^*W_i)^{-1} W_i^*` (eq. (8)), with `U = Ñ − M̃Φ` and `W = [−I; −Φ]`.
//!   Its norm is the smallest `|r(jω_i)|` that explains the datum.
//! * Special factorization, Theorem 3: `F_L(P, Φ̂⁻¹) = r·X` with
//!   `X = [0; M̃⁻¹] + [I; M̃⁻¹Ñ](Φ̂ − P₂₂)⁻¹ C M̃⁻¹`, `Φ̂ = ΦJ⁻¹`, `P₂₂ = C M̃⁻¹ Ñ`, and the
//!   datum is consistent iff `|r|·σ_p(X) > 1`: the smallest `|r|` is `1/σ_p(X)` in closed
//!   form (Schmidt–Mirsky, Theorem 7).

use crate::model::FactorsAt;
use crate::system::linalg::{extreme_singular_values, is_singular, spectral_norm};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Why a datum cannot be processed: the assumption that fails.
#[derive(Debug, Clone, PartialEq)]
pub enum AssumptionFailure {
    /// `M̃(jω)` is singular (the factorization is not valid there).
    MSingular,
    /// A2: the datum `Φ` is singular.
    DatumSingular,
    /// `J(jω)` has a zero on its diagonal.
    JSingular,
    /// A5: `Φ̂ − P₂₂` is singular (the datum equals the nominal model in some direction).
    A5,
    /// The data are not square where the special factorization needs them to be.
    NotSquare,
}

impl AssumptionFailure {
    /// A one-line explanation with what to do.
    pub fn message(&self) -> &'static str {
        match self {
            Self::MSingular => "M̃(jω) is singular: the factorization is not valid at this frequency; check the model ([model] entries, or the [physical] parameters)",
            Self::DatumSingular => "assumption A2 fails: the datum Φ is singular; remove this datum or check its columns",
            Self::JSingular => "J(jω) has a zero on its diagonal: choose an input matrix J without zeros on the jω-axis",
            Self::A5 => "assumption A5 fails: Φ̂ − C·M̃⁻¹·Ñ is singular (the datum equals the nominal model in some direction); the datum needs no perturbation there, remove it or add noise",
            Self::NotSquare => "the special factorization (Theorem 3) needs square data (p = m)",
        }
    }
}

fn singular(a: &DMatrix<Complex64>) -> bool {
    is_singular(extreme_singular_values(a))
}

/// Theorem 2, eq. (8): the minimum-norm `Δ_i` solving `Δ_i W_i = U_i`, returned with its norm.
///
/// `Δ_i = U_i (W_i^*W_i)^{-1} W_i^* = U_i W_i^+` is computed from the thin Householder QR
/// factorization `W = QR` (`Q` with orthonormal columns, `R` upper triangular):
/// `Δ = (U R^{-1}) Q^*` and `‖Δ‖ = σ_max(U R^{-1})`.  The Gram matrix `W^*W = I + Φ^*Φ` is
/// never formed, so the error grows like `cond(W)·ε`, not `cond(W)²·ε` (GitHub issue 11).
/// `W = [−I; −Φ]` has full column rank (`σ_min(W) ≥ 1`), so `R` is always invertible.
pub fn min_norm_perturbation(
    f: &FactorsAt,
    phi: &DMatrix<Complex64>,
) -> Result<(DMatrix<Complex64>, f64), AssumptionFailure> {
    if f.m_singular() {
        return Err(AssumptionFailure::MSingular);
    }
    let (zh, q) = qr_z(f, phi);
    let norm = spectral_norm(&zh);
    let delta = zh.adjoint() * q.adjoint();
    Ok((delta, norm))
}

/// Theorem 2: the smallest `|r(jω)|` consistent with the datum, `‖Δ_i‖` of eq. (8).
///
/// `‖Δ_i‖ = ‖U W^+‖ = σ_max(U R^{-1})` with `W = QR` (see [`min_norm_perturbation`]);
/// `Δ_i` itself is not formed.
pub fn r_min_standard(f: &FactorsAt, phi: &DMatrix<Complex64>) -> Result<f64, AssumptionFailure> {
    if f.m_singular() {
        return Err(AssumptionFailure::MSingular);
    }
    let (zh, _) = qr_z(f, phi);
    Ok(spectral_norm(&zh))
}

/// `Zᴴ = R^{-*} Uᴴ` with `U = Ñ − M̃Φ` and the thin QR `W = [−I; −Φ] = QR`; also returns `Q`.
/// A non-finite datum gives a non-finite `Z` (never a panic).
fn qr_z(f: &FactorsAt, phi: &DMatrix<Complex64>) -> (DMatrix<Complex64>, DMatrix<Complex64>) {
    let (p, m_in) = phi.shape();
    // Prescale by c, the power of two at or below max(1, max|Φ_ij|): W/c = Q·(R/c) and
    // (R/c)^{-*}(U/c)ᴴ = R^{-*}Uᴴ, so Z is unchanged while no Householder norm or product
    // M̃Φ overflows (a datum of 1e308 gave NaN).  A power of two scales without rounding,
    // so the accuracy up to cond(W) ≈ 1e12 is kept.  Moduli use hypot (finite to f64::MAX).
    let big = phi.iter().map(|z| z.norm()).fold(1.0, f64::max);
    let c = if big.is_finite() {
        2f64.powi(big.log2().floor() as i32)
    } else {
        1.0
    };
    let phi_c = phi.map(|z| z / c);
    let u = f.n.map(|z| z / c) - &f.m * &phi_c;
    let mut w = DMatrix::<Complex64>::zeros(m_in + p, m_in);
    for k in 0..m_in {
        w[(k, k)] = Complex64::new(-1.0 / c, 0.0);
    }
    w.view_mut((m_in, 0), (p, m_in)).copy_from(&(-phi_c));
    let qr = w.qr();
    let (q, r) = (qr.q(), qr.r());
    let zh = r
        .adjoint()
        .solve_lower_triangular(&u.adjoint())
        .unwrap_or_else(|| DMatrix::from_element(m_in, p, Complex64::new(f64::NAN, 0.0)));
    (zh, q)
}

/// The matrix `X` of Theorem 3, `F_L(P, Φ̂⁻¹) = r·X`, computed with LU solves.
pub fn theorem3_x(
    f: &FactorsAt,
    phi: &DMatrix<Complex64>,
) -> Result<DMatrix<Complex64>, AssumptionFailure> {
    let p = phi.nrows();
    if phi.ncols() != p || f.j.len() != p {
        return Err(AssumptionFailure::NotSquare);
    }
    if f.m_singular() {
        return Err(AssumptionFailure::MSingular);
    }
    if singular(phi) {
        return Err(AssumptionFailure::DatumSingular);
    }
    if f.j.iter().any(|j| j.norm() == 0.0 || !j.is_finite()) {
        return Err(AssumptionFailure::JSingular);
    }
    let n = f.m.nrows();
    // Φ̂ = Φ J⁻¹ (J diagonal).
    let mut phi_hat = phi.clone();
    for (k, jk) in f.j.iter().enumerate() {
        let mut col = phi_hat.column_mut(k);
        col /= *jk;
    }
    // [M̃⁻¹Ñ | M̃⁻¹] from one LU factorization of M̃.
    let mut rhs = DMatrix::zeros(n, p + n);
    rhs.view_mut((0, 0), (n, p)).copy_from(&f.n);
    rhs.view_mut((0, p), (n, n)).fill_with_identity();
    let sol = f.m_solve(&rhs).ok_or(AssumptionFailure::MSingular)?;
    let minv_n = sol.columns(0, p).into_owned();
    let minv = sol.columns(p, n).into_owned();
    let p22 = &f.c * &minv_n;
    let k = &phi_hat - &p22;
    if singular(&k) {
        return Err(AssumptionFailure::A5);
    }
    // Z = (Φ̂ − P₂₂)⁻¹ C M̃⁻¹
    let z = k.lu().solve(&(&f.c * &minv)).ok_or(AssumptionFailure::A5)?;
    let mut x = DMatrix::zeros(p + n, n);
    x.view_mut((0, 0), (p, n)).copy_from(&z);
    x.view_mut((p, 0), (n, n)).copy_from(&(minv + minv_n * z));
    Ok(x)
}

/// Theorem 3: the smallest `|r(jω)|` consistent with the datum, `1/σ_p(X)`.
pub fn r_min_special(f: &FactorsAt, phi: &DMatrix<Complex64>) -> Result<f64, AssumptionFailure> {
    let x = theorem3_x(f, phi)?;
    let p = phi.nrows();
    let mut sv: Vec<f64> = x
        .svd(false, false)
        .singular_values
        .iter()
        .copied()
        .collect();
    sv.sort_by(|a, b| b.total_cmp(a));
    Ok(1.0 / sv[p - 1])
}

//! Spectral factorization: from `|r(jω)|² = A(ω²)/B(ω²)` to
//! `r(s) = gain·Π(s − z_k)/Π(s − p_k)` with every pole and zero in the open left half-plane.
//!
//! `A(x)` is positive on `x ≥ 0`, so its roots `ξ_k` avoid `[0, ∞)`.  With `x = −s²`,
//! `A(−s²) = a(s)·a(−s)` and each root `ξ` gives the stable root `s = −√(−ξ)` (principal
//! square root: `Re √· ≥ 0`), because `|jω − s|² = ω² − ξ` for `s² = −ξ`.
//! A root `ξ` on (or numerically on) the positive real axis would give a root `s` on the
//! jω-axis: that means the positivity floor failed, and it is reported as an error, never
//! dropped.
//!
//! The roots of `A` come from its monomial coefficients (Aberth, capped) and are then
//! polished by Newton steps on the well-conditioned partial-fraction form
//! `A/D = c₀ + Σ c_k q_k²/(x + q_k²)`, which can be evaluated accurately at any `x`.

use crate::system::Polynomial;
use num_complex::Complex64;
use serde::Serialize;

/// Which polynomial a root belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RootKind {
    /// A zero of `r` (numerator `A`).
    Zero,
    /// A pole of `r` (denominator `B`).
    Pole,
}

/// Why a spectral factorization failed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum SpectralError {
    /// A root lies on the jω-axis (to the tolerance): `|r|²` touches zero (zero) or
    /// infinity (pole) at `ω̂`; the positivity floor failed.
    RootOnAxis {
        /// Zero or pole.
        which: RootKind,
        /// Scaled frequency of the root on the axis.
        omega_hat: f64,
    },
    /// The root iteration hit its cap.
    NotConverged(RootKind),
    /// The leading coefficient is not positive: `r(∞) = 0` or `|r|² < 0` at infinity.
    NonPositiveLeading(RootKind),
}

impl std::fmt::Display for SpectralError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::RootOnAxis { which, omega_hat } => write!(
                f,
                "spectral factor has a {which:?} on the jω-axis at scaled ω = {omega_hat:.6e} (positivity floor failed)"
            ),
            Self::NotConverged(w) => write!(f, "{w:?} root iteration did not converge"),
            Self::NonPositiveLeading(w) => {
                write!(f, "{w:?} polynomial has a non-positive leading coefficient")
            }
        }
    }
}

/// A unit in gain-zero-pole form (scaled or unscaled units).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Zpk {
    /// Positive gain `r(∞)`.
    pub gain: f64,
    /// Zeros, conjugate pairs adjacent.
    pub zeros: Vec<Complex64>,
    /// Poles, conjugate pairs adjacent.
    pub poles: Vec<Complex64>,
}

impl Zpk {
    /// `|r(jω)|`, as a product of distances (no polynomial coefficients involved);
    /// `ω = ∞` gives the gain.
    pub fn mag(&self, omega: f64) -> f64 {
        if omega.is_infinite() {
            return self.gain.abs();
        }
        let s = Complex64::new(0.0, omega);
        let mut m = self.gain.abs();
        // Interleave zeros and poles to keep the running product in range.
        for k in 0..self.zeros.len().max(self.poles.len()) {
            if let Some(z) = self.zeros.get(k) {
                m *= (s - z).norm();
            }
            if let Some(p) = self.poles.get(k) {
                m /= (s - p).norm();
            }
        }
        m
    }

    /// The same unit in unscaled units: `r(s) = ρ·r̂(s/ω₀)`.
    pub fn unscale(&self, omega0: f64, rho: f64) -> Zpk {
        Zpk {
            gain: self.gain * rho,
            zeros: self.zeros.iter().map(|z| z * omega0).collect(),
            poles: self.poles.iter().map(|p| p * omega0).collect(),
        }
    }

    /// Order (number of poles).
    pub fn order(&self) -> usize {
        self.poles.len()
    }
}

fn pf_eval(q: &[f64], c: &[f64], x: Complex64) -> (Complex64, Complex64) {
    let mut f = Complex64::new(c[0], 0.0);
    let mut df = Complex64::new(0.0, 0.0);
    for (qk, ck) in q.iter().zip(&c[1..]) {
        let q2 = qk * qk;
        let inv = (x + q2).inv();
        f += ck * q2 * inv;
        df -= ck * q2 * inv * inv;
    }
    (f, df)
}

fn polish(q: &[f64], c: &[f64], mut x: Complex64, real: bool) -> Complex64 {
    let (mut f, _) = pf_eval(q, c, x);
    for _ in 0..8 {
        let (fx, dfx) = pf_eval(q, c, x);
        if !(dfx.norm() > 0.0) {
            break;
        }
        let mut nx = x - fx / dfx;
        if real {
            nx.im = 0.0;
        }
        let (nf, _) = pf_eval(q, c, nx);
        if nf.is_finite() && nf.norm() < f.norm() {
            x = nx;
            f = nf;
        } else {
            break;
        }
    }
    x
}

/// Stable roots `s` of the spectral factor of `c₀ + Σ c_k q_k²/(x + q_k²)` times
/// `D(x) = Π(x + q_k²)`, i.e. of the polynomial `A(x)` of degree `len(q)` in `x = ω̂²`.
/// `axis_tol` is the smallest accepted `|Re s|/|s|`.
pub fn stable_roots(
    q: &[f64],
    c: &[f64],
    which: RootKind,
    axis_tol: f64,
    max_iter: usize,
) -> Result<Vec<Complex64>, SpectralError> {
    if !(c[0] > 0.0) || !c[0].is_finite() {
        return Err(SpectralError::NonPositiveLeading(which));
    }
    if q.is_empty() {
        return Ok(Vec::new());
    }
    let lin = |q2: f64| Polynomial::new(vec![1.0, q2]);
    let mut a = Polynomial::constant(c[0]);
    for qk in q {
        a = a.mul(&lin(qk * qk));
    }
    for (k, qk) in q.iter().enumerate() {
        let mut term = Polynomial::constant(c[k + 1] * qk * qk);
        for (j, qj) in q.iter().enumerate() {
            if j != k {
                term = term.mul(&lin(qj * qj));
            }
        }
        a = a.add(&term);
    }
    let roots = a.roots_capped(max_iter);
    if !roots.converged {
        return Err(SpectralError::NotConverged(which));
    }
    // Polish on the partial-fraction form, keeping conjugate symmetry.
    let mut xi = Vec::with_capacity(roots.roots.len());
    for r in &roots.roots {
        if r.im == 0.0 {
            xi.push(polish(q, c, *r, true));
        } else if r.im > 0.0 {
            let p = polish(q, c, *r, false);
            xi.push(p.conj());
            xi.push(p);
        }
    }
    if xi.len() != roots.roots.len() {
        xi = roots.roots.clone();
    }
    let mut out = Vec::with_capacity(xi.len());
    for x in xi {
        let s = -(-x).sqrt();
        let s = if x.im == 0.0 {
            Complex64::new(s.re, 0.0)
        } else {
            s
        };
        if !(s.re < -axis_tol * s.norm()) || s.norm() == 0.0 {
            return Err(SpectralError::RootOnAxis {
                which,
                omega_hat: s.im.abs(),
            });
        }
        out.push(s);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factor_of_known_unit() {
        // r = 2(s+3)/(s+0.5): |r|² = 4(x+9)/(x+0.25).  With q = [1]:
        // A/D = 4(x+9)/(x+1) = 4 + 32/(x+1) → c = [4, 32].
        let z = stable_roots(&[1.0], &[4.0, 32.0], RootKind::Zero, 1e-9, 200).unwrap();
        assert_eq!(z.len(), 1);
        assert!((z[0] - Complex64::new(-3.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn root_on_axis_is_an_error() {
        // A = x − 4 has its root at x = 4 (ω = 2): A/D with q = [1]: (x−4)/(x+1) = 1 − 5/(x+1).
        let e = stable_roots(&[1.0], &[1.0, -5.0], RootKind::Zero, 1e-9, 200).unwrap_err();
        assert!(matches!(e, SpectralError::RootOnAxis { .. }));
    }

    #[test]
    fn complex_pair() {
        // (s² + 0.2 s + 1): |.|² = x² − 1.96 x + 1 (roots complex); q = [0.5, 2].
        let roots = [
            Complex64::new(-0.1, 0.99498743710662),
            Complex64::new(-0.1, -0.99498743710662),
        ];
        let zp = Zpk {
            gain: 1.0,
            zeros: roots.to_vec(),
            poles: vec![],
        };
        // Fit c by sampling 3 points.
        let q = [0.5, 2.0];
        let xs = [0.3, 1.0, 5.0];
        let m = nalgebra::Matrix3::from_fn(|i, j| super::super::basis::basis_row(&q, xs[i])[j]);
        let d = |x: f64| (x + 0.25) * (x + 4.0);
        let rhs = nalgebra::Vector3::from_fn(|i, _| zp.mag(xs[i].sqrt()).powi(2) / d(xs[i]));
        let c = m.lu().solve(&rhs).unwrap();
        let z = stable_roots(&q, c.as_slice(), RootKind::Zero, 1e-9, 200).unwrap();
        for r in roots {
            assert!(z.iter().any(|x| (x - r).norm() < 1e-9), "{z:?}");
        }
    }
}

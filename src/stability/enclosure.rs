//! Rigorous enclosures of the factor entries over a frequency interval, for the certified
//! H∞ norms of [`certified_norm`](super::certified_norm).
//!
//! An entry `h(s) = num(s)/den(s)` on the axis is a rational function of the real `ω`:
//! `h(jω) = N(ω)/D(ω)` with `N(ω) = Σ aₖ jᵏ ωᵏ` (complex coefficients). On an interval
//! `|ω − ω₀| ≤ η` every power moves by at most `|ωᵏ − ω₀ᵏ| ≤ (|ω₀| + η)ᵏ − |ω₀|ᵏ` (binomial
//! expansion), so `|N(ω) − N(ω₀)| ≤ ΔN := Σ |cₖ|((|ω₀| + η)ᵏ − |ω₀|ᵏ)`, and
//!
//! `|h(jω) − h(jω₀)| ≤ (ΔN + |h(jω₀)|·ΔD)/(|D(ω₀)| − ΔD)` when `|D(ω₀)| > ΔD`
//!
//! (`h − h₀ = ((N − N₀) − h₀(D − D₀))/D`, `|D| ≥ |D₀| − ΔD`). The ray `ω ≥ Ω` is the interval
//! `t ∈ [0, 1/Ω]` of `t = 1/ω`: `h(jω) = t^(deg den − deg num)·Ñ(t)/D̃(t)` with the reversed
//! polynomials (a proper `h` only). Rounding of the centre (Horner's running bound
//! `γ·Σ|cₖ||x₀|ᵏ`) is added to the radius, so the computed centre and the radius enclose the
//! true values of the stored coefficients.
//!
//! The controller `K(s) = D + C(sI − A)⁻¹B` (a state space) is enclosed in norm: with
//! `R₀ = (jω₀ − A)⁻¹`, `K(jω) − K(jω₀) = C(jω − A)⁻¹·j(ω₀ − ω)·R₀B` and
//! `‖(jω − A)⁻¹‖ ≤ ‖R₀‖/(1 − η‖R₀‖)` (Neumann series); on the ray `‖(jω − A)⁻¹‖ ≤ 1/(Ω − ‖A‖)`.

use crate::system::{StateSpace, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Unit roundoff.
const U: f64 = f64::EPSILON / 2.0;

/// A frequency interval of the certified sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Interval {
    /// `[a, b]`, `0 ≤ a < b < ∞`.
    Finite(f64, f64),
    /// `[Ω, ∞]`.
    Ray(f64),
}

impl Interval {
    /// The frequency where the centre values are taken (`2Ω` on the ray, `t₀ = 1/(2Ω)`).
    pub(crate) fn omega0(&self) -> f64 {
        match *self {
            Interval::Finite(a, b) => 0.5 * (a + b),
            Interval::Ray(w) => 2.0 * w,
        }
    }

    /// The variable, its centre and half-width: `(use 1/ω, x₀, η)`.
    fn variable(&self) -> (bool, f64, f64) {
        match *self {
            Interval::Finite(a, b) => (false, 0.5 * (a + b), 0.5 * (b - a)),
            Interval::Ray(w) => (true, 0.5 / w, 0.5 / w),
        }
    }

    /// Two halves (geometric for a wide interval of positive frequencies), or `None` when
    /// the interval cannot be split further in floating point.
    pub(crate) fn split(&self) -> Option<[Interval; 2]> {
        match *self {
            Interval::Finite(a, b) => {
                let mid = if a > 0.0 && b > 1.5 * a {
                    (a * b).sqrt()
                } else {
                    0.5 * (a + b)
                };
                (mid > a && mid < b && b - a > 4.0 * f64::EPSILON * b)
                    .then_some([Interval::Finite(a, mid), Interval::Finite(mid, b)])
            }
            Interval::Ray(w) => {
                (w < 1e250).then_some([Interval::Finite(w, 8.0 * w), Interval::Ray(8.0 * w)])
            }
        }
    }
}

/// A centre value and a radius: `|h(jω) − centre| ≤ radius` on the interval.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Disk {
    /// The centre, `h(jω₀)` as computed.
    pub(crate) c: Complex64,
    /// The radius (rounding of the centre included).
    pub(crate) r: f64,
    /// The rounding part alone: `|h(jω₀) − c| ≤ e`.
    pub(crate) e: f64,
}

/// An entry `h(jω)` prepared for [`Rational::enclose`]: its complex coefficients in `ω`
/// and in `t = 1/ω` (ascending powers).
#[derive(Debug, Clone)]
pub(crate) struct Rational {
    num_w: Vec<Complex64>,
    den_w: Vec<Complex64>,
    num_t: Vec<Complex64>,
    den_t: Vec<Complex64>,
    /// `dh/dω = (N′D − ND′)/D²` in `ω`.
    dnum_w: Vec<Complex64>,
    dden_w: Vec<Complex64>,
}

/// Product of two polynomials (ascending complex coefficients).
fn poly_mul(a: &[Complex64], b: &[Complex64]) -> Vec<Complex64> {
    let mut c = vec![Complex64::new(0.0, 0.0); a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            c[i + j] += x * y;
        }
    }
    c
}

/// Derivative (ascending coefficients).
fn poly_der(a: &[Complex64]) -> Vec<Complex64> {
    if a.len() < 2 {
        return vec![Complex64::new(0.0, 0.0)];
    }
    a.iter()
        .enumerate()
        .skip(1)
        .map(|(k, x)| x * k as f64)
        .collect()
}

/// `jᵏ`.
fn j_pow(k: usize) -> Complex64 {
    match k % 4 {
        0 => Complex64::new(1.0, 0.0),
        1 => Complex64::new(0.0, 1.0),
        2 => Complex64::new(-1.0, 0.0),
        _ => Complex64::new(0.0, -1.0),
    }
}

impl Rational {
    /// `None` for an improper entry (no finite value at `ω → ∞`) or a zero denominator.
    pub(crate) fn new(h: &TransferFunction) -> Option<Self> {
        if !h.is_proper() || h.den.is_zero() {
            return None;
        }
        // Ascending real coefficients aₖ of s^k.
        let asc = |c: &[f64]| -> Vec<f64> { c.iter().rev().copied().collect() };
        let (an, ad) = (asc(h.num.coeffs()), asc(h.den.coeffs()));
        let in_w = |a: &[f64]| -> Vec<Complex64> {
            a.iter().enumerate().map(|(k, x)| j_pow(k) * *x).collect()
        };
        let dd = ad.len() - 1;
        // N(ω) = ω^dn·Σ aₖjᵏ t^(dn−k); h = t^(dd−dn)·Ñ(t)/D̃(t): coefficient of t^i in the
        // numerator is a_{dn−(i−(dd−dn))} j^… for i ≥ dd − dn.
        let mut num_t = vec![Complex64::new(0.0, 0.0); dd + 1];
        for (k, x) in an.iter().enumerate() {
            num_t[dd - k] = j_pow(k) * *x;
        }
        let den_t = (0..=dd).map(|i| j_pow(dd - i) * ad[dd - i]).collect();
        let (num_w, den_w) = (in_w(&an), in_w(&ad));
        let a = poly_mul(&poly_der(&num_w), &den_w);
        let b = poly_mul(&num_w, &poly_der(&den_w));
        let len = a.len().max(b.len());
        let dnum_w = (0..len)
            .map(|k| a.get(k).copied().unwrap_or_default() - b.get(k).copied().unwrap_or_default())
            .collect();
        let dden_w = poly_mul(&den_w, &den_w);
        Some(Self {
            num_w,
            den_w,
            num_t,
            den_t,
            dnum_w,
            dden_w,
        })
    }

    /// The disk enclosing `h(jω)` on `iv` (radius `inf` when the denominator may vanish).
    pub(crate) fn enclose(&self, iv: &Interval) -> Disk {
        let (inv, x0, eta) = iv.variable();
        let (n, d) = if inv {
            (&self.num_t, &self.den_t)
        } else {
            (&self.num_w, &self.den_w)
        };
        ratio_enclose(n, d, x0, eta)
    }

    /// The disk enclosing `dh(jω)/dω` on a finite interval `[a, b]`.
    pub(crate) fn enclose_derivative(&self, a: f64, b: f64) -> Disk {
        ratio_enclose(&self.dnum_w, &self.dden_w, 0.5 * (a + b), 0.5 * (b - a))
    }
}

/// The disk of `N(x)/D(x)` for `|x − x₀| ≤ η` (module docs).
fn ratio_enclose(n: &[Complex64], d: &[Complex64], x0: f64, eta: f64) -> Disk {
    let (nv, nb, nd) = poly_enclose(n, x0, eta);
    let (dv, db, dd) = poly_enclose(d, x0, eta);
    let h0 = nv / dv;
    let (hn, dn) = (h0.norm(), dv.norm());
    let deg = (n.len() + d.len()) as f64;
    // Horner's running bound for the centre, then a relative margin on the sums.
    let round = 8.0 * (deg + 2.0) * U * (nb + hn * db) / dn;
    let r = if dn > dd {
        (nd + hn * dd) / (dn - dd) * (1.0 + 16.0 * deg * U) + round
    } else {
        f64::INFINITY
    };
    Disk { c: h0, r, e: round }
}

/// `(P(x₀), Σ|cₖ||x₀|ᵏ, Σ|cₖ|((|x₀| + η)ᵏ − |x₀|ᵏ))` for ascending coefficients `c`.
fn poly_enclose(c: &[Complex64], x0: f64, eta: f64) -> (Complex64, f64, f64) {
    let a = x0.abs();
    let mut v = Complex64::new(0.0, 0.0);
    let mut b = 0.0;
    for ck in c.iter().rev() {
        v = v * x0 + ck;
        b = b * a + ck.norm();
    }
    // (a+η)^k − a^k = η·Σ_{i<k} (a+η)^i a^(k−1−i): a sum of non-negative terms.
    let mut delta = 0.0;
    let mut pow_a = vec![1.0; c.len().max(1)];
    let mut pow_ae = vec![1.0; c.len().max(1)];
    for k in 1..c.len() {
        pow_a[k] = pow_a[k - 1] * a;
        pow_ae[k] = pow_ae[k - 1] * (a + eta);
    }
    for (k, ck) in c.iter().enumerate().skip(1) {
        let s: f64 = (0..k).map(|i| pow_ae[i] * pow_a[k - 1 - i]).sum();
        delta += ck.norm() * eta * s;
    }
    (v, b, delta)
}

/// The controller's value at `ω₀` and a bound of `‖K(jω) − K(jω₀)‖` on the interval.
#[derive(Debug, Clone)]
pub(crate) struct ControllerEnclosure {
    a: DMatrix<Complex64>,
    b: DMatrix<Complex64>,
    c: DMatrix<Complex64>,
    d: DMatrix<Complex64>,
    a_norm: f64,
    b_norm: f64,
    c_norm: f64,
}

impl ControllerEnclosure {
    pub(crate) fn new(k: &StateSpace) -> Self {
        let cx = |m: &DMatrix<f64>| m.map(|x| Complex64::new(x, 0.0));
        Self {
            a: cx(&k.a),
            b: cx(&k.b),
            c: cx(&k.c),
            d: cx(&k.d),
            a_norm: k.a.norm(),
            b_norm: k.b.norm(),
            c_norm: k.c.norm(),
        }
    }

    /// `(K(jω₀), radius, rounding of the centre)` in the spectral norm; `None` where
    /// `jω₀ − A` is singular.
    pub(crate) fn enclose(&self, iv: &Interval) -> Option<(DMatrix<Complex64>, f64, f64)> {
        let n = self.a.nrows();
        if n == 0 {
            return Some((self.d.clone(), 0.0, 0.0));
        }
        let w0 = iv.omega0();
        let shifted = DMatrix::<Complex64>::identity(n, n) * Complex64::new(0.0, w0) - &self.a;
        let r0 = shifted.lu().solve(&DMatrix::identity(n, n))?;
        let r0n = r0.norm();
        let r0b = &r0 * &self.b;
        let k0 = &self.d + &self.c * &r0b;
        let radius = match *iv {
            Interval::Finite(a, b) => {
                let eta = 0.5 * (b - a);
                if eta * r0n < 0.5 {
                    self.c_norm * r0n / (1.0 - eta * r0n) * eta * r0b.norm()
                } else {
                    f64::INFINITY
                }
            }
            Interval::Ray(w) => {
                if w > 2.0 * self.a_norm {
                    self.c_norm * (1.0 / (w - self.a_norm) + r0n) * self.b_norm
                } else {
                    f64::INFINITY
                }
            }
        };
        // Rounding of the centre (a small dense solve; generous).
        let round = 64.0
            * (n as f64 + 4.0)
            * U
            * (self.d.norm() + self.c_norm * r0n * self.b_norm)
            * (1.0 + r0n * self.a_norm);
        Some((k0, radius + round, round))
    }
}

/// A first-order Taylor model on `|ω − ω₀| ≤ η`: `x(ω) = x₀ + (ω − ω₀)·x₁ + R`, `‖R‖ ≤ r`,
/// and `‖x(ω) − x₀‖ ≤ delta` (rounding of the centre included in both).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Taylor {
    pub(crate) x0: Complex64,
    pub(crate) x1: Complex64,
    pub(crate) r: f64,
    pub(crate) delta: f64,
}

impl Rational {
    /// The Taylor model of `h(jω)` on the finite interval `[a, b]`: the value and derivative
    /// disks give `|h(ω) − h₀ − (ω − ω₀)h₁| ≤ e₀ + η·sup|h′ − h₁|` (mean value theorem).
    pub(crate) fn taylor(&self, a: f64, b: f64) -> Taylor {
        let iv = Interval::Finite(a, b);
        let v = self.enclose(&iv);
        let d = self.enclose_derivative(a, b);
        let eta = 0.5 * (b - a);
        Taylor {
            x0: v.c,
            x1: d.c,
            r: v.e + eta * d.r,
            delta: v.r.min(v.e + eta * (d.c.norm() + d.r)),
        }
    }
}

impl ControllerEnclosure {
    /// `(K₀, K₁ = dK/dω at ω₀, r, Δ)` on `[a, b]`: `K(jω) − K₀ − tK₁ = C·R₀(jtR₀)²(I + jtR₀)⁻¹·B`
    /// (`R₀ = (jω₀ − A)⁻¹`), so `r ≤ ‖C‖‖B‖‖R₀‖³η²/(1 − η‖R₀‖)`.
    pub(crate) fn taylor(
        &self,
        a: f64,
        b: f64,
    ) -> Option<(DMatrix<Complex64>, DMatrix<Complex64>, f64, f64)> {
        let iv = Interval::Finite(a, b);
        let (k0, delta, round) = self.enclose(&iv)?;
        let n = self.a.nrows();
        if n == 0 {
            let z = DMatrix::zeros(k0.nrows(), k0.ncols());
            return Some((k0, z, 0.0, 0.0));
        }
        let w0 = iv.omega0();
        let eta = 0.5 * (b - a);
        let shifted = DMatrix::<Complex64>::identity(n, n) * Complex64::new(0.0, w0) - &self.a;
        let r0 = shifted.lu().solve(&DMatrix::identity(n, n))?;
        let r0n = r0.norm();
        if eta * r0n >= 0.5 {
            return None;
        }
        let k1 = -(&self.c * &r0 * &r0 * &self.b) * Complex64::new(0.0, 1.0);
        let r = self.c_norm * self.b_norm * r0n.powi(3) * eta * eta / (1.0 - eta * r0n)
            + round * (1.0 + 2.0 * eta * r0n);
        Some((k0, k1, r, delta))
    }
}

//! Rational transfer functions `num(s)/den(s)` with real coefficients.

use super::polynomial::Polynomial;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// A scalar rational transfer function; coefficients in descending powers of `s`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TransferFunction {
    /// Numerator polynomial.
    pub num: Polynomial,
    /// Denominator polynomial (never the zero polynomial).
    pub den: Polynomial,
}

impl TransferFunction {
    /// `num/den` from coefficient vectors; the denominator must not be identically zero.
    pub fn new(num: Vec<f64>, den: Vec<f64>) -> Self {
        Self {
            num: Polynomial::new(num),
            den: Polynomial::new(den),
        }
    }

    /// A constant gain.
    pub fn gain(k: f64) -> Self {
        Self::new(vec![k], vec![1.0])
    }

    /// Gain-zero-pole form `k·Π(s−z)/Π(s−p)`; complex zeros and poles in conjugate pairs.
    pub fn from_zpk(zeros: &[Complex64], poles: &[Complex64], k: f64) -> Self {
        Self {
            num: Polynomial::from_roots(zeros).scale(k),
            den: Polynomial::from_roots(poles),
        }
    }

    /// Value at a complex point `s`.  The ratio is formed from the two `1/s`-scaled Horner
    /// sums at high frequency, so no intermediate overflows.
    pub fn eval(&self, s: Complex64) -> Complex64 {
        let dn = self.num.degree() as i32;
        let dd = self.den.degree() as i32;
        if s.norm() <= 1.0 {
            self.num.eval(s) / self.den.eval(s)
        } else {
            // num(s)/den(s) = s^(dn-dd) · rev_num(1/s)/rev_den(1/s)
            let z = s.inv();
            let rn = self
                .num
                .coeffs()
                .iter()
                .rev()
                .fold(Complex64::new(0.0, 0.0), |a, c| a * z + c);
            let rd = self
                .den
                .coeffs()
                .iter()
                .rev()
                .fold(Complex64::new(0.0, 0.0), |a, c| a * z + c);
            rn / rd * s.powi(dn - dd)
        }
    }

    /// Value at `s = jω`.
    pub fn freq(&self, omega: f64) -> Complex64 {
        self.eval(Complex64::new(0.0, omega))
    }

    /// True when `deg num ≤ deg den`.
    pub fn is_proper(&self) -> bool {
        self.num.degree() <= self.den.degree() || self.num.is_zero()
    }

    /// True when `deg num = deg den` (finite nonzero value at infinity).
    pub fn is_biproper(&self) -> bool {
        !self.num.is_zero() && self.num.degree() == self.den.degree()
    }

    /// Value at `s = ∞` for a proper transfer function.
    pub fn at_infinity(&self) -> f64 {
        if self.num.degree() < self.den.degree() {
            0.0
        } else {
            self.num.leading() / self.den.leading()
        }
    }

    /// Product of two transfer functions.
    pub fn mul(&self, other: &TransferFunction) -> TransferFunction {
        TransferFunction {
            num: self.num.mul(&other.num),
            den: self.den.mul(&other.den),
        }
    }

    /// Poles (roots of the denominator).
    pub fn poles(&self) -> Vec<Complex64> {
        self.den.roots().roots
    }

    /// Zeros (roots of the numerator).
    pub fn zeros(&self) -> Vec<Complex64> {
        if self.num.is_zero() {
            return Vec::new();
        }
        self.num.roots().roots
    }

    /// Why the transfer function is not a unit of RH∞ (`None` when it is one): not
    /// biproper, a pole or a zero in `Re s ≥ 0` (the first one named), or roots that the
    /// capped iteration could not compute.
    pub fn unit_violation(&self) -> Option<String> {
        if !self.is_biproper() {
            return Some(format!(
                "it is not biproper (numerator degree {}, denominator degree {})",
                self.num.degree(),
                self.den.degree()
            ));
        }
        let fmt = |z: Complex64| {
            if z.im == 0.0 {
                format!("s = {}", z.re)
            } else {
                format!("s = {}{:+}j", z.re, z.im)
            }
        };
        let poles = self.den.roots();
        let zeros = self.num.roots();
        if !poles.converged || !zeros.converged {
            return Some(format!(
                "its poles and zeros could not be computed from the coefficients of degree {} (root iteration cap): give r of lower order",
                self.den.degree()
            ));
        }
        if let Some(p) = poles.roots.iter().find(|p| p.re >= 0.0 || p.re.is_nan()) {
            return Some(format!("it is not stable (pole at {})", fmt(*p)));
        }
        if let Some(z) = zeros.roots.iter().find(|z| z.re >= 0.0 || z.re.is_nan()) {
            return Some(format!("it is not minimum phase (zero at {})", fmt(*z)));
        }
        None
    }

    /// The coefficients for a message: `num/den` when short, the degrees otherwise (a
    /// message stays one readable line whatever the order).
    pub fn brief(&self) -> String {
        if self.num.coeffs().len() + self.den.coeffs().len() <= 12 {
            format!("({:?})/({:?})", self.num.coeffs(), self.den.coeffs())
        } else {
            format!(
                "(degree {} / degree {})",
                self.num.degree(),
                self.den.degree()
            )
        }
    }

    /// True when the transfer function is a unit of RH∞: biproper, and every pole and zero
    /// strictly in the open left half-plane.
    pub fn is_unit(&self) -> bool {
        self.is_biproper()
            && self.poles().iter().all(|p| p.re < 0.0)
            && self.zeros().iter().all(|z| z.re < 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eval_agrees_with_zpk_product() {
        let z = [Complex64::new(-3.0, 0.0)];
        let p = [Complex64::new(-0.01, 50.0), Complex64::new(-0.01, -50.0)];
        let g = TransferFunction::from_zpk(&z, &p, 2.0);
        for w in [1e-3, 1.0, 49.99, 1e5] {
            let s = Complex64::new(0.0, w);
            let direct = 2.0 * (s - z[0]) / ((s - p[0]) * (s - p[1]));
            assert!((g.eval(s) - direct).norm() / direct.norm() < 1e-12);
        }
    }

    #[test]
    fn unit_detection() {
        assert!(TransferFunction::new(vec![1e-8, 0.3], vec![1.0, 1.0]).is_unit());
        assert!(!TransferFunction::new(vec![0.3], vec![1.0, 1.0]).is_unit());
        assert!(!TransferFunction::new(vec![1.0, -1.0], vec![1.0, 1.0]).is_unit());
    }
}

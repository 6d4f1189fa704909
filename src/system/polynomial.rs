//! Real polynomials in descending powers of `s` (the MATLAB / python-control convention).
//!
//! `Polynomial::new(vec![1.0, 3.0, 2.0])` is `s² + 3s + 2`.  Evaluation at large `|s|` runs
//! Horner's rule on the reversed polynomial in `1/s`, so high orders at 1e5 rad/s neither
//! overflow nor lose the leading terms.  Roots come from the Aberth–Ehrlich simultaneous
//! iteration (capped), polished by Newton steps on the original coefficients.

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// A real polynomial `c[0] s^d + c[1] s^(d-1) + … + c[d]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Polynomial {
    coeffs: Vec<f64>,
}

/// Outcome of a root computation: the roots and whether the iteration converged.
#[derive(Debug, Clone)]
pub struct Roots {
    /// The roots, complex pairs adjacent, sorted by real part then imaginary part.
    pub roots: Vec<Complex64>,
    /// True when every root met the tolerance within the iteration cap.
    pub converged: bool,
    /// Iterations used.
    pub iterations: usize,
}

impl Polynomial {
    /// Builds a polynomial from coefficients in descending powers; leading zeros are dropped.
    /// An empty vector (or all zeros) is the zero polynomial.
    pub fn new(coeffs: Vec<f64>) -> Self {
        let first = coeffs.iter().position(|c| *c != 0.0);
        let coeffs = match first {
            Some(i) => coeffs[i..].to_vec(),
            None => vec![0.0],
        };
        Self { coeffs }
    }

    /// The constant polynomial `c`.
    pub fn constant(c: f64) -> Self {
        Self::new(vec![c])
    }

    /// The monic polynomial with the given roots; complex roots must come in conjugate pairs,
    /// and the (negligible) imaginary parts of the product are discarded.
    pub fn from_roots(roots: &[Complex64]) -> Self {
        let mut c = vec![Complex64::new(1.0, 0.0)];
        for r in roots {
            let mut next = vec![Complex64::new(0.0, 0.0); c.len() + 1];
            for (k, ck) in c.iter().enumerate() {
                next[k] += ck;
                next[k + 1] -= ck * r;
            }
            c = next;
        }
        Self::new(c.into_iter().map(|z| z.re).collect())
    }

    /// Coefficients in descending powers of `s`.
    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }

    /// Degree (the zero polynomial has degree 0).
    pub fn degree(&self) -> usize {
        self.coeffs.len() - 1
    }

    /// True for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.coeffs.iter().all(|c| *c == 0.0)
    }

    /// Leading coefficient.
    pub fn leading(&self) -> f64 {
        self.coeffs[0]
    }

    /// Evaluates at a complex point.  For `|s| > 1` the reversed polynomial is evaluated in
    /// `1/s` and rescaled, which keeps the dominant terms exact at high frequency.
    pub fn eval(&self, s: Complex64) -> Complex64 {
        let d = self.degree();
        if s.norm() <= 1.0 {
            self.coeffs
                .iter()
                .fold(Complex64::new(0.0, 0.0), |acc, c| acc * s + c)
        } else {
            let z = s.inv();
            let rev = self
                .coeffs
                .iter()
                .rev()
                .fold(Complex64::new(0.0, 0.0), |acc, c| acc * z + c);
            rev * s.powu(d as u32)
        }
    }

    /// Evaluates the polynomial and its derivative at `s` (plain Horner, for root polishing).
    fn eval_with_derivative(&self, s: Complex64) -> (Complex64, Complex64) {
        let mut p = Complex64::new(0.0, 0.0);
        let mut dp = Complex64::new(0.0, 0.0);
        for c in &self.coeffs {
            dp = dp * s + p;
            p = p * s + c;
        }
        (p, dp)
    }

    /// Product of two polynomials.
    pub fn mul(&self, other: &Polynomial) -> Polynomial {
        let mut out = vec![0.0; self.coeffs.len() + other.coeffs.len() - 1];
        for (i, a) in self.coeffs.iter().enumerate() {
            for (j, b) in other.coeffs.iter().enumerate() {
                out[i + j] += a * b;
            }
        }
        Polynomial::new(out)
    }

    /// Sum of two polynomials.
    pub fn add(&self, other: &Polynomial) -> Polynomial {
        let n = self.coeffs.len().max(other.coeffs.len());
        let mut out = vec![0.0; n];
        for (k, c) in self.coeffs.iter().rev().enumerate() {
            out[n - 1 - k] += c;
        }
        for (k, c) in other.coeffs.iter().rev().enumerate() {
            out[n - 1 - k] += c;
        }
        Polynomial::new(out)
    }

    /// The polynomial multiplied by a scalar.
    pub fn scale(&self, k: f64) -> Polynomial {
        Polynomial::new(self.coeffs.iter().map(|c| c * k).collect())
    }

    /// The polynomial `p(a·s)`: frequency scaling, used to prescale before solving.
    pub fn scale_variable(&self, a: f64) -> Polynomial {
        let d = self.degree();
        Polynomial::new(
            self.coeffs
                .iter()
                .enumerate()
                .map(|(k, c)| c * a.powi((d - k) as i32))
                .collect(),
        )
    }

    /// Roots by the Aberth–Ehrlich iteration, at most `max_iter` sweeps, followed by Newton
    /// polishing.  The polynomial is first rescaled in `s` so that its roots have unit
    /// geometric mean modulus, which keeps the iteration well conditioned for roots spread
    /// over many decades.  Zero roots (trailing zero coefficients) are split off exactly.
    pub fn roots_capped(&self, max_iter: usize) -> Roots {
        let mut coeffs = self.coeffs.clone();
        let mut zeros = 0;
        while coeffs.len() > 1 && *coeffs.last().unwrap() == 0.0 {
            coeffs.pop();
            zeros += 1;
        }
        let d = coeffs.len() - 1;
        let mut roots = vec![Complex64::new(0.0, 0.0); zeros];
        if d == 0 {
            return Roots {
                roots,
                converged: true,
                iterations: 0,
            };
        }
        // Scale s = a·z so that |product of roots| = 1 for the scaled polynomial.
        let a = (coeffs[d] / coeffs[0]).abs().powf(1.0 / d as f64);
        let scaled = Polynomial::new(coeffs.clone()).scale_variable(a);
        let lead = scaled.leading();
        let scaled = scaled.scale(1.0 / lead);
        let mut z: Vec<Complex64> = (0..d)
            .map(|k| {
                let theta = 2.0 * std::f64::consts::PI * (k as f64 + 0.25) / d as f64 + 0.4;
                Complex64::from_polar(1.0, theta)
            })
            .collect();
        let mut converged = false;
        let mut iterations = 0;
        for it in 0..max_iter {
            iterations = it + 1;
            let mut max_step: f64 = 0.0;
            for i in 0..d {
                let (p, dp) = scaled.eval_with_derivative(z[i]);
                if p.norm() == 0.0 {
                    continue;
                }
                let ratio = p / dp;
                let mut sum = Complex64::new(0.0, 0.0);
                for (j, zj) in z.iter().enumerate() {
                    if j != i {
                        let diff = z[i] - zj;
                        if diff.norm() > 0.0 {
                            sum += diff.inv();
                        }
                    }
                }
                let denom = Complex64::new(1.0, 0.0) - ratio * sum;
                let step = if denom.norm() > 0.0 {
                    ratio / denom
                } else {
                    ratio
                };
                if step.is_finite() {
                    z[i] -= step;
                    max_step = max_step.max(step.norm() / z[i].norm().max(1e-300));
                }
            }
            if max_step < 1e-15 {
                converged = true;
                break;
            }
        }
        if !converged {
            // Aberth converges to machine precision quickly for simple roots; for multiple
            // roots it stalls near sqrt(eps): accept when residuals are tiny.
            converged = z.iter().all(|zi| {
                let (p, _) = scaled.eval_with_derivative(*zi);
                let bound: f64 = scaled
                    .coeffs
                    .iter()
                    .enumerate()
                    .map(|(k, c)| c.abs() * zi.norm().powi((d - k) as i32))
                    .sum();
                p.norm() <= 1e-10 * bound
            });
        }
        for zi in z.iter_mut() {
            *zi *= a;
            // Real roots: clean the tiny imaginary parts that the complex iteration leaves.
            if zi.im.abs() <= 1e-12 * zi.norm() {
                zi.im = 0.0;
            }
        }
        roots.extend(z);
        pair_conjugates(&mut roots);
        Roots {
            roots,
            converged,
            iterations,
        }
    }

    /// Roots with the default cap of 500 sweeps.
    pub fn roots(&self) -> Roots {
        self.roots_capped(500)
    }
}

/// Makes complex roots exact conjugate pairs and sorts them (real part, then imaginary part).
fn pair_conjugates(roots: &mut [Complex64]) {
    roots.sort_by(|a, b| {
        a.re.partial_cmp(&b.re)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.im.partial_cmp(&b.im).unwrap_or(std::cmp::Ordering::Equal))
    });
    let n = roots.len();
    let mut used = vec![false; n];
    for i in 0..n {
        if used[i] || roots[i].im == 0.0 {
            continue;
        }
        let mut best = None;
        let mut best_d = f64::INFINITY;
        for j in 0..n {
            if j != i && !used[j] && roots[j].im != 0.0 {
                let d = (roots[j] - roots[i].conj()).norm();
                if d < best_d {
                    best_d = d;
                    best = Some(j);
                }
            }
        }
        if let Some(j) = best {
            let re = 0.5 * (roots[i].re + roots[j].re);
            let im = 0.5 * (roots[i].im.abs() + roots[j].im.abs());
            roots[i] = Complex64::new(re, -im);
            roots[j] = Complex64::new(re, im);
            used[i] = true;
            used[j] = true;
        }
    }
    roots.sort_by(|a, b| {
        a.re.partial_cmp(&b.re)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.im.partial_cmp(&b.im).unwrap_or(std::cmp::Ordering::Equal))
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_of_known_product_are_recovered() {
        let want = [
            Complex64::new(-1.0, 0.0),
            Complex64::new(-2e3, 0.0),
            Complex64::new(-0.05, 7.0),
            Complex64::new(-0.05, -7.0),
            Complex64::new(-1e-3, 0.0),
        ];
        let p = Polynomial::from_roots(&want);
        let got = p.roots();
        assert!(got.converged);
        for w in want {
            let nearest = got
                .roots
                .iter()
                .map(|r| (r - w).norm() / w.norm())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-9, "root {w} missed by {nearest}");
        }
    }

    #[test]
    fn eval_matches_direct_sum_at_high_frequency() {
        let p = Polynomial::new(vec![4.0, 90.8, 20116.0]);
        let s = Complex64::new(0.0, 1e5);
        let direct = 4.0 * s * s + 90.8 * s + 20116.0;
        assert!((p.eval(s) - direct).norm() / direct.norm() < 1e-14);
    }

    #[test]
    fn zero_roots_are_split_exactly() {
        let p = Polynomial::new(vec![1.0, 3.0, 0.0, 0.0]);
        let r = p.roots();
        assert_eq!(r.roots.iter().filter(|z| z.norm() == 0.0).count(), 2);
    }
}

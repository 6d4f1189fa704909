//! State-space models `ẋ = Ax + Bu, y = Cx + Du`, evaluated by a linear solve.

use super::polynomial::Polynomial;
use super::transfer_function::TransferFunction;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// A real continuous-time state-space model.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    /// State matrix (n×n).
    pub a: DMatrix<f64>,
    /// Input matrix (n×m).
    pub b: DMatrix<f64>,
    /// Output matrix (p×n).
    pub c: DMatrix<f64>,
    /// Feedthrough (p×m).
    pub d: DMatrix<f64>,
}

impl StateSpace {
    /// Frequency response `C(jωI − A)⁻¹B + D`, by LU solve (no explicit inverse).
    /// Returns `None` when `jω` is an eigenvalue of `A` to working precision.
    pub fn freq(&self, omega: f64) -> Option<DMatrix<Complex64>> {
        let n = self.a.nrows();
        let dc = self.d.map(|x| Complex64::new(x, 0.0));
        if n == 0 {
            return Some(dc);
        }
        let jw = Complex64::new(0.0, omega);
        let lhs = DMatrix::from_fn(n, n, |i, j| {
            let v = Complex64::new(-self.a[(i, j)], 0.0);
            if i == j {
                v + jw
            } else {
                v
            }
        });
        let rhs = self.b.map(|x| Complex64::new(x, 0.0));
        let x = lhs.lu().solve(&rhs)?;
        let cc = self.c.map(|v| Complex64::new(v, 0.0));
        let y = cc * x + dc;
        y.iter().all(|v| v.is_finite()).then_some(y)
    }

    /// Controllable-canonical realization of a proper SISO transfer function.
    pub fn from_tf(tf: &TransferFunction) -> Self {
        let lead = tf.den.leading();
        let den: Vec<f64> = tf.den.coeffs().iter().map(|c| c / lead).collect();
        let n = den.len() - 1;
        let mut num = vec![0.0; n + 1];
        let nc = tf.num.coeffs();
        for (k, c) in nc.iter().rev().enumerate() {
            if k <= n {
                num[n - k] = c / lead;
            }
        }
        let d0 = num[0];
        // Strictly proper remainder: num - d0*den, coefficients of s^(n-1)..s^0.
        let rem: Vec<f64> = (1..=n).map(|k| num[k] - d0 * den[k]).collect();
        let mut a = DMatrix::zeros(n, n);
        for j in 0..n {
            a[(0, j)] = -den[j + 1];
        }
        for i in 1..n {
            a[(i, i - 1)] = 1.0;
        }
        let mut b = DMatrix::zeros(n, 1);
        if n > 0 {
            b[(0, 0)] = 1.0;
        }
        let c = DMatrix::from_row_slice(1, n, &rem);
        let d = DMatrix::from_element(1, 1, d0);
        Self { a, b, c, d }
    }

    /// Characteristic polynomial check helper: the denominator of a SISO realization from
    /// `from_tf` is the monic denominator of the transfer function.
    pub fn companion_polynomial(&self) -> Polynomial {
        let mut c = vec![1.0];
        c.extend((0..self.a.ncols()).map(|j| -self.a[(0, j)]));
        Polynomial::new(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn realization_reproduces_frequency_response() {
        let tf = TransferFunction::new(vec![2.0, 3.0, 5.0], vec![1.0, 0.4, 9.0]);
        let ss = StateSpace::from_tf(&tf);
        for w in [0.01, 1.0, 3.0, 100.0] {
            let a = tf.freq(w);
            let b = ss.freq(w).unwrap()[(0, 0)];
            assert!((a - b).norm() / a.norm() < 1e-12);
        }
    }
}

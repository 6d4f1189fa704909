//! Compensated (error-free transformation) arithmetic: dot products and matrix products
//! computed as if in twice the working precision, then rounded.
//!
//! `Dot2` of Ogita, Rump & Oishi, "Accurate sum and dot product", *SIAM J. Sci. Comput.*
//! 26(6), 2005, Algorithm 5.3: the result is as accurate as the dot product evaluated in
//! 106-bit arithmetic and rounded to `f64` (their Proposition 5.5), i.e. its error is at most
//! `eps·|xᵀy| + γ²·|x|ᵀ|y|`. Used where a residual is the small difference of large terms
//! (the refinement of an ill-conditioned Riccati solution, [`super::riccati`]).

use nalgebra::DMatrix;

/// `a + b = s + e` exactly (Knuth's TwoSum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let z = s - a;
    (s, (a - (s - z)) + (b - z))
}

/// `a·b = p + e` exactly (by the fused multiply-add).
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// Accumulator of `Σ xᵢyᵢ` in about twice the working precision.
#[derive(Debug, Clone, Copy, Default)]
pub struct Dot2 {
    hi: f64,
    lo: f64,
}

impl Dot2 {
    /// Adds `x·y`.
    pub fn add_product(&mut self, x: f64, y: f64) {
        let (h, r) = two_prod(x, y);
        let (p, q) = two_sum(self.hi, h);
        self.hi = p;
        self.lo += q + r;
    }

    /// Adds `x`.
    pub fn add(&mut self, x: f64) {
        let (p, q) = two_sum(self.hi, x);
        self.hi = p;
        self.lo += q;
    }

    /// The sum as an unevaluated pair `hi + lo` with `|lo| ≤ ulp(hi)/2`.
    pub fn pair(&self) -> (f64, f64) {
        two_sum(self.hi, self.lo)
    }

    /// The sum rounded to `f64`.
    pub fn value(&self) -> f64 {
        self.hi + self.lo
    }
}

/// `x·y` with compensated dot products, returned as the pair `(hi, lo)` of matrices whose sum
/// is the product to about twice the working precision.
pub fn product_pair(x: &DMatrix<f64>, y: &DMatrix<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let (n, m) = (x.nrows(), y.ncols());
    let mut hi = DMatrix::zeros(n, m);
    let mut lo = DMatrix::zeros(n, m);
    for i in 0..n {
        for j in 0..m {
            let mut acc = Dot2::default();
            for k in 0..x.ncols() {
                acc.add_product(x[(i, k)], y[(k, j)]);
            }
            (hi[(i, j)], lo[(i, j)]) = acc.pair();
        }
    }
    (hi, lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sums whose terms cancel to 1 in 1e-32 of their size: the naive sum is 0 or 2,
    /// the compensated one exact (checked against i128 arithmetic on integer data).
    #[test]
    fn cancelling_dot_products_are_exact() {
        let x = [1e16, 1.0, -1e16, 3.0, -3.0];
        let y = [1.0; 5];
        let naive: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        let mut acc = Dot2::default();
        for (a, b) in x.iter().zip(&y) {
            acc.add_product(*a, *b);
        }
        assert_eq!(acc.value(), 1.0);
        assert_ne!(naive, 1.0, "the example must defeat naive summation");
        // Random integer data below 2^26: every product is exact in i128, the sum too.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 38) as i64 - (1 << 25)) as f64
        };
        for _ in 0..200 {
            let a: Vec<f64> = (0..40).map(|_| next() * 2f64.powi(20)).collect();
            let b: Vec<f64> = (0..40).map(|_| next()).collect();
            let exact: i128 = a.iter().zip(&b).map(|(p, q)| *p as i128 * *q as i128).sum();
            let mut acc = Dot2::default();
            for (p, q) in a.iter().zip(&b) {
                acc.add_product(*p, *q);
            }
            assert_eq!(acc.value(), exact as f64);
        }
    }

    #[test]
    fn product_pair_carries_the_rounding_error() {
        let x = DMatrix::from_row_slice(1, 2, &[1.0 + f64::EPSILON, 1.0]);
        let y = DMatrix::from_row_slice(2, 1, &[1.0 + f64::EPSILON, -1.0]);
        // (1+ε)² − 1 = 2ε + ε²: the ε² survives in the low part.
        let (hi, lo) = product_pair(&x, &y);
        assert_eq!(hi[(0, 0)], 2.0 * f64::EPSILON);
        assert_eq!(lo[(0, 0)], f64::EPSILON * f64::EPSILON);
    }
}

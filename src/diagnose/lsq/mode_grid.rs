//! The rough placement of [`crate::diagnose::lsq::retune`]: the least-squares cost as one
//! mode's `ω_n`, `ζ` move, by projection off the other columns factored once.

use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::shapes::mode_den;
use crate::diagnose::lsq::slots::{design, Lin, Term};
use crate::diagnose::lsq::varpro::factor_block;
use crate::model::physical::PhysicalModel;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// The cost of the least squares as one mode's `ω_n`, `ζ` move (the rough placement of
/// [`crate::diagnose::lsq::retune`]): the other columns `A_o` are factored once (`A_o S = Q R`), and at
/// each point the mode's columns `a` are projected off them,
/// `V(ω_n, ζ) = ‖r_o − Q_b Q_bᵀ r_o‖²`, `r_o = P⊥_o y`, `b = P⊥_o a = Q_b R_b`: the cost of
/// the full least squares, in `O(m n)` per point instead of `O(m n²)`.
pub(crate) struct ModeGrid<'a> {
    data: &'a Channels,
    mask: &'a [usize],
    /// The mode's columns with its denominator left out: `a_{row,j} = coef_{row,j}/d(s_k)`
    /// (`path · gain/m · weight`, zero where the column does not act), one complex number per
    /// row pair, column-major.
    coef: Vec<Complex64>,
    n_own: usize,
    q: DMatrix<f64>,
    r_o: DVector<f64>,
}

impl<'a> ModeGrid<'a> {
    /// `None` when the mode has no column or the other columns are rank-deficient.
    pub fn new(
        m: &PhysicalModel,
        mode: usize,
        lin: &[Lin],
        data: &'a Channels,
        mask: &'a [usize],
    ) -> Option<Self> {
        let is_own = |l: &Lin| matches!(l, Lin::Out(Term::Mode(i), _) if *i == mode);
        let own: Vec<Lin> = lin.iter().copied().filter(is_own).collect();
        let others: Vec<Lin> = lin.iter().copied().filter(|l| !is_own(l)).collect();
        if own.is_empty() {
            return None;
        }
        let (a, y) = design(m, &others, data, mask);
        let (q, r_o) = if others.is_empty() {
            (DMatrix::zeros(y.len(), 0), y)
        } else {
            // One factorization over every row (the blocks change nothing in the span).
            let (q, _, _) = factor_block(a)?;
            let r_o = &y - &q * q.tr_mul(&y);
            (q, r_o)
        };
        // The mode's own columns times its denominator: what does not move on the grid.
        let (own_a, _) = design(m, &own, data, mask);
        let (w, z) = (m.mode[mode].omega_n, m.mode[mode].zeta);
        let rows_per_ch = 2 * mask.len();
        let mut coef = Vec::with_capacity(own_a.len() / 2);
        for j in 0..own.len() {
            for row in (0..own_a.nrows()).step_by(2) {
                let s = Complex64::new(0.0, data.omega[mask[(row % rows_per_ch) / 2]]);
                coef.push(Complex64::new(own_a[(row, j)], own_a[(row + 1, j)]) * mode_den(s, w, z));
            }
        }
        if coef.iter().any(|c| !c.is_finite()) {
            return None;
        }
        Some(Self {
            data,
            mask,
            coef,
            n_own: own.len(),
            q,
            r_o,
        })
    }

    /// The least-squares cost with the mode at `(ω_n, ζ)`.
    pub fn cost(&self, w: f64, z: f64) -> f64 {
        let inv_d: Vec<Complex64> = self
            .mask
            .iter()
            .map(|k| mode_den(Complex64::new(0.0, self.data.omega[*k]), w, z).inv())
            .collect();
        let rows = self.r_o.len();
        let pairs = rows / 2;
        let a = DMatrix::from_fn(rows, self.n_own, |row, j| {
            let v = self.coef[j * pairs + row / 2] * inv_d[(row / 2) % inv_d.len()];
            if row % 2 == 0 {
                v.re
            } else {
                v.im
            }
        });
        let b = if self.q.ncols() == 0 {
            a
        } else {
            &a - &self.q * self.q.tr_mul(&a)
        };
        // The residual itself, not ‖r_o‖² − ‖Q_bᵀ r_o‖² (no cancellation on a close fit).
        let v = match factor_block(b) {
            Some((qb, _, _)) => (&self.r_o - &qb * qb.tr_mul(&self.r_o)).norm_squared(),
            None => self.r_o.norm_squared(),
        };
        if v.is_finite() {
            v
        } else {
            f64::INFINITY
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::lsq::retune::solve_linear_res;
    use crate::diagnose::lsq::slots::slots;
    use crate::diagnose::lsq::varpro::tests::{channels, model};

    /// The rough placement's cost by projection equals the full least squares' cost (QR of
    /// every column at every point) over a grid that crosses the mode's resonance.
    #[test]
    fn the_mode_grid_cost_is_the_full_least_squares_cost() {
        let data = channels(&model(1.07));
        let start = model(1.0);
        let (lin, _) = slots(&start, &data);
        let mask: Vec<usize> = (0..data.len()).collect();
        for i in 0..2 {
            let g = ModeGrid::new(&start, i, &lin, &data, &mask).expect("full rank");
            let w0 = start.mode[i].omega_n;
            for j in 0..9 {
                let w = w0 * 1.3f64.powf(-1.0 + j as f64 / 4.0);
                for z in [1e-3, 0.01, 0.1] {
                    let mut t = start.clone();
                    t.mode[i].omega_n = w;
                    t.mode[i].zeta = z;
                    let full = solve_linear_res(&mut t, &lin, &data, &mask).norm_squared();
                    let fast = g.cost(w, z);
                    assert!(
                        (fast - full).abs() <= 1e-9 * full,
                        "mode {i} at ({w}, {z}): {fast} vs {full}"
                    );
                }
            }
        }
    }
}

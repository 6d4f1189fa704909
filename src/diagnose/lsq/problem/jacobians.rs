//! The analytic Jacobians of [`Problem::residual`] for the screen's two most frequent fits:
//! an added mode alone and a one-parameter path effect alone ([`Problem::refit`] uses them;
//! every other fit takes forward differences).

use super::Problem;
use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::lsq::shapes::{mode_den, mode_log_slope};
use nalgebra::DMatrix;
use num_complex::Complex64;

impl Problem<'_> {
    /// The Jacobian of [`Problem::residual`] for a lone added mode, `θ = (ln ω_n, ln ζ,
    /// ρ_1 … ρ_C)`: with `e = (G_d − (G₀ + ρ_c/d(s))·P)/σ`, `d = s² + 2ζω_n s + ω_n²`,
    /// `∂e/∂ln ω_n = ρ_c P (2ζω_n s + 2ω_n²)/(d² σ)`, `∂e/∂ln ζ = ρ_c P 2ζω_n s/(d² σ)`
    /// (zero where ζ is clamped to its bounds) and `∂e/∂ρ_c = −P/(d σ)` on channel `c`'s
    /// rows.  `false` when `jac` is not the residual's shape.
    pub(super) fn lone_mode_jacobian(
        &self,
        th: &[f64],
        mask: &[usize],
        jac: &mut DMatrix<f64>,
    ) -> bool {
        let n_ch = self.n_ch();
        if th.len() != 2 + n_ch || jac.nrows() != 2 * mask.len() * n_ch || jac.ncols() != th.len() {
            return false;
        }
        let mut nat = Vec::with_capacity(th.len());
        Cand::Mode.natural(th, &mut nat);
        let (w, z) = (nat[0], nat[1]);
        let z_free = z == th[1].exp();
        // The denominator and the log-slopes depend on the line only: once per line, not
        // once per channel (the same values).
        let per_line: Vec<(Complex64, Complex64, Complex64)> = mask
            .iter()
            .map(|&k| {
                let s = Complex64::new(0.0, self.data.omega[k]);
                let by_z = if z_free {
                    mode_log_slope(s, w, z, false)
                } else {
                    Complex64::new(0.0, 0.0)
                };
                (mode_den(s, w, z), mode_log_slope(s, w, z, true), by_z)
            })
            .collect();
        jac.fill(0.0);
        for ch in 0..n_ch {
            let rho = nat[2 + ch];
            for (q, (&k, &(den, slope_w, slope_z))) in mask.iter().zip(&per_line).enumerate() {
                let row = 2 * (ch * mask.len() + q);
                let p = self.path0[ch][k] * self.inv_sigma[ch][k];
                let by_rho = -p / den;
                let by_w = by_rho * rho * slope_w;
                let by_z = if z_free {
                    by_rho * rho * slope_z
                } else {
                    Complex64::new(0.0, 0.0)
                };
                for (col, v) in [(0, by_w), (1, by_z), (2 + ch, by_rho)] {
                    jac[(row, col)] = v.re;
                    jac[(row + 1, col)] = v.im;
                }
            }
        }
        jac.iter().all(|v| v.is_finite())
    }

    /// The Jacobian of [`Problem::residual`] for a lone one-parameter path effect `c`
    /// (delay, lag, NMP zero, ZOH: the path multiplied by `f(jω; θ)`): on a channel it acts
    /// on, `e = (G_d − core₀·path₀·f)/σ`, so `∂e/∂θ = −(G_d/σ − e)·∂ ln f/∂θ`
    /// ([`Cand::path_log_slope`], closed form) with `e` the residual `r` at θ; the folded row
    /// of the other channels does not depend on θ.  `false` when `jac` is not the residual's
    /// shape or a value is not finite.
    pub(super) fn lone_path_jacobian(
        &self,
        c: &Cand,
        th: &[f64],
        mask: &[usize],
        r: &[f64],
        jac: &mut DMatrix<f64>,
    ) -> bool {
        if th.len() != 1 || jac.ncols() != 1 || jac.nrows() != r.len() {
            return false;
        }
        let slopes: Option<Vec<Complex64>> = mask
            .iter()
            .map(|k| c.path_log_slope(th[0], self.data.omega[*k]))
            .collect();
        let Some(slopes) = slopes else {
            return false;
        };
        let mut row = 0;
        for ch in 0..self.n_ch() {
            if !c.acts_on(self.data.entries[ch]) {
                continue;
            }
            if row + 2 * mask.len() > r.len() {
                return false;
            }
            for (q, &k) in mask.iter().enumerate() {
                let e = Complex64::new(r[row], r[row + 1]);
                let d = -(self.data.g[ch][k] * self.inv_sigma[ch][k] - e) * slopes[q];
                jac[(row, 0)] = d.re;
                jac[(row + 1, 0)] = d.im;
                row += 2;
            }
        }
        match r.len() - row {
            0 => {}
            1 => jac[(row, 0)] = 0.0,
            _ => return false,
        }
        jac.iter().all(|v| v.is_finite())
    }
}

//! Starting points of each candidate's new parameters: closed-form estimates (linear least
//! squares on the residual), the best points of a 1-D grid, and for an added mode the peaks
//! of the noise-normalized misfit (effects.md, step 3).

use super::candidates::Cand;
use super::problem::{Mods, Problem};
use num_complex::Complex64;

impl Problem<'_> {
    /// Starting points for the new parameters of `c`, given the current model `cur`.
    pub(super) fn starts(&self, cur: &Mods, c: Cand, mask: &[usize]) -> Vec<Vec<f64>> {
        let gm = self.response(cur);
        let (wmin, wmax) = (self.omega[0], self.omega_max());
        let w2 = |k: usize| self.inv_sigma[k].powi(2);
        // Linear LS of e = G_d − G_m on a basis ψ: ρ = Re Σ ψ* e w / Σ|ψ|² w.
        let ls = |psi: &dyn Fn(usize) -> Complex64| -> f64 {
            let (mut a, mut b) = (0.0, 0.0);
            for &k in mask {
                let p = psi(k);
                a += (p.conj() * (self.g[k] - gm[k])).re * w2(k);
                b += p.norm_sqr() * w2(k);
            }
            if b > 0.0 {
                a / b
            } else {
                0.0
            }
        };
        // Best few points of a 1-D grid of the new parameter.
        let grid_best = |grid: &[f64], keep: usize| -> Vec<Vec<f64>> {
            let mut vs: Vec<(f64, f64)> = grid
                .iter()
                .map(|x| (self.v(&cur.with(c, &[*x]), mask), *x))
                .collect();
            let mut local: Vec<(f64, f64)> = (0..vs.len())
                .filter(|&i| {
                    (i == 0 || vs[i].0 <= vs[i - 1].0)
                        && (i + 1 == vs.len() || vs[i].0 <= vs[i + 1].0)
                })
                .map(|i| vs[i])
                .collect();
            local.sort_by(|a, b| a.0.total_cmp(&b.0));
            vs.sort_by(|a, b| a.0.total_cmp(&b.0));
            local
                .into_iter()
                .chain(vs)
                .take(keep)
                .map(|(_, x)| vec![x])
                .collect()
        };
        let log_grid = |lo: f64, hi: f64, n: usize| -> Vec<f64> {
            (0..n)
                .map(|i| lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1) as f64)
                .collect()
        };
        // The path of the current model at each datum (for additive bases).
        let path_of = |k: usize| {
            let mut core = self.core0[k];
            let mut path = self.path0[k];
            let mut off = 0;
            for cc in &cur.cands {
                let n = cc.n_params();
                cc.modify(
                    &cur.theta[off..off + n],
                    self.base,
                    self.omega[k],
                    &mut core,
                    &mut path,
                );
                off += n;
            }
            path
        };
        let s = |k: usize| Complex64::new(0.0, self.omega[k]);
        match c {
            Cand::Sign => vec![vec![]],
            Cand::Gain => vec![vec![1.0 + ls(&|k| gm[k])]],
            Cand::Delay => {
                let step = 0.05 / wmax;
                let grid: Vec<f64> = (0..=((6.0 * std::f64::consts::PI / 0.05) as usize))
                    .map(|j| (j as f64 + 0.5) * step)
                    .collect();
                grid_best(&grid, 3)
            }
            Cand::Lag | Cand::NmpZero => grid_best(&log_grid(wmin / 3.0, wmax * 30.0, 40), 3),
            Cand::Zoh => grid_best(&log_grid(0.01 / wmax, 3.0 / wmax, 40), 3),
            Cand::Integrator(o) => {
                vec![vec![ls(&|k| path_of(k) / s(k).powi(o as i32))]]
            }
            Cand::Feedthrough => vec![vec![ls(&|k| path_of(k))]],
            Cand::ModeShift(i) => {
                let w0 = self.base.mode[i].omega_n;
                let grid: Vec<f64> = (0..61)
                    .map(|j| w0.ln() + (j as f64 - 30.0) / 60.0)
                    .collect();
                grid_best(&grid, 3)
            }
            Cand::Damping(i) => {
                let _ = i;
                grid_best(&log_grid(1e-3, 0.7, 30), 3)
            }
            Cand::Friction(_) => grid_best(&log_grid(wmin / 1000.0, wmax, 40), 3),
            Cand::Mode => {
                // ω_n candidates: local maxima of |e|/r, plus a log grid over the band.
                let c: Vec<f64> = (0..self.f())
                    .map(|k| (self.g[k] - gm[k]).norm() / self.radius[k])
                    .collect();
                let mut peaks: Vec<(f64, f64)> = (0..self.f())
                    .filter(|&k| {
                        (k == 0 || c[k] >= c[k - 1]) && (k + 1 == self.f() || c[k] >= c[k + 1])
                    })
                    .map(|k| (c[k], self.omega[k]))
                    .collect();
                peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
                let mut ws: Vec<f64> = peaks.iter().take(4).map(|p| p.1).collect();
                ws.extend(log_grid(wmin, wmax, 30).iter().map(|x| x.exp()));
                let mut trials: Vec<(f64, Vec<f64>)> = Vec::new();
                for w in ws {
                    for z in [0.005, 0.02, 0.06, 0.2, 0.5] {
                        let rho = ls(&|k| path_of(k) / (s(k) * s(k) + 2.0 * z * w * s(k) + w * w));
                        let th = vec![w.ln(), f64::ln(z), rho];
                        trials.push((self.v(&cur.with(Cand::Mode, &th), mask), th));
                    }
                }
                trials.sort_by(|a, b| a.0.total_cmp(&b.0));
                trials.into_iter().take(4).map(|t| t.1).collect()
            }
        }
    }
}

//! Starting points of each candidate's new parameters: closed-form estimates (linear least
//! squares on the residual, one residue per channel), the best points of a 1-D grid, and for
//! an added mode the peaks of the noise-normalized misfit (docs/design/effects.md, step 3)
//! and the poles of the residual an LSCF stabilization diagram proposes ([`crate::diagnose::effects::lscf`]).

use crate::diagnose::effects::candidates::{Cand, Sel};
use crate::diagnose::lsq::problem::{Mods, Problem};
use num_complex::Complex64;

impl Problem<'_> {
    /// Starting points for the new parameters of `c`, given the current model `cur`.
    pub(crate) fn starts(&self, cur: &Mods, c: Cand, mask: &[usize]) -> Vec<Vec<f64>> {
        let gm = self.response(cur);
        let (wmin, wmax) = (self.omega_min(), self.omega_max());
        let om = self.omega();
        let n_ch = self.n_ch();
        let ls = |chs: &[usize], psi: &dyn Fn(usize, usize) -> Complex64| -> f64 {
            self.ls_coefficient(&gm, chs, mask, psi)
        };
        // Best few points of a 1-D grid of the new parameter: the grid's local minima by
        // cost, then the rest by cost.
        let pick = |mut vs: Vec<(f64, f64)>, keep: usize| -> Vec<Vec<f64>> {
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
        let grid_best = |grid: &[f64], keep: usize| -> Vec<Vec<f64>> {
            let vs = grid
                .iter()
                .map(|x| (self.v(&cur.with(c, &[*x]), mask), *x))
                .collect();
            pick(vs, keep)
        };
        let log_grid = |lo: f64, hi: f64, n: usize| -> Vec<f64> {
            (0..n)
                .map(|i| lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1) as f64)
                .collect()
        };
        // The path of the current model at each datum (for additive bases).
        let path_of = |ch: usize, k: usize| self.parts(cur, ch, Some(k), om[k]).1;
        let s = |k: usize| Complex64::new(0.0, om[k]);
        let sel_chans = |sel: Sel| -> Vec<usize> {
            (0..n_ch)
                .filter(|ch| sel.hits(self.data.entries[*ch]))
                .collect()
        };
        match c {
            Cand::Sign(_) => vec![vec![]],
            Cand::Gain(sel) => vec![vec![1.0 + ls(&sel_chans(sel), &|ch, k| gm[ch][k])]],
            Cand::Delay(sel) => {
                let step = 0.05 / wmax;
                let n = (6.0 * std::f64::consts::PI / 0.05) as usize + 1;
                pick(self.delay_grid(&gm, sel, mask, step, n), 3)
            }
            Cand::Lag(_) | Cand::NmpZero(_) => grid_best(&log_grid(wmin / 3.0, wmax * 30.0, 40), 3),
            Cand::Zoh(_) => grid_best(&log_grid(0.01 / wmax, 3.0 / wmax, 40), 3),
            Cand::Integrator(o) => vec![(0..n_ch)
                .map(|ch| ls(&[ch], &|ch, k| path_of(ch, k) / s(k).powi(o as i32)))
                .collect()],
            Cand::Feedthrough => vec![(0..n_ch)
                .map(|ch| ls(&[ch], &|ch, k| path_of(ch, k)))
                .collect()],
            Cand::ModeShift(i) => {
                let w0 = self.base.mode[i].omega_n;
                let grid: Vec<f64> = (0..61)
                    .map(|j| w0.ln() + (j as f64 - 30.0) / 60.0)
                    .collect();
                grid_best(&grid, 3)
            }
            Cand::Damping(_) => grid_best(&log_grid(1e-3, 0.7, 30), 3),
            Cand::Friction(_) => grid_best(&log_grid(wmin / 1000.0, wmax, 40), 3),
            Cand::Mode => {
                // ω_n candidates: local maxima of the worst channel's |e|/r (five dampings
                // each), plus the LSCF proposals; residues by LS per channel.
                let (cw, _) = self.invalid_flags(cur);
                let f = self.f();
                let mut peaks: Vec<(f64, f64)> = (0..f)
                    .filter(|&k| {
                        (k == 0 || cw[k] >= cw[k - 1]) && (k + 1 == f || cw[k] >= cw[k + 1])
                    })
                    .map(|k| (cw[k], om[k]))
                    .collect();
                peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
                let zetas = [0.005, 0.02, 0.06, 0.2, 0.5];
                let mut points: Vec<(f64, f64)> = peaks
                    .iter()
                    .take(4)
                    .flat_map(|p| zetas.map(|z| (p.1, z)))
                    .collect();
                // The poles of the residual stable across the orders of an LSCF diagram
                // (`crate::diagnose::effects::lscf`), at their own damping; the log grid over the band only
                // when the diagram has none.
                let proposals = self.mode_proposals(&gm, mask);
                if proposals.is_empty() {
                    points.extend(
                        log_grid(wmin, wmax, 30)
                            .iter()
                            .flat_map(|x| zetas.map(|z| (x.exp(), z))),
                    );
                }
                points.extend(proposals.iter().map(|p| (p.omega_n, p.zeta)));
                let mut trials: Vec<(f64, Vec<f64>)> = Vec::new();
                for (w, z) in points {
                    let th = self.mode_theta(cur, &gm, w, z, mask);
                    trials.push((self.v(&cur.with(Cand::Mode, &th), mask), th));
                }
                trials.sort_by(|a, b| a.0.total_cmp(&b.0));
                trials.into_iter().take(4).map(|t| t.1).collect()
            }
        }
    }

    /// Linear least squares of the residual `e = G_d − G_m` (`gm`: the model's response) on
    /// a basis `ψ` over the channels `chs` and the data in `mask`, noise-weighted:
    /// `ρ = Re Σ ψ* e w / Σ |ψ|² w` (0 when the basis vanishes or the sum is not finite).
    pub(crate) fn ls_coefficient(
        &self,
        gm: &[Vec<Complex64>],
        chs: &[usize],
        mask: &[usize],
        psi: &dyn Fn(usize, usize) -> Complex64,
    ) -> f64 {
        let (mut a, mut b) = (0.0, 0.0);
        for &ch in chs {
            for &k in mask {
                let w2 = self.inv_sigma[ch][k].powi(2);
                let p = psi(ch, k);
                a += (p.conj() * (self.data.g[ch][k] - gm[ch][k])).re * w2;
                b += p.norm_sqr() * w2;
            }
        }
        if b > 0.0 && a.is_finite() {
            a / b
        } else {
            0.0
        }
    }

    /// The parameters `[ln ω_n, ln ζ, ρ_1 … ρ_C]` of an added mode at `(w, z)` on the model
    /// `cur` (response `gm`): each channel's residue by [`Problem::ls_coefficient`] on the
    /// basis `path/(s² + 2ζω_n s + ω_n²)`.
    pub(crate) fn mode_theta(
        &self,
        cur: &Mods,
        gm: &[Vec<Complex64>],
        w: f64,
        z: f64,
        mask: &[usize],
    ) -> Vec<f64> {
        let om = self.omega();
        let mut th = vec![w.ln(), f64::ln(z)];
        for ch in 0..self.n_ch() {
            th.push(self.ls_coefficient(gm, &[ch], mask, &|ch, k| {
                let s = Complex64::new(0.0, om[k]);
                self.parts(cur, ch, Some(k), om[k]).1 / (s * s + 2.0 * z * w * s + w * w)
            }));
        }
        th
    }

    /// The mode proposals of an LSCF stabilization diagram ([`crate::diagnose::effects::lscf`]) on the
    /// residual `G_d − G_m` (`gm`: the current model) at the data in `mask`, noise-weighted.
    pub(crate) fn mode_proposals(
        &self,
        gm: &[Vec<Complex64>],
        mask: &[usize],
    ) -> Vec<crate::diagnose::effects::lscf::Proposal> {
        let omega: Vec<f64> = mask.iter().map(|k| self.omega()[*k]).collect();
        let h: Vec<Vec<Complex64>> = (0..self.n_ch())
            .map(|ch| {
                mask.iter()
                    .map(|k| self.data.g[ch][*k] - gm[ch][*k])
                    .collect()
            })
            .collect();
        let w: Vec<Vec<f64>> = (0..self.n_ch())
            .map(|ch| mask.iter().map(|k| self.inv_sigma[ch][*k]).collect())
            .collect();
        crate::diagnose::effects::lscf::propose(
            &crate::diagnose::effects::lscf::Frf {
                omega: &omega,
                h: &h,
                w: &w,
            },
            &Default::default(),
        )
    }

    /// The cost with a delay `τ_j = (j + ½)·step` (`j < n`) on the channels of `sel`, the
    /// model otherwise `gm`: `(V(τ_j), τ_j)`.  A delay multiplies the model by `e^{−jωτ}`,
    /// so along the uniform grid the factor at each datum advances by one rotation
    /// `e^{−jω·step}` (a complex product instead of an `exp` of the whole model per point;
    /// the same costs to rounding).
    fn delay_grid(
        &self,
        gm: &[Vec<Complex64>],
        sel: Sel,
        mask: &[usize],
        step: f64,
        n: usize,
    ) -> Vec<(f64, f64)> {
        let om = self.omega();
        let mut fixed = 0.0;
        // Per hit datum: the data, the model, the weight, the factor and its rotation.
        let mut hit: Vec<(Complex64, Complex64, f64, Complex64, Complex64)> = Vec::new();
        for (ch, gm_ch) in gm.iter().enumerate() {
            let on = sel.hits(self.data.entries[ch]);
            for &k in mask {
                let (g, m, w) = (self.data.g[ch][k], gm_ch[k], self.inv_sigma[ch][k]);
                if on {
                    let rot = Complex64::from_polar(1.0, -om[k] * step);
                    let first = Complex64::from_polar(1.0, -om[k] * 0.5 * step);
                    hit.push((g, m, w, first, rot));
                } else {
                    fixed += ((g - m) * w).norm_sqr();
                }
            }
        }
        (0..n)
            .map(|j| {
                let mut v = fixed;
                for (g, m, w, f, rot) in hit.iter_mut() {
                    v += ((*g - *m * *f) * *w).norm_sqr();
                    *f *= *rot;
                }
                let v = if v.is_finite() { v } else { f64::INFINITY };
                (v, (j as f64 + 0.5) * step)
            })
            .collect()
    }
}

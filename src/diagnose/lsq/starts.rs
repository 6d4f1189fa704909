//! Starting points of each candidate's new parameters: closed-form estimates (linear least
//! squares on the residual, one residue per channel), the best points of a 1-D grid, and for
//! an added mode the peaks of the noise-normalized misfit (docs/design/effects.md, step 3)
//! and the poles of the residual an LSCF stabilization diagram proposes ([`crate::diagnose::effects::lscf`]).

use crate::diagnose::effects::candidates::{Cand, Sel};
use crate::diagnose::effects::effect::Site;
use crate::diagnose::lsq::problem::{Mods, Problem};
use crate::model::physical::PhysicalModel;
use num_complex::Complex64;

/// The least-squares problem as an effect's starts see it ([`Site`]): the current model
/// `cur` (response `gm`), candidate `c` and the data in `mask`.
struct StartSite<'p, 'a> {
    p: &'p Problem<'a>,
    cur: &'p Mods,
    c: Cand,
    mask: &'p [usize],
    gm: Vec<Vec<Complex64>>,
}

impl Site for StartSite<'_, '_> {
    fn omega(&self) -> &[f64] {
        self.p.omega()
    }

    fn band(&self) -> (f64, f64) {
        (self.p.omega_min(), self.p.omega_max())
    }

    fn n_ch(&self) -> usize {
        self.p.n_ch()
    }

    fn base(&self) -> &PhysicalModel {
        self.p.base
    }

    fn channels(&self, sel: Sel) -> Vec<usize> {
        (0..self.p.n_ch())
            .filter(|ch| sel.hits(self.p.data.entries[*ch]))
            .collect()
    }

    fn response(&self, ch: usize, k: usize) -> Complex64 {
        self.gm[ch][k]
    }

    fn path(&self, ch: usize, k: usize) -> Complex64 {
        let om = self.p.omega();
        self.p.parts(self.cur, ch, Some(k), om[k]).1
    }

    fn ls(&self, chs: &[usize], psi: &dyn Fn(usize, usize) -> Complex64) -> f64 {
        self.p.ls_coefficient(&self.gm, chs, self.mask, psi)
    }

    fn cost(&self, th: &[f64]) -> f64 {
        self.p.v(&self.cur.with(self.c, th), self.mask)
    }

    fn delay_costs(&self, sel: Sel, step: f64, n: usize) -> Vec<(f64, f64)> {
        self.p.delay_grid(&self.gm, sel, self.mask, step, n)
    }

    fn worst_misfit(&self) -> Vec<f64> {
        self.p.invalid_flags(self.cur).0
    }

    fn mode_proposals(&self) -> Vec<(f64, f64)> {
        self.p
            .mode_proposals(&self.gm, self.mask)
            .iter()
            .map(|p| (p.omega_n, p.zeta))
            .collect()
    }

    fn mode_theta(&self, w: f64, z: f64) -> Vec<f64> {
        self.p.mode_theta(self.cur, &self.gm, w, z, self.mask)
    }
}

impl Problem<'_> {
    /// Starting points for the new parameters of `c`, given the current model `cur`: each
    /// effect's own ([`crate::diagnose::effects::effect::Effect::starts`]).
    pub(crate) fn starts(&self, cur: &Mods, c: Cand, mask: &[usize]) -> Vec<Vec<f64>> {
        let site = StartSite {
            p: self,
            cur,
            c,
            mask,
            gm: self.response(cur),
        };
        c.starts(&site)
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

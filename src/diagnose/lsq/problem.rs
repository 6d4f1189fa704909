//! The diagnose fitting problem: data channels with noise radii, the base model split as
//! `core · path` per channel, candidate effects on top (`Mods`), the cost
//! `V = Σ_ch Σ_k |G_d − Ĝ(θ)|²/σ²` (`σ = r/√2`, noise uniform in the disk of radius `r`), and
//! the bounded Levenberg–Marquardt refit of every candidate parameter.

use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::effects::effect::Stands;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::lm::{lm_box_jac, LmSettings};
use crate::diagnose::lsq::measures::{measures_of, Measures};
use crate::diagnose::lsq::shapes::path_at;
use crate::error::{Error, Result};
use crate::model::physical::PhysicalModel;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The fitting problem.
pub struct Problem<'a> {
    pub(crate) base: &'a PhysicalModel,
    pub(crate) data: &'a Channels,
    pub(crate) inv_sigma: Vec<Vec<f64>>,
    pub(crate) core0: Vec<Vec<Complex64>>,
    pub(crate) path0: Vec<Vec<Complex64>>,
    /// Residue of each configured mode at each channel, `[ch][mode]`.
    mode_rho: Vec<Vec<f64>>,
    /// Residue of each rigid body at each channel, `[ch][body]`.
    rigid_rho: Vec<Vec<f64>>,
    /// The record's lower bound on ζ ([`super::resolution::band_floor`]).
    pub(crate) zeta_floor: f64,
    /// The weighted residual of the base model, `(G_d − core₀·path₀)/σ`, `[ch][k]`: a
    /// channel no effect of the model acts on (a path effect on one input leaves the other
    /// channels as they are) keeps these rows, computed once ([`Problem::residual`]).
    e0: Vec<Vec<Complex64>>,
    /// `Σ_k |e0[ch][k]|²` over every datum in index order, per channel: the folded row's
    /// share of a channel on the whole band, summed once (the same sum a residual on every
    /// datum would form).
    e0_sum: Vec<f64>,
}

/// A model: the base plus effects with their internal parameters (concatenated).
#[derive(Debug, Clone, Default)]
pub struct Mods {
    /// The effects, in order.
    pub cands: Vec<Cand>,
    /// Their parameters, concatenated.
    pub theta: Vec<f64>,
}

impl Mods {
    pub(crate) fn with(&self, c: Cand, th: &[f64]) -> Mods {
        let mut m = self.clone();
        m.cands.push(c);
        m.theta.extend_from_slice(th);
        m
    }
}

/// Checks that `base` can be diagnosed on `data`: sizes agree, and with several channels
/// the model has one input or one output (so a residue per channel is a modal `c bᵀ`).
pub fn check_shapes(base: &PhysicalModel, data: &Channels) -> Result<()> {
    let (p, m) = (base.n_outputs(), base.n_inputs());
    if data.entries.iter().any(|(o, i)| *o >= p || *i >= m) {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!("the data channels do not fit the {p}×{m} model"),
        });
    }
    if data.n_ch() > 1 && p > 1 && m > 1 {
        return Err(Error::Invalid(
            "diagnose of several channels needs a model with one input or one output (each added mode gets a residue per channel); pick one channel with --channel OUT,IN".into(),
        ));
    }
    Ok(())
}

impl<'a> Problem<'a> {
    /// Sets up the problem.
    pub fn new(base: &'a PhysicalModel, data: &'a Channels) -> Result<Self> {
        check_shapes(base, data)?;
        let mut core0: Vec<Vec<Complex64>> = Vec::new();
        let mut path0: Vec<Vec<Complex64>> = Vec::new();
        let cores: Vec<DMatrix<Complex64>> =
            data.omega.iter().map(|w| base.eval_core(*w)).collect();
        for e in &data.entries {
            core0.push(cores.iter().map(|c| c[*e]).collect());
            path0.push(data.omega.iter().map(|w| path_at(base, *w, *e)).collect());
        }
        // Residues of the configured terms a candidate changes, `[ch][term]`.
        let table = |n: usize, cand: fn(usize) -> Cand| -> Vec<Vec<f64>> {
            data.entries
                .iter()
                .map(|e| (0..n).map(|i| cand(i).base_residue(base, *e)).collect())
                .collect()
        };
        let mode_rho = table(base.mode.len(), Cand::ModeShift);
        let rigid_rho = table(base.rigid_body.len(), Cand::Friction);
        let inv_sigma: Vec<Vec<f64>> = data
            .radius
            .iter()
            .map(|r| r.iter().map(|x| std::f64::consts::SQRT_2 / x).collect())
            .collect();
        // The same expression as the residual's, so a cached row is the row it replaces.
        let e0: Vec<Vec<Complex64>> = (0..data.n_ch())
            .map(|ch| {
                (0..data.len())
                    .map(|k| (data.g[ch][k] - core0[ch][k] * path0[ch][k]) * inv_sigma[ch][k])
                    .collect()
            })
            .collect();
        let e0_sum = e0
            .iter()
            .map(|e| e.iter().map(|x| x.norm_sqr()).sum::<f64>())
            .collect();
        Ok(Self {
            base,
            data,
            mode_rho,
            rigid_rho,
            inv_sigma,
            core0,
            path0,
            zeta_floor: super::resolution::band_floor(data),
            e0,
            e0_sum,
        })
    }

    /// Number of frequencies.
    pub(crate) fn f(&self) -> usize {
        self.data.len()
    }

    /// Number of channels.
    pub(crate) fn n_ch(&self) -> usize {
        self.data.n_ch()
    }

    /// Number of complex data (for `ln(2F)` in the BIC).
    pub(crate) fn n_data(&self) -> usize {
        self.data.n_data()
    }

    pub(crate) fn omega(&self) -> &[f64] {
        &self.data.omega
    }

    pub(crate) fn omega_max(&self) -> f64 {
        *self.data.omega.last().expect("data")
    }

    pub(crate) fn omega_min(&self) -> f64 {
        self.data.omega[0]
    }

    /// `(core, path)` of channel `ch` with `mods` applied, at datum `k` or at any `ω` with
    /// `k = None`.
    pub(crate) fn parts(
        &self,
        mods: &Mods,
        ch: usize,
        k: Option<usize>,
        omega: f64,
    ) -> (Complex64, Complex64) {
        self.parts_nat(mods, &self.naturals_of(mods), ch, k, omega)
    }

    /// The natural parameters of every effect of `mods`, concatenated ([`Cand::natural`]).
    fn naturals_of(&self, mods: &Mods) -> Vec<f64> {
        let n_ch = self.n_ch();
        let mut nat = Vec::with_capacity(mods.theta.len());
        let mut off = 0;
        for c in &mods.cands {
            let n = c.n_params(n_ch);
            c.natural(&mods.theta[off..off + n], &mut nat);
            off += n;
        }
        nat
    }

    /// Per effect of `mods` on channel `ch`: where its natural parameters start in `nat`,
    /// how many, and the residue of the configured term it changes (the same at every
    /// datum, so a residual looks them up once per channel).
    fn channel_terms(&self, mods: &Mods, ch: usize) -> Vec<(usize, usize, f64)> {
        let entry = self.data.entries[ch];
        let n_ch = self.n_ch();
        let mut off = 0;
        mods.cands
            .iter()
            .map(|c| {
                let n = c.n_params(n_ch);
                // The residues of the configured terms are cached; the others' are not (0
                // for every effect that changes no configured term).
                let rho = match c.stands() {
                    Stands::ConfiguredMode(i) => self.mode_rho[ch][i],
                    Stands::FrictionPole(i) => self.rigid_rho[ch][i],
                    Stands::AddedMode
                    | Stands::AddedPoleAtZero(_)
                    | Stands::Feedthrough
                    | Stands::AddedPathEffect => c.base_residue(self.base, entry),
                };
                off += n;
                (off - n, n, rho)
            })
            .collect()
    }

    /// [`Problem::parts`] with the natural parameters `nat` of `mods` computed once.
    fn parts_nat(
        &self,
        mods: &Mods,
        nat: &[f64],
        ch: usize,
        k: Option<usize>,
        omega: f64,
    ) -> (Complex64, Complex64) {
        let terms = self.channel_terms(mods, ch);
        self.parts_at(mods, nat, &terms, ch, k, omega)
    }

    /// [`Problem::parts_nat`] with the channel's [`Problem::channel_terms`] given.
    fn parts_at(
        &self,
        mods: &Mods,
        nat: &[f64],
        terms: &[(usize, usize, f64)],
        ch: usize,
        k: Option<usize>,
        omega: f64,
    ) -> (Complex64, Complex64) {
        let entry = self.data.entries[ch];
        let (mut core, mut path) = match k {
            Some(k) => (self.core0[ch][k], self.path0[ch][k]),
            None => (
                self.base.eval_core(omega)[entry],
                path_at(self.base, omega, entry),
            ),
        };
        for (c, &(off, n, rho)) in mods.cands.iter().zip(terms) {
            c.modify_natural(
                &nat[off..off + n],
                rho,
                self.base,
                omega,
                ch,
                entry,
                &mut core,
                &mut path,
            );
        }
        (core, path)
    }

    /// Model response at the data, `[ch][k]`.
    pub fn response(&self, mods: &Mods) -> Vec<Vec<Complex64>> {
        let nat = self.naturals_of(mods);
        let all: Vec<usize> = (0..self.f()).collect();
        let (mut core, mut path) = (Vec::new(), Vec::new());
        (0..self.n_ch())
            .map(|ch| {
                self.channel_parts(mods, &nat, ch, &all, &mut core, &mut path);
                core.iter().zip(&path).map(|(c, p)| c * p).collect()
            })
            .collect()
    }

    /// `(core, path)` of channel `ch` with `mods` applied at the data in `mask`, into
    /// `core` and `path` (one entry per datum of `mask`): [`Problem::parts_at`] effect by
    /// effect over the channel's data ([`Cand::modify_natural_many`]), the same values.
    fn channel_parts(
        &self,
        mods: &Mods,
        nat: &[f64],
        ch: usize,
        mask: &[usize],
        core: &mut Vec<Complex64>,
        path: &mut Vec<Complex64>,
    ) {
        let (c0, p0) = (&self.core0[ch], &self.path0[ch]);
        core.clear();
        core.extend(mask.iter().map(|k| c0[*k]));
        path.clear();
        path.extend(mask.iter().map(|k| p0[*k]));
        let entry = self.data.entries[ch];
        for (c, (off, n, rho)) in mods.cands.iter().zip(self.channel_terms(mods, ch)) {
            c.modify_natural_many(
                &nat[off..off + n],
                rho,
                self.base,
                &self.data.omega,
                mask,
                ch,
                entry,
                core,
                path,
            );
        }
    }

    /// The weighted residual `(G_d − Ĝ)/σ` (real and imaginary parts, channel by channel) on
    /// the data in `mask`, with the rows of the channels no effect of `mods` acts on folded
    /// into one last row, the root of their sum of squares (none when every channel is acted
    /// on): the cost `Σ r²` is the whole residual's (to rounding), and the other rows'
    /// derivatives are the whole residual's (the folded rows do not depend on the
    /// parameters).  A fit of a path effect on one input of nine carries a ninth of the rows.
    pub(crate) fn residual(&self, mods: &Mods, mask: &[usize], out: &mut Vec<f64>) {
        out.clear();
        self.residual_rows(mods, mask, &mut |x| out.push(x));
    }

    /// [`Problem::residual`]'s rows, in order, each handed to `row`.
    fn residual_rows<F: FnMut(f64)>(&self, mods: &Mods, mask: &[usize], row: &mut F) {
        let nat = self.naturals_of(mods);
        let whole = mask.len() == self.f() && mask.iter().enumerate().all(|(i, k)| i == *k);
        let mut fixed: Option<f64> = None;
        let (mut core, mut path) = (Vec::new(), Vec::new());
        for ch in 0..self.n_ch() {
            let entry = self.data.entries[ch];
            if !mods.cands.iter().any(|c| c.acts_on(entry)) {
                let e0 = &self.e0[ch];
                *fixed.get_or_insert(0.0) += if whole {
                    self.e0_sum[ch]
                } else {
                    mask.iter().map(|k| e0[*k].norm_sqr()).sum::<f64>()
                };
                continue;
            }
            self.channel_parts(mods, &nat, ch, mask, &mut core, &mut path);
            let (g, w) = (&self.data.g[ch], &self.inv_sigma[ch]);
            for ((&k, c), p) in mask.iter().zip(&core).zip(&path) {
                let e = (g[k] - c * p) * w[k];
                row(e.re);
                row(e.im);
            }
        }
        if let Some(f) = fixed {
            row(f.sqrt());
        }
    }

    /// The cost `Σ r²` of [`Problem::residual`] (summed row by row in its order, so the
    /// same value, without storing the rows); `∞` when it is not finite.
    pub(crate) fn v(&self, mods: &Mods, mask: &[usize]) -> f64 {
        let mut v = 0.0;
        self.residual_rows(mods, mask, &mut |x| v += x * x);
        if v.is_finite() {
            v
        } else {
            f64::INFINITY
        }
    }

    /// Normalized misfit `|e|/r` per channel and datum.
    pub(crate) fn misfits(&self, mods: &Mods) -> Vec<Vec<f64>> {
        let gm = self.response(mods);
        (0..self.n_ch())
            .map(|ch| {
                (0..self.f())
                    .map(|k| (self.data.g[ch][k] - gm[ch][k]).norm() / self.data.radius[ch][k])
                    .collect()
            })
            .collect()
    }

    /// Error measures of a model on all data.
    pub fn measures(&self, mods: &Mods) -> Measures {
        measures_of(&self.misfits(mods))
    }

    /// Per frequency: the largest misfit over the channels, and whether any channel is
    /// invalid there.
    pub(crate) fn invalid_flags(&self, mods: &Mods) -> (Vec<f64>, Vec<bool>) {
        let c = self.misfits(mods);
        let worst: Vec<f64> = (0..self.f())
            .map(|k| c.iter().map(|ch| ch[k]).fold(0.0, f64::max))
            .collect();
        let flags = worst.iter().map(|x| *x > 1.0).collect();
        (worst, flags)
    }

    /// Box bounds of every parameter of `mods`.
    pub(crate) fn bounds(&self, mods: &Mods) -> (Vec<f64>, Vec<f64>) {
        let (mut lo, mut hi) = (Vec::new(), Vec::new());
        for c in &mods.cands {
            for (a, b) in c.bounds(
                self.n_ch(),
                self.omega_min(),
                self.omega_max(),
                self.zeta_floor,
            ) {
                lo.push(a);
                hi.push(b);
            }
        }
        (lo, hi)
    }

    /// Joint bounded LM fit of `mods` (all its parameters free) on the data in `mask`.
    pub(crate) fn refit(&self, mods: &Mods, mask: &[usize]) -> (Mods, f64, DMatrix<f64>) {
        if mods.theta.is_empty() {
            return (mods.clone(), self.v(mods, mask), DMatrix::zeros(0, 0));
        }
        let mut typ = Vec::new();
        let mut off = 0;
        for c in &mods.cands {
            let n = c.n_params(self.n_ch());
            typ.extend(c.typ(&mods.theta[off..off + n], self.omega_max()));
            off += n;
        }
        let (lo, hi) = self.bounds(mods);
        let cands = mods.cands.clone();
        // An added mode fitted alone (the screen's most frequent fit, from several starts)
        // and a one-parameter path effect fitted alone (the screen's most numerous fits:
        // four effects on every input) have analytic Jacobians; every other fit, forward
        // differences.
        let lone_mode = mods.cands == [Cand::Mode];
        let lone_path = match mods.cands.as_slice() {
            [c] if c.path_log_slope(mods.theta[0], self.omega_max()).is_some() => Some(*c),
            _ => None,
        };
        let res = lm_box_jac(
            |th: &[f64], out: &mut Vec<f64>| {
                let m = Mods {
                    cands: cands.clone(),
                    theta: th.to_vec(),
                };
                self.residual(&m, mask, out)
            },
            &|th: &[f64], r: &[f64], jac: &mut DMatrix<f64>| {
                (lone_mode && self.lone_mode_jacobian(th, mask, jac))
                    || lone_path.is_some_and(|c| self.lone_path_jacobian(&c, th, mask, r, jac))
            },
            &mods.theta,
            &typ,
            &lo,
            &hi,
            &LmSettings::likelihood(80),
        );
        (
            Mods {
                cands: mods.cands.clone(),
                theta: res.theta,
            },
            res.v,
            res.jtj,
        )
    }
}

mod jacobians;
#[cfg(test)]
mod tests;

//! `diagnose`: rank candidate missing effects by how much each lowers the error once fitted,
//! and add them greedily.
//!
//! * Noise: `σ_k = r_k/√2` (noise uniform in the disk of radius `r_k`); the cost is
//!   `V = Σ|G_d − Ĝ(θ)|²/σ_k²` (`E V ≈ F` for a right model), the complex-Gaussian `−ln L`.
//! * Each candidate is fitted by Levenberg–Marquardt from the best points of a grid or a
//!   closed-form estimate (effects.md), jointly with every effect accepted before.
//! * Score: `ΔBIC = 2(V₀ − V) − n_θ·ln(2F)`. A candidate **passes** when ΔBIC > 10, the
//!   invalid fraction does not rise, and the holdout checks pass: fit on 3 of every 4 data,
//!   the held-out quarter's `V` must fall too; for a global (multiplicative) candidate, also
//!   fit below 70 % of the band (log frequency) and the top 30 %'s `V` must fall.
//! * Stop when the model is consistent (`invalid_fraction ≤ 5 %` and `misfit_rms ≤ 1`), when no
//!   candidate passes, or after `max_effects` effects. Candidates within 6 of the best BIC are
//!   reported as ties, with the frequency range where the two fitted models differ by more
//!   than the noise.

use super::candidates::{explain, fmt_w, Cand};
use super::compare::{bands, Siso, MAX_INVALID_FRACTION, MAX_MISFIT_RMS};
use super::fit::lm;
use super::nominal::refit_nominal;
pub use super::report::{CandidateReport, Diagnosis, Step, Tie};
use crate::error::{Error, Result};
use crate::model::physical::PhysicalModel;
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::Serialize;
use std::collections::BTreeMap;

/// ΔBIC a candidate needs to be accepted.
pub const MIN_DELTA_BIC: f64 = 10.0;
/// BIC gap under which two candidates are a tie.
pub const TIE_BIC: f64 = 6.0;
/// Extrapolation holdout: fit below this share of the band (log frequency), predict above.
pub const EXTRAPOLATION_SPLIT: f64 = 0.7;
/// Fewest data on either side of the split for the extrapolation holdout to run.
pub const MIN_SPLIT_DATA: usize = 8;

/// The fitting problem: data, noise and the base model split as `core · path`.
pub struct Problem<'a> {
    base: &'a PhysicalModel,
    omega: Vec<f64>,
    g: Vec<Complex64>,
    radius: Vec<f64>,
    inv_sigma: Vec<f64>,
    core0: Vec<Complex64>,
    path0: Vec<Complex64>,
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
    fn with(&self, c: Cand, th: &[f64]) -> Mods {
        let mut m = self.clone();
        m.cands.push(c);
        m.theta.extend_from_slice(th);
        m
    }
}

/// Error measures of a model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Measures {
    /// `Σ|e|²/σ²`.
    pub v: f64,
    /// `sqrt(mean (|e|/r)²)`.
    pub misfit_rms: f64,
    /// Share of data with `|e| > r`.
    pub invalid_fraction: f64,
}

impl Measures {
    /// Explained within the noise.
    pub fn consistent(&self) -> bool {
        self.invalid_fraction <= MAX_INVALID_FRACTION && self.misfit_rms <= MAX_MISFIT_RMS
    }
}

impl<'a> Problem<'a> {
    /// Sets up the problem; the model must be SISO and the noise radius known.
    pub fn new(base: &'a PhysicalModel, siso: &Siso) -> Result<Self> {
        if base.n_inputs() != 1 || base.n_outputs() != 1 {
            return Err(Error::Invalid(
                "diagnose works on a SISO [physical] model: describe the selected channel as a SISO model".into(),
            ));
        }
        let radius = siso.radius.clone().ok_or_else(|| {
            Error::Invalid(format!(
                "{}: diagnose needs the noise radius: pass --noise-radius X, add a noise_radius column, or [noise] radius / std_file",
                siso.path.display()
            ))
        })?;
        let core0: Vec<Complex64> = siso
            .omega
            .iter()
            .map(|w| base.eval_core(*w)[(0, 0)])
            .collect();
        let path0 = siso
            .omega
            .iter()
            .map(|w| {
                base.effect
                    .iter()
                    .fold(Complex64::new(1.0, 0.0), |a, e| a * e.eval(*w))
            })
            .collect();
        Ok(Self {
            base,
            omega: siso.omega.clone(),
            g: siso.g.clone(),
            inv_sigma: radius
                .iter()
                .map(|r| std::f64::consts::SQRT_2 / r)
                .collect(),
            radius,
            core0,
            path0,
        })
    }

    fn f(&self) -> usize {
        self.omega.len()
    }

    /// Indices of the data below and above `ω_min·(ω_max/ω_min)^share`.
    fn split_band(&self, share: f64) -> (Vec<usize>, Vec<usize>) {
        let (lo, hi) = (self.omega[0].max(1e-300), self.omega_max().max(1e-300));
        let w = (lo.ln() + share * (hi.ln() - lo.ln())).exp();
        (0..self.f()).partition(|&k| self.omega[k] < w)
    }

    fn omega_max(&self) -> f64 {
        *self.omega.last().expect("data")
    }

    /// Model response at datum `k`, or at any `ω` with `k = None`.
    fn eval_at(&self, mods: &Mods, k: Option<usize>, omega: f64) -> Complex64 {
        let (mut core, mut path) = match k {
            Some(k) => (self.core0[k], self.path0[k]),
            None => (
                self.base.eval_core(omega)[(0, 0)],
                self.base
                    .effect
                    .iter()
                    .fold(Complex64::new(1.0, 0.0), |a, e| a * e.eval(omega)),
            ),
        };
        let mut off = 0;
        for c in &mods.cands {
            let n = c.n_params();
            c.modify(
                &mods.theta[off..off + n],
                self.base,
                omega,
                &mut core,
                &mut path,
            );
            off += n;
        }
        core * path
    }

    /// Model response at the data.
    pub fn response(&self, mods: &Mods) -> Vec<Complex64> {
        (0..self.f())
            .map(|k| self.eval_at(mods, Some(k), self.omega[k]))
            .collect()
    }

    fn residual(&self, mods: &Mods, mask: &[usize], out: &mut Vec<f64>) {
        out.clear();
        for &k in mask {
            let e = (self.g[k] - self.eval_at(mods, Some(k), self.omega[k])) * self.inv_sigma[k];
            out.push(e.re);
            out.push(e.im);
        }
    }

    fn v(&self, mods: &Mods, mask: &[usize]) -> f64 {
        let mut r = Vec::with_capacity(2 * mask.len());
        self.residual(mods, mask, &mut r);
        let v: f64 = r.iter().map(|x| x * x).sum();
        if v.is_finite() {
            v
        } else {
            f64::INFINITY
        }
    }

    /// Error measures of a model on all data.
    pub fn measures(&self, mods: &Mods) -> Measures {
        let gm = self.response(mods);
        let mut v = 0.0;
        let mut c2 = 0.0;
        let mut bad = 0usize;
        for (k, gmk) in gm.iter().enumerate() {
            let e = (self.g[k] - gmk).norm();
            v += (e * self.inv_sigma[k]).powi(2);
            let c = e / self.radius[k];
            c2 += c * c;
            if c > 1.0 {
                bad += 1;
            }
        }
        let n = self.f() as f64;
        Measures {
            v,
            misfit_rms: (c2 / n).sqrt(),
            invalid_fraction: bad as f64 / n,
        }
    }

    fn invalid_flags(&self, mods: &Mods) -> (Vec<f64>, Vec<bool>) {
        let gm = self.response(mods);
        let c: Vec<f64> = (0..self.f())
            .map(|k| (self.g[k] - gm[k]).norm() / self.radius[k])
            .collect();
        let flags = c.iter().map(|x| *x > 1.0).collect();
        (c, flags)
    }

    /// Joint LM fit of `mods` (all parameters free) on the data in `mask`.
    fn refit(&self, mods: &Mods, mask: &[usize]) -> (Mods, f64, DMatrix<f64>) {
        if mods.theta.is_empty() {
            return (mods.clone(), self.v(mods, mask), DMatrix::zeros(0, 0));
        }
        let mut typ = Vec::new();
        let mut off = 0;
        for c in &mods.cands {
            let n = c.n_params();
            typ.extend(c.typ(&mods.theta[off..off + n], self.omega_max()));
            off += n;
        }
        let cands = mods.cands.clone();
        let res = lm(
            |th: &[f64], out: &mut Vec<f64>| {
                let m = Mods {
                    cands: cands.clone(),
                    theta: th.to_vec(),
                };
                self.residual(&m, mask, out)
            },
            &mods.theta,
            &typ,
            80,
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

    /// Starting points for the new parameters of `c`, given the current model `cur`.
    fn starts(&self, cur: &Mods, c: Cand, mask: &[usize]) -> Vec<Vec<f64>> {
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
                        trials.push((self.v(&cur.with(c_mode(), &th), mask), th));
                    }
                }
                trials.sort_by(|a, b| a.0.total_cmp(&b.0));
                trials.into_iter().take(4).map(|t| t.1).collect()
            }
        }
    }
}

/// Prior order among near-ties (lower first).
fn prior(c: &Cand) -> usize {
    match c {
        Cand::Sign => 0,
        Cand::Gain => 1,
        Cand::Delay => 2,
        Cand::Lag => 3,
        Cand::Zoh => 4,
        Cand::Feedthrough => 5,
        Cand::Integrator(_) => 6,
        Cand::Damping(_) => 7,
        Cand::ModeShift(_) => 8,
        Cand::NmpZero => 9,
        Cand::Mode => 10,
        Cand::Friction(_) => 6,
    }
}

fn c_mode() -> Cand {
    Cand::Mode
}

fn si_map(c: &Cand, th: &[f64]) -> BTreeMap<String, f64> {
    c.si_params(th)
        .into_iter()
        .map(|(n, v, _)| (n.to_string(), v))
        .collect()
}

/// The candidate list for a base model (mode shifts and damping for every base mode).
pub fn candidate_list(base: &PhysicalModel) -> Vec<Cand> {
    let mut v = vec![
        Cand::Delay,
        Cand::Lag,
        Cand::Gain,
        Cand::Sign,
        Cand::Mode,
        Cand::Integrator(1),
        Cand::Integrator(2),
        Cand::Feedthrough,
        Cand::NmpZero,
        Cand::Zoh,
    ];
    for i in 0..base.mode.len() {
        v.push(Cand::ModeShift(i));
        v.push(Cand::Damping(i));
    }
    for i in 0..base.rigid_body.len() {
        v.push(Cand::Friction(i));
    }
    v
}

impl Problem<'_> {
    fn fit_candidate(&self, cur: &Mods, c: Cand, mask: &[usize]) -> (Mods, f64, DMatrix<f64>) {
        let mut best: Option<(Mods, f64, DMatrix<f64>)> = None;
        for st in self.starts(cur, c, mask) {
            let m = cur.with(c, &st);
            let fit = self.refit(&m, mask);
            if best.as_ref().is_none_or(|b| fit.1 < b.1) {
                best = Some(fit);
            }
        }
        best.expect("at least one start")
    }

    fn disambiguate(&self, a: &Mods, b: &Mods) -> String {
        let (wmin, wmax) = (self.omega[0], self.omega_max());
        let rel: Vec<f64> = (0..self.f())
            .map(|k| self.radius[k] / self.g[k].norm().max(1e-300))
            .collect();
        let mut sorted = rel.clone();
        sorted.sort_by(|x, y| x.total_cmp(y));
        let rel_noise = sorted[sorted.len() / 2];
        let differs = |w: f64| {
            let (ga, gb) = (self.eval_at(a, None, w), self.eval_at(b, None, w));
            (ga - gb).norm() > rel_noise * ga.norm()
        };
        let above = (1..=200)
            .map(|i| wmax * 10f64.powf(i as f64 * 2.0 / 200.0))
            .find(|w| differs(*w));
        let below = (1..=200)
            .map(|i| wmin / 10f64.powf(i as f64 * 2.0 / 200.0))
            .find(|w| differs(*w));
        match (above, below) {
            (Some(h), Some(l)) => format!(
                "the two fitted models differ by more than the noise above {} and below {}: measure there to tell them apart",
                fmt_w(h),
                fmt_w(l)
            ),
            (Some(h), None) => format!(
                "the two fitted models differ by more than the noise above {}: measure there to tell them apart",
                fmt_w(h)
            ),
            (None, Some(l)) => format!(
                "the two fitted models differ by more than the noise below {}: measure there to tell them apart",
                fmt_w(l)
            ),
            (None, None) => "the two fitted models agree within the noise from a hundredth of the lowest to a hundred times the highest measured frequency: lower the noise (more periods or averages) to tell them apart".into(),
        }
    }

    /// Fits and ranks every candidate on top of the current model `cur`.
    fn rank(&self, cur: &Mods, cur_m: Measures) -> Vec<CandidateReport> {
        let all: Vec<usize> = (0..self.f()).collect();
        let fit_mask: Vec<usize> = (0..self.f()).filter(|k| k % 4 != 3).collect();
        let ho_mask: Vec<usize> = (0..self.f()).filter(|k| k % 4 == 3).collect();
        let cur_fit = self.refit(cur, &fit_mask).0;
        let v_ho_cur = self.v(&cur_fit, &ho_mask);
        // Extrapolation holdout for global (multiplicative) candidates: fit below 70 % of the
        // band (in log frequency), predict the top 30 %.
        let (lo_mask, hi_mask) = self.split_band(EXTRAPOLATION_SPLIT);
        let extrap = lo_mask.len() >= MIN_SPLIT_DATA && hi_mask.len() >= MIN_SPLIT_DATA;
        let v_hi_cur = if extrap {
            let f = self.refit(cur, &lo_mask).0;
            self.v(&f, &hi_mask)
        } else {
            f64::INFINITY
        };
        let (_, flags0) = self.invalid_flags(cur);
        let ln2f = (2.0 * self.f() as f64).ln();
        let used: Vec<Cand> = cur.cands.clone();
        let mut out: Vec<CandidateReport> = Vec::new();
        for c in candidate_list(self.base) {
            // A base mode is shifted or re-damped once.
            let clash = |i: usize| {
                used.iter()
                    .any(|u| matches!(u, Cand::ModeShift(j) | Cand::Damping(j) if *j == i))
            };
            if let Cand::ModeShift(i) | Cand::Damping(i) = c {
                if clash(i) {
                    continue;
                }
            }
            if matches!(c, Cand::Friction(_)) && used.contains(&c) {
                continue;
            }
            let (mods, v, jtj) = self.fit_candidate(cur, c, &all);
            if !v.is_finite() {
                continue;
            }
            let m = self.measures(&mods);
            let n_new = c.n_params();
            let delta_bic = 2.0 * (cur_m.v - v) - n_new as f64 * ln2f;
            let ho = self.refit(&mods, &fit_mask).0;
            let interleaved_ok = self.v(&ho, &ho_mask) < v_ho_cur;
            let extrapolation_ok = (extrap && c.multiplicative()).then(|| {
                let f = self.refit(&mods, &lo_mask).0;
                self.v(&f, &hi_mask) < v_hi_cur
            });
            let holdout_ok = interleaved_ok && extrapolation_ok.unwrap_or(true);
            let th_new = &mods.theta[mods.theta.len() - n_new..];
            // 2σ of the new parameters.
            let ntot = mods.theta.len();
            let cov = (jtj * 2.0).try_inverse();
            let si = c.si_params(th_new);
            let mut unc = BTreeMap::new();
            for (j, (name, _, fac)) in si.iter().enumerate() {
                if *fac == 0.0 {
                    continue;
                }
                let idx = ntot - n_new + j.min(n_new.saturating_sub(1));
                let idx = match c {
                    Cand::ModeShift(_)
                    | Cand::Damping(_)
                    | Cand::Integrator(_)
                    | Cand::Friction(_) => ntot - 1,
                    _ => idx,
                };
                let sd = cov
                    .as_ref()
                    .map(|cv| cv[(idx, idx)].max(0.0).sqrt())
                    .unwrap_or(f64::NAN);
                unc.insert(name.to_string(), 2.0 * sd * fac);
            }
            let (cm, flags1) = self.invalid_flags(&mods);
            let fixed: Vec<bool> = flags0.iter().zip(&flags1).map(|(a, b)| *a && !*b).collect();
            let passes = delta_bic > MIN_DELTA_BIC
                && m.invalid_fraction <= cur_m.invalid_fraction
                && holdout_ok;
            out.push(CandidateReport {
                rank: 0,
                effect: c.name().into(),
                params: si_map(&c, th_new),
                uncertainty_2sigma: unc,
                v_before: cur_m.v,
                v_after: v,
                misfit_rms_before: cur_m.misfit_rms,
                misfit_rms_after: m.misfit_rms,
                invalid_fraction_before: cur_m.invalid_fraction,
                invalid_fraction_after: m.invalid_fraction,
                delta_bic,
                n_params: n_new,
                holdout_ok,
                holdout_interleaved_ok: interleaved_ok,
                holdout_extrapolation_ok: extrapolation_ok,
                passes,
                tie_with_best: false,
                explanation: explain(&c, th_new, self.base, &self.omega),
                explained_bands: bands(&self.omega, &cm, &fixed),
                cand: c,
                mods,
            });
        }
        out.sort_by(|a, b| b.delta_bic.total_cmp(&a.delta_bic));
        // Near-ties with the best are ordered by fewer parameters, then by the prior order
        // of the catalogue (a delay before an NMP zero far above the band, which only a
        // measurement there can tell apart); the tie is still reported.
        if let Some(best) = out.first().map(|c| c.delta_bic) {
            let n_tied = out
                .iter()
                .take_while(|c| best - c.delta_bic < TIE_BIC)
                .count();
            out[..n_tied].sort_by_key(|c| (c.n_params, prior(&c.cand)));
        }
        // Keep the best of each effect name (mode_shift over modes, integrator over orders).
        let mut seen = std::collections::HashSet::new();
        out.retain(|c| seen.insert(c.effect.clone()));
        for (k, c) in out.iter_mut().enumerate() {
            c.rank = k + 1;
        }
        if let Some(best) = out.iter().map(|c| c.delta_bic).reduce(f64::max) {
            for c in out.iter_mut().skip(1) {
                c.tie_with_best = best - c.delta_bic < TIE_BIC && c.delta_bic > MIN_DELTA_BIC;
            }
        }
        out
    }

    fn ties(&self, ranked: &[CandidateReport]) -> Vec<Tie> {
        let Some(best) = ranked.first() else {
            return vec![];
        };
        ranked
            .iter()
            .skip(1)
            .filter(|c| c.tie_with_best)
            .map(|c| Tie {
                effects: [best.effect.clone(), c.effect.clone()],
                bic_gap: (best.delta_bic - c.delta_bic).abs(),
                disambiguation: self.disambiguate(&best.mods, &c.mods),
            })
            .collect()
    }
}

/// Runs the greedy diagnosis.
pub fn diagnose(base: &PhysicalModel, siso: &Siso, max_effects: usize) -> Result<Diagnosis> {
    let p = Problem::new(base, siso)?;
    let mut cur = Mods::default();
    let before = p.measures(&cur);
    let mut cur_m = before;
    let mut steps = Vec::new();
    let mut first: Option<(Vec<CandidateReport>, Vec<Tie>)> = None;
    if before.consistent() {
        return Ok(Diagnosis {
            verdict: "consistent".into(),
            message: format!(
                "the model explains the data within the noise (misfit_rms = {:.3}, invalid_fraction = {:.1} %): nothing needs to be added",
                before.misfit_rms,
                100.0 * before.invalid_fraction
            ),
            n_data: p.f(),
            before,
            after: before,
            candidates: vec![],
            ties: vec![],
            steps,
            cost_test: Some([p.f() as f64, before.v]),
            final_model: base.clone(),
        });
    }
    let before_f = p.f() as f64;
    drop(p);
    // After each accepted effect the model is rebuilt with the effect written into it, and
    // every parameter (the configured ones and the accepted effects') is refit jointly
    // (bounded LM, `nominal::refit_nominal`); the next step ranks candidates on that model.
    let radius = siso.radius.clone().expect("checked by Problem::new");
    let mut model = base.clone();
    let mut n_fitted = 0usize;
    for step in 0..max_effects {
        let p = Problem::new(&model, siso)?;
        let ranked = p.rank(&cur, cur_m);
        let ties = p.ties(&ranked);
        let accept = ranked.iter().find(|c| c.passes).cloned();
        if first.is_none() {
            first = Some((ranked, ties.clone()));
        }
        let Some(acc) = accept else { break };
        let with_effect = p.measures(&acc.mods);
        let n = acc.cand.n_params();
        let th = &acc.mods.theta[acc.mods.theta.len() - n..];
        let params = si_map(&acc.cand, th);
        let mut next = model.clone();
        acc.cand.apply_to(
            th,
            &mut next,
            &format!("added by rshape diagnose: {}", acc.effect),
        );
        let refit = refit_nominal(&next, &siso.omega, &siso.g, &radius);
        n_fitted = refit.n_params;
        model = refit.model;
        cur = Mods::default();
        cur_m = Problem::new(&model, siso)?.measures(&cur);
        steps.push(Step {
            step: step + 1,
            effect: acc.effect.clone(),
            params,
            explanation: acc.explanation.clone(),
            misfit_rms: cur_m.misfit_rms,
            invalid_fraction: cur_m.invalid_fraction,
            delta_bic: acc.delta_bic,
            misfit_rms_before_refit: with_effect.misfit_rms,
            invalid_fraction_before_refit: with_effect.invalid_fraction,
            n_refit: refit.n_params,
            ties,
        });
        if cur_m.consistent() {
            break;
        }
    }
    let (candidates, ties) = first.unwrap_or_default();
    let verdict = if steps.is_empty() {
        "no_effect_found"
    } else {
        "effects_found"
    };
    let message = if steps.is_empty() {
        "the model does not explain the data, but no candidate effect passes (ΔBIC > 10, fewer invalid data, holdout): the missing dynamics are not in the catalogue, or the noise radius is too small".to_string()
    } else {
        let list: Vec<String> = steps.iter().map(|s| s.effect.clone()).collect();
        format!(
            "added {}: misfit_rms {:.3} → {:.3}, invalid_fraction {:.1} % → {:.1} %{}",
            list.join(" + "),
            before.misfit_rms,
            cur_m.misfit_rms,
            100.0 * before.invalid_fraction,
            100.0 * cur_m.invalid_fraction,
            if cur_m.consistent() {
                " (now consistent with the data within the noise)"
            } else {
                " (still not consistent: more is missing)"
            }
        )
    };
    let n_theta = n_fitted as f64;
    Ok(Diagnosis {
        verdict: verdict.into(),
        message,
        n_data: siso.omega.len(),
        before,
        after: cur_m,
        candidates,
        ties,
        steps,
        cost_test: Some([before_f - n_theta / 2.0, cur_m.v]),
        final_model: model,
    })
}

/// The base model with candidate `rank` (1-based) of the first step added.
pub fn apply_candidate(base: &PhysicalModel, d: &Diagnosis, rank: usize) -> Result<PhysicalModel> {
    let c = d.candidates.get(rank.wrapping_sub(1)).ok_or_else(|| {
        Error::Invalid(format!(
            "--apply {rank}: there are {} candidates (1..={})",
            d.candidates.len(),
            d.candidates.len()
        ))
    })?;
    let mut m = base.clone();
    let n = c.cand.n_params();
    let th = &c.mods.theta[c.mods.theta.len() - n..];
    c.cand.apply_to(
        th,
        &mut m,
        &format!("added by rshape diagnose: {}", c.effect),
    );
    Ok(m)
}

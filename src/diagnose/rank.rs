//! Fitting and ranking the candidates on top of a model: ΔBIC, invalid fraction, the
//! interleaved and extrapolation holdouts, 2σ uncertainties and ties.

use super::candidates::{explain, fmt_w, Cand};
use super::compare::bands;
use super::problem::{Measures, Mods, Problem};
use super::report::{CandidateReport, Tie};
use crate::model::physical::PhysicalModel;
use nalgebra::DMatrix;
use std::collections::BTreeMap;

/// ΔBIC a candidate needs to be accepted.
pub const MIN_DELTA_BIC: f64 = 10.0;
/// BIC gap under which two candidates are a tie.
pub const TIE_BIC: f64 = 6.0;
/// Extrapolation holdout: fit below this share of the band (log frequency), predict above.
pub const EXTRAPOLATION_SPLIT: f64 = 0.7;
/// Fewest data on either side of the split for the extrapolation holdout to run.
pub const MIN_SPLIT_DATA: usize = 8;
/// Prior order among near-ties (lower first).
pub(super) fn prior(c: &Cand) -> usize {
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

pub(super) fn si_map(c: &Cand, th: &[f64]) -> BTreeMap<String, f64> {
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
    pub(super) fn fit_candidate(
        &self,
        cur: &Mods,
        c: Cand,
        mask: &[usize],
    ) -> (Mods, f64, DMatrix<f64>) {
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

    pub(super) fn disambiguate(&self, a: &Mods, b: &Mods) -> String {
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
    pub(super) fn rank(&self, cur: &Mods, cur_m: Measures) -> Vec<CandidateReport> {
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

    pub(super) fn ties(&self, ranked: &[CandidateReport]) -> Vec<Tie> {
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

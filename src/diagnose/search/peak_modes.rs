//! Every peak proposed (issue 33): the screen's one mode candidate goes to the start with
//! the lowest cost, so when its joint refit is refused (a peak the lines cannot resolve, a
//! mains line) the next step proposes the same peak again and the other peaks are never
//! tried.  Here every unexplained peak of the node's residual ([`super::peaks::find_peaks`])
//! gets a mode fitted at it alone ([`super::peaks::fit_at`]); those that would pass the
//! screen (ΔBIC above the threshold, plausible, fewer invalid data or a lower `misfit_rms`,
//! the fit staying in the peak's window) are proposed as mode candidates of their own, each
//! refit jointly by the search, so a refused candidate never hides the others.
//!
//! Peaks at a mode the model already has (what is left of its fit: a retune's job, or a
//! cancelling pair if a second mode were put there) and at the screen's own mode candidate
//! are skipped.

use super::peaks::{find_peaks, fit_at, residual, AtPeak, MAX_PEAKS};
#[cfg(test)]
use super::rank::MIN_DELTA_BIC;
use super::rank::{improves, plausibility, Screened};
use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::problem::Problem;
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;

/// Most mode proposals from peaks per node.
pub const MAX_PEAK_MODES: usize = 4;

/// The mode candidates at the peaks of the residual of `model` that would pass the screen
/// (see the module docs), highest ΔBIC first, and apart those that pass on the lines
/// around their peak only (a ΔBIC above the threshold there, plausible, in the window: alone
/// they do not pass, the tails of the modes still missing costing more elsewhere, but
/// proposed together with those modes they may, [`super::multi_mode`]); `taken`: ω_n
/// (rad/s) of the screen's own mode candidates.
pub(super) fn peak_modes(
    model: &PhysicalModel,
    data: &Channels,
    cur: Measures,
    taken: &[f64],
    min_delta_bic: f64,
) -> Result<(Vec<Screened>, Vec<Screened>)> {
    let pb = Problem::new(model, data)?;
    let (s, e) = residual(model, data)?;
    let peaks: Vec<_> = find_peaks(&data.omega, &s, &e)
        .into_iter()
        .take(MAX_PEAKS)
        .filter(|p| {
            let inside = |w: f64| (p.lo..=p.hi).contains(&w);
            !taken.iter().any(|w| inside(*w)) && !model.mode.iter().any(|m| inside(m.omega_n))
        })
        .collect();
    let ln2f = (2.0 * data.n_data() as f64).ln();
    let n_new = Cand::Mode.n_params(data.n_ch()) as f64 * ln2f;
    let w_band = (data.omega[0], *data.omega.last().expect("data"));
    // (the fit, whether it passes on all lines).
    let fits: Vec<(Screened, bool)> = peaks
        .par_iter()
        .filter_map(|p| {
            let AtPeak {
                fit: mods,
                v,
                local_gain,
                jtj,
            } = fit_at(&pb, p, data)?;
            let w = mods.theta[0].exp();
            if !(p.lo..=p.hi).contains(&w) {
                return None;
            }
            let measures = pb.measures(&mods);
            let delta_bic = 2.0 * (cur.v - v) - n_new;
            let (flags, no_fit) = plausibility(
                &Cand::Mode,
                &mods.theta,
                v,
                &data.entries,
                w_band,
                pb.zeta_floor,
                model.quantity,
            );
            let plausible = no_fit.is_none() && flags.is_empty();
            let locally = plausible && 2.0 * local_gain - n_new > min_delta_bic;
            let passes = plausible && delta_bic > min_delta_bic && improves(&measures, &cur);
            (passes || locally).then_some((
                Screened {
                    cand: Cand::Mode,
                    mods,
                    v,
                    measures,
                    delta_bic,
                    flags,
                    no_fit,
                    jtj,
                },
                passes,
            ))
        })
        .collect();
    let (mut out, mut local): (Vec<_>, Vec<_>) = fits.into_iter().partition(|f| f.1);
    out.sort_by(|a, b| b.0.delta_bic.total_cmp(&a.0.delta_bic));
    local.sort_by(|a, b| b.0.delta_bic.total_cmp(&a.0.delta_bic));
    Ok((one_per_resonance(out), one_per_resonance(local)))
}

/// One proposal per resonance (two peaks' fits that met at one frequency are one), at most
/// [`MAX_PEAK_MODES`].
fn one_per_resonance(fits: Vec<(Screened, bool)>) -> Vec<Screened> {
    let mut kept: Vec<Screened> = Vec::new();
    for (sc, _) in fits {
        let w = sc.mods.theta[0].exp();
        if !kept
            .iter()
            .any(|k| (k.mods.theta[0].exp() / w - 1.0).abs() < 1e-3)
        {
            kept.push(sc);
        }
    }
    kept.truncate(MAX_PEAK_MODES);
    kept
}

#[cfg(test)]
mod tests {
    //! A constructed case where the tallest peak is refused (a line-narrow resonance at
    //! 50.2 Hz: mains) and two real modes stand beside it: every peak is proposed, and the
    //! refusal does not hide the others.
    use super::*;
    use crate::diagnose::search::beam::SearchSettings;
    use crate::model::physical::{Gains, ModeSpec};

    const TAU: f64 = std::f64::consts::TAU;
    /// (f Hz, ζ, residue): the configured mode, then the mains line, then two real modes.
    const MODES: [(f64, f64, f64); 4] = [
        (350.0, 0.01, 1e6),
        (50.2, 1e-5, 5e4),
        (137.3, 2e-3, 1e5),
        (263.7, 2e-3, 3e5),
    ];

    fn model(which: &[usize]) -> PhysicalModel {
        PhysicalModel {
            mode: which
                .iter()
                .map(|&i| ModeSpec {
                    omega_n: TAU * MODES[i].0,
                    zeta: MODES[i].1,
                    mass: 1.0,
                    output_gain: Gains::Scalar(MODES[i].2),
                    input_gain: Gains::Scalar(1.0),
                    name: None,
                })
                .collect(),
            ..Default::default()
        }
    }

    /// 1 Hz lines; noise 1 % of |G| plus a floor of 0.02.
    fn data() -> Channels {
        data_with((0.01, 0.02))
    }

    /// 1 Hz lines, the four modes; noise `(relative, floor)`.
    fn data_with(noise: (f64, f64)) -> Channels {
        let omega: Vec<f64> = (10..=400).map(|k| TAU * k as f64).collect();
        Channels::of_model(&model(&[0, 1, 2, 3]), omega, vec![(0, 0)], 1.0, noise)
    }

    /// With a radius proportional to |G| alone, the truth's anti-resonances weigh the other
    /// missing mode's tail so heavily that a one-mode fit of the whole band started at
    /// 263.7 Hz leaves its peak's window (measured: 265.5 Hz, see issue 33); fitted on the
    /// lines around the peak it stays, and passes there (alone it costs more elsewhere than
    /// it gains: proposed for the group only, [`super::super::multi_mode`]).
    #[test]
    fn proposals_are_fitted_locally_where_the_radius_follows_g() {
        let (d, base) = (data_with((0.01, 0.0)), model(&[0]));
        let pb = Problem::new(&base, &d).unwrap();
        let cur = pb.measures(&Default::default());
        let (singles, local) = peak_modes(&base, &d, cur, &[], MIN_DELTA_BIC).unwrap();
        let found: Vec<f64> = singles.iter().chain(&local).map(hz).collect();
        for f in [137.3, 263.7] {
            assert!(
                singles
                    .iter()
                    .chain(&local)
                    .any(|sc| (hz(sc) / f - 1.0).abs() < 1e-3),
                "{f} Hz not proposed: {found:?}"
            );
        }
        assert!(!found.iter().any(|f| (f - 50.2).abs() < 1.0), "{found:?}");
        assert!(local.iter().all(|sc| sc.delta_bic <= MIN_DELTA_BIC));
        // The whole-band fit from the same start does leave the window (the case the local
        // fit is for): started at the 263.7 Hz peak's line.
        let (s, e) = residual(&base, &d).unwrap();
        let p = find_peaks(&d.omega, &s, &e)
            .into_iter()
            .find(|p| (d.omega[p.k] / TAU - 263.7).abs() < 1.0)
            .expect("a peak at 263.7 Hz");
        let every: Vec<usize> = (0..d.len()).collect();
        let empty = crate::diagnose::lsq::problem::Mods::default();
        let resp = pb.response(&empty);
        let z0 = ((p.hi - p.lo) / (2.0 * 3f64.sqrt() * d.omega[p.k])).clamp(2e-4, 0.3);
        let global = [z0, 3.0 * z0, z0 / 3.0]
            .into_iter()
            .map(|z| {
                let th = pb.mode_theta(&empty, &resp, d.omega[p.k], z, &every);
                pb.refit(&empty.with(Cand::Mode, &th), &every)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let w = global.0.theta[0].exp();
        assert!(
            !(p.lo..=p.hi).contains(&w),
            "the whole-band fit stayed at {} Hz",
            w / TAU
        );
    }

    fn hz(sc: &Screened) -> f64 {
        sc.mods.theta[0].exp() / TAU
    }

    #[test]
    fn every_peak_is_proposed_except_those_taken() {
        let (d, base) = (data(), model(&[0]));
        let cur = Problem::new(&base, &d)
            .unwrap()
            .measures(&Default::default());
        let near = |v: &[Screened], f: f64| v.iter().any(|sc| (hz(sc) / f - 1.0).abs() < 2e-3);
        // Nothing taken: both resonances proposed, highest ΔBIC first; the line-narrow
        // 50.2 Hz peak's one-mode fit ends on the record's floor (flagged: not identified).
        let all = peak_modes(&base, &d, cur, &[], MIN_DELTA_BIC).unwrap().0;
        let found: Vec<f64> = all.iter().map(hz).collect();
        assert_eq!(all.len(), 2, "{found:?}");
        assert!(near(&all, 137.3) && near(&all, 263.7), "{found:?}");
        assert!(all.windows(2).all(|w| w[0].delta_bic >= w[1].delta_bic));
        // The screen's own candidate at one peak: the other still proposed.
        let rest = peak_modes(&base, &d, cur, &[TAU * 137.3], MIN_DELTA_BIC)
            .unwrap()
            .0;
        assert_eq!(rest.len(), 1);
        assert!(near(&rest, 263.7));
        // A mode the model already has is not proposed again.
        let with_b = model(&[0, 2]);
        let cur_b = Problem::new(&with_b, &d)
            .unwrap()
            .measures(&Default::default());
        let left = peak_modes(&with_b, &d, cur_b, &[], MIN_DELTA_BIC)
            .unwrap()
            .0;
        assert_eq!(left.len(), 1);
        assert!(near(&left, 263.7));
    }

    #[test]
    fn a_refused_mains_peak_does_not_hide_the_modes_beside_it() {
        let (d, base) = (data(), model(&[0]));
        let s = SearchSettings::default();
        let r =
            crate::diagnose::engine::diagnose_channels(&base, &d, &s, &Default::default()).unwrap();
        let modes: Vec<f64> = r.final_model.mode.iter().map(|m| m.omega_n / TAU).collect();
        let has = |f: f64| modes.iter().any(|x| (x / f - 1.0).abs() < 1e-3);
        assert!(has(137.3) && has(263.7), "{modes:?}: {}", r.message);
        assert!(!has(50.2), "the mains line was written: {modes:?}");
        assert!(
            r.refused.iter().any(
                |x| x.refusal.rule == crate::diagnose::admissible::Rule::Mains
                    && x.refusal
                        .frequency_hz
                        .is_some_and(|f| (f - 50.2).abs() < 0.5)
            ),
            "{:?}",
            r.refused
        );
    }

    /// Both modes are proposed together as well as singly: one step adds both (the group
    /// explains more than either alone), and the mains line stays refused.  (With the radius
    /// proportional to |G| and no floor, `data_with((0.01, 0.0))`, the group is proposed and
    /// accepted at the first step too, but later joint refits wander: not asserted here.)
    #[test]
    fn passing_modes_are_also_proposed_together_in_one_step() {
        let (d, base) = (data_with((0.01, 0.02)), model(&[0]));
        let s = SearchSettings::default();
        let r =
            crate::diagnose::engine::diagnose_channels(&base, &d, &s, &Default::default()).unwrap();
        let modes: Vec<f64> = r.final_model.mode.iter().map(|m| m.omega_n / TAU).collect();
        let has = |f: f64| modes.iter().any(|x| (x / f - 1.0).abs() < 1e-3);
        assert!(has(137.3) && has(263.7), "{modes:?}: {}", r.message);
        assert!(!has(50.2), "the mains line was written: {modes:?}");
        let group = r
            .search
            .mode_groups_hz
            .iter()
            .find(|g| {
                [137.3, 263.7]
                    .iter()
                    .all(|f| g.iter().any(|x| (x / f - 1.0).abs() < 2e-3))
            })
            .unwrap_or_else(|| panic!("no group of both: {:?}", r.search.mode_groups_hz));
        assert!(group.len() >= 2);
        // Both modes written at one step (the group's), reported as two steps.
        let step_of = |f: f64| {
            r.steps
                .iter()
                .find(|st| {
                    st.effect == "mode"
                        && st
                            .params
                            .get("omega_n")
                            .is_some_and(|w| (w / TAU / f - 1.0).abs() < 1e-3)
                })
                .map(|st| st.step)
        };
        let (a, b) = (step_of(137.3), step_of(263.7));
        assert!(a.is_some() && a == b, "{:?}", r.steps);
        assert_eq!(r.steps.len(), r.final_effects.len());
    }
}

//! The multi-mode proposal (issue 33, "all peaks proposed together"): every mode fitted
//! alone at a node that would pass the screen — the screen's own mode candidate and the
//! modes at the residual's other peaks ([`super::peak_modes`]) — written into the model in
//! **one** step and refit jointly.  Proposed one at a time, each mode is refit with the
//! others still missing, whose tails it partly answers for (and, with the radius
//! proportional to `|G|`, is pulled by); proposed together, each is refit beside the others.
//! The singles are still proposed, so a refused group hides none of its modes.
//!
//! The group is admissible when every one of its modes is ([`check_each`]): each is
//! checked by the one-mode rules of [`crate::diagnose::admissible::check`] on the joint
//! refit, as if it were the mode added last, against the refit model without it (its own
//! share of the improvement, not the group's, decides whether it is negligible).

use super::peaks::MIN_WINDOW_REL;
use super::rank::Screened;
use crate::diagnose::admissible::{check, Child, Refusal};
use crate::diagnose::effects::candidates::{sig, Cand};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::problem::Problem;
use crate::model::physical::PhysicalModel;

/// Two modes proposed within this relative distance are one resonance (the lines of a
/// peak's local fit, [`super::peaks::LOCAL_MIN_REL`]).
const SAME_RESONANCE_REL: f64 = super::peaks::LOCAL_MIN_REL;

/// The modes proposed together: the modes fitted at the residual's peaks (`at_peaks`, which
/// pass the screen, then `local`, which pass on the lines around their peak only: alone, the
/// tails of the modes still missing cost more elsewhere than they gain there), then the
/// screen's own mode candidates (`screen`) that would pass it (fitted, no flag, ΔBIC above
/// `min_delta_bic`); one per resonance (within 2 %: the peak's local fit first, a
/// whole-band fit being pulled by the other missing modes), none at a mode `model` already
/// has (within its half-power band, at least ±0.3 %: what is left of that mode's fit is a
/// retune's job, and a second mode there a cancelling pair); at most `budget` (the effects
/// the search may still add: each mode of a group counts); `None` unless two or more.
pub(super) fn proposal(
    model: &PhysicalModel,
    screen: &[Screened],
    at_peaks: &[Screened],
    local: &[Screened],
    min_delta_bic: f64,
    budget: usize,
) -> Option<Vec<Screened>> {
    let at_a_mode = |sc: &Screened| {
        let w = sc.mods.theta[0].exp();
        model
            .mode
            .iter()
            .any(|m| (w / m.omega_n - 1.0).abs() <= m.zeta.max(MIN_WINDOW_REL))
    };
    let mut own: Vec<&Screened> = screen
        .iter()
        .filter(|sc| {
            sc.cand == Cand::Mode
                && sc.no_fit.is_none()
                && sc.flags.is_empty()
                && sc.delta_bic > min_delta_bic
        })
        .collect();
    own.sort_by(|a, b| b.delta_bic.total_cmp(&a.delta_bic));
    let mut kept: Vec<Screened> = Vec::new();
    for sc in at_peaks.iter().chain(local).chain(own) {
        let w = sc.mods.theta[0].exp();
        let seen = kept
            .iter()
            .any(|k| (k.mods.theta[0].exp() / w - 1.0).abs() < SAME_RESONANCE_REL);
        if !seen && !at_a_mode(sc) {
            kept.push(sc.clone());
        }
    }
    kept.truncate(budget);
    (kept.len() >= 2).then_some(kept)
}

/// The first refusal among the last `k` modes of the refit `model` (the group's, placed
/// last by the assignment), each checked as the mode added last; `measures` are the
/// model's.  The reason says the mode was proposed with others.
pub(super) fn check_each(
    model: &PhysicalModel,
    k: usize,
    measures: &Measures,
    allow_mains: bool,
    min_delta_bic: f64,
    data: &Channels,
) -> Option<Refusal> {
    let n = model.mode.len();
    for i in n.saturating_sub(k)..n {
        // Mode i last: the one-mode rules read the last mode.
        let mut last = model.clone();
        let md = last.mode.remove(i);
        let without = last.clone();
        last.mode.push(md);
        let Ok(pb) = Problem::new(&without, data) else {
            continue;
        };
        let reference = pb.measures(&Default::default());
        let refusal = check(
            &Child {
                cand: Cand::Mode,
                model: &last,
                measures,
                reference: &reference,
                allow_mains,
                min_delta_bic,
            },
            data,
        );
        if let Some(mut r) = refusal {
            r.reason = format!(
                "{} (proposed with {} other mode{} at {} Hz, together)",
                r.reason,
                k - 1,
                if k == 2 { "" } else { "s" },
                (n - k..n)
                    .filter(|j| *j != i)
                    .map(|j| sig(model.mode[j].omega_n / std::f64::consts::TAU))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            return Some(r);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    //! Constructed cases: a group is admissible when each of its modes is, and the proposal
    //! keeps one mode per resonance, none at a mode the model has.
    use super::*;
    use crate::diagnose::admissible::Rule;
    use crate::diagnose::lsq::problem::Mods;
    use crate::diagnose::search::rank::MIN_DELTA_BIC;
    use crate::model::physical::{Gains, ModeSpec};

    const TAU: f64 = std::f64::consts::TAU;

    fn with_modes(modes: &[(f64, f64, f64)]) -> PhysicalModel {
        PhysicalModel {
            mode: modes
                .iter()
                .map(|&(f, zeta, rho)| ModeSpec {
                    omega_n: TAU * f,
                    zeta,
                    mass: 1.0,
                    output_gain: Gains::Scalar(rho),
                    input_gain: Gains::Scalar(1.0),
                    name: None,
                })
                .collect(),
            ..Default::default()
        }
    }

    /// 1 Hz lines 50–400 Hz of modes at 100 (configured), 137.3 and 263.7 Hz.
    fn data() -> Channels {
        let truth = with_modes(&[(100.0, 0.01, 1e5), (137.3, 0.005, 5e4), (263.7, 0.005, 1e5)]);
        let omega: Vec<f64> = (50..=400).map(|k| TAU * k as f64).collect();
        Channels::of_model(&truth, omega, vec![(0, 0)], 1.0, (0.01, 0.02))
    }

    fn measures(m: &PhysicalModel, d: &Channels) -> Measures {
        Problem::new(m, d).unwrap().measures(&Default::default())
    }

    #[test]
    fn a_group_is_admissible_when_each_of_its_modes_is() {
        let d = data();
        // The two missing modes: admissible (each is most of the misfit where it stands).
        let good = with_modes(&[(100.0, 0.01, 1e5), (137.3, 0.005, 5e4), (263.7, 0.005, 1e5)]);
        assert_eq!(
            check_each(&good, 2, &measures(&good, &d), false, MIN_DELTA_BIC, &d),
            None
        );
        // One real mode and a cancelling pair at 203 Hz (bands overlap, residues ±): the
        // pair's mode is refused as an artefact, and the reason names the group.
        let bad = with_modes(&[
            (100.0, 0.01, 1e5),
            (137.3, 0.005, 5e4),
            (203.0, 0.01, 4e4),
            (203.5, 0.01, -4e4),
        ]);
        let r =
            check_each(&bad, 3, &measures(&bad, &d), false, MIN_DELTA_BIC, &d).expect("refused");
        assert_eq!(r.rule, Rule::Artefact, "{r:?}");
        assert!((r.frequency_hz.unwrap() - 203.0).abs() < 1.0, "{r:?}");
        assert!(r.reason.contains("proposed with 2 other modes"), "{r:?}");
        // The same pair's modes checked one by one as the mode added last: the same rule.
        let one = check(
            &Child {
                cand: Cand::Mode,
                model: &bad,
                measures: &measures(&bad, &d),
                reference: &measures(&with_modes(&[(100.0, 0.01, 1e5)]), &d),
                allow_mains: false,
                min_delta_bic: MIN_DELTA_BIC,
            },
            &d,
        )
        .expect("refused alone");
        assert_eq!(one.rule, Rule::Artefact);
    }

    fn fitted(f: f64, delta_bic: f64) -> Screened {
        Screened {
            cand: Cand::Mode,
            mods: Mods {
                cands: vec![Cand::Mode],
                theta: vec![(TAU * f).ln(), 0.01f64.ln(), 1e4],
            },
            v: 0.0,
            measures: Measures {
                v: 0.0,
                misfit_rms: 1.0,
                invalid_fraction: 0.0,
            },
            delta_bic,
            flags: vec![],
            no_fit: None,
            jtj: nalgebra::DMatrix::zeros(0, 0),
        }
    }

    #[test]
    fn the_group_keeps_one_mode_per_resonance_and_none_at_a_mode_it_has() {
        let model = with_modes(&[(100.0, 0.01, 1e5)]);
        let hz = |g: &[Screened]| -> Vec<f64> {
            g.iter()
                .map(|s| (s.mods.theta[0].exp() / TAU).round())
                .collect()
        };
        // The peak's local fit (150) before the screen's whole-band fit of the same
        // resonance (152.5, 1.7 % away, higher ΔBIC); the screen's mode at the configured
        // one (100.3) left to the retune; a screen mode below the threshold left out.
        let screen = [
            fitted(152.5, 900.0),
            fitted(100.3, 800.0),
            fitted(320.0, 5.0),
        ];
        let (at, local) = ([fitted(150.0, 500.0)], [fitted(250.0, -3.0)]);
        let g = proposal(&model, &screen, &at, &local, 10.0, 3).expect("a group");
        assert_eq!(hz(&g), vec![150.0, 250.0]);
        // One mode is no group, nor is a budget of one effect.
        assert!(proposal(&model, &screen, &[], &[], 10.0, 3).is_none());
        assert!(proposal(&model, &screen, &at, &local, 10.0, 1).is_none());
    }
}

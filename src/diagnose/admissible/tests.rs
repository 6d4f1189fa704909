//! One constructed case per admissibility rule: the truth is one mode at 100 rad/s
//! (ζ 0.01) measured on dense lines; a child adds a term that breaks exactly one rule.
#![cfg(test)]

use super::*;
use crate::model::physical::{EffectKind, EffectSpec, Gains, ModeSpec};

fn mode(w: f64, z: f64, rho: f64) -> ModeSpec {
    ModeSpec {
        name: None,
        omega_n: w,
        zeta: z,
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Scalar(rho),
    }
}

fn truth() -> PhysicalModel {
    PhysicalModel {
        mode: vec![mode(100.0, 0.01, 1.0)],
        ..Default::default()
    }
}

/// Lines from `lo` to `hi` rad/s, `step` apart.
fn lines(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    (0..)
        .map(|k| lo + step * k as f64)
        .take_while(|w| *w <= hi)
        .collect()
}

/// The response of `m` measured at `omega` (radius 1 % of |G|, floor 1e-9).
fn data_of(m: &PhysicalModel, omega: Vec<f64>) -> Channels {
    Channels::of_model(m, omega, vec![(0, 0)], 1.0, (0.01, 1e-9))
}

/// Dense lines: 50–200 rad/s, 0.25 rad/s apart.
fn dense() -> Vec<f64> {
    lines(50.0, 200.0, 0.25)
}

/// The truth measured at `omega`.
fn data(omega: Vec<f64>) -> Channels {
    data_of(&truth(), omega)
}

const BEFORE: Measures = Measures {
    v: 1e4,
    misfit_rms: 5.0,
    invalid_fraction: 0.5,
};
const AFTER: Measures = Measures {
    v: 1e3,
    misfit_rms: 2.0,
    invalid_fraction: 0.3,
};

/// The refusal of `cand` refit as `m` on `d` with measures `after` (against `BEFORE`).
fn refused(
    cand: Cand,
    m: &PhysicalModel,
    d: &Channels,
    after: &Measures,
    mains: bool,
) -> Option<Refusal> {
    check(
        &Child {
            cand,
            model: m,
            measures: after,
            reference: &BEFORE,
            allow_mains: mains,
        },
        d,
    )
}

/// The rule of [`refused`].
fn rule_of(
    cand: Cand,
    m: &PhysicalModel,
    d: &Channels,
    after: &Measures,
    mains: bool,
) -> Option<Rule> {
    refused(cand, m, d, after, mains).map(|r| r.rule)
}

fn with_mode(md: ModeSpec) -> PhysicalModel {
    let mut m = truth();
    m.mode.push(md);
    m
}

#[test]
fn a_line_narrow_mode_at_50_hz_is_mains_unless_allowed() {
    let tau = std::f64::consts::TAU;
    // 1 Hz lines, 10–100 Hz; a mode at exactly 50 Hz, ζ 1e-5 (0.001 Hz wide).
    let d = data(lines(10.0 * tau, 100.0 * tau, tau));
    let m = with_mode(mode(50.0 * tau, 1e-5, 1e-3));
    assert_eq!(
        rule_of(Cand::Mode, &m, &d, &AFTER, false),
        Some(Rule::Mains)
    );
    assert_ne!(rule_of(Cand::Mode, &m, &d, &AFTER, true), Some(Rule::Mains));
    // 3 Hz off the 50 Hz line: not mains.
    let m = with_mode(mode(53.0 * tau, 1e-5, 1e-3));
    assert_ne!(
        rule_of(Cand::Mode, &m, &d, &AFTER, false),
        Some(Rule::Mains)
    );
}

#[test]
fn a_mode_with_zeta_above_0_2_is_a_broad_term() {
    let d = data(dense());
    let m = with_mode(mode(150.0, 0.3, 1.0));
    assert_eq!(
        rule_of(Cand::Mode, &m, &d, &AFTER, false),
        Some(Rule::Broad)
    );
    let m = with_mode(mode(150.0, 0.15, 1.0));
    assert_ne!(
        rule_of(Cand::Mode, &m, &d, &AFTER, false),
        Some(Rule::Broad)
    );
}

#[test]
fn a_mode_between_lines_the_residual_does_not_show_is_unresolved() {
    // 1 rad/s lines; a mode at 150.5 rad/s with ζ 1e-4 (half-power band 0.03 rad/s): no line
    // in it, and the data (the truth) have no peak there.
    let d = data(lines(50.0, 200.0, 1.0));
    let m = with_mode(mode(150.5, 1e-4, 1e-3));
    let r = refused(Cand::Mode, &m, &d, &AFTER, false).unwrap();
    assert_eq!(r.rule, Rule::Unresolved);
    assert!(
        r.reason.contains("measure denser lines around"),
        "{}",
        r.reason
    );
    // The same mode present in the data: its flanks show it, so it is not "unresolved".
    let tr = with_mode(mode(150.5, 1e-4, 1.0));
    let d2 = data_of(&tr, lines(50.0, 200.0, 1.0));
    assert_ne!(
        rule_of(Cand::Mode, &tr, &d2, &AFTER, false),
        Some(Rule::Unresolved)
    );
}

#[test]
fn overlapping_modes_with_cancelling_residues_are_an_artefact() {
    let d = data(dense());
    let mut m = with_mode(mode(150.0, 0.05, 100.0));
    m.mode.push(mode(150.5, 0.05, -99.0));
    let r = refused(Cand::Mode, &m, &d, &AFTER, false).unwrap();
    assert_eq!(r.rule, Rule::Artefact);
    assert!(r.reason.contains("cancelling pair"), "{}", r.reason);
    // Same residue signs: no cancelling pair.
    let mut m = with_mode(mode(150.0, 0.05, 1e-3));
    m.mode.push(mode(150.5, 0.05, 1e-3));
    let r = refused(Cand::Mode, &m, &d, &AFTER, false);
    assert!(
        r.as_ref().is_none_or(|r| !r.reason.contains("cancelling")),
        "{r:?}"
    );
}

#[test]
fn a_mode_far_above_the_data_is_an_artefact() {
    let d = data(dense());
    // |data| near 150 rad/s ≈ 1/(150² − 100²) = 8e-5; the mode's ≈ ρ/(2ζω²) ≫ 10×.
    let m = with_mode(mode(150.0, 0.05, 10.0));
    let r = refused(Cand::Mode, &m, &d, &AFTER, false).unwrap();
    assert_eq!(r.rule, Rule::Artefact);
    assert!(r.reason.contains("exceeds the data"), "{}", r.reason);
}

#[test]
fn a_delay_below_the_phase_resolution_and_a_tiny_misfit_change_are_negligible() {
    let d = data(dense());
    let mut m = truth();
    let mut e = EffectSpec::new(EffectKind::Delay);
    e.tau_s = Some(1e-6); // 2e-4 rad at 200 rad/s, against asin(0.01) = 0.01 rad
    m.effect.push(e);
    assert_eq!(
        rule_of(
            Cand::Delay(crate::diagnose::effects::candidates::Sel::All),
            &m,
            &d,
            &AFTER,
            false
        ),
        Some(Rule::Negligible)
    );
    // Any effect that moves misfit_rms by < 1 %.
    let almost = Measures {
        misfit_rms: 4.97,
        ..BEFORE
    };
    let mut m = truth();
    m.feedthrough = Some(crate::model::physical::Feedthrough::Scalar(1e-9));
    assert_eq!(
        rule_of(Cand::Feedthrough, &m, &d, &almost, false),
        Some(Rule::Negligible)
    );
    assert_eq!(rule_of(Cand::Feedthrough, &m, &d, &AFTER, false), None);
}

#[test]
fn a_mode_the_covariance_does_not_determine_is_not_identified() {
    let d = data(dense());
    // A residue 1e-12 of the data's size: its ω_n and ζ have no information.
    let m = with_mode(mode(150.0, 0.01, 1e-16));
    let r = refused(Cand::Mode, &m, &d, &AFTER, false).unwrap();
    assert_eq!(r.rule, Rule::NotIdentified, "{}", r.reason);
    // A real second mode of the data is identified.
    let tr = with_mode(mode(150.0, 0.01, 1.0));
    let d2 = data_of(&tr, dense());
    assert_eq!(rule_of(Cand::Mode, &tr, &d2, &AFTER, false), None);
}

/// A friction pole far below the band (its relative effect at the band bottom `p/ω_min`
/// below the noise's relative resolution there) is negligible whatever the likelihood says;
/// one that changes the response at the band bottom by 40 % is not.
#[test]
fn a_friction_pole_far_below_the_band_is_negligible() {
    let body = |pole: Option<f64>| {
        let mut m = truth();
        m.rigid_body.push(crate::model::physical::PoleAtZeroSpec {
            name: None,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(500.0),
            friction_pole: pole,
        });
        m
    };
    let d = data_of(&body(None), dense());
    // 1e-4 rad/s against a 50 rad/s band bottom: 2e-6, below r/|G| = 0.01/√n.
    let tiny = refused(Cand::Friction(0), &body(Some(1e-4)), &d, &AFTER, false);
    assert_eq!(
        tiny.as_ref().map(|r| r.rule),
        Some(Rule::Negligible),
        "{tiny:?}"
    );
    assert!(tiny.unwrap().reason.contains("relative resolution"));
    assert_eq!(
        rule_of(Cand::Friction(0), &body(Some(20.0)), &d, &AFTER, false),
        None
    );
}

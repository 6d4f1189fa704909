//! One constructed case per admissibility rule: the truth is one mode at 100 rad/s
//! (ζ 0.01) measured on dense lines; a child adds a term that breaks exactly one rule.
#![cfg(test)]

use super::*;
use crate::diagnose::search::rank::MIN_DELTA_BIC;
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
            min_delta_bic: MIN_DELTA_BIC,
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

/// 1 Hz lines from 2500 to 2800 Hz (exact multiples of 1 Hz).
fn hz_lines() -> Vec<f64> {
    (2500..=2800)
        .map(|k| std::f64::consts::TAU * k as f64)
        .collect()
}

/// The smooth part at high frequency: one mode at 2000 Hz (ζ 0.02).
fn smooth() -> PhysicalModel {
    PhysicalModel {
        mode: vec![mode(std::f64::consts::TAU * 2000.0, 0.02, 1.0)],
        ..Default::default()
    }
}

/// The smooth part and a mode at `f` Hz with damping `z` whose peak is `peak`× the smooth
/// part's magnitude there.
fn smooth_and(f: f64, z: f64, peak: f64) -> PhysicalModel {
    let w = std::f64::consts::TAU * f;
    let mut m = smooth();
    let rho = peak * m.eval(w)[(0, 0)].norm() * 2.0 * z * w * w;
    m.mode.push(mode(w, z, rho));
    m
}

/// The smooth part measured on `omega`, plus at the one line nearest `f` Hz the contribution
/// `with` makes there beyond the smooth part: a spectral line, no skirts.
fn spike(with: &PhysicalModel, omega: Vec<f64>, f: f64) -> Channels {
    let mut d = data_of(&smooth(), omega);
    let i = d
        .omega
        .iter()
        .enumerate()
        .min_by(|a, b| {
            (a.1 - std::f64::consts::TAU * f)
                .abs()
                .total_cmp(&(b.1 - std::f64::consts::TAU * f).abs())
        })
        .unwrap()
        .0;
    let w = d.omega[i];
    d.g[0][i] += with.eval(w)[(0, 0)] - smooth().eval(w)[(0, 0)];
    d.radius[0][i] = 0.01 * d.g[0][i].norm() + 1e-9;
    d
}

/// Issue 33: at 2640.2 Hz (44 × 60 Hz, 0.2 Hz from the harmonic), ζ 2.65e-4 (half-power
/// half-width 0.70 Hz, narrower than the 1 Hz lines).  The same refit mode is a resonance
/// where the data show its skirts on the lines beside the harmonic (admitted: no rule
/// refuses it; the coincidence rule before refused it), and a spectral line where the data
/// hold the same value at the 2640 Hz line only (refused as mains: its ΔBIC off that line
/// is negative).  A mode fitted to the spike alone (ζ 1e-7, no skirts to speak of) too.
#[test]
fn a_mode_with_skirts_at_44_x_60_hz_is_admitted_and_a_one_line_spike_there_is_mains() {
    let tau = std::f64::consts::TAU;
    let (f, z) = (2640.2, 2.65e-4);
    let m = smooth_and(f, z, 5.0);
    // The premise: the mode is line-narrow and within the resolution of 44 × 60 Hz.
    let hm = mains::harmonics_at(f, z, 1.0);
    assert_eq!(hm.len(), 1, "{hm:?}");
    assert_eq!((hm[0].f0, hm[0].h), (60.0, 44.0));
    assert!(!hm[0].stable(), "{hm:?}");
    // Skirts: the mode's contribution 10 lines away is still 0.35× the smooth part there.
    let skirt = (m.eval(tau * 2650.0)[(0, 0)] - smooth().eval(tau * 2650.0)[(0, 0)]).norm()
        / smooth().eval(tau * 2650.0)[(0, 0)].norm();
    assert!(skirt > 0.3, "{skirt}");
    let resonance = data_of(&m, hz_lines());
    assert_eq!(refused(Cand::Mode, &m, &resonance, &AFTER, false), None);
    let line = spike(&m, hz_lines(), 2640.0);
    let r = refused(Cand::Mode, &m, &line, &AFTER, false).unwrap();
    assert_eq!(r.rule, Rule::Mains, "{}", r.reason);
    assert!(
        r.reason.contains("do not show a resonance's skirts"),
        "{}",
        r.reason
    );
    assert!((r.frequency_hz.unwrap() - f).abs() < 1e-9);
    // The independent check: the lines beside 2640 Hz hold the smooth part exactly.
    let off = mains::off_line_support(&m, 1, &line, 2640.0, 0.7);
    assert_eq!(off.n_out, 1);
    assert!(off.delta_bic < 0.0, "{off:?}");
    // A mode fitted to the spike alone: at the line, its value there.
    let narrow = smooth_and(2640.0, 1e-7, 5.0);
    let line = spike(&narrow, hz_lines(), 2640.0);
    assert_eq!(
        rule_of(Cand::Mode, &narrow, &line, &AFTER, false),
        Some(Rule::Mains)
    );
    // --allow-mains writes the spike's mode anyway (as far as the mains rule goes).
    assert_ne!(
        rule_of(Cand::Mode, &narrow, &line, &AFTER, true),
        Some(Rule::Mains)
    );
}

/// A one-line spike at 50 Hz is refused as a spectral line; a resonance with skirts at
/// 50 Hz (h = 1: the harmonic stays within 0.05 Hz of its line, where an off-centre tone
/// leaks like a resonance's skirts) is refused as mains too, by the stable-harmonic test.
#[test]
fn at_50_hz_a_spike_and_a_line_narrow_resonance_are_both_mains() {
    let tau = std::f64::consts::TAU;
    let omega: Vec<f64> = (10..=100).map(|k| tau * k as f64).collect();
    let base = truth();
    let mut m = truth();
    let w = tau * 50.0;
    let rho = base.eval(w)[(0, 0)].norm() * 2.0 * 2e-3 * w * w;
    m.mode.push(mode(w, 2e-3, rho));
    // The resonance: its skirts are in the data (0.1× |G| one line away: 10 radii).
    let d = data_of(&m, omega.clone());
    let r = refused(Cand::Mode, &m, &d, &AFTER, false).unwrap();
    assert_eq!(r.rule, Rule::Mains, "{}", r.reason);
    assert!(r.reason.contains("wander"), "{}", r.reason);
    assert!(!r.reason.contains("spectral line"), "{}", r.reason);
    assert!(mains::off_line_support(&m, 1, &d, 50.0, 0.5).delta_bic > 100.0);
    // The spike: the same value at the 50 Hz line only.
    let mut d = data_of(&base, omega);
    let i = d.omega.iter().position(|x| *x == w).unwrap();
    d.g[0][i] = m.eval(w)[(0, 0)];
    d.radius[0][i] = 0.01 * d.g[0][i].norm() + 1e-9;
    let r = refused(Cand::Mode, &m, &d, &AFTER, false).unwrap();
    assert_eq!(r.rule, Rule::Mains, "{}", r.reason);
    assert!(
        r.reason.contains("do not show a resonance's skirts"),
        "{}",
        r.reason
    );
}

/// Where the coincidence alone decides: `h·0.05 Hz` within the tolerance (1 Hz lines: up to
/// the 10th harmonic; 0.25 Hz lines: the 2nd).
#[test]
fn the_stable_harmonics_follow_the_line_spacing() {
    let stable = |f: f64, df: f64| mains::harmonics_at(f, 1e-6, df).iter().any(|h| h.stable());
    assert!(stable(500.0, 1.0) && stable(600.0, 1.0));
    assert!(!stable(550.0, 1.0) && !stable(660.0, 1.0));
    assert!(stable(120.0, 0.25) && !stable(150.0, 0.25));
    // Not narrower than a line, or 1 Hz off the harmonic: no harmonic.
    assert!(mains::harmonics_at(2640.0, 4e-4, 1.0).is_empty());
    assert!(mains::harmonics_at(2641.0, 1e-6, 1.0).is_empty());
}

/// The spectral-line test asks of the lines beside a harmonic the evidence the search asks of
/// any effect: the run's `min_delta_bic`, not a constant of its own.  The 2640.2 Hz resonance
/// (skirts on every line beside it) has off-line evidence `X`; with the threshold just above
/// `X` it is refused as a spectral line, just below it admitted.
#[test]
fn the_spectral_line_test_reads_the_searchs_threshold() {
    let m = smooth_and(2640.2, 2.65e-4, 5.0);
    let d = data_of(&m, hz_lines());
    let hm = mains::harmonics_at(2640.2, 2.65e-4, 1.0);
    let x = mains::off_line_support(&m, 1, &d, hm[0].hz(), hm[0].tol).delta_bic;
    assert!(x > MIN_DELTA_BIC, "{x}");
    let at = |min_delta_bic: f64| {
        check(
            &Child {
                cand: Cand::Mode,
                model: &m,
                measures: &AFTER,
                reference: &BEFORE,
                allow_mains: false,
                min_delta_bic,
            },
            &d,
        )
    };
    let r = at(1.01 * x).expect("refused above its evidence");
    assert_eq!(r.rule, Rule::Mains, "{}", r.reason);
    assert!(
        r.reason.contains("do not show a resonance's skirts"),
        "{}",
        r.reason
    );
    assert_eq!(at(0.99 * x), None);
}

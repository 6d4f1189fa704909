//! Ties: two effect sets that explain the data equally (BIC within 6) are reported as a tie,
//! with the frequency where a measurement would tell them apart; where the data do choose,
//! no tie is reported.
//!
//! The servo of the hidden-effect suite (rigid body and two modes, 11–250 Hz, 2 % noise)
//! with a pure delay `τ` added.  A non-minimum-phase all-pass `(1 − s/z)/(1 + s/z)` with
//! `z ≈ 2/τ` (the first-order Padé approximant) has the phase `−2 atan(ω/z) ≈ −ωτ +
//! (ωτ)³/12`: with `ω_max τ = 0.3` the two differ by `2.3e-3` rad at the top of the band, a
//! tenth of the noise (2 %), so the data cannot tell them apart; with `ω_max τ = 2` they
//! differ by 0.5 rad and the NMP zero cannot fit.
//!
//! The separating frequency is checked against a closed form: the two path factors
//! `e^{−jωτ}` and the all-pass are both of unit modulus, so they differ by
//! `2|sin((φ_delay − φ_allpass)/2)|`, which crosses the data's relative noise at `ω_c`; the
//! frequency `diagnose` names (searched on the two jointly refit models, 100 steps per
//! decade) must lie within 5 % of it.

use crate::hidden;

use hidden::{add, data, servo, Hidden};
use rshape::diagnose::{diagnose, Diagnosis};

const RELATIVE_NOISE: f64 = hidden::NOISE_REL;

fn run(omega_tau: f64, seed: u64) -> (Diagnosis, f64) {
    let (base, w) = servo();
    let wmax = *w.last().unwrap();
    let mut truth = base.clone();
    add(&mut truth, &Hidden::Delay(omega_tau / wmax));
    let d = diagnose(&base, &data(&truth, &w, seed), 3).unwrap();
    (d, wmax)
}

fn candidate_param(d: &Diagnosis, effect: &str, p: &str) -> f64 {
    d.candidates
        .iter()
        .find(|c| c.effect == effect)
        .and_then(|c| c.params.get(p).copied())
        .unwrap_or_else(|| panic!("{effect}.{p} not fitted"))
}

/// `2|sin((φ_delay − φ_allpass)/2)|`: the relative difference of the two path factors.
fn path_difference(w: f64, tau: f64, z: f64) -> f64 {
    let dphi = -w * tau + 2.0 * (w / z).atan();
    2.0 * (dphi / 2.0).sin().abs()
}

/// The frequency above `w0` where [`path_difference`] reaches `level` (bisection).
fn crossing(w0: f64, tau: f64, z: f64, level: f64) -> f64 {
    let (mut lo, mut hi) = (w0, w0);
    while path_difference(hi, tau, z) < level {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if path_difference(mid, tau, z) < level {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

#[test]
fn a_short_delay_ties_with_an_nmp_zero_and_diagnose_says_where_to_measure() {
    for seed in hidden::SEEDS {
        let (d, wmax) = run(0.3, seed);
        // Within a tie the prior order decides (a delay before an NMP zero).
        assert_eq!(d.chosen, ["delay"], "seed {seed}: {}", d.message);
        assert!(d.after.consistent(), "seed {seed}: {:?}", d.after);
        let tie = d
            .ties
            .iter()
            .find(|t| {
                let mut e = t.effects.clone();
                e.sort();
                e == ["delay", "nmp_zero"]
            })
            .unwrap_or_else(|| panic!("seed {seed}: no delay/NMP-zero tie in {:?}", d.ties));
        assert!(tie.bic_gap < 6.0, "{tie:?}");
        let w_sep = tie
            .separates_above
            .unwrap_or_else(|| panic!("seed {seed}: no separating frequency: {tie:?}"));
        assert!(
            tie.disambiguation.contains("measure there"),
            "{}",
            tie.disambiguation
        );
        // The premise: the two fitted path factors agree within a tenth of the noise over
        // the band.
        let tau = candidate_param(&d, "delay", "tau_s");
        let z = candidate_param(&d, "nmp_zero", "z");
        assert!(
            ((z * tau) / 2.0 - 1.0).abs() < 0.05,
            "z = {z}, τ = {tau}: not the Padé zero 2/τ"
        );
        assert!(path_difference(wmax, tau, z) < 0.1 * RELATIVE_NOISE);
        // The named frequency is where the closed form crosses the noise.
        let w_c = crossing(wmax, tau, z, RELATIVE_NOISE);
        assert!(
            (w_sep / w_c - 1.0).abs() < 0.05,
            "seed {seed}: diagnose names {w_sep} rad/s, the closed form {w_c} rad/s"
        );
        assert!(w_sep > wmax);
    }
}

#[test]
fn a_long_delay_is_not_a_tie() {
    for seed in hidden::SEEDS {
        let (d, wmax) = run(2.0, seed);
        assert_eq!(d.chosen, ["delay"], "seed {seed}: {}", d.message);
        assert!(d.after.consistent(), "seed {seed}: {:?}", d.after);
        assert!(d.ties.is_empty(), "seed {seed}: {:?}", d.ties);
        let bic = |e: &str| {
            d.candidates
                .iter()
                .find(|c| c.effect == e)
                .unwrap()
                .delta_bic
        };
        assert!(bic("delay") - bic("nmp_zero") > 100.0);
        // The best NMP zero differs from the delay by far more than the noise in the band.
        let tau = candidate_param(&d, "delay", "tau_s");
        let z = candidate_param(&d, "nmp_zero", "z");
        assert!(path_difference(wmax, tau, z) > 5.0 * RELATIVE_NOISE);
    }
}

//! Output-path (sensor) effects on a 1×2 model: a delay or a lag on output 2 only is
//! proposed as an output-2 effect (`path = "output"`, `channel = 2`), not as an input effect
//! nor as per-channel terms; the same delay on both outputs is an input delay. The final
//! model exports to the special factorization (modal rows split per output group) and the
//! export reproduces the exact evaluation.

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rshape::diagnose::{diagnose_channels, Channels, Diagnosis, SearchSettings};
use rshape::model::physical::{
    EffectKind, EffectPath, EffectSpec, Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec,
};

/// Rigid body + torsional mode seen by two encoders (motor and load side).
fn base() -> PhysicalModel {
    PhysicalModel {
        outputs: Some(2),
        factor_pole: Some(10.0),
        rigid_body: vec![PoleAtZeroSpec {
            friction_pole: None,
            name: None,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Vector(vec![100.0, 100.0]),
        }],
        mode: vec![ModeSpec {
            name: None,
            omega_n: 484.0,
            zeta: 0.02,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Vector(vec![110.0, -100.0]),
        }],
        ..Default::default()
    }
}

fn effect(kind: EffectKind, output: Option<usize>, x: f64) -> EffectSpec {
    let mut e = EffectSpec::new(kind);
    match kind {
        EffectKind::Delay => e.tau_s = Some(x),
        _ => e.omega_c = Some(x),
    }
    if let Some(o) = output {
        e.path = EffectPath::Output;
        e.channel = Some(o);
    }
    e
}

/// Noisy 1×2 data of `truth` (noise uniform in a disk of radius 1 % of |G|), 300
/// frequencies from 11 Hz to 1 kHz. The band must reach ωτ ≈ 1: below it a delay `τ`, an
/// NMP zero `2/τ` and a lag `1/τ` differ by less than 1 % (phases `−ωτ`, `−2 atan(ωτ/2)`,
/// `−atan(ωτ)`): a tie, which `diagnose` reports as such.
fn data(truth: &PhysicalModel, seed: u64) -> Channels {
    let omega: Vec<f64> = (0..300)
        .map(|k| std::f64::consts::TAU * 11.0 * (1000.0f64 / 11.0).powf(k as f64 / 299.0))
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut g = vec![Vec::new(), Vec::new()];
    let mut r = vec![Vec::new(), Vec::new()];
    for w in &omega {
        let gt = truth.eval(*w);
        for ch in 0..2 {
            let v = gt[(ch, 0)];
            let rk = 0.01 * v.norm();
            let rad = rk * rng.gen::<f64>().sqrt();
            let ph = rng.gen::<f64>() * std::f64::consts::TAU;
            g[ch].push(v + Complex64::from_polar(rad, ph));
            r[ch].push(rk);
        }
    }
    Channels {
        path: "synthetic 1x2".into(),
        omega,
        entries: vec![(0, 0), (1, 0)],
        g,
        radius: r,
        radius_source: vec!["synthetic".into(); 2],
    }
}

fn run(truth: &PhysicalModel, seed: u64) -> Diagnosis {
    let d = diagnose_channels(
        &base(),
        &data(truth, seed),
        &SearchSettings::default(),
        &Default::default(),
    )
    .unwrap();
    println!(
        "seed {seed}: {} chosen {:?} {:?}",
        d.message, d.chosen, d.final_effects
    );
    d
}

/// The final model's rational export equals its exact evaluation (a Padé `[6/6]` of a
/// 150 µs delay is exact to 1e-8 relative up to 1500 rad/s).
fn export_matches(m: &PhysicalModel) {
    let f = m.to_factorization().unwrap();
    for w in [70.0, 480.0, 1500.0] {
        let (a, b) = (f.plant(w).unwrap(), m.eval(w));
        for i in 0..2 {
            let (x, y) = (a[(i, 0)], b[(i, 0)]);
            assert!((x - y).norm() <= 1e-8 * y.norm(), "{w} row {i}: {x} vs {y}");
        }
    }
}

#[test]
fn a_delay_on_output_2_only_is_an_output_2_delay() {
    let mut truth = base();
    truth
        .effect
        .push(effect(EffectKind::Delay, Some(2), 1.5e-4));
    for seed in [1, 2] {
        let d = run(&truth, seed);
        assert_eq!(d.chosen, ["delay (output 2)"], "seed {seed}");
        let e = &d.final_effects[0];
        assert!(
            (e.params["tau_s"] / 1.5e-4 - 1.0).abs() < 0.05,
            "{:?}",
            e.params
        );
        assert!(d.after.consistent(), "{:?}", d.after);
        // Written as a sensor effect on output 2; no mode or per-channel term was added.
        let m = &d.final_model;
        assert_eq!(m.mode.len(), 1);
        assert!(m.feedthrough.is_none() && m.integrator.is_empty());
        let added: Vec<_> = m.effect.iter().collect();
        assert_eq!(added.len(), 1);
        assert_eq!(added[0].path, EffectPath::Output);
        assert_eq!(added[0].channel, Some(2));
        export_matches(m);
        // The output-2 delay beats the same delay on every channel in the first screen.
        let rank = |name: &str| d.candidates.iter().position(|c| c.effect == name);
        let (out2, all) = (
            rank("delay (output 2)").expect("proposed"),
            rank("delay").expect("tried"),
        );
        assert!(out2 < all, "output 2 at {out2}, every channel at {all}");
    }
}

#[test]
fn a_sensor_lag_on_output_2_is_an_output_2_lag() {
    let mut truth = base();
    truth.effect.push(effect(EffectKind::Lag, Some(2), 3000.0));
    let d = run(&truth, 3);
    assert_eq!(d.chosen, ["lag (output 2)"]);
    let wc = d.final_effects[0].params["omega_c"];
    assert!((wc / 3000.0 - 1.0).abs() < 0.1, "omega_c = {wc}");
    assert!(d.after.consistent(), "{:?}", d.after);
    let e = d.final_model.effect.last().unwrap();
    assert_eq!((e.path, e.channel), (EffectPath::Output, Some(2)));
    export_matches(&d.final_model);
}

/// Control: the same delay on both outputs is one delay on the (single) input.
#[test]
fn the_same_delay_on_both_outputs_is_an_input_delay() {
    let mut truth = base();
    truth
        .effect
        .push(effect(EffectKind::Delay, Some(1), 1.5e-4));
    truth
        .effect
        .push(effect(EffectKind::Delay, Some(2), 1.5e-4));
    let d = run(&truth, 4);
    assert_eq!(d.chosen, ["delay"]);
    assert!((d.final_effects[0].params["tau_s"] / 1.5e-4 - 1.0).abs() < 0.05);
    assert!(d.after.consistent(), "{:?}", d.after);
    let e = d.final_model.effect.last().unwrap();
    assert_eq!((e.path, e.channel), (EffectPath::Input, None));
    // Exported through J: no modal row is split.
    let f = d.final_model.to_factorization().unwrap();
    assert_eq!(f.c.ncols(), 2);
}

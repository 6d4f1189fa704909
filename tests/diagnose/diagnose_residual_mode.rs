//! Out-of-band modes (issue 33): a mode 1.5× above the band top bends the in-band error more
//! than the upper residual (a constant feedthrough) follows, so the residual left by the
//! configured upper residual is structured towards the top.  `diagnose` adds a pseudo-mode
//! above the band and reports it as a residual term, not as an identified mode.
//!
//! A receptance, 20–400 Hz, 300 lines, two configured modes (80 and 210 Hz) exactly as
//! generated, the upper residual configured at the hidden mode's static value; the hidden
//! mode at 600 Hz; noise radius 1 % |G| + 1e-6 (noise-free data).

use num_complex::Complex64;
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
use rshape::model::physical::{Feedthrough, Gains, ModeSpec, PhysicalModel};

const TAU: f64 = std::f64::consts::TAU;
/// The hidden mode above the band: 1.5 × 400 Hz, static compliance 2e-3.
const HIDDEN_HZ: f64 = 600.0;
const HIDDEN_STATIC: f64 = 2e-3;

fn mode(f: f64, zeta: f64, stat: f64) -> ModeSpec {
    let w = TAU * f;
    ModeSpec {
        name: None,
        omega_n: w,
        zeta,
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Scalar(stat * w * w),
    }
}

fn truth() -> PhysicalModel {
    PhysicalModel {
        mode: vec![
            mode(80.0, 0.01, 1e-3),
            mode(210.0, 0.01, 1e-3),
            mode(HIDDEN_HZ, 0.01, HIDDEN_STATIC),
        ],
        ..Default::default()
    }
}

/// The configured model: the two in-band modes and the upper residual `D = ρ/ω_n²` of the
/// hidden mode (its first term).
fn configured() -> PhysicalModel {
    PhysicalModel {
        mode: vec![mode(80.0, 0.01, 1e-3), mode(210.0, 0.01, 1e-3)],
        feedthrough: Some(Feedthrough::Scalar(HIDDEN_STATIC)),
        ..Default::default()
    }
}

fn data() -> Channels {
    let m = truth();
    let omega: Vec<f64> = (0..300)
        .map(|k| TAU * (20.0 + 380.0 * k as f64 / 299.0))
        .collect();
    let g: Vec<Complex64> = omega.iter().map(|w| m.eval(*w)[(0, 0)]).collect();
    let radius = g.iter().map(|v| 0.01 * v.norm() + 1e-6).collect();
    Channels {
        path: "receptance".into(),
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius: vec![radius],
        radius_source: vec!["test".into()],
    }
}

#[test]
fn a_mode_above_the_band_is_added_as_a_residual_term() {
    let d_ = data();
    // The premise, computed directly: the two configured modes plus the best constant
    // (weighted least squares, closed form) leave a structured residual far above the noise.
    let two = PhysicalModel {
        feedthrough: None,
        ..configured()
    };
    let e: Vec<Complex64> = d_
        .omega
        .iter()
        .zip(&d_.g[0])
        .map(|(w, g)| g - two.eval(*w)[(0, 0)])
        .collect();
    let wt: Vec<f64> = d_.radius[0].iter().map(|r| 2.0 / (r * r)).collect();
    let dhat = e.iter().zip(&wt).map(|(x, w)| w * x.re).sum::<f64>() / wt.iter().sum::<f64>();
    let v_const: f64 = e
        .iter()
        .zip(&wt)
        .map(|(x, w)| w * (x - dhat).norm_sqr())
        .sum();
    let f = d_.len() as f64;
    assert!(
        v_const / f > 10.0,
        "a constant leaves V/F = {}",
        v_const / f
    );
    // And it is structured: the top fifth of the band holds twice its share of it.
    let top: f64 = e
        .iter()
        .zip(&wt)
        .skip(240)
        .map(|(x, w)| w * (x - dhat).norm_sqr())
        .sum();
    assert!(top > 0.4 * v_const, "top {top} of {v_const}");

    let s = SearchSettings {
        max_effects: 1,
        ..Default::default()
    };
    let d = diagnose_channels(&configured(), &d_, &s, &Default::default()).unwrap();
    eprintln!("{}", d.message);
    assert_eq!(d.verdict, "effects_found", "{}", d.message);
    assert_eq!(
        d.chosen,
        ["residual term: mode above the band"],
        "{}",
        d.message
    );
    // Reported as a residual term, nowhere as an identified mode.
    assert!(d.final_effects.iter().all(|e| e.effect != "mode"));
    assert!(d.steps.iter().all(|s| s.effect != "mode"));
    let fe = &d.final_effects[0];
    assert_eq!(fe.effect, "residual term: mode above the band");
    // Its frequency and residue, no damping (the band does not measure it).
    assert!(!fe.params.contains_key("zeta"), "{fe:?}");
    assert!(fe.params.contains_key("rho"), "{fe:?}");
    let w = fe.params["omega_n"];
    assert!(w > 1.05 * TAU * 400.0, "{w}");
    // The written model: the two configured modes where they were, and the pseudo-mode,
    // named as the residual term, above the band and near the hidden mode.
    let m = &d.final_model;
    assert_eq!(m.mode.len(), 3);
    for (a, b) in m.mode.iter().zip(&configured().mode) {
        assert!((a.omega_n / b.omega_n - 1.0).abs() < 1e-3);
        assert_eq!(a.name, b.name);
    }
    let p = &m.mode[2];
    assert_eq!(
        p.name.as_deref(),
        Some("added by rshape diagnose: residual term: mode above the band")
    );
    assert!((p.omega_n / w - 1.0).abs() < 1e-12);
    assert!(
        (p.omega_n / (TAU * HIDDEN_HZ) - 1.0).abs() < 0.2,
        "{} Hz",
        p.omega_n / TAU
    );
    assert!(
        d.after.misfit_rms < 0.1 * d.before.misfit_rms,
        "{:?}",
        d.after
    );
}

//! Out-of-band modes below the band (issue 33): a mode at 0.6× the band bottom is, in the
//! band, the lower residual `−ρ/ω²` (a rigid body's `c/s²`) plus a curvature
//! `−ρ ω_n²/ω⁴` that no `c/s²` follows, so the residual the configured rigid body leaves is
//! structured towards the bottom.  `diagnose` adds a pseudo-mode below the band beside the
//! rigid body and reports it as a residual term, not as an identified mode.  Where the data
//! show a rigid body and nothing else (an accelerance's mass line), the rigid body stays a
//! rigid body: no pseudo-mode is added.
//!
//! A receptance, 20–400 Hz, 300 lines, two configured modes (80 and 210 Hz) exactly as
//! generated, a rigid body configured at the hidden mode's lower residual; the hidden mode at
//! 12 Hz; noise radius 1 % |G| + 1e-7 (noise-free data).

use num_complex::Complex64;
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
use rshape::model::physical::{Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec, Quantity};

const TAU: f64 = std::f64::consts::TAU;
/// The hidden mode below the band: 0.6 × 20 Hz, static compliance 5e-3.
const HIDDEN_HZ: f64 = 12.0;
const HIDDEN_STATIC: f64 = 5e-3;

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

fn rigid(c: f64) -> PoleAtZeroSpec {
    PoleAtZeroSpec {
        name: None,
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Scalar(c),
        friction_pole: None,
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

/// The configured model: the two in-band modes and the lower residual `c/s²` of the hidden
/// mode (its first term above `ω_n`: `ρ/(ω_n² − ω²) ≈ −ρ/ω²`, so `c = ρ`).
fn configured() -> PhysicalModel {
    let w = TAU * HIDDEN_HZ;
    PhysicalModel {
        mode: vec![mode(80.0, 0.01, 1e-3), mode(210.0, 0.01, 1e-3)],
        rigid_body: vec![rigid(HIDDEN_STATIC * w * w)],
        ..Default::default()
    }
}

fn data(m: &PhysicalModel) -> Channels {
    let omega: Vec<f64> = (0..300)
        .map(|k| TAU * (20.0 + 380.0 * k as f64 / 299.0))
        .collect();
    let g: Vec<Complex64> = omega.iter().map(|w| m.eval(*w)[(0, 0)]).collect();
    let radius = g.iter().map(|v| 0.01 * v.norm() + 1e-7).collect();
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
fn a_mode_below_the_band_is_added_as_a_residual_term() {
    let d_ = data(&truth());
    // The premise, computed directly: the two configured modes plus the best c/s² (weighted
    // least squares on the basis −1/ω², closed form) leave a structured residual far above
    // the noise, concentrated at the bottom of the band.
    let two = PhysicalModel {
        rigid_body: vec![],
        ..configured()
    };
    let e: Vec<Complex64> = d_
        .omega
        .iter()
        .zip(&d_.g[0])
        .map(|(w, g)| g - two.eval(*w)[(0, 0)])
        .collect();
    let wt: Vec<f64> = d_.radius[0].iter().map(|r| 2.0 / (r * r)).collect();
    let basis: Vec<f64> = d_.omega.iter().map(|w| -1.0 / (w * w)).collect();
    let num: f64 = e
        .iter()
        .zip(&wt)
        .zip(&basis)
        .map(|((x, w), b)| w * b * x.re)
        .sum();
    let den: f64 = wt.iter().zip(&basis).map(|(w, b)| w * b * b).sum();
    let chat = num / den;
    let resid = |k: usize| e[k] - chat * basis[k];
    let v_rigid: f64 = (0..e.len()).map(|k| wt[k] * resid(k).norm_sqr()).sum();
    let f = d_.len() as f64;
    assert!(v_rigid / f > 10.0, "a c/s² leaves V/F = {}", v_rigid / f);
    let bottom: f64 = (0..60).map(|k| wt[k] * resid(k).norm_sqr()).sum();
    assert!(bottom > 0.4 * v_rigid, "bottom {bottom} of {v_rigid}");

    let s = SearchSettings {
        max_effects: 1,
        ..Default::default()
    };
    let d = diagnose_channels(&configured(), &d_, &s, &Default::default()).unwrap();
    eprintln!("{}", d.message);
    assert_eq!(d.verdict, "effects_found", "{}", d.message);
    assert_eq!(
        d.chosen,
        ["residual term: mode below the band"],
        "{}",
        d.message
    );
    // Reported as a residual term, nowhere as an identified mode.
    assert!(d.final_effects.iter().all(|e| e.effect != "mode"));
    assert!(d.steps.iter().all(|s| s.effect != "mode"));
    let fe = &d.final_effects[0];
    assert_eq!(fe.effect, "residual term: mode below the band");
    assert!(!fe.params.contains_key("zeta"), "{fe:?}");
    assert!(fe.params.contains_key("rho"), "{fe:?}");
    let w = fe.params["omega_n"];
    assert!(w < 0.95 * TAU * 20.0, "{w}");
    // The written model: the two configured modes where they were, the rigid body kept, and
    // the pseudo-mode, named as the residual term, below the band and near the hidden mode.
    let m = &d.final_model;
    assert_eq!(m.rigid_body.len(), 1, "the lower residual stays");
    assert_eq!(m.mode.len(), 3);
    for (a, b) in m.mode.iter().zip(&configured().mode) {
        assert!((a.omega_n / b.omega_n - 1.0).abs() < 1e-3);
        assert_eq!(a.name, b.name);
    }
    let p = &m.mode[2];
    assert_eq!(
        p.name.as_deref(),
        Some("added by rshape diagnose: residual term: mode below the band")
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

/// An accelerance of a free body (a true rigid body: the mass line) with two modes; the
/// configured model has the rigid body's residue 20 % off and lacks the 210 Hz mode, so the
/// candidates are tried (the retune alone does not explain the data).  The data show a rigid
/// body: its residue is retuned, the mode is added, and the pseudo-mode below the band,
/// tried, is not chosen.
#[test]
fn a_true_rigid_body_stays_a_rigid_body() {
    let c_true = -0.12;
    // Static compliances small enough that the mass line rules below the first mode
    // (|ω² · 1e-6| = 0.016 at 20 Hz against |c| = 0.12).
    let acc = |c: f64, modes: &[f64]| PhysicalModel {
        quantity: Quantity::Acceleration,
        mode: modes.iter().map(|f| mode(*f, 0.01, 1e-6)).collect(),
        rigid_body: vec![rigid(c)],
        ..Default::default()
    };
    let mut d_ = data(&acc(c_true, &[80.0, 210.0]));
    d_.path = "accelerance".into();
    let s = SearchSettings {
        max_effects: 1,
        ..Default::default()
    };
    let d = diagnose_channels(&acc(0.8 * c_true, &[80.0]), &d_, &s, &Default::default()).unwrap();
    eprintln!("{}", d.message);
    // Tried (the model has a rigid body), and not chosen: the missing mode is.
    assert!(
        d.candidates
            .iter()
            .any(|c| c.effect == "residual term: mode below the band"),
        "{}",
        d.message
    );
    assert_eq!(d.chosen, ["mode"], "{}", d.message);
    let m = &d.final_model;
    assert_eq!(m.rigid_body.len(), 1);
    assert_eq!(m.mode.len(), 2, "{:?}", m.mode);
    assert!(m.mode.iter().all(|md| md.omega_n > TAU * 20.0));
    assert!(
        (m.mode[1].omega_n / (TAU * 210.0) - 1.0).abs() < 1e-3,
        "{} Hz",
        m.mode[1].omega_n / TAU
    );
    // The rigid body's residue is the truth's (to 1 %).
    let r = &m.rigid_body[0];
    let res = r.output_gain.to_vec(1)[0] * r.input_gain.to_vec(1)[0] / r.mass;
    assert!((res / c_true - 1.0).abs() < 0.01, "{res} vs {c_true}");
    assert!(
        d.after.misfit_rms < 0.1 * d.before.misfit_rms,
        "{:?}",
        d.after
    );
}

//! `diagnose` on closed-loop data (issue 9, item 6): a `[physical]` nominal plus a
//! `[closed_loop]` table giving only the controllers.  The data are the closed-loop map
//! `Φ = P₀/(1 + P₀C̄)` of a flexible servo whose true plant has a mode (50 rad/s, ζ = 0.02)
//! that the rigid-body nominal lacks, with noise of radius ρ on `Φ`; `diagnose` recovers
//! `P₀` and its radius (the open-loop equivalent) and must find the mode.

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};
use std::process::Command;

const OMEGA_N: f64 = 50.0;
const ZETA: f64 = 0.02;
const GAIN: f64 = 0.4;
const RHO: f64 = 2e-5;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
}

/// The true plant: rigid body 1/s² plus the mode the nominal lacks.
fn p0(w: f64) -> Complex64 {
    let s = Complex64::new(0.0, w);
    1.0 / (s * s) + GAIN / (s * s + 2.0 * ZETA * OMEGA_N * s + OMEGA_N * OMEGA_N)
}

/// The experiment controller C̄ = 12(s + 0.8)/(s + 8).
fn c_bar(w: f64) -> Complex64 {
    let s = Complex64::new(0.0, w);
    12.0 * (s + 0.8) / (s + 8.0)
}

const CONFIG: &str = r#"name = "servo, closed loop, rigid-body nominal"
data = "cl.csv"

[noise]
radius = 2e-5      # on Φ = Y/R

[physical]
factor_pole = 2.0

[[physical.rigid_body]]
output_gain = 1.0

[closed_loop]      # the controllers only: the nominal is [physical]
controller = [[{ num = [20, 20], den = [1, 10] }]]
experiment_controller = [[{ num = [12, 9.6], den = [1, 8] }]]
"#;

fn setup(dir: &Path) -> PathBuf {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let mut csv = String::from("omega_rad_s,re_1_1,im_1_1\n");
    let n = 240;
    for k in 0..n {
        let w = 10f64.powf(-0.5 + 3.0 * k as f64 / (n - 1) as f64);
        let (p, c) = (p0(w), c_bar(w));
        let phi = p / (1.0 + p * c);
        // Noise inside the disk of radius ρ.
        let (r, t) = (
            RHO * rng.gen::<f64>().sqrt(),
            std::f64::consts::TAU * rng.gen::<f64>(),
        );
        let m = phi + Complex64::from_polar(r, t);
        csv.push_str(&format!("{w:.12e},{:.15e},{:.15e}\n", m.re, m.im));
    }
    std::fs::write(dir.join("cl.csv"), csv).unwrap();
    let cfg = dir.join("servo_cl.toml");
    std::fs::write(&cfg, CONFIG).unwrap();
    cfg
}

#[test]
fn diagnose_finds_the_missing_mode_from_closed_loop_data() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = setup(dir.path());
    let o = bin()
        .args(["diagnose", "--json"])
        .arg(&cfg)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(d["verdict"], "effects_found", "{d:#}");
    let top = &d["candidates"][0];
    assert_eq!(top["effect"], "mode", "{top:#}");
    let w = top["params"]["omega_n"].as_f64().unwrap();
    let z = top["params"]["zeta"].as_f64().unwrap();
    // Stated tolerances: ω_n within 0.5 %, ζ within 20 %.
    assert!((w - OMEGA_N).abs() < 0.005 * OMEGA_N, "omega_n = {w}");
    assert!((z - ZETA).abs() < 0.2 * ZETA, "zeta = {z}");
    // The rigid-body nominal fails on the recovered plant; the mode brings it to the noise.
    let before = d["before"]["misfit_rms"].as_f64().unwrap();
    let after = top["misfit_rms_after"].as_f64().unwrap();
    println!("closed-loop diagnose: mode ω_n = {w:.4} rad/s, ζ = {z:.5}; misfit_rms {before:.3} -> {after:.3}");
    assert!(before > 10.0, "before {before}");
    assert!(after < 2.0, "after {after}");

    // --apply --write keeps the closed-loop table and the noise (a radius on Φ).
    let out = dir.path().join("rev1.toml");
    let o = bin()
        .args(["diagnose", "--apply", "1", "--write"])
        .arg(&out)
        .arg(&cfg)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let c = rshape::model::Config::load(&out).unwrap();
    assert!(c.closed_loop.is_some());
    assert_eq!(c.raw.noise.radius, Some(RHO));
    let ph = c.physical.as_ref().unwrap();
    assert_eq!(ph.mode.len(), 1);
    assert!((ph.mode[0].omega_n - OMEGA_N).abs() < 0.005 * OMEGA_N);
    // The revised nominal now explains the closed-loop data: compare on it is consistent.
    let o = bin()
        .args(["compare", "--json"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["verdict"], "consistent", "{rep:#}");
}

#[test]
fn discovery_inputs_recover_the_plant_and_its_radius() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = setup(dir.path());
    let config = rshape::model::Config::load(&cfg).unwrap();
    let data =
        rshape::pipeline::closed_loop::read_data(&config, config.data.as_ref().unwrap()).unwrap();
    let d = rshape::pipeline::closed_loop::discovery_inputs(config, data, None).unwrap();
    assert!(d.dropped.is_empty());
    assert!(d.noise_radius.is_none());
    assert!(d.config.raw.noise.radius.is_none());
    assert_eq!(d.raw.noise.radius, Some(RHO));
    let radii = d.data.noise_radius.as_ref().unwrap();
    for (i, w) in d.data.omega.iter().enumerate() {
        // The measured Φ lies within ρ of the true one, so the true P₀ lies within the
        // propagated radius of the recovered plant (the exact Möbius image of the disk).
        let got = d.data.response[i][(0, 0)];
        let err = (got - p0(*w)).norm();
        assert!(err <= radii[i] * (1.0 + 1e-9), "{w}: {err} > {}", radii[i]);
        // First-order radius ρ/|1 − ΦC̄|² = ρ|1 + P₀C̄|² to within the Möbius factor.
        let first = RHO * (1.0 + p0(*w) * c_bar(*w)).norm_sqr();
        assert!(
            radii[i] >= first * (1.0 - 1e-3) && radii[i] <= first * 1.5,
            "{w}: {} vs {first}",
            radii[i]
        );
    }
}

#[test]
fn a_physical_nominal_and_plant_factors_together_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = setup(dir.path());
    let text = CONFIG.replace(
        "[closed_loop]      # the controllers only: the nominal is [physical]\n",
        "[closed_loop]\nplant = [[{ num = [1], den = [1, 1] }]]\n",
    );
    std::fs::write(&cfg, text).unwrap();
    let o = bin().args(["diagnose"]).arg(&cfg).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("given twice") && e.lines().count() == 1, "{e}");
}

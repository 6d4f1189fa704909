//! Joint diagnosis of several channels: a structural mode has one ω_n and ζ across the
//! channels and a residue per channel, so a mode missing from a 1×2 model is found once,
//! not once per output.  And no printed or JSON parameter is non-finite or far outside the
//! measured band.

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
use rshape::model::physical::{Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec};
use std::process::Command;

fn base() -> PhysicalModel {
    PhysicalModel {
        outputs: Some(2),
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

#[test]
fn a_shared_missing_mode_is_found_once_with_a_residue_per_output() {
    let b = base();
    let mut truth = b.clone();
    // The missing mode: 30 % of the response at 900 rad/s on output 1, opposite sign on 2.
    truth.mode.push(ModeSpec {
        name: None,
        omega_n: 900.0,
        zeta: 0.02,
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Vector(vec![4.0, -3.0]),
    });
    let omega: Vec<f64> = (11..=250)
        .map(|f| std::f64::consts::TAU * f as f64)
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut g = vec![Vec::new(), Vec::new()];
    let mut r = vec![Vec::new(), Vec::new()];
    for w in &omega {
        let gt = truth.eval(*w);
        for ch in 0..2 {
            let v = gt[(ch, 0)];
            let rk = 0.02 * v.norm();
            let rad = rk * rng.gen::<f64>().sqrt();
            let ph = rng.gen::<f64>() * std::f64::consts::TAU;
            g[ch].push(v + Complex64::from_polar(rad, ph));
            r[ch].push(rk);
        }
    }
    let data = Channels {
        path: "synthetic 1x2".into(),
        omega,
        entries: vec![(0, 0), (1, 0)],
        g,
        radius: r,
        radius_source: vec!["synthetic".into(); 2],
    };
    let d = diagnose_channels(&b, &data, &SearchSettings::default(), &Default::default()).unwrap();
    println!("{}: chosen {:?} {:?}", d.message, d.chosen, d.final_effects);
    let modes: Vec<_> = d
        .final_effects
        .iter()
        .filter(|e| e.effect == "mode")
        .collect();
    assert_eq!(modes.len(), 1, "{:?}", d.final_effects);
    assert_eq!(d.chosen, ["mode"]);
    let p = &modes[0].params;
    assert!((p["omega_n"] / 900.0 - 1.0).abs() < 0.01, "{p:?}");
    assert!((p["zeta"] / 0.02 - 1.0).abs() < 0.25, "{p:?}");
    assert!((p["rho_1_1"] / 4.0 - 1.0).abs() < 0.1, "{p:?}");
    assert!((p["rho_2_1"] / -3.0 - 1.0).abs() < 0.1, "{p:?}");
    assert!(d.after.consistent(), "{:?}", d.after);
    assert_eq!(d.n_channels, 2);
}

/// Every number `diagnose --json` prints is finite, and every fitted frequency lies within
/// 1e6× of the measured band (a candidate that runs away is "no fit" with its reason).
#[test]
fn json_output_has_no_absurd_numbers() {
    let exe = env!("CARGO_BIN_EXE_rshape");
    let out = Command::new(exe)
        .args([
            "diagnose",
            "configs/twomass_rigid.toml",
            "--max-effects",
            "2",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        !text.contains("NaN") && !text.contains("inf"),
        "non-finite in the output"
    );
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let (w_lo, w_hi) = (std::f64::consts::TAU * 11.0, std::f64::consts::TAU * 250.0);
    let mut n_checked = 0;
    let mut scan = |params: &serde_json::Value| {
        for (k, x) in params.as_object().unwrap() {
            let x = x
                .as_f64()
                .unwrap_or_else(|| panic!("{k} = {x} is not a number"));
            assert!(x.is_finite(), "{k}");
            if ["omega_n", "omega_c", "z", "pole"].contains(&k.as_str()) {
                assert!(x > w_lo / 1e6 && x < w_hi * 1e6, "{k} = {x}");
            }
            n_checked += 1;
        }
    };
    for c in v["candidates"].as_array().unwrap() {
        scan(&c["params"]);
        scan(&c["uncertainty_2sigma"]);
        if !c["no_fit"].is_null() {
            assert!(c["params"].as_object().unwrap().is_empty());
        }
    }
    for e in v["final_effects"].as_array().unwrap() {
        scan(&e["params"]);
    }
    for s in v["steps"].as_array().unwrap() {
        scan(&s["params"]);
    }
    assert!(n_checked > 10);
    // The text report prints no inf or NaN either.
    let out = Command::new(exe)
        .args([
            "diagnose",
            "configs/twomass_rigid.toml",
            "--max-effects",
            "2",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    for bad in ["inf", "NaN", "e+4", "e4", "e5"] {
        assert!(
            !text
                .split_whitespace()
                .any(|w| w.contains(bad) && w.chars().next().is_some_and(|c| c.is_ascii_digit())),
            "{bad} in:\n{text}"
        );
    }
}

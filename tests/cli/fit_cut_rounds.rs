//! The cutting-plane round seen from the command line: on the DaISy arm with ζ = 0.01 (the
//! fit suite's `arm_z001`), `rshape fit --order 3` certifies only after the certificate's
//! failing frequencies join the grid, and `--verbose` names each round and the frequency it
//! added. The checks are independent of the certificate's code: for normalized coprime
//! factors of a SISO plant `σ_min(M̃) = 1/√(1 + |G|²)`, so A1 is `|r|·√(1 + |G|²) < 1`,
//! with `G` from the config's coefficients and `r` from `r.json`'s `num`/`den`.

use crate::common::{after, repo, rshape, stdout};
use num_complex::Complex64;

const NUM: [f64; 5] = [-1.93391, -0.103041, -2.55255, -0.0234311, -0.1];
const DEN: [f64; 5] = [12.032, 0.3659, 9.2346, 0.13578, 1.0];

/// A polynomial with coefficients in descending powers at `s`.
fn horner(c: &[f64], s: Complex64) -> Complex64 {
    c.iter()
        .fold(Complex64::new(0.0, 0.0), |acc, &k| acc * s + k)
}

fn plant_mag(w: f64) -> f64 {
    let s = Complex64::new(0.0, w);
    (horner(&NUM, s) / horner(&DEN, s)).norm()
}

/// The frequency of the smallest `σ_min(M̃)` within `[lo, hi]` by a dense search.
fn notch(lo: f64, hi: f64) -> f64 {
    let sigma = |w: f64| 1.0 / (1.0 + plant_mag(w).powi(2)).sqrt();
    (0..=200_000)
        .map(|k| lo + (hi - lo) * k as f64 / 200_000.0)
        .min_by(|a, b| sigma(*a).total_cmp(&sigma(*b)))
        .unwrap()
}

#[test]
fn order_3_of_the_lightly_damped_arm_certifies_after_a_cut_round() {
    let d = tempfile::tempdir().unwrap();
    let data = repo("configs/data/daisy_robot_arm/frf_etfe_normfreq.csv");
    let fmt = |c: &[f64]| {
        c.iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let cfg = d.path().join("arm_z001.toml");
    std::fs::write(
        &cfg,
        format!(
            "data = \"{}\"\nsample_time = 1.0\n[plant]\ntf = [[{{ num = [{}], den = [{}] }}]]\n",
            data.display(),
            fmt(&NUM),
            fmt(&DEN)
        ),
    )
    .unwrap();
    let out = d.path().join("o");
    let o = rshape(&[
        "fit",
        cfg.to_str().unwrap(),
        "--order",
        "3",
        "--verbose",
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{text}");
    assert!(text.contains("certificate: passed"), "{text}");
    assert!(text.contains("A1 (proved)"), "{text}");
    // The first round names a frequency beside the notch of σ_min(M̃) near the second mode.
    let round = &text[text
        .find("cutting-plane round 1 of at most 3")
        .unwrap_or_else(|| panic!("no cut round listed:\n{text}"))..];
    assert!(round.contains("added as constraint points"), "{text}");
    let named = after(
        round,
        "fails between the fit's constraint points at omega = ",
    );
    let w2 = notch(0.7, 0.9);
    assert!(
        (named / w2 - 1.0).abs() < 0.01,
        "named {named} rad/s, notch {w2}"
    );
    // The r written meets A1 by the closed form, on ±3 % around both notches and each pole of
    // r (3000 points each) and over the band.
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("r.json")).unwrap()).unwrap();
    let coeffs = |k: &str| -> Vec<f64> {
        j[k].as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (num, den) = (coeffs("num"), coeffs("den"));
    assert_eq!(den.len(), 4, "order 3");
    let r = |w: f64| {
        let s = Complex64::new(0.0, w);
        (horner(&num, s) / horner(&den, s)).norm()
    };
    let mut centres = vec![notch(0.3, 0.45), w2];
    for p in j["poles"].as_array().unwrap() {
        centres.push(p["re"].as_f64().unwrap().hypot(p["im"].as_f64().unwrap()));
    }
    for w in crate::common::a1_check_points(&centres) {
        let v = r(w) * (1.0 + plant_mag(w).powi(2)).sqrt();
        assert!(v < 1.0, "A1 fails at {w} rad/s: |r|·√(1+|G|²) = {v}");
    }
}

//! A1 notches narrower than the fit's grid (docs/guide/outside-data.md, the DaISy robot arm
//! with ζ = 0.01 on its second mode): `σ_min(M̃)` dips about 1 % wide at the plant's
//! lightly damped poles, between the fit's 50 grid points per decade and between the data
//! lines. Before the dips became constraint points of the fit, every candidate of every order
//! rose through the notch at 0.7977 rad/s and the certificate refused them all ("the fit
//! fails at every order").

use rshape::fit::{fit_unit, FitSettings};
use rshape::pipeline::envelope::load_data;
use rshape::{Config, RunOptions};
use std::path::Path;

const ARM_Z001: &str = "data = \"configs/data/daisy_robot_arm/frf_etfe_normfreq.csv\"\nsample_time = 1.0\n[plant]\ntf = [[{ num = [-1.93391, -0.103041, -2.55255, -0.0234311, -0.1], den = [12.032, 0.3659, 9.2346, 0.13578, 1.0] }]]\n";
const NUM: [f64; 5] = [-1.93391, -0.103041, -2.55255, -0.0234311, -0.1];
const DEN: [f64; 5] = [12.032, 0.3659, 9.2346, 0.13578, 1.0];

/// `|G(jω)|` from the transfer function's coefficients (highest power first), by Horner.
fn plant_mag(w: f64) -> f64 {
    let s = num_complex::Complex64::new(0.0, w);
    let horner = |c: &[f64]| {
        c.iter()
            .fold(num_complex::Complex64::new(0.0, 0.0), |a, k| a * s + k)
    };
    (horner(&NUM) / horner(&DEN)).norm()
}

#[test]
fn a1_notch_between_grid_points_is_kept_by_the_fit() {
    let cfg = Config::parse(ARM_Z001, Path::new("arm_z001.toml")).unwrap();
    let data = load_data(&cfg, cfg.data.as_ref().unwrap()).unwrap();
    let env = rshape::envelope(&cfg, &data, &RunOptions::default())
        .unwrap()
        .envelope;
    let f = &cfg.factorization;
    let set = FitSettings {
        order: 6,
        ..FitSettings::default().with_a1_model(f)
    };
    let a1 = |w: f64| f.a1_limit(w);
    let fit = fit_unit(&env, Some(&a1), &set, &Default::default()).unwrap();
    assert!(fit.certificate.passed, "{:?}", fit.certificate.failures);
    // Independently of the factorization's code: for normalized coprime factors of a SISO
    // plant σ_min(M̃) = |M̃| = 1/√(1 + |G|²), so A1 is |r|·√(1 + |G|²) < 1. Checked densely
    // across the notch (±3 % around 0.7977 rad/s) and over the band.
    let r = |w: f64| fit.r.freq(w).norm();
    let mut worst: f64 = 0.0;
    let notch = (0..=3000).map(|k| 0.7977 * (0.97 + 0.06 * k as f64 / 3000.0));
    let band = (0..=2000).map(|k| 10f64.powf(-2.0 + 3.0 * k as f64 / 2000.0));
    for w in notch.chain(band) {
        worst = worst.max(r(w) * (1.0 + plant_mag(w).powi(2)).sqrt());
    }
    assert!(worst < 1.0, "|r|/σ_min(M̃) reaches {worst}");
}

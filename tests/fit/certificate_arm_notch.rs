//! The DaISy robot arm with ζ = 0.01 on its second mode (docs/guide/outside-data.md, "Where a
//! user gets stuck"): the fit failed at every order, its hint naming two notches of the A1
//! limit `σ_min(M̃)`. Is it the nominal model or the fit?  For a SISO plant `σ_min(M̃) = |M̃|`,
//! and `M̃` of a stable plant is itself a unit (stable, its zeros the plant's stable poles,
//! biproper).  So `r = α·M̃` meets A1 with the margin `1/α` at every frequency, and it lies
//! above the envelope, between the data too, when `α ≥ α*`, the largest ratio of the level
//! the certificate asks (`r_min` at a datum, `min(r_min,i, r_min,i+1)` between two) to `|M̃|`.
//! `α* < 1` means the nominal leaves room for a biproper `r` (of the plant's order); the
//! certificate of the fit, applied to `α·M̃`, must then pass.

use rshape::fit::{certify, fit_unit, CertInput, FitSettings, Zpk};
use rshape::pipeline::envelope::load_data;
use rshape::{Config, RunOptions};
use std::path::Path;

const ARM_Z001: &str = "data = \"configs/data/daisy_robot_arm/frf_etfe_normfreq.csv\"\nsample_time = 1.0\n[plant]\ntf = [[{ num = [-1.93391, -0.103041, -2.55255, -0.0234311, -0.1], den = [12.032, 0.3659, 9.2346, 0.13578, 1.0] }]]\n";

/// The config and its Theorem 2 envelope.
pub(crate) fn arm_z001() -> (Config, rshape::Envelope) {
    let cfg = Config::parse(ARM_Z001, Path::new("arm_z001.toml")).unwrap();
    let data = load_data(&cfg, cfg.data.as_ref().unwrap()).unwrap();
    let env = rshape::envelope(&cfg, &data, &RunOptions::default())
        .unwrap()
        .envelope;
    (cfg, env)
}

/// `α*` (by brute force: data, and a dense grid between consecutive data), and the
/// certificate of `α·M̃` with `α` between `α*` and 1: it passes, A1 proved.
#[test]
fn the_z001_arm_admits_alpha_times_m_tilde() {
    let (cfg, env) = arm_z001();
    let f = &cfg.factorization;
    // M̃ of the normalized factors in zero-pole form: its zeros are the plant's poles, its
    // poles those of the factors' realization [Ñ M̃], its value at infinity R̃^(-1/2).
    let ncf = f
        .realization
        .as_ref()
        .expect("a [plant]'s normalized factors");
    let eig = |a: &nalgebra::DMatrix<f64>| rshape::system::eigenvalues(a, "test").unwrap();
    let m = Zpk {
        gain: ncf.factors.d[(0, 1)].abs(),
        zeros: eig(&ncf.plant.a),
        poles: eig(&ncf.factors.a),
    };
    assert!(
        m.zeros.iter().chain(&m.poles).all(|z| z.re < 0.0),
        "M̃ is not a unit"
    );
    let mag = |w: f64| m.mag(w);
    // The A1 limit of rshape is |M̃| here (SISO), this M̃ included.
    for w in [0.1, 0.3616, 0.7978, 2.0] {
        let (a, b) = (f.a1_limit(w), mag(w));
        assert!((a / b - 1.0).abs() < 1e-8, "{w}: {a} vs {b}");
    }
    let (om, rmin) = (&env.omega, &env.r_min);
    let mut alpha: f64 = 0.0;
    let mut worst = (0.0, 0.0);
    for i in 0..om.len() {
        let a = rmin[i] / mag(om[i]);
        if a > alpha {
            (alpha, worst) = (a, (om[i], rmin[i]));
        }
        if i + 1 < om.len() {
            let level = rmin[i].min(rmin[i + 1]);
            for k in 1..400 {
                let w = om[i] * (om[i + 1] / om[i]).powf(k as f64 / 400.0);
                let a = level / mag(w);
                if a > alpha {
                    (alpha, worst) = (a, (w, level));
                }
            }
        }
    }
    println!(
        "alpha* = {alpha:.6} at {:.6} rad/s (level {:.6}, |M~| {:.6})",
        worst.0,
        worst.1,
        mag(worst.0)
    );
    assert!(alpha < 1.0, "the nominal leaves no room: alpha* = {alpha}");
    let set = FitSettings::default().with_a1_model(f);
    let a1 = |w: f64| f.a1_limit(w);
    let inp = CertInput::of_fit(&env, Some(&a1), &set);
    let a = (alpha * (1.0 + 1e-3)).min(0.5 * (alpha + 1.0));
    // r = α·M̃: a unit with a positive gain.
    let r = Zpk {
        gain: a * m.gain,
        ..m.clone()
    };
    let cert = certify(&r, &inp);
    println!(
        "alpha = {a:.6}: passed {}, worst ratio {:.6} at {:.6}, between {:.6}, A1 margin {:?} ({}), failures {:?}",
        cert.passed,
        cert.worst_ratio,
        cert.worst_ratio_omega,
        cert.between_lower_bound,
        cert.worst_a1_margin,
        cert.a1_checked_on,
        cert.failures
    );
    assert!(cert.passed, "{:?}", cert.failures);
    assert_eq!(cert.a1_checked_on, "proved");
}

// The arm's transfer function (ARM_Z001's), for an A1 check that does not go through the
// factorization.
const NUM: [f64; 5] = [-1.93391, -0.103041, -2.55255, -0.0234311, -0.1];
const DEN: [f64; 5] = [12.032, 0.3659, 9.2346, 0.13578, 1.0];

/// `|G(jω)|` from the transfer function's coefficients (highest power first), by Horner.
pub(crate) fn plant_mag(w: f64) -> f64 {
    let s = num_complex::Complex64::new(0.0, w);
    let horner = |c: &[f64]| {
        c.iter()
            .fold(num_complex::Complex64::new(0.0, 0.0), |a, k| a * s + k)
    };
    (horner(&NUM) / horner(&DEN)).norm()
}

/// The fit on the same arm (stop 48): A1 notches narrower than the fit's grid are constraint
/// points of the fit. Before, every candidate of every order rose through the notch at
/// 0.7977 rad/s and the certificate refused them all.
#[test]
fn a1_notch_between_grid_points_is_kept_by_the_fit() {
    let (cfg, env) = arm_z001();
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

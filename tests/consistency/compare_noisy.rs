//! `compare` with a noise radius uses the Theorem 4 envelope: `r_env_max` is the largest
//! finite `r_min` of `noisy_envelope`, `n_unexplainable` counts the `inf`, and a datum fails
//! with the configured `r` exactly when `|r(jω)| ≤ r_min`.

use rshape::consistency::{noise_free_envelope, noisy_envelope, BisectionSettings};
use rshape::data::read_frf_csv;
use rshape::diagnose::{compare, prepare, PlantModel};
use rshape::model::Config;
use std::path::Path;

fn check(config: &str, radius: Option<f64>) {
    let c = Config::load(Path::new(config)).unwrap();
    let d = read_frf_csv(Path::new("configs/robot.csv")).unwrap();
    let s = prepare(&c, &d, None, radius).unwrap();
    let model = PlantModel::from_config(&c);
    let rep = compare(&c, &model, &s).unwrap();
    // Independent computation.
    let f = match &model {
        PlantModel::Physical(p) => p.to_factorization().unwrap(),
        PlantModel::ScaledPhysical(..) => panic!("these configs have no [scaling]"),
        PlantModel::Factored(f) => f.clone(),
    };
    let rad = s.radius.clone().unwrap();
    let env = noisy_envelope(
        &f,
        &s.as_frf(),
        &rad,
        &BisectionSettings::default(),
        &Default::default(),
    )
    .unwrap();
    let finite: Vec<f64> = env
        .r_min
        .iter()
        .cloned()
        .filter(|x| x.is_finite())
        .collect();
    let max_finite = finite.iter().cloned().fold(0.0, f64::max);
    let n_inf = env.r_min.len() - finite.len();
    println!(
        "{config} (radius {:?}): r_env_max = {:?}, n_unexplainable = {:?}, independent {max_finite} / {n_inf}; {}",
        radius, rep.r_env_max, rep.n_unexplainable, rep.r_env_method
    );
    assert!(
        rep.r_env_method.contains("Theorem 4"),
        "{}",
        rep.r_env_method
    );
    assert!(max_finite > 0.0);
    assert!(
        (rep.r_env_max.unwrap() - max_finite).abs() <= 1e-12 * max_finite,
        "{:?} vs {max_finite}",
        rep.r_env_max
    );
    assert_eq!(rep.n_unexplainable, Some(n_inf));
    // Per-datum r_min is the Theorem 4 envelope.
    for (row, e) in rep.rows.iter().zip(&env.r_min) {
        let r = row.r_min.unwrap();
        assert!(r == *e || (r - e).abs() <= 1e-12 * e.abs(), "{r} vs {e}");
    }
    // Fails with r ⇔ |r(jω)| ≤ r_min.
    let r = c.r.as_ref().unwrap();
    assert!(rep.with_r_exact);
    let mut n_fail = 0;
    for (k, row) in rep.rows.iter().enumerate() {
        let ra = r.freq(row.omega).norm();
        assert!(ra > 0.0);
        let fails = ra <= env.r_min[k];
        n_fail += fails as usize;
        assert_eq!(
            row.invalid_with_r,
            Some(fails),
            "datum {k} at {}",
            row.omega
        );
    }
    let frac = n_fail as f64 / rep.rows.len() as f64;
    assert!((rep.invalid_fraction_with_r.unwrap() - frac).abs() < 1e-15);
    // The noise lowers the envelope: r_min(Theorem 4) ≤ r_min(noise-free), datum by datum.
    let nf = noise_free_envelope(&f, &s.as_frf()).unwrap();
    for (a, b) in env.r_min.iter().zip(&nf.r_min) {
        if a.is_finite() {
            assert!(*a <= b * (1.0 + 1e-8), "noisy {a} > noise-free {b}");
        }
    }
}

#[test]
fn robot_r_env_max_is_the_theorem4_envelope() {
    check("configs/robot.toml", None); // [noise] radius = 0.06
    check("configs/robot.toml", Some(0.02));
}

#[test]
fn no_radius_keeps_the_noise_free_envelope() {
    let c = Config::load(Path::new("configs/robot.toml")).unwrap();
    let d = read_frf_csv(Path::new("configs/robot.csv")).unwrap();
    let mut s = prepare(&c, &d, None, None).unwrap();
    s.radius = None;
    let rep = compare(&c, &PlantModel::from_config(&c), &s).unwrap();
    assert!(
        rep.r_env_method.contains("noise-free"),
        "{}",
        rep.r_env_method
    );
    assert!(!rep.with_r_exact);
    let f = c.factorization.clone();
    let nf = noise_free_envelope(&f, &s.as_frf()).unwrap();
    let m = nf.r_min.iter().cloned().fold(0.0, f64::max);
    assert!((rep.r_env_max.unwrap() - m).abs() <= 1e-12 * m);
}

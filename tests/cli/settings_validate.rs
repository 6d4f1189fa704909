//! Settings are validated by field at the library's entry points: a bad value is refused with
//! a message naming the settings type, the field, the value and the range (issue 25).

use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::consistency::{noisy_envelope, BisectionSettings};
use rshape::data::FrfData;
use rshape::fit::{fit_unit, FitSettings};
use rshape::model::Config;
use rshape::mu::MuSettings;
use std::path::Path;

fn siso() -> (Config, FrfData) {
    let config = Config::parse(
        "[plant]\ntf = [[{ num = [1], den = [1, 1] }]]\n",
        Path::new("s.toml"),
    )
    .expect("config");
    let omega = vec![0.5, 1.0, 2.0];
    let response = omega
        .iter()
        .map(|&w| DMatrix::from_element(1, 1, Complex64::new(1.2, 0.0) / Complex64::new(1.0, w)))
        .collect();
    let data = FrfData {
        path: "d.csv".into(),
        lines: vec![2, 3, 4],
        omega,
        response,
        noise_radius: None,
    };
    (config, data)
}

#[test]
fn noisy_envelope_names_the_bad_mu_setting() {
    let (config, data) = siso();
    let settings = BisectionSettings {
        mu: MuSettings {
            max_evals: 0,
            ..Default::default()
        },
        ..Default::default()
    };
    let e = noisy_envelope(
        &config.factorization,
        &data,
        &[0.01; 3],
        &settings,
        &Default::default(),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "MuSettings.max_evals = 0: must be at least 1"
    );
    let settings = BisectionSettings {
        rel_tol: 2.0,
        ..Default::default()
    };
    let e = noisy_envelope(
        &config.factorization,
        &data,
        &[0.01; 3],
        &settings,
        &Default::default(),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "BisectionSettings.rel_tol = 2: must be in (0, 1)"
    );
    // A typed kind a library user can match on, its message unchanged.
    assert!(matches!(e, rshape::Error::Setting(ref s) if s.field == "rel_tol"));
    let e = noisy_envelope(
        &config.factorization,
        &data,
        &[0.01; 2],
        &BisectionSettings::default(),
        &Default::default(),
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "d.csv: 2 noise radii for 3 data");
    assert!(matches!(e, rshape::Error::Input { ref path, .. } if path == Path::new("d.csv")));
    // The defaults work.
    let env = noisy_envelope(
        &config.factorization,
        &data,
        &[0.01; 3],
        &BisectionSettings::default(),
        &Default::default(),
    )
    .expect("default settings");
    assert_eq!(env.r_min.len(), 3);
}

#[test]
fn fit_names_the_bad_tolerance() {
    let (config, data) = siso();
    let env = rshape::pipeline::envelope::envelope(
        &config,
        &data,
        &rshape::RunOptions::noise_radius(Some(0.01)),
    )
    .expect("envelope")
    .envelope;
    let settings = FitSettings {
        bisection_tol: 0.0,
        ..Default::default()
    };
    let e = fit_unit(&env, None, &settings, &Default::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "FitSettings.bisection_tol = 0: must be in (0, 1)"
    );
}

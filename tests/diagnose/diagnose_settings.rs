//! `SearchSettings` are validated before any work, the acceptance threshold `min_delta_bic`
//! included, and also where the search would not run (a model already consistent).

use num_complex::Complex64;
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
use rshape::model::physical::{Gains, ModeSpec, PhysicalModel};

fn model() -> PhysicalModel {
    PhysicalModel {
        mode: vec![ModeSpec {
            name: None,
            omega_n: 600.0,
            zeta: 0.02,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(4e5),
        }],
        ..Default::default()
    }
}

/// The model's own response, noise radius 1 % of it: consistent.
fn data() -> Channels {
    let m = model();
    let omega: Vec<f64> = (0..60).map(|k| 100.0 * 1.05f64.powi(k)).collect();
    let g: Vec<Complex64> = omega.iter().map(|w| m.eval(*w)[(0, 0)]).collect();
    let radius = g.iter().map(|v| 0.01 * v.norm()).collect();
    Channels {
        path: "mode.csv".into(),
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius: vec![radius],
        radius_source: vec!["test".into()],
    }
}

#[test]
fn a_bad_min_delta_bic_is_refused_even_on_a_consistent_model() {
    let ok = diagnose_channels(
        &model(),
        &data(),
        &SearchSettings::default(),
        &Default::default(),
    )
    .expect("valid");
    assert!(
        ok.message.contains("nothing needs to be added"),
        "{}",
        ok.message
    );
    for (x, shown) in [(f64::NAN, "NaN"), (-1.0, "-1"), (f64::INFINITY, "inf")] {
        let s = SearchSettings {
            min_delta_bic: x,
            ..Default::default()
        };
        let e = diagnose_channels(&model(), &data(), &s, &Default::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("SearchSettings.min_delta_bic = {shown}: must be a finite number ≥ 0")
        );
    }
    let s = SearchSettings {
        beam: 0,
        ..Default::default()
    };
    let e = diagnose_channels(&model(), &data(), &s, &Default::default()).unwrap_err();
    assert_eq!(e.to_string(), "SearchSettings.beam = 0: must be at least 1");
}

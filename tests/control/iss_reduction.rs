//! The model-reduction use case: the ISS 1R module (270 states, 3×3) reduced to 20 states by
//! balanced truncation; the data are the full model's exact frequency response
//! (configs/iss1r_reduced.toml). rshape must find a certified r that covers the neglected
//! dynamics.
use crate::common;

use common::{repo, rshape, stderr, stdout};
use rshape::consistency::noise_free_envelope;
use rshape::data::read_frf_csv;
use rshape::model::Config;

#[test]
fn envelope_is_bounded_by_the_model_error_and_the_fit_is_certified() {
    let cfg = Config::load(&repo("configs/iss1r_reduced.toml")).unwrap();
    let ncf = cfg.factorization.realization.clone().unwrap();
    assert_eq!(ncf.plant.states(), 20);
    let data = read_frf_csv(cfg.data.as_ref().unwrap()).unwrap();
    assert_eq!(data.len(), 2000);
    let env = noise_free_envelope(&cfg.factorization, &data).unwrap();
    // Independent bound: ΔN = M̃(G_p − G), ΔM = 0 explains the datum, and ‖M̃‖ ≤ 1 for
    // normalized factors, so r_min(ω) ≤ σ_max(G_p(jω) − G(jω)); the balanced-truncation
    // bound 2·Σ_{i>20} σᵢ = 0.0124 (hankel_sv.csv) caps the latter.
    let mut worst = 0.0f64;
    for (k, w) in data.omega.iter().enumerate() {
        let g = ncf.plant.freq(*w).unwrap();
        let err = (&data.response[k] - g)
            .svd(false, false)
            .singular_values
            .max();
        assert!(
            env.r_min[k] <= err * (1.0 + 1e-8) + 1e-15,
            "ω={w}: {} > {err}",
            env.r_min[k]
        );
        worst = worst.max(err);
    }
    assert!(worst < 0.0124, "{worst}");
    // The envelope spans three decades: the neglected modes are lightly damped.
    let (lo, hi) = env
        .r_min
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(*r), b.max(*r)));
    assert!(hi / lo > 100.0, "{lo} {hi}");

    let dir = tempfile::tempdir().unwrap();
    let out = rshape(&[
        "run",
        repo("configs/iss1r_reduced.toml").to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        stdout(&out),
        stderr(&out)
    );
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    let cert = &rep["r_fitted"]["certificate"];
    assert_eq!(cert["passed"], true, "{cert}");
    assert!(cert["worst_ratio"].as_f64().unwrap() >= 1.0 - 1e-9);
    assert!(cert["worst_between_ratio"].as_f64().unwrap() >= 1.0 - 1e-9);
}

//! Issue 34 item 2: assumption A1 `|r| < σ_min(M̃)` is *proved* by the certificate on its
//! band (the `L∞` norm of `M̃⁻¹·r` by the Hamiltonian iteration), not sampled. Each proof is
//! cross-checked against a brute-force minimum of `σ_min(M̃(jω))/|r(jω)|` computed from the
//! factors' own SVD on a grid fine enough to resolve the notch (an independent route).
use crate::common;

use common::{repo, rshape, stderr, stdout};
use rshape::fit::{certify, A1Proof, CertInput, Certificate, Zpk};
use rshape::model::{Config, Factorization};
use std::path::Path;

const WN: f64 = 478.7728546626137;

/// configs/twomass_rev1.toml with the mode's damping set to `zeta`.
fn twomass(dir: &Path, zeta: &str) -> String {
    let text = std::fs::read_to_string(repo("configs/twomass_rev1.toml"))
        .unwrap()
        .replace("zeta = 0.020144090247561523", &format!("zeta = {zeta}"))
        .replace(
            "\"data/",
            &format!("\"{}/", repo("configs/data").to_str().unwrap()),
        );
    let p = dir.join(format!("tm_{zeta}.toml"));
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

fn constant(c: f64) -> Zpk {
    Zpk {
        gain: c,
        zeros: vec![],
        poles: vec![],
    }
}

/// The certificate of `r` over data 100…720 rad/s with `r_min = |r|/2` (coverage holds), A1
/// from `f` by `proof` and no dips (the grid alone would miss a notch).
fn cert(f: &Factorization, r: &Zpk, proof: &A1Proof) -> Certificate {
    let omega: Vec<f64> = (0..200).map(|k| 100.0 * 1.01f64.powi(k)).collect();
    let r_min: Vec<f64> = omega.iter().map(|w| 0.5 * r.mag(*w)).collect();
    let a1 = |w: f64| f.a1_limit(w);
    certify(
        r,
        &CertInput {
            omega: &omega,
            r_min: &r_min,
            a1: Some(&a1),
            a1_data: None,
            a1_dips: &[],
            a1_proof: proof,
            margin: 0.0,
            floor: 1e-30,
            per_decade: 100,
            extend_decades: 2.0,
            no_dip: true,
            axis_tol: 1e-9,
        },
    )
}

/// Brute force: `min σ_min(M̃)/|r|` on a log grid over `[lo, hi]` plus a fine linear grid of
/// ±`halfwidth` (relative) around `center`, cut at `lo` (the certificate's band edge).
fn brute_min(f: &Factorization, r: &Zpk, lo: f64, hi: f64, center: f64, halfwidth: f64) -> f64 {
    let mut ws: Vec<f64> = (0..=20000)
        .map(|k| lo * (hi / lo).powf(k as f64 / 20000.0))
        .collect();
    ws.extend((0..=20000).map(|k| center * (1.0 + halfwidth * (k as f64 / 10000.0 - 1.0))));
    ws.iter()
        .filter(|w| **w >= lo)
        .map(|w| f.a1_limit(*w) / r.mag(*w))
        .fold(f64::INFINITY, f64::min)
}

/// ζ = 1e-7 and ζ = 1e-11 (the smallest class the config accepts is ≥ 1e-12): the notch is
/// 1e-7 (1e-11) wide, far between the certificate's grid points. Without the proof and
/// without dips the certificate passes an `r` above the notch (the old wrong verdict); with
/// the proof it fails at the mode. An `r` below the notch passes, and its proved bound is
/// the brute-force minimum to 1e-6.
#[test]
fn a1_proof_finds_a_notch_between_grid_points() {
    let dir = tempfile::tempdir().unwrap();
    for zeta in ["1e-7", "1e-11"] {
        let z: f64 = zeta.parse().unwrap();
        let config = Config::load(Path::new(&twomass(dir.path(), zeta))).unwrap();
        let f = &config.factorization;
        let proof: A1Proof = f.a1_inverse_blocks().into();
        assert!(matches!(proof, A1Proof::Blocks(_)), "{zeta}");
        // The notch: σ_min at the mode against its value 1 % aside.
        let deep = f.a1_limit(WN);
        let side = f.a1_limit(0.99 * WN).min(f.a1_limit(1.01 * WN));
        assert!(deep < 1e-3 * side, "{zeta}: {deep} vs {side}");
        let above = constant((deep * side).sqrt());
        let sampled = cert(f, &above, &A1Proof::Sampled);
        assert!(
            sampled.passed,
            "{zeta}: the grid alone should miss the notch: {:?}",
            sampled.failures
        );
        let proved = cert(f, &above, &proof);
        assert!(!proved.passed, "{zeta}: the proof missed the notch");
        assert_eq!(proved.a1_checked_on, "proved");
        assert!(
            proved.failures.iter().any(|m| m.contains("A1 fails")),
            "{zeta}: {:?}",
            proved.failures
        );
        let w = proved.worst_a1_omega.unwrap();
        assert!((w - WN).abs() < 10.0 * z * WN + 1e-9 * WN, "{zeta}: {w}");
        // Below the notch: passes, and the proved bound is the brute-force minimum.
        let below = constant(0.5 * deep);
        let ok = cert(f, &below, &proof);
        assert!(ok.passed, "{zeta}: {:?}", ok.failures);
        let lower = ok.a1_lower_bound.unwrap();
        let brute = brute_min(f, &below, 1.0, 1e6, WN, 20.0 * z);
        assert!(lower <= brute * (1.0 + 1e-9), "{zeta}: {lower} > {brute}");
        assert!(lower >= brute * (1.0 - 1e-6), "{zeta}: {lower} ≪ {brute}");
        assert!(
            (lower - 2.0).abs() < 1e-6,
            "{zeta}: the minimum is at the notch, σ_min/|r| = 2 there: {lower}"
        );
    }
}

/// The three kinds of `M̃⁻¹` realization: normalized factors of a plant with a ζ = 1e-7
/// mode (its notch is a zero of `M̃`, a pole of the plant), a non-diagonal 2×2 `M̃` (the
/// paper's MIMO example) and a diagonal physical model. Each proved bound is checked
/// against the brute-force minimum; a strictly proper diagonal entry has no proof (A1
/// fails at ω = ∞) and says so.
#[test]
fn a1_proof_agrees_with_brute_force_on_every_realization_kind() {
    let dir = tempfile::tempdir().unwrap();
    let plant = dir.path().join("p.toml");
    std::fs::write(
        &plant,
        "[plant]\ntf = [[{ num = [1e4], den = [1, 2e-5, 1e4] }]]\n[r]\nnum = [0.01]\nden = [1]\n",
    )
    .unwrap();
    let cases = [
        (plant.to_str().unwrap().to_string(), 100.0, 1e-7),
        (
            repo("configs/paper_mimo.toml")
                .to_str()
                .unwrap()
                .to_string(),
            1.0,
            1e-3,
        ),
        (twomass(dir.path(), "0.02"), WN, 0.05),
    ];
    for (path, center, z) in cases {
        let config = Config::load(Path::new(&path)).unwrap();
        let f = &config.factorization;
        let proof: A1Proof = f.a1_inverse_blocks().into();
        assert!(matches!(proof, A1Proof::Blocks(_)), "{path}");
        let shape = Zpk {
            gain: 1.0,
            zeros: vec![num_complex::Complex64::new(-3.0 * center, 0.0)],
            poles: vec![num_complex::Complex64::new(-center, 0.0)],
        };
        // The band is [1, ∞] (data from 100 rad/s, two decades below).
        let g0 = brute_min(f, &shape, 1.0, 1e8, center, 20.0 * z);
        for scale in [0.5, 0.999, 1.001, 2.0] {
            let r = Zpk {
                gain: scale * g0,
                ..shape.clone()
            };
            let c = cert(f, &r, &proof);
            let brute = brute_min(f, &r, 1.0, 1e8, center, 20.0 * z);
            assert_eq!(c.passed, brute > 1.0, "{path} ×{scale}: {:?}", c.failures);
            if let Some(lower) = c.a1_lower_bound {
                assert!(
                    lower <= brute * (1.0 + 1e-9) && lower >= brute * (1.0 - 1e-6),
                    "{path}: proved {lower}, brute force {brute}, {:?}",
                    c.failures
                );
            } else {
                // Only a failure already found at a real frequency skips the proof.
                assert!(!c.passed && scale > 1.0, "{path} ×{scale}: no proof");
            }
            assert!(c.a1_lower_bound.is_some() || scale > 1.0);
        }
    }
    let strict = Factorization::special(
        nalgebra::DMatrix::from_element(1, 1, 1.0),
        rshape::system::TfMatrix::diagonal(vec![rshape::system::TransferFunction::new(
            vec![1.0],
            vec![1.0, 1.0],
        )]),
        rshape::system::TfMatrix::diagonal(vec![rshape::system::TransferFunction::new(
            vec![1.0],
            vec![1.0, 2.0],
        )]),
        vec![rshape::system::TransferFunction::gain(1.0)],
    )
    .unwrap();
    let why = strict.a1_inverse_blocks().unwrap_err();
    assert!(why.contains("ω = ∞"), "{why}");
    let c = cert(&strict, &constant(1e-9), &A1Proof::Impossible(why.clone()));
    assert!(!c.passed);
    assert!(
        c.failures
            .iter()
            .any(|m| m.contains("A1 fails") && m.contains("∞")),
        "{:?}",
        c.failures
    );
}

/// The case end to end: `fit` on the ζ = 1e-7 model refuses (exit 2, one line naming
/// A1 and the mode's frequency) and leaves no output folder, where it said "certificate
/// passed".
#[test]
fn fit_on_a_notch_model_fails_its_certificate() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = twomass(dir.path(), "1e-7");
    let out = dir.path().join("out");
    let o = rshape(&["fit", &cfg, "--order", "2", "--out", out.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}{}", stdout(&o));
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("A1 fails") && err.contains("4.787729e2"),
        "{err}"
    );
    assert!(!stdout(&o).contains("certificate: passed"));
    assert!(!out.exists());
}

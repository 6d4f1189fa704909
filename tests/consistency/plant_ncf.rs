//! Normalized left coprime factors computed from a `[plant]`: normalization, exactness,
//! stability, agreement with closed forms and with hand-typed factors (Theorem 2).
use crate::common;

use common::repo;
use nalgebra::DMatrix;
use num_complex::Complex64;
use proptest::prelude::*;
use rshape::consistency::noise_free_envelope;
use rshape::data::FrfData;
use rshape::model::Config;
use rshape::system::{eigenvalues, logspace, spectral_abscissa, NormalizedLcf, StateSpace};
use std::path::{Path, PathBuf};

/// Worst normalization error ‖M̃M̃* + ÑÑ* − I‖ and worst relative error of M̃⁻¹Ñ against
/// a dense-LU evaluation of G, over `grid`.
fn ncf_errors(ncf: &NormalizedLcf, grid: &[f64]) -> (f64, f64) {
    let (p, _) = ncf.shape();
    let (mut e_norm, mut e_g) = (0.0f64, 0.0f64);
    for &w in grid {
        let (m, n) = ncf.at(w).unwrap();
        let id = DMatrix::<Complex64>::identity(p, p);
        let s = &m * m.adjoint() + &n * n.adjoint() - id;
        e_norm = e_norm.max(s.norm());
        let Some(g) = ncf.plant.freq(w) else { continue };
        let g2 = m.lu().solve(&n).unwrap();
        e_g = e_g.max((&g2 - &g).norm() / g.norm().max(1e-300));
    }
    (e_norm, e_g)
}

fn random_plant(seed: u64, n: usize, p: usize, m: usize, shift: f64) -> StateSpace {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut r = |_, _| rng.gen_range(-1.0..1.0);
    let a = DMatrix::from_fn(n, n, &mut r) * 2.0 + DMatrix::identity(n, n) * shift;
    let b = DMatrix::from_fn(n, m, &mut r);
    let c = DMatrix::from_fn(p, n, &mut r);
    let d = DMatrix::from_fn(p, m, &mut r);
    StateSpace { a, b, c, d }
}

proptest! {
    // A fixed seed keeps CI reproducible; `PROPTEST_RNG_SEED=N` (or any value) explores other
    // cases.  A random run found `ill_conditioned_case_refined_to_eps_kappa`.
    #![proptest_config(ProptestConfig {
        cases: 40,
        rng_seed: if std::env::var_os("PROPTEST_RNG_SEED").is_some() {
            ProptestConfig::default().rng_seed
        } else {
            proptest::test_runner::RngSeed::Fixed(20_261_124)
        },
        ..ProptestConfig::default()
    })]
    #[test]
    fn random_plants_stable_and_unstable(seed in 0u64..1_000_000, n in 1usize..7, p in 1usize..4,
                                         m in 1usize..4, shift in -3.0f64..3.0) {
        let plant = random_plant(seed, n, p, m, shift);
        let open = spectral_abscissa(&eigenvalues(&plant.a, "A").unwrap());
        let ncf = NormalizedLcf::new(plant).unwrap();
        let grid = logspace(1e-3, 1e3, 400);
        let (e_norm, e_g) = ncf_errors(&ncf, &grid);
        // 1e-9 as the issue asks, except where the problem itself is worse conditioned:
        // the output injection is L = −(BDᵀ + YCᵀ)R̃⁻¹, so a nearly unobservable unstable
        // mode makes ‖Y‖‖C‖² large (1.5e7 for seed 262164, n = 6, shift 2.115) and any
        // evaluation of the factors' realization rounds at about ε·κ (4e-9 there, with a
        // Riccati residual of 2e-16). The bound is 1e-15·κ ≈ 4.5·ε·κ beyond κ = 1e6.
        let kappa = 1.0 + ncf.riccati.x.norm() * ncf.plant.c.norm().powi(2);
        let tol = 1e-9f64.max(1e-15 * kappa);
        prop_assert!(e_norm < tol, "normalization error {e_norm} (κ = {kappa:e})");
        prop_assert!(e_g < tol, "M̃⁻¹Ñ vs G: {e_g} (κ = {kappa:e})");
        // The factors are stable, whatever the plant.
        let fa = spectral_abscissa(&eigenvalues(&ncf.factors.a, "A+LC").unwrap());
        prop_assert!(fa < 0.0, "factor abscissa {fa} (plant {open})");
        // Residual of the filter Riccati equation, recomputed here from its definition
        // (D-terms included) instead of the solver's own form.
        let (a, b, c, d) = (&ncf.plant.a, &ncf.plant.b, &ncf.plant.c, &ncf.plant.d);
        let y = &ncf.riccati.x;
        let rt = DMatrix::<f64>::identity(p, p) + d * d.transpose();
        let rti = rt.clone().try_inverse().unwrap();
        let r = DMatrix::<f64>::identity(m, m) + d.transpose() * d;
        let ri = r.try_inverse().unwrap();
        let ab = a - b * d.transpose() * &rti * c;
        let res = &ab * y + y * ab.transpose() - y * c.transpose() * &rti * c * y + b * &ri * b.transpose();
        let scale = 1.0 + ab.norm() * y.norm() + y.norm().powi(2) * c.norm().powi(2);
        prop_assert!(res.norm() / scale < 1e-10, "Riccati residual {}", res.norm() / scale);
    }
}

/// The cases proptest found where 1e-9 cannot hold: several unstable poles seen through one
/// output make `‖Y‖‖C‖²` 3e7 and 9e9; the error stays below 1e-15·κ (about 4.5·ε·κ).
#[test]
fn ill_conditioned_random_plants_round_at_eps_kappa() {
    for (seed, n, p, m, shift) in [
        (262164u64, 6usize, 1usize, 1usize, 2.1150200664710375f64),
        (564471, 4, 1, 3, 2.8026083228436462),
        (774030, 5, 1, 2, 3.0),
    ] {
        let ncf = NormalizedLcf::new(random_plant(seed, n, p, m, shift)).unwrap();
        let kappa = 1.0 + ncf.riccati.x.norm() * ncf.plant.c.norm().powi(2);
        assert!(
            kappa > 1e6,
            "seed {seed}: κ = {kappa:e} is not ill-conditioned"
        );
        let (e_norm, e_g) = ncf_errors(&ncf, &logspace(1e-3, 1e3, 400));
        assert!(
            e_norm < 1e-15 * kappa,
            "seed {seed}: {e_norm:e} at κ = {kappa:e}"
        );
        assert!(e_g < 1e-15 * kappa, "seed {seed}: {e_g:e} at κ = {kappa:e}");
    }
}

/// Found by a random proptest run (2026-11-24): a 5-state plant (poles 3.40, 1.49 unstable;
/// the one at 3.40 seen by the output through a gain of 1.4e-3), 1 output, 2 inputs, κ = 8.2e7.
/// Its Riccati solution had a relative residual of 1e-16 but a forward error of 5.5e-8
/// (60-digit Newton reference), which gave a normalization error of 1.08e-6, 13× the bound.
/// Refinement with the residual in twice the precision (`system::compensated`) brings it to
/// 1.35e-9; 1500 further random plants stay below 2.7e-16·κ.
#[test]
fn ill_conditioned_case_refined_to_eps_kappa() {
    let ncf = NormalizedLcf::new(random_plant(64791, 5, 1, 2, 0.0)).unwrap();
    let kappa = 1.0 + ncf.riccati.x.norm() * ncf.plant.c.norm().powi(2);
    assert!(kappa > 1e7, "κ = {kappa:e} is not ill-conditioned");
    let (e_norm, e_g) = ncf_errors(&ncf, &logspace(1e-3, 1e3, 400));
    assert!(e_norm < 1e-15 * kappa, "{e_norm:e} at κ = {kappa:e}");
    assert!(e_g < 1e-15 * kappa, "{e_g:e} at κ = {kappa:e}");
}

#[test]
fn unstable_first_order_matches_closed_form() {
    // G = 1/(s − 1): Y = 1 + √2, M̃ = (s − 1)/(s + √2), Ñ = 1/(s + √2).
    let plant = StateSpace {
        a: DMatrix::from_element(1, 1, 1.0),
        b: DMatrix::from_element(1, 1, 1.0),
        c: DMatrix::from_element(1, 1, 1.0),
        d: DMatrix::from_element(1, 1, 0.0),
    };
    let ncf = NormalizedLcf::new(plant).unwrap();
    let r2 = 2f64.sqrt();
    assert!((ncf.riccati.x[(0, 0)] - (1.0 + r2)).abs() < 1e-13);
    for w in logspace(1e-3, 1e3, 50) {
        let s = Complex64::new(0.0, w);
        let (m, n) = ncf.at(w).unwrap();
        assert!((m[(0, 0)] - (s - 1.0) / (s + r2)).norm() < 1e-13);
        assert!((n[(0, 0)] - 1.0 / (s + r2)).norm() < 1e-13);
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn mimo_tf_plant_with_integrator_and_unstable_pole() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "p.toml",
        r#"
[plant]
tf = [[{ num = [1], den = [1, 0] }, { num = [1], den = [1, 1] }],
      [{ num = [0.5], den = [1, -2] }, { num = [2, 1], den = [1, 3, 2] }]]
"#,
    );
    let c = Config::load(&cfg).unwrap();
    let ncf = c.factorization.realization.clone().unwrap();
    // 1/s, 1/(s+1), 1/(s−2), (2s+1)/((s+1)(s+2)): McMillan degree 4 (the pole −1 is shared
    // within a row and realized once).
    assert_eq!(ncf.plant.states(), 4);
    let (e_norm, e_g) = ncf_errors(&ncf, &logspace(1e-3, 1e3, 300));
    assert!(e_norm < 1e-9 && e_g < 1e-9, "{e_norm} {e_g}");
    // The factors agree with the transfer functions as typed.
    for w in [0.01, 0.3, 2.0, 50.0] {
        let g = c.factorization.plant(w).unwrap();
        let s = Complex64::new(0.0, w);
        let g11 = 1.0 / s;
        let g22 = (2.0 * s + 1.0) / ((s + 1.0) * (s + 2.0));
        let g21 = 0.5 / (s - 2.0);
        assert!((g[(0, 0)] - g11).norm() < 1e-10 * g11.norm());
        assert!((g[(1, 1)] - g22).norm() < 1e-10 * g22.norm());
        assert!((g[(1, 0)] - g21).norm() < 1e-10 * g21.norm());
    }
}

#[test]
fn theorem2_envelope_on_tf_plant_equals_hand_typed_factors() {
    let dir = tempfile::tempdir().unwrap();
    let plant = write(
        dir.path(),
        "plant.toml",
        "[plant]\ntf = [[{ num = [1], den = [1, -1] }]]\n",
    );
    let r2 = 2f64.sqrt();
    let hand = write(
        dir.path(),
        "hand.toml",
        &format!(
            "[model]\nfactorization = \"standard\"\nm = [[{{ num = [1, -1], den = [1, {r2:.17}] }}]]\nn = [[{{ num = [1], den = [1, {r2:.17}] }}]]\n"
        ),
    );
    let omega = logspace(0.01, 100.0, 40);
    let response: Vec<_> = omega
        .iter()
        .map(|w| {
            let s = Complex64::new(0.0, *w);
            DMatrix::from_element(1, 1, 1.3 / (s - 0.8) * (10.0 / (s + 10.0)))
        })
        .collect();
    let data = FrfData {
        path: dir.path().join("d.csv"),
        lines: (1..=omega.len()).collect(),
        omega,
        response,
        noise_radius: None,
    };
    let a = noise_free_envelope(&Config::load(&plant).unwrap().factorization, &data).unwrap();
    let b = noise_free_envelope(&Config::load(&hand).unwrap().factorization, &data).unwrap();
    for k in 0..a.len() {
        assert!((a.r_min[k] - b.r_min[k]).abs() < 1e-10 * b.r_min[k], "{k}");
        let (x, y) = (
            a.a1_limit.as_ref().unwrap()[k],
            b.a1_limit.as_ref().unwrap()[k],
        );
        assert!((x - y).abs() < 1e-10 * y);
    }
}

#[test]
fn iss_model_factors_are_normalized_and_exact() {
    let path = repo("configs/data/iss1r/model.json");
    if !path.exists() {
        panic!("missing {}", path.display());
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "iss.toml",
        &format!("[plant]\nfile = \"{}\"\n", path.display()),
    );
    let c = Config::load(&cfg).unwrap();
    let ncf = c.factorization.realization.clone().unwrap();
    assert_eq!(ncf.plant.states(), 270);
    assert!(ncf.riccati.residual < 1e-12, "{}", ncf.riccati.residual);
    // Dense grid through the modes (0.62–61.3 rad/s) and beyond.
    let grid = logspace(0.06, 600.0, 300);
    let (e_norm, e_g) = ncf_errors(&ncf, &grid);
    assert!(e_norm < 1e-9, "{e_norm}");
    assert!(e_g < 1e-9, "{e_g}");
    let fa = spectral_abscissa(&eigenvalues(&ncf.factors.a, "A+LC").unwrap());
    assert!(fa < 0.0);
}

#[test]
fn no_stabilizing_solution_is_a_clear_error() {
    // An unstable mode (λ = 1) that the output does not see.
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "bad.toml",
        "[plant]\na = [[1, 0], [0, -1]]\nb = [[1], [1]]\nc = [[0, 1]]\n",
    );
    let e = Config::load(&cfg).unwrap_err().to_string();
    assert!(
        e.contains("bad.toml") && e.contains("no stabilizing solution"),
        "{e}"
    );
    assert!(!e.contains('\n'));
    let cfg = write(
        dir.path(),
        "nan.toml",
        "[plant]\na = [[nan]]\nb = [[1]]\nc = [[1]]\n",
    );
    let e = Config::load(&cfg).unwrap_err().to_string();
    assert!(e.contains("A[1][1] is not finite"), "{e}");
    let cfg = write(
        dir.path(),
        "dims.toml",
        "[plant]\na = [[1, 0], [0, -1]]\nb = [[1]]\nc = [[0, 1]]\n",
    );
    let e = Config::load(&cfg).unwrap_err().to_string();
    assert!(e.contains("B must be 2×1"), "{e}");
}

#[test]
fn every_subcommand_runs_on_a_plant_config() {
    use common::{rshape, stdout};
    let cfg = repo("configs/plant_first.toml");
    let cfg = cfg.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = |s: &str| dir.path().join(s).to_str().unwrap().to_string();
    std::fs::create_dir_all(dir.path().join("sets")).unwrap();
    std::fs::copy(
        repo("configs/plant_first.csv"),
        dir.path().join("sets/a.csv"),
    )
    .unwrap();
    let runs: Vec<Vec<String>> = vec![
        vec!["envelope".into(), cfg.into(), "--out".into(), d("env")],
        vec!["check".into(), cfg.into()],
        vec!["fit".into(), cfg.into(), "--out".into(), d("fit")],
        vec!["run".into(), cfg.into(), "--out".into(), d("run")],
        vec![
            "batch".into(),
            cfg.into(),
            "--data-dir".into(),
            d("sets"),
            "--out".into(),
            d("batch"),
        ],
        vec!["compare".into(), cfg.into()],
    ];
    for args in runs {
        let a: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        let out = rshape(&a);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stdout(&out));
    }
    assert!(dir.path().join("run/r.json").exists());
    assert!(dir.path().join("batch/summary.csv").exists());
}

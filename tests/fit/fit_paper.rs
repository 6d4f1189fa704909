//! Acceptance of `rshape fit` on the paper MIMO example (Boulet & Francis 1998, Sec. IV-A)
//! and on a robot-like envelope (eqs. (18)–(21)): coverage, score, order monotonicity.

use rshape::consistency::{check, noise_free_envelope, Envelope, EnvelopeMethod};
use rshape::data::read_frf_csv;
use rshape::fit::{fit_auto, fit_unit, FitSettings, Objective};
use rshape::model::{Config, Factorization};
use rshape::system::{logspace, TfMatrix, TransferFunction};
use std::path::Path;

fn paper() -> (Factorization, Envelope) {
    let cfg = Config::load(Path::new("configs/paper_mimo.toml")).unwrap();
    let data = read_frf_csv(Path::new("configs/paper_mimo.csv")).unwrap();
    let env = noise_free_envelope(&cfg.factorization, &data).unwrap();
    (cfg.factorization, env)
}

fn tf(num: &[f64], den: &[f64]) -> TransferFunction {
    TransferFunction::new(num.to_vec(), den.to_vec())
}

/// The robot model of eqs. (19)–(21) (special factorization) and a jagged envelope below
/// its A1 limit, on the paper's 211 frequencies from 1 to 64 rad/s.
fn robot() -> (Factorization, Envelope) {
    let d = [1.0, 41.2, 40.2];
    let diag = [
        [4.0, 4.1, 105.0],
        [4.0, 36.1, 8228.6],
        [4.0, 16.1, 1634.0],
        [4.0, 90.8, 20116.0],
        [4.0, 22.8, 1310.3],
    ];
    let m = TfMatrix::diagonal(diag.iter().map(|n| tf(n, &d)).collect());
    let n = TfMatrix::from_rows(
        [1800.0, -1800.0, -1800.0, 1800.0, 1800.0]
            .iter()
            .map(|k| vec![tf(&[*k], &d)])
            .collect(),
    )
    .unwrap();
    let c = nalgebra::DMatrix::from_row_slice(1, 5, &[-3.30e-3, 3.40e-3, -3.39e-3, 0.0, -0.01e-3]);
    let f = Factorization::special(c, m, n, vec![tf(&[1.0], &[1.0])]).unwrap();
    let omega = logspace(1.0, 64.0, 211);
    let a1: Vec<f64> = omega.iter().map(|w| f.a1_limit(*w)).collect();
    // Deterministic jagged envelope: a smooth trend times a pseudo-random factor, below A1.
    let mut seed = 12345u64;
    let r_min: Vec<f64> = omega
        .iter()
        .zip(&a1)
        .map(|(w, a)| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
            let trend = 0.05 * (1.0 + (w / 8.0).powi(2)).sqrt();
            (trend * (0.4 + 0.6 * u)).min(0.6 * a)
        })
        .collect();
    let env = Envelope {
        omega,
        r_min,
        a1_limit: Some(a1),
        method: EnvelopeMethod::File,
    };
    (f, env)
}

fn log_ratios(r: &TransferFunction, env: &Envelope) -> Vec<f64> {
    env.omega
        .iter()
        .zip(&env.r_min)
        .map(|(w, m)| (r.freq(*w).norm() / m).log10())
        .collect()
}

#[test]
fn paper_order1_beats_hand_made_r1() {
    let (f, env) = paper();
    let a1 = |w: f64| f.a1_limit(w);
    let set = FitSettings {
        order: 1,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let fit = fit_unit(&env, Some(&a1), &set, &Default::default()).unwrap();
    let dt = t0.elapsed();
    let lr = log_ratios(&fit.r, &env);
    let mean = lr.iter().sum::<f64>() / lr.len() as f64;
    let hand = tf(&[1e-8, 0.3], &[0.5, 1.0]);
    let lh = log_ratios(&hand, &env);
    let hand_mean = lh.iter().sum::<f64>() / lh.len() as f64;
    println!("r_min = {:?}", env.r_min);
    println!(
        "fit r = {:?}/{:?}, zeros {:?} poles {:?}",
        fit.r.num, fit.r.den, fit.zeros, fit.poles
    );
    println!(
        "log ratios {lr:?}\nmean {mean:.5} (hand {hand_mean:.5}), {dt:?}, origin {}",
        fit.origin
    );
    println!("certificate {:#?}", fit.certificate);
    assert!(
        (hand_mean - 0.113).abs() < 0.002,
        "hand r1 scores {hand_mean}"
    );
    assert!(
        lr.iter().all(|l| *l >= 0.0),
        "a datum is not covered: {lr:?}"
    );
    assert!(mean <= 0.035, "mean log10 ratio {mean} > 0.035");
    assert!(fit.certificate.passed);
    // `rshape check` logic: every datum consistent, A1 holds.
    let rep = check(&fit.r, &env);
    assert!(rep.consistent, "{:?}", rep.failing_omegas);
    assert!(rep.a1_violations.is_empty());
    assert!(fit.r.is_unit());
    // Area objective also covers and is certified.
    let set = FitSettings {
        order: 1,
        objective: Objective::Area,
        ..Default::default()
    };
    let fit = fit_unit(&env, Some(&a1), &set, &Default::default()).unwrap();
    let lr = log_ratios(&fit.r, &env);
    println!("area: mean {}", lr.iter().sum::<f64>() / 5.0);
    assert!(lr.iter().all(|l| *l >= 0.0));
}

fn assert_monotone(name: &str, env: &Envelope, a1: Option<&dyn Fn(f64) -> f64>) {
    for objective in [Objective::Minimax, Objective::Area] {
        let set = FitSettings {
            objective,
            ..Default::default()
        };
        let (fit, rows) = fit_auto(env, a1, &set, 6, &Default::default()).unwrap();
        println!(
            "{name} {objective:?}:\n{}",
            rshape::fit::format_table(&rows, fit.order, set.auto_tolerance)
        );
        for w in rows[1..].windows(2) {
            assert!(w[1].status == "ok" && w[0].status == "ok", "{:?}", w);
            let (p, c) = (
                (w[0].max_log10, w[0].mean_log10),
                (w[1].max_log10, w[1].mean_log10),
            );
            assert!(
                promise_kept(objective, set.bisection_tol, p, c),
                "{name} {objective:?}: conservatism increased from order {} to {}: {:?}",
                w[0].order,
                w[1].order,
                w
            );
        }
        assert!(fit.certificate.passed);
    }
    // Independent fixed-order fits with `chain` (orders 0..N carried forward) keep the
    // promise too.  (Without `chain`, the default, a fixed-order fit is 2–5× faster but its
    // mean can exceed a lower order's by a little: robot order 4 vs 3, 0.1713 vs 0.1697.)
    let mut prev = (f64::INFINITY, f64::INFINITY);
    for n in 1..=6 {
        let set = FitSettings {
            order: n,
            chain: true,
            ..Default::default()
        };
        let fit = fit_unit(env, a1, &set, &Default::default()).unwrap();
        let c = (
            fit.certificate.max_log10_ratio,
            fit.certificate.mean_log10_ratio,
        );
        assert!(
            promise_kept(set.objective, set.bisection_tol, prev, c),
            "{name}: order {n} (max, mean) {c:?} after {prev:?}"
        );
        prev = c;
    }
}

/// The promise of each objective about order `n` (`c`, as (max, mean) of `log10 |r|/r_min`)
/// against order `n − 1` (`p`), as the docs state it: the max never rises; with `--objective
/// area` nor does the mean; with minimax the mean may rise only where the max fell by more
/// than the bisection tolerance (`log10(1 + bisection_tol)` decade).  (Until session 13
/// both objectives promised both; the minimax promise changed with issue 38's tenth step.)
pub(crate) fn promise_kept(
    objective: Objective,
    bisection_tol: f64,
    p: (f64, f64),
    c: (f64, f64),
) -> bool {
    let max_tol = (1.0 + bisection_tol).log10();
    let max_ok = c.0 <= p.0 + 1e-9;
    let mean_ok = c.1 <= p.1 + 1e-9;
    match objective {
        Objective::Minimax => max_ok && (mean_ok || c.0 < p.0 - max_tol + 1e-9),
        Objective::Area => max_ok && mean_ok,
    }
}

#[test]
fn conservatism_does_not_increase_with_order_paper() {
    let (f, env) = paper();
    let a1 = |w: f64| f.a1_limit(w);
    assert_monotone("paper", &env, Some(&a1));
}

#[test]
fn conservatism_does_not_increase_with_order_robot() {
    let (f, env) = robot();
    let a1 = |w: f64| f.a1_limit(w);
    assert_monotone("robot", &env, Some(&a1));
}

#[test]
fn beyond_a1_is_reported_with_frequencies() {
    let (_, mut env) = paper();
    let a1 = env.a1_limit.clone().unwrap();
    env.r_min[2] = a1[2] * 1.5;
    let e = fit_unit(&env, None, &FitSettings::default(), &Default::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("model must change") && msg.contains("1.000000e0"),
        "{msg}"
    );
    env.r_min[2] = f64::INFINITY;
    let e = fit_unit(&env, None, &FitSettings::default(), &Default::default()).unwrap_err();
    assert!(e.to_string().contains("r_min = inf"), "{e}");
}

/// The shipped robot example (configs/robot.toml: eqs. (18)–(21), L_a = 0.06, 211 noisy
/// data): the Theorem 4 envelope, fitted at orders 1 to 6.
#[test]
fn conservatism_does_not_increase_with_order_shipped_robot() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let cfg = rshape::model::Config::load(&root.join("configs/robot.toml")).unwrap();
    let data = rshape::data::read_frf_csv(&root.join("configs/robot.csv")).unwrap();
    let radii = rshape::model::noise_radii(None, Some(&cfg), &data)
        .unwrap()
        .expect("robot.toml has a noise radius");
    let env = rshape::consistency::noisy_envelope(
        &cfg.factorization,
        &data,
        &radii,
        &rshape::consistency::BisectionSettings::default(),
        &Default::default(),
    )
    .unwrap();
    assert!(env.r_min.iter().any(|r| *r > 0.0) && env.r_min.iter().all(|r| r.is_finite()));
    let f = &cfg.factorization;
    let a1 = |w: f64| f.a1_limit(w);
    assert_monotone("shipped robot", &env, Some(&a1));
}

//! The chained sweep against each order alone, on the closed-loop example where they parted
//! (`configs/closed_loop_retuned_noisy.toml`'s envelope with A1 from the config's open-loop
//! factorization, as `rshape fit` imposed it until stop 50; found at stop 49). The chain's
//! defect does not depend on where A1 comes from: any A1 that rules out the lowest orders
//! showed it.
//!
//! Orders 0–3 fail there (no unit of those orders certifies under A1), so the chain reaches
//! order 4 without a previous `r`; it used to carry the working sets the failed orders' level
//! searches had grown, and from those the order-4 search ended on a level whose spectral
//! factor had a zero at `ω = 0`: order 4 was marked failed although it certifies alone
//! (max 2.49563), and order 5 (1.35117) was far above order 5 alone (0.94330). A failed
//! order now leaves the working sets as the last certified order left them.
//!
//! The chosen `r` is checked here on a dense grid evaluated from its coefficients
//! (`num/den` in `r.json`'s form), not by the fit's certificate.

use rshape::consistency::Envelope;
use rshape::fit::{fit_auto, fit_unit, FitResult, FitSettings};
use rshape::model::Config;
use rshape::pipeline::envelope::{envelope, load_data};
use rshape::pipeline::RunOptions;
use rshape::system::logspace;
use std::path::Path;

const CONFIG: &str = "configs/closed_loop_retuned_noisy.toml";

/// The envelope and the config of `rshape fit CONFIG` (A1 from `config.factorization`).
fn inputs() -> (Config, Envelope) {
    let config = Config::load(Path::new(CONFIG)).unwrap();
    let data = load_data(&config, config.data.as_ref().unwrap()).unwrap();
    let env = envelope(&config, &data, &RunOptions::default())
        .unwrap()
        .envelope;
    (config, env)
}

/// `log10 |r(jω)|/r_min` at the data, from the transfer function's coefficients.
fn log_ratios(r: &FitResult, env: &Envelope) -> Vec<f64> {
    env.omega
        .iter()
        .zip(&env.r_min)
        .filter(|(_, m)| **m > 0.0)
        .map(|(w, m)| (r.r.freq(*w).norm() / m).log10())
        .collect()
}

/// The checks of the certificate redone from the coefficients on a dense grid (400 points
/// per decade over the band widened by two decades): `|r| ≥ r_min` at the data, `|r|` above
/// the smaller neighbouring `r_min` between data, `|r| < σ_min(M̃)`; and the max over the data
/// agrees with the one the fit reports.
fn check_independently(r: &FitResult, config: &Config, env: &Envelope) -> f64 {
    let f = &config.factorization;
    let l = log_ratios(r, env);
    let max = l.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(l.iter().all(|v| *v >= -1e-9), "|r| below r_min at a datum");
    assert!(
        (max - r.certificate.max_log10_ratio).abs() < 1e-6,
        "{max} against the certificate's {}",
        r.certificate.max_log10_ratio
    );
    let (lo, hi) = (env.omega[0], *env.omega.last().unwrap());
    let decades = (hi / lo).log10() + 4.0;
    let grid = logspace(lo / 100.0, hi * 100.0, (400.0 * decades) as usize);
    for w in &grid {
        let m = r.r.freq(*w).norm();
        let a1 = f.a1_limit(*w);
        assert!(m < a1, "A1 fails at {w} rad/s: |r| = {m}, σ_min = {a1}");
        let k = env.omega.partition_point(|x| x < w);
        if k > 0 && k < env.omega.len() {
            let need = env.r_min[k - 1].min(env.r_min[k]);
            assert!(
                m >= need * (1.0 - 1e-9),
                "|r| = {m} dips below {need} at {w} rad/s"
            );
        }
    }
    max
}

/// The fixed-order chain (`FitSettings::chain`, orders 0–4 carried forward) certifies order 4
/// as order 4 alone does, to the same max: the failed orders 0–3 leave nothing behind that
/// changes its search.  On the former code the chained fit of order 4 failed.
#[test]
fn chained_order_4_certifies_as_alone() {
    let (config, env) = inputs();
    let f = &config.factorization;
    let a1 = |w: f64| f.a1_limit(w);
    let base = FitSettings::default().with_a1_model(f);
    let alone = fit_unit(
        &env,
        Some(&a1),
        &FitSettings {
            order: 4,
            ..base.clone()
        },
        &Default::default(),
    )
    .expect("order 4 alone certifies");
    let chained = fit_unit(
        &env,
        Some(&a1),
        &FitSettings {
            order: 4,
            chain: true,
            ..base
        },
        &Default::default(),
    )
    .expect("order 4 chained certifies");
    let (ma, mc) = (
        check_independently(&alone, &config, &env),
        check_independently(&chained, &config, &env),
    );
    println!("order 4: alone {ma:.5}, chained {mc:.5}");
    assert!(mc <= ma + (1.002f64).log10(), "chained {mc} > alone {ma}");
}

/// `--order auto` on this config: no order that certifies alone is marked failed, every
/// order's max is at most its max alone plus the bisection tolerance, and the chosen `r`
/// passes the independent check.  Heavy (orders 0–8 chained and each alone):
/// `cargo test --release --test fit fit_chain::auto_at_least_as_good_as_each_order_alone --
/// --ignored --nocapture`.
#[test]
#[ignore = "heavy: orders 0-8 chained and alone (run with --release)"]
fn auto_at_least_as_good_as_each_order_alone() {
    let (config, env) = inputs();
    let f = &config.factorization;
    let a1 = |w: f64| f.a1_limit(w);
    let base = FitSettings::default().with_a1_model(f);
    let (chosen, rows) =
        fit_auto(&env, Some(&a1), &base, 8, &Default::default()).expect("auto certifies");
    let tol = (1.002f64).log10();
    let mut bad = Vec::new();
    for row in &rows {
        let alone = fit_unit(
            &env,
            Some(&a1),
            &FitSettings {
                order: row.order,
                ..base.clone()
            },
            &Default::default(),
        );
        let alone_max = alone.as_ref().ok().map(|r| r.certificate.max_log10_ratio);
        println!(
            "order {}: auto {:.5} ({}), alone {:?}",
            row.order, row.max_log10, row.status, alone_max
        );
        if let Some(m) = alone_max {
            if row.status != "ok" {
                bad.push(format!(
                    "order {} failed in the chain, certifies alone at {m:.5}",
                    row.order
                ));
            } else if row.max_log10 > m + tol {
                bad.push(format!(
                    "order {}: auto {:.5} > alone {m:.5}",
                    row.order, row.max_log10
                ));
            }
        }
    }
    let max = check_independently(&chosen, &config, &env);
    println!("chosen order {} at {max:.5}", chosen.order);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

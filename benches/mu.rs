//! Benchmarks of `μ_Γ` (eq. (17)) and of the noisy envelope (Theorem 4) on the five-mode robot
//! model of Boulet & Francis (1998), eqs. (18)–(21), with the shipped data `configs/robot.csv`.
//!
//! Run: `cargo bench --bench mu`.

use divan::{black_box, Bencher};
use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::consistency::{gamma_lft, noisy_envelope, r_min_noisy, BisectionSettings};
use rshape::data::{read_frf_csv, FrfData};
use rshape::model::Config;
use rshape::mu::{mu_full_scalar, FullPlusScalar, MuSettings};
use std::path::Path;

fn main() {
    divan::main();
}

fn robot() -> (Config, FrfData) {
    let cfg =
        Config::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml")).unwrap();
    let data = read_frf_csv(cfg.data.as_ref().unwrap()).unwrap();
    (cfg, data)
}

/// The 7×6 LFT `F_L[V(jω), φ⁻¹]` at every 10th datum, with `L_a = 0.02` and `|r|` at the
/// datum's `r_min` (μ = 1, the regime the envelope search works in) or at the A1 limit
/// where `r_min` is 0 or infinite.
fn robot_lfts() -> Vec<DMatrix<Complex64>> {
    let (cfg, data) = robot();
    let la = 0.02;
    (0..data.len())
        .step_by(10)
        .map(|k| {
            let at = cfg.factorization.at(data.omega[k]);
            let phi = data.response[k][(0, 0)];
            let d = r_min_noisy(&at, phi, la, &BisectionSettings::default()).unwrap();
            let rho = if d.r_min > 0.0 && d.r_min.is_finite() {
                d.r_min
            } else {
                d.a1_limit
            };
            gamma_lft(&at, phi, Complex64::new(rho, 0.0), la).unwrap()
        })
        .collect()
}

/// One `μ_Γ` evaluation of a 7×6 robot LFT (cold start, default settings: gap ≤ 1e-10).
/// Divan reports the time for all 22 matrices; divide by 22.
#[divan::bench]
fn mu_robot_7x6_per_22(b: Bencher) {
    let ms = robot_lfts();
    let s = FullPlusScalar::gamma(5);
    let set = MuSettings::default();
    b.counter(divan::counter::ItemsCount::new(ms.len()))
        .bench(|| {
            for m in &ms {
                black_box(mu_full_scalar(black_box(m), s, &set).unwrap());
            }
        });
}

/// The whole 211-point noisy envelope with the configured `L_a = 0.06` (most data lie within
/// the noise of the nominal model: `r_min = 0` after one scalar test).
#[divan::bench]
fn envelope_robot_211_la_0_06(b: Bencher) {
    let (cfg, data) = robot();
    let radius = vec![0.06; data.len()];
    let set = BisectionSettings::default();
    b.bench(|| {
        black_box(
            noisy_envelope(
                &cfg.factorization,
                &data,
                &radius,
                &set,
                &Default::default(),
            )
            .unwrap(),
        )
    });
}

/// The whole 211-point noisy envelope with `L_a = 0.02`: most data need the full search.
#[divan::bench]
fn envelope_robot_211_la_0_02(b: Bencher) {
    let (cfg, data) = robot();
    let radius = vec![0.02; data.len()];
    let set = BisectionSettings::default();
    b.bench(|| {
        black_box(
            noisy_envelope(
                &cfg.factorization,
                &data,
                &radius,
                &set,
                &Default::default(),
            )
            .unwrap(),
        )
    });
}

/// The whole 211-point noisy envelope with `L_a = 0.005`.
#[divan::bench]
fn envelope_robot_211_la_0_005(b: Bencher) {
    let (cfg, data) = robot();
    let radius = vec![0.005; data.len()];
    let set = BisectionSettings::default();
    b.bench(|| {
        black_box(
            noisy_envelope(
                &cfg.factorization,
                &data,
                &radius,
                &set,
                &Default::default(),
            )
            .unwrap(),
        )
    });
}

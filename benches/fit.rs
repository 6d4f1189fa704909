//! `rshape fit` timing: a 1000-point envelope (smooth and jagged, 4 decades) at orders 2, 4
//! and 6, minimax objective, certificate included; order N alone (the default) and orders
//! 0..N chained; and (issue 11) 1000- and 100,000-point jagged envelopes at orders 2, 6, 10.
//! Target: ≤ 200 ms per fit at order ≤ 6; the 1000-point order-6 fit within 1.5× of its
//! time before the exact certificate (jagged 190 ms, smooth 86 ms median on the 2-core CI
//! machine).  Run: `cargo bench --bench fit -- --sample-count 5`.  Issue 21 targets: order 6
//! on 1000 points ≤ 200 ms (whole process), `--order auto` on 2000 points ≤ 3 s
//! (`jagged_2000_auto`), order 6 on 100,000 points ≤ 6 s (`jagged_100000`), the fit of
//! ISS `stability --fit` ≤ 5 s (`iss_stability_fit`), paper `run` ≤ 0.4 s (`paper_run`).

#[path = "support/random_envelopes.rs"]
mod random_envelopes;

use rshape::consistency::{Envelope, EnvelopeMethod};
use rshape::fit::{fit_auto, fit_unit, FitSettings};
use rshape::system::logspace;

fn main() {
    divan::main();
}

fn envelope(jagged: bool) -> Envelope {
    envelope_n(jagged, 1000)
}

fn envelope_n(jagged: bool, n: usize) -> Envelope {
    let omega = logspace(0.1, 1000.0, n);
    let mut seed = 7u64;
    let r_min = omega
        .iter()
        .map(|w| {
            let mut v = 0.05 * (1.0 + (w / 3.0).powi(2)).sqrt()
                / (1.0 + (w / 200.0).powi(2)).sqrt()
                * (1.0 + 2.0 / (1.0 + (4.0 * (w / 30.0).ln()).powi(2)));
            if jagged {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                v *= 0.5 + 0.5 * ((seed >> 11) as f64 / (1u64 << 53) as f64);
            }
            v
        })
        .collect();
    Envelope {
        omega,
        r_min,
        a1_limit: None,
        method: EnvelopeMethod::File,
    }
}

/// Orders 0..N chained (`chain = true`, what `--order auto` does up to N).
#[divan::bench(args = [2, 4, 6], sample_count = 10)]
fn smooth_1000_chained(bencher: divan::Bencher, order: usize) {
    let env = envelope(false);
    let set = FitSettings {
        order,
        chain: true,
        ..Default::default()
    };
    bencher.bench(|| fit_unit(&env, None, &set, &Default::default()).expect("fit"));
}

/// Orders 0..N chained (`chain = true`).
#[divan::bench(args = [2, 4, 6], sample_count = 10)]
fn jagged_1000_chained(bencher: divan::Bencher, order: usize) {
    let env = envelope(true);
    let set = FitSettings {
        order,
        chain: true,
        ..Default::default()
    };
    bencher.bench(|| fit_unit(&env, None, &set, &Default::default()).expect("fit"));
}

/// Order N alone (`chain = false`, the default of `fit_unit` and `--order N`).
#[divan::bench(args = [2, 4, 6], sample_count = 10)]
fn jagged_1000_unchained(bencher: divan::Bencher, order: usize) {
    let env = envelope(true);
    let set = FitSettings {
        order,
        chain: false,
        ..Default::default()
    };
    bencher.bench(|| fit_unit(&env, None, &set, &Default::default()).expect("fit"));
}

/// Order N alone (`chain = false`), smooth envelope.
#[divan::bench(args = [2, 4, 6], sample_count = 10)]
fn smooth_1000_unchained(bencher: divan::Bencher, order: usize) {
    let env = envelope(false);
    let set = FitSettings {
        order,
        chain: false,
        ..Default::default()
    };
    bencher.bench(|| fit_unit(&env, None, &set, &Default::default()).expect("fit"));
}

/// Issue 11: jagged 1000-point envelope, orders 2, 6, 10 (order N alone).
#[divan::bench(args = [2, 6, 10], sample_count = 5)]
fn jagged_1000(bencher: divan::Bencher, order: usize) {
    let env = envelope_n(true, 1000);
    let set = FitSettings {
        order,
        ..Default::default()
    };
    bencher.bench(|| fit_unit(&env, None, &set, &Default::default()).expect("fit"));
}

/// Issue 11: jagged 100,000-point envelope, orders 2, 6, 10 (order N alone).
#[divan::bench(args = [2, 6, 10], sample_count = 2)]
fn jagged_100000(bencher: divan::Bencher, order: usize) {
    let env = envelope_n(true, 100_000);
    let set = FitSettings {
        order,
        ..Default::default()
    };
    bencher.bench(|| fit_unit(&env, None, &set, &Default::default()).expect("fit"));
}

/// Issue 21: `--order auto` (orders 0..=8 chained, the order table) on a jagged 2000-point
/// envelope.  Target ≤ 3 s.
#[divan::bench(sample_count = 3)]
fn jagged_2000_auto(bencher: divan::Bencher) {
    let env = envelope_n(true, 2000);
    let set = FitSettings::default();
    bencher.bench(|| fit_auto(&env, None, &set, 8, &Default::default()).expect("fit"));
}

/// Issue 38: `--order auto` on a smooth 4-decade 2000-point envelope with two bumps
/// (`random_envelopes::smooth_bumps`).  Target ≤ 1 s.
#[divan::bench(sample_count = 2)]
fn smooth_2000_bumps_auto(bencher: divan::Bencher) {
    let env = random_envelopes::smooth_bumps(2000);
    let set = FitSettings::default();
    bencher.bench(|| fit_auto(&env, None, &set, 8, &Default::default()).expect("fit"));
}

/// Issue 38: `--order auto` on the same envelope at 21 points.  Target ≤ 0.2 s.
#[divan::bench(sample_count = 3)]
fn smooth_21_bumps_auto(bencher: divan::Bencher) {
    let env = random_envelopes::smooth_bumps(21);
    let set = FitSettings::default();
    bencher.bench(|| fit_auto(&env, None, &set, 8, &Default::default()).expect("fit"));
}

/// Issue 38: `--order auto` on each of the 24 random envelopes of the sweep
/// (`random_envelopes::sweep_specs`, fixed seed), one after the other.  Target ≤ 15 s.
#[divan::bench(sample_count = 1)]
fn sweep24_auto(bencher: divan::Bencher) {
    let envs: Vec<Envelope> = random_envelopes::sweep_specs()
        .iter()
        .map(random_envelopes::envelope)
        .collect();
    let set = FitSettings::default();
    bencher.bench(|| {
        for env in &envs {
            fit_auto(env, None, &set, 8, &Default::default()).expect("fit");
        }
    });
}

/// Issue 38: `--order 6` (order 6 alone) on each of the 24 envelopes of the sweep (the
/// comparison with dkpy's order-6 fit: `benches/dkpy_compare.py`).
#[divan::bench(sample_count = 1)]
fn sweep24_order6(bencher: divan::Bencher) {
    let envs: Vec<Envelope> = random_envelopes::sweep_specs()
        .iter()
        .map(random_envelopes::envelope)
        .collect();
    let set = FitSettings {
        order: 6,
        ..Default::default()
    };
    bencher.bench(|| {
        for env in &envs {
            fit_unit(env, None, &set, &Default::default()).expect("fit");
        }
    });
}

/// The shipped config `name` with its envelope (Theorem 2 on its data).
fn shipped(name: &str) -> (rshape::Config, Envelope) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    let config = rshape::Config::load(&path).expect("config");
    let data = rshape::read_frf_csv(config.data.as_ref().expect("data")).expect("data");
    let env = rshape::envelope(&config, &data, &rshape::RunOptions::default())
        .expect("envelope")
        .envelope;
    (config, env)
}

/// Issue 21: the fit of `stability configs/iss1r_reduced.toml --fit` (`--order auto` with
/// the A1 limit of the 20-state normalized factors, 2000 data).  Target ≤ 5 s for the whole
/// process (the envelope and the Theorem 1 test add about 0.7 s).
#[divan::bench(sample_count = 2)]
fn iss_stability_fit(bencher: divan::Bencher) {
    let (config, env) = shipped("configs/iss1r_reduced.toml");
    let f = &config.factorization;
    let a1 = |w: f64| f.a1_limit(w);
    let set = FitSettings::default();
    bencher.bench(|| fit_auto(&env, Some(&a1), &set, 8, &Default::default()).expect("fit"));
}

/// Issue 21: `run configs/paper_mimo.toml` as the library runs it (envelope, check,
/// `--order auto` fit, certificate; the CLI adds the files).  Target ≤ 0.4 s whole process.
#[divan::bench(sample_count = 5)]
fn paper_run(bencher: divan::Bencher) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/paper_mimo.toml");
    let config = rshape::Config::load(&path).expect("config");
    let data = rshape::read_frf_csv(config.data.as_ref().expect("data")).expect("data");
    let order = rshape::fit::OrderChoice::Auto { max: 8 };
    bencher
        .bench(|| rshape::run(&config, &data, order, &rshape::RunOptions::default()).expect("run"));
}

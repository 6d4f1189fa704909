//! Closed-loop envelopes (Crowder & de Callafon) per datum, next to the open-loop noisy
//! envelope (Boulet & Francis Theorem 4) for comparison: the shipped flexible-servo example
//! (160 data), noise-free (Theorem 1), noisy with `C̄ = C` (eq. (18)) and noisy with
//! `C̄ ≠ C` (bisection with the exact two-scalar μ); the open-loop one on `configs/robot.toml`
//! (211 data, μ for one full plus one scalar block).
//!
//! Run: `cargo bench --bench closed_loop -- --sample-count 5`.
use rshape::consistency::closed_loop::closed_loop_envelope;
use rshape::consistency::closed_loop::VBisectionSettings;
use rshape::consistency::{noisy_envelope, BisectionSettings};
use rshape::data::FrfData;
use rshape::model::Config;
use std::path::Path;

fn main() {
    divan::main();
}

fn load(name: &str) -> (Config, FrfData) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cfg = Config::load(&root.join("configs").join(name)).unwrap();
    let data = rshape::pipeline::closed_loop::read_data(&cfg, cfg.data.as_ref().unwrap()).unwrap();
    (cfg, data)
}

fn closed(bencher: divan::Bencher, name: &str, noisy: bool) {
    let (cfg, data) = load(name);
    let radii = data.noise_radius.clone();
    let cl = cfg.closed_loop.clone().unwrap();
    bencher
        .counter(divan::counter::ItemsCount::new(data.len()))
        .bench(|| {
            closed_loop_envelope(
                &cl,
                divan::black_box(&data),
                if noisy { radii.as_deref() } else { None },
                &VBisectionSettings::default(),
            )
            .unwrap()
        });
}

#[divan::bench(sample_count = 20)]
fn closed_loop_noise_free(bencher: divan::Bencher) {
    closed(bencher, "closed_loop_retuned.toml", false);
}

#[divan::bench(sample_count = 20)]
fn closed_loop_noisy_eq18(bencher: divan::Bencher) {
    closed(bencher, "closed_loop_same_noisy.toml", true);
}

#[divan::bench(sample_count = 20)]
fn closed_loop_noisy_mu_bisection(bencher: divan::Bencher) {
    closed(bencher, "closed_loop_retuned_noisy.toml", true);
}

#[divan::bench(sample_count = 5)]
fn open_loop_noisy_theorem4(bencher: divan::Bencher) {
    let (cfg, data) = load("robot.toml");
    let radii = vec![cfg.raw.noise.radius.unwrap_or(0.06); data.len()];
    bencher
        .counter(divan::counter::ItemsCount::new(data.len()))
        .bench(|| {
            noisy_envelope(
                &cfg.factorization,
                divan::black_box(&data),
                &radii,
                &BisectionSettings::default(),
                &Default::default(),
            )
            .unwrap()
        });
}

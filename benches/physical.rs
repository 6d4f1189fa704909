//! Issue 21: "a 200-mode physical model's `run` ≤ 30 s, with progress shown".  The model and
//! data are those of `examples/modes_data.rs` (`benches/support/modes.rs`): 200 lightly damped
//! modes, 1000 noisy data (Theorem 4 per datum), `--order auto`.  `run_200_modes` is the whole
//! library pipeline (envelope, fit, certificate; no files); `envelope_200_modes` the noisy
//! envelope alone.  Run: `cargo bench --bench physical`.

#[path = "support/modes.rs"]
#[allow(dead_code)]
mod modes;

fn main() {
    divan::main();
}

fn inputs(k: usize, points: usize) -> (rshape::Config, rshape::data::FrfData, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let cfg = modes::write(dir.path(), k, points);
    let config = rshape::Config::load(&cfg).expect("config");
    let data = rshape::read_frf_csv(config.data.as_ref().expect("data")).expect("data");
    (config, data, dir)
}

/// `rshape run` of the 200-mode model without the files: envelope, fit (`--order auto`),
/// certificate.
#[divan::bench(sample_count = 2)]
fn run_200_modes(bencher: divan::Bencher) {
    let (config, data, _dir) = inputs(200, 1000);
    let order = rshape::fit::OrderChoice::Auto { max: 8 };
    bencher
        .bench(|| rshape::run(&config, &data, order, &rshape::RunOptions::default()).expect("run"));
}

/// The noisy envelope (Theorem 4) of the same model and data.
#[divan::bench(sample_count = 3)]
fn envelope_200_modes(bencher: divan::Bencher) {
    let (config, data, _dir) = inputs(200, 1000);
    bencher.bench(|| {
        rshape::pipeline::envelope::envelope(&config, &data, &rshape::RunOptions::default())
            .expect("envelope")
    });
}

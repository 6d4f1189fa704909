//! Batch of 1000 datasets × 211 frequencies on the robot model with noise (Theorem 4 μ
//! bisection per datum), end to end through the library: read, envelope, check, per-dataset
//! files, combined envelope, fit, summary.  Target: ≤ 30 s on 2 cores.
//!
//! Run: `cargo bench --bench batch`.  Falls back to the paper's MIMO model (noise-free)
//! when `configs/robot.toml` is not present.
#[path = "support/gen.rs"]
mod gen;

use rshape::batch::{self, combine, discover_dir, run_all, BatchSettings, Shard, SummaryRow};
use rshape::model::Config;
use std::path::PathBuf;

fn main() {
    divan::main();
}

const N: usize = 1000;

fn setup() -> (Config, tempfile::TempDir) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let robot = root.join("configs/robot.toml");
    let path = if robot.exists() {
        robot
    } else {
        root.join("configs/paper_mimo.toml")
    };
    let config = Config::load(&path).unwrap();
    let data = rshape::data::read_frf_csv(config.data.as_ref().unwrap()).unwrap();
    eprintln!(
        "batch bench: {} × {} frequencies from {}",
        N,
        data.len(),
        path.display()
    );
    let dir = tempfile::tempdir().unwrap();
    gen::write_datasets(&data, N, 0.01, dir.path());
    (config, dir)
}

#[divan::bench(sample_count = 1, sample_size = 1)]
fn batch_1000(bencher: divan::Bencher) {
    let (config, dir) = setup();
    // The output directory is made before and deleted after the timed part.
    bencher
        .with_inputs(|| tempfile::tempdir().unwrap())
        .bench_local_values(|out| {
            let t = std::time::Instant::now();
            let list = discover_dir(dir.path()).unwrap();
            let opts = BatchSettings {
                noise_radius: None,
                per_dataset_files: true,
            };
            let res = run_all(&config, &list, &opts, out.path(), &|| {});
            assert!(
                res.iter().all(|r| r.ok()),
                "{:?}",
                res.iter().find(|r| !r.ok()).map(|r| &r.error)
            );
            let combined = combine(res.iter().filter_map(|r| r.envelope.as_ref()));
            let rows: Vec<SummaryRow> = res.iter().map(SummaryRow::from).collect();
            batch::finish(
                out.path(),
                &rows,
                combined.as_ref(),
                batch::FinishInput {
                    config: config.path.clone(),
                    config_digest: None,
                    scaling: rshape::report::ScalingNote::of_opt(config.scaling.as_ref()),
                    r_configured: config.r.as_ref(),
                    n_total: list.len(),
                    shard: Shard::ALL,
                    merged_from: vec![],
                    timings_ms: Default::default(),
                    order: rshape::fit::OrderChoice::Auto { max: 8 },
                    factorization: Some(&config.factorization),
                    closed_loop: false,
                    datasets: res.iter().filter_map(|r| r.envelope.as_ref()).collect(),
                },
            )
            .unwrap();
            eprintln!(
                "batch bench: {} datasets in {:.2} s",
                list.len(),
                t.elapsed().as_secs_f64()
            );
        });
}

//! Noise-free envelope (Theorem 2, eq. (8)) on 10,000 frequencies of the paper's 2×3
//! example.  Target: ≥ 1 million data points per second on one core.
//!
//! Run: `cargo bench --bench envelope`.
use rshape::data::FrfData;
use rshape::model::Config;
use rshape::system::{logspace, TfMatrix, TransferFunction};
use std::path::{Path, PathBuf};

fn main() {
    divan::main();
}

fn tf(num: &[f64], den: &[f64]) -> TransferFunction {
    TransferFunction::new(num.to_vec(), den.to_vec())
}

fn paper_data(n: usize) -> FrfData {
    let mp = TfMatrix::from_rows(vec![
        vec![tf(&[1.0, 1.9], &[1.0, 1.0]), tf(&[1.0, 2.9], &[1.0, 2.0])],
        vec![tf(&[0.1], &[1.0]), tf(&[1.1, 1.0], &[1.0, 2.0])],
    ])
    .unwrap();
    let np = TfMatrix::from_rows(vec![
        vec![
            tf(&[1.1], &[1.0, 1.0]),
            tf(&[2.2], &[1.0, 1.0]),
            tf(&[0.0], &[1.0]),
        ],
        vec![
            tf(&[0.0], &[1.0]),
            tf(&[0.9], &[1.0, 3.0]),
            tf(&[1.8], &[1.0, 2.0]),
        ],
    ])
    .unwrap();
    let omega = logspace(1e-3, 1e5, n);
    let response = omega
        .iter()
        .map(|w| mp.freq(*w).lu().solve(&np.freq(*w)).unwrap())
        .collect();
    FrfData {
        path: PathBuf::from("bench"),
        lines: (1..=n).collect(),
        omega,
        response,
        noise_radius: None,
    }
}

#[divan::bench(sample_count = 20)]
fn noise_free_envelope_10k(bencher: divan::Bencher) {
    let cfg = Config::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/paper_mimo.toml"))
        .unwrap();
    let data = paper_data(10_000);
    bencher
        .counter(divan::counter::ItemsCount::new(10_000usize))
        .bench(|| {
            rshape::consistency::noise_free_envelope(&cfg.factorization, divan::black_box(&data))
                .unwrap()
        });
}

//! Benchmarks of issue 10 on the ISS 1R model (270 states, 3×3, configs/data/iss1r): the
//! normalized left coprime factorization (filter Riccati equation by the sign function +
//! Newton–Kleinman), the factors on the 2000-point data grid, and the exact H∞ norm of the
//! Theorem 1 system (full and balanced-truncated plant, static controller 5·I).
//!
//! Run: `cargo bench --bench plant -- --sample-count 3`.

use divan::{black_box, Bencher};
use nalgebra::DMatrix;
use rshape::model::{Factorization, PlantSection};
use rshape::stability::theorem1_system;
use rshape::system::{hinf_norm, logspace, NormalizedLcf, StateSpace};
use std::path::Path;

fn main() {
    divan::main();
}

fn iss(reduce: Option<usize>) -> StateSpace {
    let section = PlantSection {
        file: Some("configs/data/iss1r/model.json".into()),
        reduce_order: reduce,
        ..Default::default()
    };
    section
        .state_space(Path::new(env!("CARGO_MANIFEST_DIR")))
        .unwrap()
}

#[divan::bench(sample_count = 3)]
fn ncf_iss_270_states(b: Bencher) {
    let plant = iss(None);
    b.bench(|| black_box(NormalizedLcf::new(plant.clone()).unwrap()));
}

#[divan::bench(sample_count = 3)]
fn balanced_truncation_iss_to_20(b: Bencher) {
    let plant = iss(None);
    b.bench(|| black_box(plant.balanced_truncation(20).unwrap()));
}

#[divan::bench(sample_count = 3)]
fn factors_on_2000_points_iss_270(b: Bencher) {
    let ncf = NormalizedLcf::new(iss(None)).unwrap();
    let grid = logspace(0.062, 613.0, 2000);
    b.bench(|| {
        for w in &grid {
            black_box(ncf.at(*w));
        }
    });
}

fn theorem1(reduce: Option<usize>) -> StateSpace {
    let f = Factorization::normalized(NormalizedLcf::new(iss(reduce)).unwrap());
    let k = StateSpace {
        a: DMatrix::zeros(0, 0),
        b: DMatrix::zeros(0, 3),
        c: DMatrix::zeros(3, 0),
        d: DMatrix::identity(3, 3) * 5.0,
    };
    theorem1_system(&f, &k).unwrap()
}

#[divan::bench(sample_count = 3)]
fn hinf_theorem1_iss_20_states(b: Bencher) {
    let t = theorem1(Some(20));
    b.bench(|| black_box(hinf_norm(&t).unwrap()));
}

#[divan::bench(sample_count = 2)]
fn hinf_theorem1_iss_270_states(b: Bencher) {
    let t = theorem1(None);
    b.bench(|| black_box(hinf_norm(&t).unwrap()));
}

//! Issue 34 item 9: where the time of a large modal model goes. The model is the issue-21
//! structure of `benches/support/modes.rs` (`K` lightly damped modes, special factorization
//! with a diagonal `M̃`, 4 states per mode in the loop), with a static controller
//! `K = 10⁻³` and the constant bound `r = 10⁻³`.
//!
//! * `load`: `Config::load` (what `compare` and every command pays first);
//! * `theorem1_system`: the realization of the loop (`modal_system` = `M̃⁻¹·[Ñ·J  I]`, the
//!   minimal realizations, the feedback);
//! * `closed_loop_poles`: that plus the eigenvalues (the internal-stability verdict);
//! * `stability_run`: `pipeline::stability::run` (poles, the grid, the exact H∞ norms);
//! * `compare_run`: `diagnose::compare` on the model's 200 noisy data (Theorem 4's μ
//!   envelope, what `compare` and each step of `diagnose` pay);
//! * `loop_realization` (200, 1000 modes): `theorem1_system`, the loop realized row by row
//!   from 50 modal coordinates (fourth session; the whole-matrix staircase had not finished
//!   the 1000-mode loop in 600 s);
//! * `diagnose_root_retune` (200, 1000 modes): the retune at `diagnose`'s root from a rough
//!   start (1000 modes on 200 data: settled, the output gains' least-norm fit only);
//! * `loop_poles_structured` (100, 1000 modes): `closed_loop_poles` from the loop's structure
//!   (`stability::loop_poles`: the loop of the cancelled rows, 2 states per mode, and the
//!   roots of each mode's factor denominator; fifth session).
//! * `certified_norms` (100, 1000 modes): `‖T‖∞` and `1/b(G,K)` by the certified frequency
//!   sweep on the factor values (sixth session; `stability::certified_t_norm`).
//!
//! Sixth session (`cargo bench --bench large_models -- certified_norms --sample-count 1`,
//! load 2.3–4.5): `certified_norms` 100 / 1000 modes 1.16 s / 24.2 s (both norms; the
//! Hamiltonian route at 1000 modes: 4000 × 4000 eigenproblems, more than 20 min of CPU).
//!
//! Fourth session (`cargo bench --bench large_models -- loop_realization diagnose_root_retune
//! --sample-count 1`, load 6–8): `loop_realization` 200 / 1000 modes 63 ms / 2.6 s (the
//! whole-matrix staircase: > 600 s at 1000); `diagnose_root_retune` 4.6 s / 0.12 s (1000
//! modes: 20–40 s per mode placed before).
//!
//! Fifth session (`cargo bench --bench large_models -- loop_poles_structured --sample-count
//! 1`, load 8–9): `loop_poles_structured` 100 / 1000 modes 84.5 ms / 65.5 s (the dense
//! 4000 × 4000 eigenvalues of the 1000-mode loop had not finished in 600 s).
//!
//! Run: `cargo bench --bench large_models -- --sample-count 1` (under `cargo test` only the
//! smallest size of the two long benches runs, as a check that the measurement works).
//!
//! Measured before issue 34's second session (2 shared cores, loaded, one sample), K = 25 /
//! 50 / 100: `stability_run` 1.03 s / 10.7 s / 2.36 min, 200 modes > 10 min; a perf profile put
//! 60 % in `FreqEvaluator::eval` for the 8 starting candidates per pole of `hinf_norm`, and
//! `compare` at 1000 modes in Theorem 4's dense `(n+1)²` copies per μ evaluation (70 s).
//! After it (one starting frequency per pole and a 40-point grid, row-wise back
//! substitution and real GEMMs in the responses, `|r|·‖T‖∞` for a constant `r`, no dense
//! `M̃⁻¹`, `V`, `F_L` or copy per datum or μ step on a diagonal `M̃`), the same machine and
//! load: see the table in the session's report (docs/internals-large-models.md).
//! Third session (`cargo bench --bench large_models -- stability_run --sample-count 1`,
//! load 4.8–5.8): `stability_run` 25 / 50 / 100 / 200 modes 0.39 s / 0.32 s / 1.87 s /
//! 15.2 s (norms on the row-by-row loop from 200 loop states, the structured grid value
//! from 50 modes, the norm started from the grid's peaks, `hqr` eigenvalues from 200 × 200).

#[path = "support/modes.rs"]
#[allow(dead_code)]
mod modes;

use divan::Bencher;
use rshape::model::{Config, Controller};

fn main() {
    divan::main();
}

const SIZES: &[usize] = &[25, 50, 100];

/// Sizes of the long benches (`stability_run` at 1000 modes has dense eigenproblems of
/// 2000 × 2000 for the loop's poles and 4000 × 4000 for each Hamiltonian iteration: not
/// measured).
const STABILITY_SIZES: &[usize] = &[25, 50, 100, 200];
const COMPARE_SIZES: &[usize] = &[50, 100, 200, 1000];

/// Whether this is `cargo bench` (it passes `--bench`), not a `cargo test` check run.
fn benching() -> bool {
    std::env::args().any(|a| a == "--bench")
}

fn inputs(k: usize) -> (Config, Controller, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let cfg = modes::write(dir.path(), k, 200);
    let kp = dir.path().join("k.toml");
    std::fs::write(&kp, "[controller]\ntf = [[1e-3]]\n").expect("controller");
    let config = Config::load(&cfg).expect("config");
    let controller = Controller::load(&kp).expect("controller");
    (config, controller, dir)
}

#[divan::bench(args = SIZES, sample_count = 2)]
fn load(bencher: Bencher, k: usize) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let cfg = modes::write(dir.path(), k, 200);
    bencher.bench(|| Config::load(&cfg).expect("config"));
}

#[divan::bench(args = SIZES, sample_count = 2)]
fn theorem1_system(bencher: Bencher, k: usize) {
    let (config, controller, _dir) = inputs(k);
    let kk = controller.negative_feedback_gain();
    bencher.bench(|| rshape::stability::theorem1_system(&config.factorization, &kk).expect("T"));
}

#[divan::bench(args = SIZES, sample_count = 2)]
fn closed_loop_poles(bencher: Bencher, k: usize) {
    let (config, controller, _dir) = inputs(k);
    bencher.bench(|| {
        rshape::stability::closed_loop_poles(&config.factorization, &controller).expect("poles")
    });
}

#[divan::bench(args = STABILITY_SIZES, sample_count = 1)]
fn stability_run(bencher: Bencher, k: usize) {
    // `cargo test --all-targets` runs each bench once in a debug build, where the larger
    // sizes take minutes: there only the smallest is run, the others measure nothing.
    if k > STABILITY_SIZES[0] && !benching() {
        bencher.bench(|| ());
        return;
    }
    let (config, controller, _dir) = inputs(k);
    let r = vec![(
        "configured".to_string(),
        rshape::system::TransferFunction::gain(1e-3),
    )];
    bencher.bench(|| {
        rshape::pipeline::stability::run(&config, &controller, &r, None).expect("stability")
    });
}

#[divan::bench(args = COMPARE_SIZES, sample_count = 1)]
fn compare_run(bencher: Bencher, k: usize) {
    if k > COMPARE_SIZES[0] && !benching() {
        bencher.bench(|| ());
        return;
    }
    let (config, _controller, _dir) = inputs(k);
    let data =
        rshape::data::read_frf_csv(config.data.as_deref().expect("data file")).expect("data");
    let model = rshape::diagnose::PlantModel::from_config(&config);
    let siso = rshape::diagnose::prepare(&config, &data, None, None).expect("prepare");
    bencher.bench(|| rshape::diagnose::compare(&config, &model, &siso).expect("compare"));
}

/// Sizes of the structured routes of issue 34's fourth session: the loop realized row by row
/// (`modal_system` from 50 modal coordinates; the whole-matrix staircase had not finished
/// the 1000-mode loop in 600 s) and the retune of `diagnose`'s root (1000 modes on 200 data:
/// the linear slots already fit the data, so the retune is their least squares).
const ROW_SIZES: &[usize] = &[200, 1000];

#[divan::bench(args = ROW_SIZES, sample_count = 1)]
fn loop_realization(bencher: Bencher, k: usize) {
    if k > ROW_SIZES[0] && !benching() {
        bencher.bench(|| ());
        return;
    }
    let (config, controller, _dir) = inputs(k);
    let kk = controller.negative_feedback_gain();
    bencher.bench(|| rshape::stability::theorem1_system(&config.factorization, &kk).expect("T"));
}

#[divan::bench(args = ROW_SIZES, sample_count = 1)]
fn diagnose_root_retune(bencher: Bencher, k: usize) {
    // 200 modes is a full rough placement and joint refit (seconds to a minute): only in
    // `cargo bench`; under `cargo test` the settled 1000-mode case is the check.
    if k == ROW_SIZES[0] && !benching() {
        bencher.bench(|| ());
        return;
    }
    let (config, _controller, _dir) = inputs(k);
    let data =
        rshape::data::read_frf_csv(config.data.as_deref().expect("data file")).expect("data");
    let siso = rshape::diagnose::prepare(&config, &data, None, None).expect("prepare");
    let channels = rshape::diagnose::Channels::from_siso(&siso).expect("channels");
    let model = config.physical.clone().expect("[physical]");
    bencher.bench(|| rshape::diagnose::retune(&model, &channels, None, true));
}

/// Sizes of the closed-loop poles from the loop's structure (fifth session): the loop of the
/// cancelled rows' eigenvalues and the factors' denominators' roots, from 200 loop states
/// (50 modes); 1000 modes is a 2000 × 2000 eigenproblem instead of 4000 × 4000.
const POLE_SIZES: &[usize] = &[100, 1000];

#[divan::bench(args = POLE_SIZES, sample_count = 1)]
fn loop_poles_structured(bencher: Bencher, k: usize) {
    if k > POLE_SIZES[0] && !benching() {
        bencher.bench(|| ());
        return;
    }
    let (config, controller, _dir) = inputs(k);
    bencher.bench(|| {
        rshape::stability::closed_loop_poles(&config.factorization, &controller).expect("poles")
    });
}

/// Sizes of the certified norms (sixth session): `‖T‖∞` and `1/b(G,K)` by the certified
/// frequency sweep on the factor values (`stability::certified_t_norm`,
/// `certified_gang_norm`), started from a 1000-point grid, instead of Hamiltonians of
/// twice the loop's states (1000 modes: 4000 × 4000, tens of minutes of CPU).
const SWEEP_SIZES: &[usize] = &[100, 1000];

#[divan::bench(args = SWEEP_SIZES, sample_count = 1)]
fn certified_norms(bencher: Bencher, k: usize) {
    if k > SWEEP_SIZES[0] && !benching() {
        bencher.bench(|| ());
        return;
    }
    let (config, controller, _dir) = inputs(k);
    let f = &config.factorization;
    let kk = controller.negative_feedback_gain();
    let grid = rshape::system::logspace(1.0, 1e5, 1000);
    bencher.bench(|| {
        let t = rshape::stability::certified_t_norm(f, &kk, &grid, &grid).expect("||T||");
        let g = rshape::stability::certified_gang_norm(f, &kk, &grid, &grid).expect("gang");
        (t, g)
    });
}

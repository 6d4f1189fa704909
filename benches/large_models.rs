//! Issue 34 item 9: where the time of a large modal model goes. The model is the issue-21
//! structure of `benches/support/modes.rs` (`K` lightly damped modes, special factorization
//! with a diagonal `M̃`), `K` = 25, 50, 100 (200 and 1000 are minutes: see the report of
//! issue 34), with a static controller `K = 10⁻³`.
//!
//! * `load`: `Config::load` (what `compare` and every command pays first);
//! * `theorem1_system`: the realization of the loop (`modal_system` = `M̃⁻¹·[Ñ·J  I]`, the
//!   minimal realizations, the feedback);
//! * `closed_loop_poles`: that plus the eigenvalues (the internal-stability verdict);
//! * `stability_run`: `pipeline::stability::run` (poles, the grid, the exact H∞ norms).
//!
//! Run: `cargo bench --bench large_models -- --sample-count 1`.
//!
//! Measured 2026-11-27 (2 shared cores, one sample each), K = 25 / 50 / 100 modes:
//! `load` 0.24 / 0.42 / 1.1 ms; `theorem1_system` 2.2 / 13 / 91 ms; `closed_loop_poles`
//! 5.3 / 35 / 262 ms; `stability_run` 1.03 s / 10.7 s / 2.36 min. The poles are cheap; the
//! time is the exact H∞ norms (`‖T‖∞`, `b(G,K)`, `‖r·T‖∞`): a perf profile of 200 modes puts
//! 60 % in `FreqEvaluator::eval` and 29 % in dense products — the lower-bound candidates of
//! `hinf_norm` (8 per pole: 3200 responses of a system with one input per mode, each
//! `O(N²·n)`), not the Hamiltonian eigenvalues.

#[path = "support/modes.rs"]
#[allow(dead_code)]
mod modes;

use divan::Bencher;
use rshape::model::{Config, Controller};

fn main() {
    divan::main();
}

const SIZES: &[usize] = &[25, 50, 100];

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

#[divan::bench(args = SIZES, sample_count = 1)]
fn stability_run(bencher: Bencher, k: usize) {
    // `cargo bench` passes `--bench`; `cargo test --all-targets` runs each bench once in a
    // debug build, where 50 and 100 modes take minutes: there only 25 modes are run (a
    // check that the measurement works), the larger sizes measure nothing.
    if k > SIZES[0] && !std::env::args().any(|a| a == "--bench") {
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

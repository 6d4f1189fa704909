//! The robot half of the hidden-effect suite in CI (`tests/diagnose/hidden/`): every case of the
//! two-link flexible robot (five modes, 211 points from 1 to 64 rad/s, 2 % noise) on seed 11
//! (the seed on which 10 of 42 cases failed before the consistency polish and the anchored
//! refit boxes), and the null case.  The full sweep (three seeds) is the ignored
//! `hidden_effects_robot` of tests/diagnose/diagnose_hidden.rs.

use crate::hidden;

use hidden::{robot, run_suite, Selection};

fn run(cases: &[usize], null: bool, n: usize) {
    let (b, w) = robot();
    let o = run_suite(
        "robot",
        b,
        w,
        &Selection {
            seeds: &[11],
            cases: Some(cases),
            null,
        },
    );
    assert_eq!(o.total(), n);
    assert!(
        o.failures.is_empty(),
        "{} of {} failed:\n{}",
        o.failures.len(),
        o.total(),
        o.failures.join("\n")
    );
}

/// Single effects (delay, mode, lag, second integrator, NMP zero, gain) and the null case.
#[test]
fn robot_single_effects_and_null_seed_11() {
    run(&[0, 1, 2, 3, 4, 5], true, 7);
}

/// Pairs, triples and rough starts.
#[test]
fn robot_several_effects_and_rough_starts_seed_11() {
    run(&[6, 7, 8, 9, 10, 11, 12], false, 7);
}

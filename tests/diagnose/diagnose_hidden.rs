//! Hidden-effect suite: true plant = nominal model + hidden effects (one, two or three at
//! once) + bounded complex noise (uniform in a disk of radius r_k = 2 % of |G_true(jω_k)|,
//! known to diagnose), 3 noise seeds per case, from the right and from a rough start.
//!
//! Two nominal models: the two-link flexible robot of Boulet & Francis 1998 (five modes,
//! 211 points from 1 to 64 rad/s) and a servo with a rigid body and two modes (100/s², 77 Hz
//! and 190 Hz, 240 points from 11 to 250 Hz).
//!
//! A case passes when `diagnose` chooses exactly the hidden set of added effects (gain,
//! sign, mode shift and damping errors are the retune's: they must be absorbed with no
//! effect added, and the retuned parameter must match), every parameter is within its
//! tolerance (after the joint refit), and the final model is consistent (misfit_rms ≤ 1,
//! ≤ 5 % invalid).  The null case adds nothing.  Pass rates per class are printed; every
//! case must pass.  Every diagnosis is also scanned (`hidden::scan`): no non-finite number,
//! no frequency beyond 1e6× the band.
//!
//! The suite lives in `tests/diagnose/hidden/`; this file runs the servo (every case, in CI) and the
//! full robot sweep (ignored: 22 s at opt-level 1 on a loaded 2-core machine, 11 s in release); `tests/diagnose/diagnose_hidden_robot.rs`
//! runs a robot subset in CI.

use crate::hidden;

use hidden::{robot, run_suite, servo, ALL};

/// The robot (five heavily damped modes, one of them a spare with a residue 300× smaller
/// than the others, 15 configured parameters): 42/42 cases pass (single 18/18, pair 9/9,
/// triple 6/6, rough start 6/6, null 3/3), and 140/140 on seeds 1–10.
#[test]
#[ignore = "the full robot sweep (≈22 s at opt-level 1); tests/diagnose/diagnose_hidden_robot.rs runs seed 11 in CI"]
fn hidden_effects_robot() {
    let (b, w) = robot();
    let o = run_suite("robot", b, w, &ALL);
    assert!(
        o.failures.is_empty(),
        "{} of {} failed:\n{}",
        o.failures.len(),
        o.total(),
        o.failures.join("\n")
    );
}

/// Rigid body and two modes: every case passes (42/42: single 18/18, pair 9/9, triple 6/6,
/// rough start 6/6, null 3/3; 140/140 on seeds 1–10).
#[test]
fn hidden_effects_servo() {
    let (b, w) = servo();
    let o = run_suite("servo", b, w, &ALL);
    assert_eq!(o.total(), 42);
    assert_eq!(o.scanned, 42);
    assert!(
        o.failures.is_empty(),
        "{} of {} failed:\n{}",
        o.failures.len(),
        o.total(),
        o.failures.join("\n")
    );
}

//! The hidden-effect suite (tests/diagnose/hidden) on an **accelerance**: the servo (rigid body and two
//! modes) measured as acceleration (`quantity = "acceleration"`: the model is s² times the
//! displacement model, the rigid body a flat mass line), every case of the displacement suite
//! with the same physical hidden terms, three noise seeds; and the out-of-band modes (a mode
//! 5× above the band: the upper residual; 5× below: the lower residual) on both quantities.

use crate::hidden;

use hidden::{out_of_band_cases, run_cases, run_suite, servo, ALL};
use rshape::model::physical::Quantity;

fn accelerance_servo() -> (rshape::model::physical::PhysicalModel, Vec<f64>) {
    let (mut b, w) = servo();
    b.quantity = Quantity::Acceleration;
    (b, w)
}

#[test]
fn hidden_effects_servo_accelerance() {
    let (b, w) = accelerance_servo();
    let o = run_suite("servo accelerance", b, w, &ALL);
    assert_eq!(o.total(), 42);
    assert!(
        o.failures.is_empty(),
        "{} of {} failed:\n{}",
        o.failures.len(),
        o.total(),
        o.failures.join("\n")
    );
}

#[test]
fn out_of_band_modes_are_residual_terms() {
    for (name, (b, w)) in [
        ("servo", servo()),
        ("servo accelerance", accelerance_servo()),
    ] {
        let cases = out_of_band_cases(&b, &w);
        let o = run_cases(name, b, w, cases, &hidden::Selection { null: false, ..ALL });
        assert!(
            o.failures.is_empty(),
            "{name}: {} of {} failed:\n{}",
            o.failures.len(),
            o.total(),
            o.failures.join("\n")
        );
    }
}

/// Seeds 1–10 on the accelerance servo and the out-of-band cases: 160/160 pass (single
/// 60/60, pair 30/30, triple 20/20, rough start 20/20, mode above the band 10/10, below
/// 10/10, null 10/10; 72 s at opt-level 1, hence ignored).
#[test]
#[ignore = "seeds 1-10: about 2 min at opt-level 1"]
fn hidden_effects_servo_accelerance_ten_seeds() {
    let seeds: Vec<u64> = (1..=10).collect();
    let sel = hidden::Selection {
        seeds: &seeds,
        cases: None,
        null: true,
    };
    let (b, w) = accelerance_servo();
    let mut cases = hidden::cases(&b, &w);
    cases.extend(out_of_band_cases(&b, &w));
    let o = run_cases("servo accelerance", b, w, cases, &sel);
    assert!(
        o.failures.is_empty(),
        "{} of {} failed:\n{}",
        o.failures.len(),
        o.total(),
        o.failures.join("\n")
    );
}

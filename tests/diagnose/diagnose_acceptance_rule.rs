//! The acceptance rule of an added effect (`rank::improves`: no more invalid data, or a lower
//! `misfit_rms`; ΔBIC > 10 besides), validated on broad suites (issue 20, item 8 follow-up): the
//! hidden-effect suite (tests/diagnose/hidden) on the servo as a receptance and as an accelerance
//! with the out-of-band modes, noise seeds 1–10 each (the null case on every seed), and the
//! robot on its three seeds.  Every case must pass; the counts per class are printed
//! (docs/guide/discovery-walkthrough.md, section 6, gives the counts of the rule variants
//! compared).  Ignored: about 4 min in release on a loaded 2-core machine.

use crate::hidden;

use hidden::{out_of_band_cases, robot, run_cases, servo, Outcome, Selection, SEEDS};
use rshape::model::physical::Quantity;

fn report(name: &str, o: &Outcome) -> (usize, usize) {
    let passed: usize = o.per_class.values().map(|x| x.0).sum();
    println!("{name}: {passed}/{} pass", o.total());
    for (class, (p, n)) in &o.per_class {
        println!("  {class:<22} {p}/{n}");
    }
    (passed, o.total())
}

#[test]
#[ignore = "broad suites, seeds 1-10: about 4 min in release"]
fn the_acceptance_rule_on_broad_suites() {
    let seeds: Vec<u64> = (1..=10).collect();
    let ten = Selection {
        seeds: &seeds,
        cases: None,
        null: true,
    };
    let mut failures = Vec::new();
    let mut sum = (0, 0);
    for q in [Quantity::Displacement, Quantity::Acceleration] {
        let (mut b, w) = servo();
        b.quantity = q;
        let mut cases = hidden::cases(&b, &w);
        cases.extend(out_of_band_cases(&b, &w));
        let name = format!("servo {q:?}, seeds 1-10");
        let o = run_cases(&name, b, w, cases, &ten);
        let (p, n) = report(&name, &o);
        sum = (sum.0 + p, sum.1 + n);
        failures.extend(o.failures);
    }
    let (b, w) = robot();
    let cases = hidden::cases(&b, &w);
    let three = Selection {
        seeds: &SEEDS,
        cases: None,
        null: true,
    };
    let o = run_cases("robot, seeds 11 22 33", b, w, cases, &three);
    let (p, n) = report("robot, seeds 11 22 33", &o);
    sum = (sum.0 + p, sum.1 + n);
    failures.extend(o.failures);
    println!("total: {}/{} pass", sum.0, sum.1);
    assert!(
        failures.is_empty(),
        "{} of {} failed:\n{}",
        failures.len(),
        sum.1,
        failures.join("\n")
    );
}

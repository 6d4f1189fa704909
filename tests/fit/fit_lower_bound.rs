//! The proven lower bounds per order (issue 38, ninth step) against the fit itself, an
//! independent route (the fit never uses them): on a 40-point envelope with a resonant bump,
//! no order's certified max may lie below its bound, the order-0 bound is the closed form
//! `log10(max r_min/min r_min)`, and the bounds are not vacuous (within 0.05 decade of the
//! fit at every order, within 0.001 at orders 0–1, where the fit is known to be optimal).

use rshape::consistency::{Envelope, EnvelopeMethod};
use rshape::fit::{fit_auto, proven_lower_bounds, FitSettings};

#[test]
fn bounds_sit_below_every_certified_order() {
    let omega: Vec<f64> = (0..40)
        .map(|i| 10f64.powf(-1.0 + 2.5 * i as f64 / 39.0))
        .collect();
    let r_min: Vec<f64> = omega
        .iter()
        .map(|w| 0.3 * (1.0 + w).sqrt() * (1.0 + 3.0 / (1.0 + ((w - 2.0) / 0.2).powi(2))))
        .collect();
    let env = Envelope {
        omega,
        r_min: r_min.clone(),
        a1_limit: None,
        method: EnvelopeMethod::File,
    };
    let set = FitSettings::default();
    let (_, rows) = fit_auto(&env, None, &set, 3, &Default::default()).expect("fit");
    let maxes: Vec<f64> = rows.iter().map(|r| r.max_log10).collect();
    let bounds = proven_lower_bounds(&env, None, &set, &maxes, 1e-4).expect("bounds");
    let hi = r_min.iter().copied().fold(0.0, f64::max);
    let lo = r_min.iter().copied().fold(f64::INFINITY, f64::min);
    for (r, b) in rows.iter().zip(&bounds) {
        let lb = b
            .max_log10
            .unwrap_or_else(|| panic!("order {}: no bound", r.order));
        assert!(
            lb <= r.max_log10 + 1e-9,
            "order {}: {lb} > {}",
            r.order,
            r.max_log10
        );
        let tight = if r.order <= 1 { 1e-3 } else { 0.05 };
        assert!(
            lb >= r.max_log10 - tight,
            "order {}: {lb} ≪ {}",
            r.order,
            r.max_log10
        );
    }
    let lb0 = bounds[0].max_log10.unwrap();
    assert!((lb0 - (hi / lo).log10()).abs() < 1e-4, "{lb0}");
}

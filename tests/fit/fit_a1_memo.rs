//! Issue 38, profile step: the fit remembers the A1 limit per frequency
//! (`src/fit/a1_memo.rs`).  On the DaISy arm with ζ = 0.01 (an A1 notch the fit must keep;
//! `certificate_arm_notch.rs`) the fit's certificate is the same, to the bit, as the public
//! [`certify`] of the returned `r` with the caller's own A1 function (no memo), and the fit
//! asks the caller for each frequency once.

use super::certificate_arm_notch::arm_z001;
use rshape::fit::{certify, fit_auto, fit_unit, CertInput, FitResult, FitSettings, Zpk};
use std::cell::{Cell, RefCell};
use std::collections::HashSet;

/// The certificate of `fit.r` recomputed by [`certify`] with `a1` (the caller's function,
/// not the fit's memo), as JSON; `repair_factor` is the fit's (set by the repair, not by
/// `certify`).
fn recertified(
    fit: &FitResult,
    env: &rshape::Envelope,
    set: &FitSettings,
    a1: &dyn Fn(f64) -> f64,
) -> String {
    let inp = CertInput::of_fit(env, Some(a1), set);
    let r = Zpk {
        gain: fit.gain,
        zeros: fit.zeros.clone(),
        poles: fit.poles.clone(),
    };
    let mut c = certify(&r, &inp);
    c.repair_factor = fit.certificate.repair_factor;
    serde_json::to_string(&c).unwrap()
}

#[test]
fn the_fit_asks_for_a1_once_per_frequency_and_certifies_the_same() {
    let (cfg, env) = arm_z001();
    let f = &cfg.factorization;
    let calls = Cell::new(0usize);
    let seen = RefCell::new(HashSet::new());
    let counting = |w: f64| {
        calls.set(calls.get() + 1);
        seen.borrow_mut().insert(w.to_bits());
        f.a1_limit(w)
    };
    let plain = |w: f64| f.a1_limit(w);
    let base = FitSettings::default().with_a1_model(f);

    // fit_unit at order 4: candidates of orders 0–4 certified, the notch binding.
    let set = FitSettings {
        order: 4,
        chain: true,
        ..base.clone()
    };
    let fit = fit_unit(&env, Some(&counting), &set, &Default::default()).unwrap();
    assert!(fit.certificate.passed, "{:?}", fit.certificate.failures);
    let margin = fit.certificate.worst_a1_margin.expect("A1 checked");
    assert!(margin < 1.5, "A1 does not bind: margin {margin}");
    println!(
        "fit_unit: A1 asked {} times at {} frequencies",
        calls.get(),
        seen.borrow().len()
    );
    assert_eq!(calls.get(), seen.borrow().len(), "a frequency asked twice");
    assert!(calls.get() > 1000, "the certificate's grid was not asked");
    let fit_json = serde_json::to_string(&fit.certificate).unwrap();
    assert_eq!(fit_json, recertified(&fit, &env, &set, &plain));

    // fit_auto to order 4: every order's certificate on the same grid (the low orders fail A1
    // at the notch, their candidates certified and refused all the same).
    calls.set(0);
    seen.borrow_mut().clear();
    let (auto, rows) = fit_auto(&env, Some(&counting), &base, 4, &Default::default()).unwrap();
    assert!(auto.certificate.passed, "{rows:?}");
    assert_eq!(calls.get(), seen.borrow().len(), "a frequency asked twice");
    let auto_json = serde_json::to_string(&auto.certificate).unwrap();
    assert_eq!(auto_json, recertified(&auto, &env, &base, &plain));
}

//! Issue 38, eighth step: `FitSettings::dense_level_lp` (the polynomial candidate's level
//! LPs solved for their analytic centre by `src/fit/dense_ipm`) keeps a fit certified and
//! within the sweep's rule on an envelope where the search doubts (envelope 5 of the sweep,
//! 29 points: orders 6–8 try other disk-map centres).  Not the default: on the whole sweep
//! six orders rise beyond the rule (docs/internals-fit-speed.md, eighth step).

use super::fit_sweep::random_envelopes::{envelope, sweep_specs};
use super::fit_sweep::reference;
use rshape::fit::{fit_auto, FitSettings};

const ENVELOPE: usize = 5;

#[test]
fn dense_level_lps_keep_envelope_5_within_the_rule() {
    let env = envelope(&sweep_specs()[ENVELOPE]);
    let set = FitSettings {
        dense_level_lp: true,
        ..FitSettings::default()
    };
    let (res, rows) = fit_auto(&env, None, &set, 8, &Default::default()).expect("fit");
    let table = reference();
    assert_eq!(rows.len(), 9);
    for r in &rows {
        assert_eq!(r.status, "ok", "order {}: {}", r.order, r.status);
        let rise = r.max_log10 - table[ENVELOPE][r.order];
        assert!(
            rise <= 0.002,
            "order {}: {:.5} against {:.5}",
            r.order,
            r.max_log10,
            table[ENVELOPE][r.order]
        );
    }
    // The chosen r passes the certificate (bounds on the dense grid, between the points, A1).
    assert!(res.certificate.passed, "{:?}", res.certificate.failures);
}

//! What a fit reports about its own work (issue 21): the LPs per order add up to the total,
//! the progress callback hears of every order in turn, and `rshape fit` prints one line
//! `N LPs in T s` by default and the solver events only with `--verbose`.

use rshape::consistency::{Envelope, EnvelopeMethod};
use rshape::fit::{fit_auto, fit_unit, FitOptions, FitProgress, FitSettings};
use rshape::system::logspace;
use std::process::Command;
use std::sync::Mutex;

/// A jagged envelope over 4 decades (the one of `benches/fit.rs`).
fn envelope(n: usize) -> Envelope {
    let omega = logspace(0.1, 1000.0, n);
    let mut seed = 7u64;
    let r_min = omega
        .iter()
        .map(|w| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            0.05 * (1.0 + (w / 3.0).powi(2)).sqrt() / (1.0 + (w / 200.0).powi(2)).sqrt()
                * (1.0 + 2.0 / (1.0 + (4.0 * (w / 30.0).ln()).powi(2)))
                * (0.5 + 0.5 * ((seed >> 11) as f64 / (1u64 << 53) as f64))
        })
        .collect();
    Envelope {
        omega,
        r_min,
        a1_limit: None,
        method: EnvelopeMethod::File,
    }
}

#[test]
fn lps_per_order_add_up_and_progress_hears_every_order() {
    let env = envelope(300);
    let heard = Mutex::new(Vec::<FitProgress>::new());
    let progress = |p: FitProgress| heard.lock().unwrap().push(p);
    let options = FitOptions {
        progress: Some(&progress),
    };
    let (fit, rows) = fit_auto(&env, None, &FitSettings::default(), 4, &options).unwrap();
    assert!(fit.certificate.passed);
    let sum: usize = rows.iter().map(|r| r.lp_solves).sum();
    assert_eq!(sum, fit.lp_solves, "{rows:?}");
    // Order 0 is a constant level search; every order solves at least one LP.
    assert!(rows.iter().all(|r| r.lp_solves > 0), "{rows:?}");
    let heard = heard.into_inner().unwrap();
    assert_eq!(
        heard.iter().map(|p| p.order).collect::<Vec<_>>(),
        vec![0, 1, 2, 3, 4]
    );
    assert!(heard.iter().all(|p| p.last_order == 4));
    // Before order k: the LPs of orders 0..k exactly.
    for (k, p) in heard.iter().enumerate() {
        let before: usize = rows[..k].iter().map(|r| r.lp_solves).sum();
        assert_eq!(p.lp_solves, before, "order {k}");
    }
}

#[test]
fn a_fixed_order_reports_its_order_and_its_lps() {
    let env = envelope(300);
    let heard = Mutex::new(Vec::<FitProgress>::new());
    let progress = |p: FitProgress| heard.lock().unwrap().push(p);
    let set = FitSettings {
        order: 3,
        ..Default::default()
    };
    let options = FitOptions {
        progress: Some(&progress),
    };
    let fit = fit_unit(&env, None, &set, &options).unwrap();
    let heard = heard.into_inner().unwrap();
    assert_eq!(heard.first().map(|p| (p.order, p.last_order)), Some((3, 3)));
    assert!(fit.lp_solves > 0);
}

#[test]
fn fit_prints_one_work_line_and_the_events_only_with_verbose() {
    let dir = tempfile::tempdir().unwrap();
    let env = envelope(1000);
    let csv = dir.path().join("env.csv");
    let mut text = String::from("omega_rad_s,r_min\n");
    for (w, r) in env.omega.iter().zip(&env.r_min) {
        text.push_str(&format!("{w:e},{r:e}\n"));
    }
    std::fs::write(&csv, text).unwrap();
    let run = |verbose: bool, out: &str| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_rshape"));
        c.args(["fit", "--envelope"])
            .arg(&csv)
            .args(["--order", "6", "--out"])
            .arg(dir.path().join(out));
        if verbose {
            c.arg("--verbose");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let quiet = run(false, "q");
    let work: Vec<&str> = quiet.lines().filter(|l| l.contains(" LPs in ")).collect();
    assert_eq!(work.len(), 1, "{quiet}");
    let lps: usize = work[0].split(' ').next().unwrap().parse().unwrap();
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("q/r.json")).unwrap())
            .unwrap();
    assert_eq!(j["lp_solves"].as_u64(), Some(lps as u64));
    let events = j["solver_events"].as_array().unwrap().len();
    assert!(events > 0, "this envelope has solver events at order 6");
    assert!(!quiet.contains("solver events ("), "{quiet}");
    assert!(!quiet.lines().any(|l| l.starts_with("  order ")), "{quiet}");
    let loud = run(true, "v");
    assert!(loud.contains("solver events ("), "{loud}");
    let listed = loud.lines().filter(|l| l.starts_with("  order ")).count();
    assert_eq!(listed, events, "{loud}");
}

//! "No printed or JSON parameter is non-finite or beyond 1e6× the measured band": `rshape
//! diagnose` on every shipped config, its `--json` output and its printed report scanned
//! (`hidden::scan`).  Configs `diagnose` refuses (factor forms it cannot convert, configs
//! without data) must say why in one line with exit code 2.  The hidden-effect suite scans
//! the output of each of its diagnoses too (tests/diagnose_hidden*.rs).

use crate::common;
use crate::hidden;

use common::{repo, rshape, stderr, stdout};
use hidden::scan::{scan_json, scan_text};
use std::collections::BTreeMap;

/// The measured band of a config's data, from `rshape compare --json` (channel 1,1 of MIMO
/// data; `None`: compare refuses the config).
fn band(config: &str) -> Option<(f64, f64)> {
    let mut o = rshape(&["compare", config, "--json"]);
    if !o.status.success() {
        // MIMO data: every channel has the same frequencies.
        o = rshape(&["compare", config, "--json", "--channel", "1,1"]);
    }
    if !o.status.success() {
        return None;
    }
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let w: Vec<f64> = v["rows"]
        .as_array()?
        .iter()
        .filter_map(|r| r["omega"].as_f64())
        .collect();
    Some((
        w.iter().copied().fold(f64::INFINITY, f64::min),
        w.iter().copied().fold(0.0, f64::max),
    ))
}

/// Runs diagnose (JSON and text) on `config` and returns what is wrong.
fn scan_config(config: &str) -> (bool, Vec<String>) {
    let json = rshape(&["diagnose", config, "--json"]);
    if !json.status.success() {
        let err = stderr(&json);
        let mut bad = Vec::new();
        if json.status.code() != Some(2) || err.trim().lines().count() != 1 {
            bad.push(format!(
                "refused without a one-line error and exit code 2 ({:?}): {err}",
                json.status.code()
            ));
        }
        return (false, bad);
    }
    let Some((w_lo, w_hi)) = band(config) else {
        return (
            true,
            vec!["compare refuses a config diagnose accepts".into()],
        );
    };
    let v: serde_json::Value = serde_json::from_str(&stdout(&json)).unwrap();
    let mut bad: Vec<String> = scan_json(&v, w_lo, w_hi)
        .into_iter()
        .map(|x| format!("JSON: {x}"))
        .collect();
    let text = rshape(&["diagnose", config]);
    assert!(text.status.success(), "{config}: {}", stderr(&text));
    bad.extend(
        scan_text(&stdout(&text), w_lo, w_hi)
            .into_iter()
            .map(|x| format!("text: {x}")),
    );
    (true, bad)
}

#[test]
fn shipped_configs_print_no_absurd_numbers() {
    let mut configs: Vec<String> = std::fs::read_dir(repo("configs"))
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension().is_some_and(|x| x == "toml"))
                .then(|| format!("configs/{}", p.file_name().unwrap().to_string_lossy()))
        })
        .collect();
    configs.sort();
    // Two workers (the machine has two cores).
    let results: BTreeMap<String, (bool, Vec<String>)> = std::thread::scope(|s| {
        let chunks: Vec<Vec<String>> = (0..2)
            .map(|k| configs.iter().skip(k).step_by(2).cloned().collect())
            .collect();
        let handles: Vec<_> = chunks
            .into_iter()
            .map(|chunk| {
                s.spawn(move || {
                    chunk
                        .into_iter()
                        .map(|c| {
                            let r = scan_config(&c);
                            (c, r)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    let diagnosed: Vec<&String> = results.iter().filter(|r| r.1 .0).map(|r| r.0).collect();
    println!("diagnosed and scanned: {diagnosed:?}");
    // The physical configs with data: both rigs, every revision, and the closed-loop one.
    assert!(diagnosed.len() >= 12, "{diagnosed:?}");
    let bad: Vec<String> = results
        .iter()
        .flat_map(|(c, (_, b))| b.iter().map(move |x| format!("{c}: {x}")))
        .collect();
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The scanners catch what the issue saw on screen (ω_n = 7.5e45, z = inf, a shift of
/// +1.7e46 %) and NaN parameters (written as `null` by serde).
#[test]
fn the_scanners_catch_absurd_numbers() {
    let (w_lo, w_hi) = (69.0, 1571.0);
    let text = "omega_n = 7.5e45 rad/s, z = inf, shifted by +16520601405160130298202596026233158772604272640.0 % at 7.5e45 Hz";
    let bad = scan_text(text, w_lo, w_hi);
    assert_eq!(bad.len(), 4, "{bad:?}");
    let ok = "the misfit peaks at 478.9 rad/s (76.21 Hz), shifted by +5.0 % (fs = 157080 Hz)";
    assert!(scan_text(ok, w_lo, w_hi).is_empty());
    let mut p = BTreeMap::new();
    p.insert("omega_n".to_string(), 7.5e45);
    p.insert("rho".to_string(), f64::NAN);
    p.insert("tau_s".to_string(), 1e9);
    p.insert("t_s".to_string(), 1e-12);
    let v = serde_json::json!({ "candidates": [{ "params": p, "no_fit": null }] });
    let bad = scan_json(&v, w_lo, w_hi);
    assert_eq!(bad.len(), 4, "{bad:?}");
    let mut p = BTreeMap::new();
    p.insert("omega_n".to_string(), 900.0);
    p.insert("tau_s".to_string(), 4e-4);
    let v = serde_json::json!({ "params": p, "no_fit": null, "separates_above": 3500.0 });
    assert!(scan_json(&v, w_lo, w_hi).is_empty());
}

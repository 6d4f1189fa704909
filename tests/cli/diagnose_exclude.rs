//! `diagnose --exclude FMIN:FMAX`: the stop on a residual that is one line offers the range
//! that leaves that line out, and the diagnosis without it is the one of the other lines.
//! `configs/mains_line.toml` is built (its header says how) so that the two configured modes
//! are exact everywhere but at 2640 Hz and every other datum is off by 0.3 noise radii: so
//! `misfit_rms` without the line is 0.3 by construction, independent of the search.

use crate::common::{repo, rshape, stderr, stdout};

fn diagnose(extra: &[&str]) -> std::process::Output {
    let cfg = repo("configs/mains_line.toml");
    let mut args = vec!["diagnose", cfg.to_str().unwrap()];
    args.extend_from_slice(extra);
    rshape(&args)
}

fn json(o: &std::process::Output) -> serde_json::Value {
    assert_eq!(o.status.code(), Some(0), "{}", stderr(o));
    serde_json::from_str(&stdout(o)).unwrap()
}

#[test]
fn the_range_offered_for_an_outlier_line_leaves_it_out() {
    let o = diagnose(&[]);
    let text = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(text.contains("one line at 2640 Hz"), "{text}");
    let offered = text
        .split("(`--exclude ")
        .nth(1)
        .and_then(|t| t.split('`').next())
        .unwrap_or_else(|| panic!("no --exclude offered:\n{text}"));
    assert_eq!(offered, "2639.5:2640.5");
    let d = json(&diagnose(&["--exclude", offered, "--json"]));
    assert_eq!(d["n_data"], 300);
    assert_eq!(d["verdict"], "consistent", "{}", d["message"]);
    let rms = d["before"]["misfit_rms"].as_f64().unwrap();
    assert!((rms - 0.3).abs() < 1e-6, "{rms}");
    // With the line, the same model is far off (the line alone: 69.8× the noise).
    let d = json(&diagnose(&["--json"]));
    assert_eq!(d["n_data"], 301);
    assert!(d["before"]["misfit_rms"].as_f64().unwrap() > 5.0);
    // Ranges add up; both ends are included.
    let d = json(&diagnose(&[
        "--exclude",
        "2639.5:2640.5",
        "--exclude",
        "2500:2509",
        "--json",
    ]));
    assert_eq!(d["n_data"], 290);
}

#[test]
fn a_range_without_a_line_or_leaving_one_is_refused() {
    for (range, says) in [
        (
            "2640.2:2640.3",
            "no line of the data lies in it (the nearest is at 2640 Hz)",
        ),
        ("2400:2799.5", "it leaves 1 of the data's 301 lines"),
        ("2641:2640", "give FMIN:FMAX in Hz"),
    ] {
        let o = diagnose(&["--exclude", range]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{range}: {e}");
        assert!(e.contains(says), "{range}: {e}");
        assert_eq!(e.trim().lines().count(), 1, "{e}");
        assert!(stdout(&o).is_empty(), "{range}");
    }
}

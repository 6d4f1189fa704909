//! `diagnose --band FMIN:FMAX` (issue 20): the lines of a band, instead of a cut copy of the
//! data.  Cross-checked against the same diagnosis on a data file cut by hand (the `awk` of
//! configs/data/pyfrf/SOURCE.md, done here in Rust): the same number of data, the same
//! measures before and after, the same chosen set; and the per-peak account is in the JSON.
//! Bad bands are one-line errors with exit code 2.

use crate::common;

use common::{repo, rshape, stderr, stdout};

fn json(args: &[&str]) -> serde_json::Value {
    let o = rshape(args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap()
}

/// Keeps the header and the lines with `lo ≤ f ≤ hi` of a CSV whose first column is Hz.
fn cut(src: &str, dst: &std::path::Path, lo: f64, hi: f64) -> usize {
    let text = std::fs::read_to_string(repo(src)).unwrap();
    let mut lines = text.lines();
    let mut out = vec![lines.next().unwrap().to_string()];
    for l in lines {
        let f: f64 = l.split(',').next().unwrap().trim().parse().unwrap();
        if (lo..=hi).contains(&f) {
            out.push(l.to_string());
        }
    }
    std::fs::write(dst, out.join("\n") + "\n").unwrap();
    out.len() - 1
}

#[test]
fn band_equals_a_hand_cut_copy_of_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let n = cut(
        "configs/data/pyfrf/frf_h1_20_1200.csv",
        &dir.path().join("frf.csv"),
        700.0,
        1000.0,
    );
    let n_coh = cut(
        "configs/data/pyfrf/frf_h1_20_1200_coherence.csv",
        &dir.path().join("coh.csv"),
        700.0,
        1000.0,
    );
    assert_eq!((n, n_coh), (301, 301), "1 Hz lines, both ends kept");
    let cfg = std::fs::read_to_string(repo("configs/pyfrf_rigid.toml"))
        .unwrap()
        .replace("data/pyfrf/frf_h1_20_1200_coherence.csv", "coh.csv")
        .replace("data/pyfrf/frf_h1_20_1200.csv", "frf.csv");
    let cut_cfg = dir.path().join("cut.toml");
    std::fs::write(&cut_cfg, cfg).unwrap();
    let shipped = repo("configs/pyfrf_rigid.toml");
    let a = json(&[
        "diagnose",
        shipped.to_str().unwrap(),
        "--band",
        "700:1000",
        "--max-effects",
        "1",
        "--json",
    ]);
    let b = json(&[
        "diagnose",
        cut_cfg.to_str().unwrap(),
        "--max-effects",
        "1",
        "--json",
    ]);
    assert_eq!(a["n_data"], 301);
    assert_eq!(a["n_data"], b["n_data"]);
    assert_eq!(a["chosen"], b["chosen"]);
    for m in ["before", "after"] {
        for k in ["misfit_rms", "invalid_fraction", "v"] {
            let (x, y) = (a[m][k].as_f64().unwrap(), b[m][k].as_f64().unwrap());
            assert!(
                (x - y).abs() <= 1e-9 * y.abs().max(1e-300),
                "{m}.{k}: {x} vs {y}"
            );
        }
    }
    // The per-peak account is part of the report: every peak with its fate and reason,
    // inside the band.
    let peaks = a["peaks"].as_array().unwrap();
    assert!(!peaks.is_empty());
    for p in peaks {
        let f = p["frequency_hz"].as_f64().unwrap();
        assert!((700.0..=1000.0).contains(&f), "{p}");
        assert!(p["height"].as_f64().unwrap() >= 3.0, "{p}");
        assert!(!p["reason"].as_str().unwrap().is_empty(), "{p}");
        assert!(p["fate"].is_string(), "{p}");
    }
}

#[test]
fn bad_bands_are_one_line_errors() {
    let shipped = repo("configs/pyfrf_rigid.toml");
    for (band, needle) in [
        ("1000:700", "FMIN < FMAX"),
        ("abc", "FMIN:FMAX"),
        ("-5:10", "FMIN:FMAX"),
        ("5000:6000", "0 of the data's lines"),
        ("700:700.5", "1 of the data's lines"),
    ] {
        let o = rshape(&["diagnose", shipped.to_str().unwrap(), "--band", band]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "--band {band}: {err}");
        assert!(err.contains(needle), "--band {band}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "--band {band}: {err}");
        assert!(stdout(&o).is_empty(), "--band {band}");
    }
}

//! `sample_time = Ts`: data on a normalized frequency axis (cycles/sample as `freq_hz`,
//! rad/sample as `omega_rad_s`, as the DaISy FRFs are written). Cross-checked against the
//! same data rewritten in Hz by hand (an independent route: no scaling in rshape), for the
//! noise-free envelope, the streamed envelope, the coherence noise radii and `run`.

use crate::common::{rshape, stderr};
use std::path::Path;

const PLANT: &str = "[plant]\ntf = [[{ num = [1], den = [1, 0.4, 4] }]]\n";

/// Rows `(f, re, im, γ²)`: f in cycles/sample.
const ROWS: [(f64, f64, f64, f64); 5] = [
    (0.01, 0.26, -0.01, 0.95),
    (0.05, 0.31, -0.08, 0.9),
    (0.1, 0.7, -1.9, 0.6),
    (0.2, -0.15, -0.02, 0.8),
    (0.5, -0.03, -0.001, 0.7),
];

/// Writes `frf.csv` and `frf_coherence.csv` with frequencies `f·scale` in the `freq_hz`
/// column, and a config with the given extra lines.
fn write(dir: &Path, scale: f64, extra: &str) -> std::path::PathBuf {
    let mut frf = String::from("freq_hz,re_1_1,im_1_1\n");
    let mut coh = String::from("freq_hz,coh_1_1\n");
    for (f, re, im, g2) in ROWS {
        frf += &format!("{},{re},{im}\n", f * scale);
        coh += &format!("{},{g2}\n", f * scale);
    }
    std::fs::write(dir.join("frf.csv"), frf).unwrap();
    std::fs::write(dir.join("frf_coherence.csv"), coh).unwrap();
    let cfg = dir.join("c.toml");
    std::fs::write(&cfg, format!("data = \"frf.csv\"\n{extra}\n{PLANT}")).unwrap();
    cfg
}

fn envelope_csv(cfg: &Path, out: &Path) -> String {
    let o = rshape(&[
        "envelope",
        cfg.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::read_to_string(out.join("envelope.csv")).unwrap()
}

/// Numbers of a CSV text, row by row.
fn numbers(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

fn assert_close(a: &str, b: &str) {
    let (a, b) = (numbers(a), numbers(b));
    assert_eq!(a.len(), b.len());
    for (ra, rb) in a.iter().zip(&b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!(
                (x - y).abs() <= 1e-9 * y.abs().max(1e-300),
                "{ra:?} vs {rb:?}"
            );
        }
    }
}

#[test]
fn normalized_axis_equals_the_same_data_in_hz() {
    let ts = 0.004; // 250 Hz sampling: 0.1 cycles/sample is 25 Hz
    for noise in [
        "",
        "[noise]\ncoherence = \"frf_coherence.csv\"\naverages = 7\n",
    ] {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        // sample_time must come before the tables: it is a top-level key.
        let norm = write(a.path(), 1.0, &format!("sample_time = {ts}\n{noise}"));
        let hz = write(b.path(), 1.0 / ts, noise);
        let (ea, eb) = (
            envelope_csv(&norm, &a.path().join("o")),
            envelope_csv(&hz, &b.path().join("o")),
        );
        assert_close(&ea, &eb);
        // The first datum is at 2π·0.01/Ts rad/s.
        let w0 = numbers(&ea)[0][0];
        assert!((w0 - 2.0 * std::f64::consts::PI * 0.01 / ts).abs() < 1e-9 * w0);
    }
}

#[test]
fn run_reports_frequencies_in_rad_per_second() {
    let d = tempfile::tempdir().unwrap();
    let cfg = write(
        d.path(),
        1.0,
        "sample_time = 0.5\n[r]\nnum = [0.001]\nden = [1]\n",
    );
    let out = d.path().join("out");
    let o = rshape(&[
        "run",
        cfg.to_str().unwrap(),
        "--order",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let omegas: Vec<f64> = rep["data_points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["omega"].as_f64().unwrap())
        .collect();
    for ((f, ..), w) in ROWS.iter().zip(&omegas) {
        let want = 2.0 * std::f64::consts::PI * f / 0.5;
        assert!((w - want).abs() < 1e-12 * want, "{w} vs {want}");
    }
    // Said once, on the terminal and in report.json: the frequencies are the data's ÷ Ts.
    let text = String::from_utf8_lossy(&o.stdout);
    let said: Vec<&str> = text.lines().filter(|l| l.contains("sample_time")).collect();
    assert_eq!(said.len(), 1, "{text}");
    assert!(
        said[0].contains("divided by sample_time = 0.5 s: rad/s"),
        "{}",
        said[0]
    );
    assert_eq!(rep["sample_time"].as_f64(), Some(0.5));
    // The figures' frequency axes say rad/s or Hz, never per sample.
    for f in rep["files"].as_array().unwrap() {
        let f = f.as_str().unwrap();
        if f.ends_with(".svg") {
            let svg = std::fs::read_to_string(out.join(f)).unwrap();
            assert!(!svg.contains("/sample"), "{f}");
        }
    }
}

#[test]
fn a_file_in_hz_given_a_sample_time_is_refused_with_its_line() {
    let d = tempfile::tempdir().unwrap();
    // The data are in Hz (up to 50 Hz) but the config says they are per sample.
    let cfg = write(d.path(), 100.0, "sample_time = 0.01\n");
    for cmd in ["envelope", "run"] {
        let out = d.path().join("o");
        let o = rshape(&[cmd, cfg.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert_eq!(e.trim().lines().count(), 1, "{e}");
        // The first row (1 "cycles/sample") is beyond Nyquist: line 2.
        assert!(e.contains("frf.csv:2:"), "{e}");
        assert!(
            e.contains("Nyquist") && e.contains("remove `sample_time`"),
            "{e}"
        );
        assert!(!out.join("report.json").exists());
    }
    // A coherence file in Hz beside normalized data is refused the same way.
    let cfg = write(
        d.path(),
        1.0,
        "sample_time = 0.01\n[noise]\ncoherence = \"frf_coherence.csv\"\naverages = 7\n",
    );
    std::fs::write(
        d.path().join("frf_coherence.csv"),
        "freq_hz,coh_1_1\n1,0.9\n5,0.9\n10,0.9\n20,0.9\n50,0.9\n",
    )
    .unwrap();
    let o = rshape(&[
        "envelope",
        cfg.to_str().unwrap(),
        "--out",
        d.path().join("o2").to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("frf_coherence.csv:2:") && e.contains("Nyquist"),
        "{e}"
    );
}

#[test]
fn a_bad_sample_time_is_a_config_error() {
    let d = tempfile::tempdir().unwrap();
    for bad in ["0", "-1", "nan", "inf"] {
        let cfg = write(d.path(), 1.0, &format!("sample_time = {bad}\n"));
        let o = rshape(&[
            "check",
            cfg.to_str().unwrap(),
            "--r-num",
            "1",
            "--r-den",
            "1",
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{bad}: {e}");
        assert!(
            e.contains("c.toml") && e.contains("sample_time") && e.contains("> 0"),
            "{e}"
        );
    }
}

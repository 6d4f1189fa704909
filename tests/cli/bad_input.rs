//! Bad input gives a one-line error naming the file and the line or the frequency, exit
//! code 2, no panic, and no output file left behind.
use crate::common;

use common::{repo, rshape, stderr};
use std::path::Path;

const HEADER: &str = "omega_rad_s,re_1_1,im_1_1,re_1_2,im_1_2,re_1_3,im_1_3,re_2_1,im_2_1,re_2_2,im_2_2,re_2_3,im_2_3";

fn row(w: &str) -> String {
    format!("{w},0.5,0.1,0.8,0,-1.6,0,0,0,0.2,0.1,0.9,-0.2")
}

/// Runs `envelope` on a config and data written into a temp dir; returns (code, stderr, out dir).
fn run_envelope(config: &str, data: &str) -> (Option<i32>, String, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("model.toml"), config).unwrap();
    std::fs::write(dir.path().join("data.csv"), data).unwrap();
    let out = dir.path().join("out");
    let o = rshape(&[
        "envelope",
        dir.path().join("model.toml").to_str().unwrap(),
        "--data",
        dir.path().join("data.csv").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    (o.status.code(), stderr(&o), dir)
}

fn paper_config() -> String {
    std::fs::read_to_string(repo("configs/paper_mimo.toml")).unwrap()
}

fn assert_one_line_error(code: Option<i32>, err: &str, dir: &Path, needles: &[&str]) {
    assert_eq!(code, Some(2), "stderr: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
    assert!(
        !dir.join("out").join("envelope.csv").exists(),
        "output left behind"
    );
}

#[test]
fn missing_column() {
    let h = HEADER.replace(",im_2_3", "");
    let body = format!("{h}\n0.1,0.5,0.1,0.8,0,-1.6,0,0,0,0.2,0.1,0.9\n");
    let (c, e, d) = run_envelope(&paper_config(), &body);
    assert_one_line_error(c, &e, d.path(), &["data.csv:1", "missing column im_2_3"]);
}

#[test]
fn non_numeric_cell() {
    let body = format!(
        "{HEADER}\n{}\n{}\n",
        row("0.1"),
        row("1").replace("0.8", "abc")
    );
    let (c, e, d) = run_envelope(&paper_config(), &body);
    assert_one_line_error(
        c,
        &e,
        d.path(),
        &["data.csv:3", "`abc` is not a number", "re_1_2"],
    );
}

#[test]
fn nan_value() {
    let body = format!(
        "# comment line\n{HEADER}\n{}\n{}\n",
        row("0.1"),
        row("1").replace("-1.6", "NaN")
    );
    let (c, e, d) = run_envelope(&paper_config(), &body);
    assert_one_line_error(c, &e, d.path(), &["data.csv:4", "not finite"]);
}

#[test]
fn duplicate_frequency() {
    let body = format!("{HEADER}\n{}\n{}\n{}\n", row("0.1"), row("1"), row("0.1"));
    let (c, e, d) = run_envelope(&paper_config(), &body);
    assert_one_line_error(c, &e, d.path(), &["data.csv:4", "duplicate frequency 0.1"]);
}

#[test]
fn negative_frequency() {
    let body = format!("{HEADER}\n{}\n{}\n", row("0.1"), row("-1"));
    let (c, e, d) = run_envelope(&paper_config(), &body);
    assert_one_line_error(c, &e, d.path(), &["data.csv:3", "must be positive"]);
}

#[test]
fn data_size_does_not_match_model() {
    let body = "omega_rad_s,re_1_1,im_1_1\n1,0.5,0.1\n";
    let (c, e, d) = run_envelope(&paper_config(), body);
    assert_one_line_error(c, &e, d.path(), &["data.csv", "1×1", "2×3"]);
}

#[test]
fn unknown_config_key() {
    let cfg = paper_config().replace("[r]\n", "[r]\ngian = 3\n");
    let body = format!("{HEADER}\n{}\n", row("1"));
    let (c, e, d) = run_envelope(&cfg, &body);
    assert_one_line_error(
        c,
        &e,
        d.path(),
        &["model.toml", "line ", "unknown field `gian`"],
    );
}

#[test]
fn m_singular_at_a_datum() {
    // M̃ = diag((s² + 1)/(s + 1)², 1) is singular at ω = 1 rad/s.
    let cfg = r#"
data = "data.csv"
[model]
factorization = "standard"
m = [[{ num = [1, 0, 1], den = [1, 2, 1] }, 0], [0, 1]]
n = [[1, 0, 0], [0, 1, 0]]
"#;
    let body = format!("{HEADER}\n{}\n{}\n{}\n", row("0.5"), row("1"), row("2"));
    let (c, e, d) = run_envelope(cfg, &body);
    assert_one_line_error(c, &e, d.path(), &["omega = 1 rad/s", "M̃(jω) is singular"]);
}

#[test]
fn non_unit_r_is_rejected() {
    let cfg = repo("configs/paper_mimo.toml");
    let o = rshape(&[
        "check",
        cfg.to_str().unwrap(),
        "--r-num",
        "0.3",
        "--r-den",
        "1,1",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a unit"));
}

#[test]
fn hz_and_mag_phase_columns_equal_rad_s_and_re_im() {
    use rshape::data::parse_frf_csv;
    let a = parse_frf_csv(
        "freq_hz,mag_1_1,phase_deg_1_1,noise_radius\n1.5,2,-30,0.1\n",
        Path::new("a.csv"),
    )
    .unwrap();
    let b = parse_frf_csv(
        &format!(
            "omega_rad_s,re_1_1,im_1_1\n{},{},{}\n",
            3.0 * std::f64::consts::PI,
            2.0 * (30f64.to_radians()).cos(),
            -2.0 * (30f64.to_radians()).sin()
        ),
        Path::new("b.csv"),
    )
    .unwrap();
    assert!((a.omega[0] - b.omega[0]).abs() < 1e-12);
    assert!((a.response[0][(0, 0)] - b.response[0][(0, 0)]).norm() < 1e-12);
    assert_eq!(a.noise_radius, Some(vec![0.1]));
}

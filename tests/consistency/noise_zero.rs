//! `--noise-radius 0` (and every other way of saying "zero noise") is no noise: the
//! noise-free theorems, the same envelope byte for byte, finite beyond the A1 limit.  Any
//! positive radius switches to Theorem 4, which reports `inf` at or beyond A1.
use crate::common;

use std::path::Path;

/// M̃ = (s + 2)/(s + 1), Ñ = 1/(s + 1); A1 limit |M̃(jω)| in (1, 2].
const SISO: &str = r#"data = "d.csv"
[model]
factorization = "standard"
m = [[{ num = [1, 2], den = [1, 1] }]]
n = [[{ num = [1], den = [1, 1] }]]
"#;

/// φ(j1) = −10 is beyond A1: r_min = |Ñ − M̃φ|/√(1 + |φ|²) = |21 + 10j|/(√2·√101) ≈ 1.637
/// above |M̃(j1)| = √(5/2) ≈ 1.581.
const ROWS: [(f64, f64, f64); 3] = [(0.1, 0.5, -0.02), (1.0, -10.0, 0.0), (10.0, 0.01, -0.05)];

fn envelope(
    dir: &Path,
    cfg: &str,
    noise_col: Option<f64>,
    flag: Option<&str>,
    tag: &str,
) -> String {
    let mut data = String::from("omega_rad_s,re_1_1,im_1_1");
    data += if noise_col.is_some() {
        ",noise_radius\n"
    } else {
        "\n"
    };
    for (w, re, im) in ROWS {
        data += &format!("{w},{re},{im}");
        data += &noise_col.map_or("\n".to_string(), |r| format!(",{r}\n"));
    }
    std::fs::write(dir.join("d.csv"), data).unwrap();
    std::fs::write(dir.join("m.toml"), cfg).unwrap();
    let out = dir.join(tag);
    let mut args = vec![
        "envelope".to_string(),
        dir.join("m.toml").display().to_string(),
        "--out".into(),
        out.display().to_string(),
    ];
    if let Some(x) = flag {
        args.extend(["--noise-radius".to_string(), x.to_string()]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = common::rshape(&args);
    assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    std::fs::read_to_string(out.join("envelope.csv")).unwrap()
}

fn r_min(csv: &str) -> Vec<f64> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn zero_noise_is_the_noise_free_envelope() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plain = envelope(d, SISO, None, None, "plain");
    let flag = envelope(d, SISO, None, Some("0"), "flag");
    let cfg = envelope(
        d,
        &format!("{SISO}[noise]\nradius = 0.0\n"),
        None,
        None,
        "cfg",
    );
    let col = envelope(d, SISO, Some(0.0), None, "col");
    assert_eq!(flag, plain);
    assert_eq!(cfg, plain);
    assert_eq!(col, plain);
    // The closed form, beyond A1 and finite.
    let r = r_min(&plain);
    let want = (21f64.hypot(10.0)) / (2f64.sqrt() * 101f64.sqrt());
    assert!((r[1] - want).abs() < 1e-12 * want, "{} vs {want}", r[1]);
    assert!(r[1] > (2.5f64).sqrt());

    // Any positive radius: Theorem 4, inf at the datum beyond A1, the same values below it
    // (up to the tiny noise and the bisection tolerance).
    let noisy = r_min(&envelope(d, SISO, None, Some("1e-12"), "noisy"));
    assert!(noisy[1].is_infinite(), "{noisy:?}");
    for k in [0, 2] {
        assert!((noisy[k] - r[k]).abs() <= 1e-8 * r[k], "{noisy:?} vs {r:?}");
    }
}

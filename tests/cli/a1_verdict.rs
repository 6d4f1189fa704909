//! Assumption A1 in the verdict (issue 24): an `r` with `|r(jω)| ≥ σ_min(M̃(jω))` at some
//! datum is not admissible there (Boulet & Francis 1998, A1 in Sec. II; the proofs of
//! Theorems 2 and 4 use it to keep `M̃ + Δ_M` invertible), so `check` must not say
//! "consistent" nor exit 0.  The A1 limit is cross-checked against the closed form of the
//! paper's eq. (19), independently of the factorization code.
use crate::common;

use common::{repo, rshape, stdout};

/// `σ_min(M̃(jω))` of eq. (19) in closed form: M̃ is diagonal, so its smallest singular
/// value is the smallest modulus of its diagonal entries.
fn sigma_min_eq19(w: f64) -> f64 {
    let s = num_complex::Complex64::new(0.0, w);
    let d = s * s + 41.2 * s + 40.2;
    [
        (4.1, 105.0),
        (36.1, 8228.6),
        (16.1, 1634.0),
        (90.8, 20116.0),
        (22.8, 1310.3),
    ]
    .iter()
    .map(|(a, b)| ((4.0 * s * s + a * s + b) / d).norm())
    .fold(f64::INFINITY, f64::min)
}

fn check_json(args: &[&str]) -> (Option<i32>, serde_json::Value) {
    let cfg = repo("configs/robot.toml");
    let mut all = vec!["check", cfg.to_str().unwrap(), "--json"];
    all.extend_from_slice(args);
    let o = rshape(&all);
    (o.status.code(), serde_json::from_str(&stdout(&o)).unwrap())
}

#[test]
fn paper_robot_r_breaks_a1_and_is_not_admissible() {
    let (code, rep) = check_json(&[]);
    assert_eq!(code, Some(1), "not admissible must not exit 0");
    assert_eq!(rep["verdict"], "not_admissible");
    assert_eq!(rep["consistent"], false);
    // μ_Γ > 1 everywhere: the data alone do not fail; A1 does.
    assert_eq!(rep["failing_omegas"], serde_json::json!([]));
    let rows = rep["rows"].as_array().unwrap();
    let mut fails = 0;
    for row in rows {
        let w = row["omega"].as_f64().unwrap();
        let lim = row["a1_limit"].as_f64().unwrap();
        let want = sigma_min_eq19(w);
        assert!(
            (lim - want).abs() <= 1e-9 * want,
            "ω = {w}: {lim} vs {want}"
        );
        // |r(jω)| of r = (5e-4 s + 75)/(s + 1), by hand.
        let r = (75.0f64.powi(2) + (5e-4 * w).powi(2)).sqrt() / (1.0 + w * w).sqrt();
        assert!((row["r_abs"].as_f64().unwrap() - r).abs() <= 1e-12 * r);
        let a1_ok = r < want;
        assert_eq!(row["a1_ok"], a1_ok, "ω = {w}");
        assert_eq!(row["consistent"], a1_ok, "ω = {w}: consistent needs A1");
        fails += usize::from(!a1_ok);
    }
    assert_eq!(fails, 205);
    // The numbers: |r(j1)| ≈ 53.03 against σ_min(M̃(j1)) ≈ 1.777.
    assert!((rows[0]["r_abs"].as_f64().unwrap() - 53.033).abs() < 1e-3);
    assert!((rows[0]["a1_limit"].as_f64().unwrap() - 1.7775).abs() < 1e-3);
}

#[test]
fn paper_robot_r_scaled_by_1e_minus_3_is_admissible_and_decides() {
    // r/1000 keeps |r| < σ_min(M̃) at every datum (the worst ratio |r|/σ_min of the printed
    // r is 145, at 5.07 rad/s), so Theorem 4 decides: inconsistent at two data near the
    // first mode, as the paper's Fig. 8 found the printed r inconsistent with its data.
    let (code, rep) = check_json(&["--r-num", "5e-7,0.075", "--r-den", "1,1"]);
    assert_eq!(code, Some(1));
    assert_eq!(rep["verdict"], "inconsistent");
    assert_eq!(rep["a1_violations"], serde_json::json!([]));
    assert!(!rep["failing_omegas"].as_array().unwrap().is_empty());
    // and a level above the envelope but below the A1 limit everywhere is consistent:
    let (code, rep) = check_json(&["--r-num", "0.05", "--r-den", "1"]);
    assert_eq!(code, Some(0));
    assert_eq!(rep["verdict"], "consistent");
}

#[test]
fn a1_on_a_dense_grid_paper_ratio() {
    // Independent of rshape: the largest |r|/σ_min(M̃) of the printed r over 0..∞ is about
    // 145 near the first mode (5.07 rad/s), where σ_min(M̃) dips to 0.0998 — no common
    // scale under 145 can make the printed r satisfy A1.
    let (mut worst, mut at) = (0.0, 0.0);
    for k in 0..=60_000 {
        let w = 10f64.powf(-3.0 + 7.0 * k as f64 / 60_000.0);
        let r = (75.0f64.powi(2) + (5e-4 * w).powi(2)).sqrt() / (1.0 + w * w).sqrt();
        let q = r / sigma_min_eq19(w);
        if q > worst {
            (worst, at) = (q, w);
        }
    }
    assert!((worst - 145.4).abs() < 0.5, "{worst}");
    assert!((at - 5.07).abs() < 0.05, "{at}");
}

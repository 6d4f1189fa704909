//! A fit that fails because A1 leaves `r` no or little room between two data names the gap
//! and what to change (it used to list the fit's candidates only, e.g. on the DaISy robot arm
//! with a lightly damped nominal mode).  The named `σ_min(M̃)` is checked against the closed
//! form of the normalized factors of a SISO plant, `σ_min(M̃(jω)) = 1/√(1 + |G(jω)|²)`.

use crate::common::{after, rshape, stderr, stdout};

/// `G = 1/(s² + 2ζs + 1)`, ζ = 1e-3: `|G(j1)|` = 500, so `σ_min(M̃(j1))` ≈ 0.002.
const PLANT: &str = "[plant]\ntf = [[{ num = [1], den = [1, 0.002, 1] }]]\n";

/// Data of `1.3/(s² + 0.02s + 1)` at four frequencies around the mode, none on it.
fn data() -> String {
    let mut s = String::from("omega_rad_s,re_1_1,im_1_1\n");
    for w in [0.5_f64, 0.9, 1.1, 2.0] {
        let (re, im) = (1.0 - w * w, 0.02 * w);
        let d = re * re + im * im;
        s += &format!("{w},{},{}\n", 1.3 * re / d, -1.3 * im / d);
    }
    s
}

fn sigma_min(w: f64) -> f64 {
    let (re, im) = (1.0 - w * w, 0.002 * w);
    let g2 = 1.0 / (re * re + im * im);
    1.0 / (1.0 + g2).sqrt()
}

#[test]
fn a_notch_of_a1_between_data_is_named_with_what_to_do() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("frf.csv"), data()).unwrap();
    let cfg = d.path().join("c.toml");
    std::fs::write(&cfg, format!("data = \"frf.csv\"\n{PLANT}")).unwrap();
    let out = d.path().join("o");
    let o = rshape(&[
        "fit",
        cfg.to_str().unwrap(),
        "--order",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("no r of any order can pass"), "{e}");
    assert!(
        e.contains("damp or move that mode, or rescale the plant's units"),
        "{e}"
    );
    // The gap is between the data at 0.9 and 1.1, and the σ_min(M̃) named there is the
    // closed form's, below the level that r must keep.
    assert!(e.contains("(data at 0.9 and 1.1 rad/s)"), "{e}");
    let h = &e[e.find("no r of any order can pass").unwrap()..];
    let (w, s) = (after(h, "at ω = "), after(h, "σ_min(M̃) = "));
    assert!(w > 0.9 && w < 1.1, "{e}");
    // Both numbers are printed to six decimals; σ_min changes by 2·Δω there.
    assert!((s - sigma_min(w)).abs() <= 3e-6, "{s} vs {}", sigma_min(w));
    assert!(s < after(h, "× the level "), "{e}");
    // `run` keeps going and reports the same reason in report.json and once on stdout.
    let o = rshape(&[
        "run",
        cfg.to_str().unwrap(),
        "--order",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    assert_eq!(
        text.matches("no r of any order can pass").count(),
        1,
        "{text}"
    );
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let said = rep["fit_error"].as_str().unwrap();
    assert!(said.starts_with("no r of any order can pass"), "{said}");
    // `fit` and `run` explain the failure in the same words (one builder).
    assert_eq!(e.trim().trim_start_matches("error: "), said);
}

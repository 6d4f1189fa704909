//! Closed-loop data through the ordinary subcommands (`check`, `run`, `batch`, `compare`):
//! the config decides open- or closed-loop.  Bad closed-loop input: a one-line error naming
//! the file/line or frequency, exit 2, nothing written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn cfg(name: &str) -> PathBuf {
    root().join("configs").join(name)
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn svg_text(p: &Path) -> String {
    let s = std::fs::read_to_string(p).unwrap();
    let doc = roxmltree::Document::parse(&s).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    doc.descendants()
        .filter(|n| n.is_text())
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join("\n")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn check_exit_codes_follow_the_weight_v() {
    let o = bin()
        .arg("check")
        .arg(cfg("closed_loop_same.toml"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // The tighter V of the retuned experiment fails at the flexible mode (48.96 rad/s).
    let o = bin()
        .args(["check", "--json"])
        .arg(cfg("closed_loop_retuned.toml"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let failing: Vec<f64> = rep["failing_omegas"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(
        failing.iter().any(|w| (w - 48.960801).abs() < 1e-4),
        "{failing:?}"
    );
    assert!(
        rep["rows"][0]["a1_limit"].is_null(),
        "no A1 limit in closed loop"
    );
}

#[test]
fn run_writes_the_closed_loop_report_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("noisy");
    let o = bin()
        .arg("run")
        .arg(cfg("closed_loop_retuned_noisy.toml"))
        .args(["--order", "3", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rep = json(&out.join("report.json"));
    assert_eq!(rep["method"], "closed_loop_theorem2");
    assert_eq!(rep["noisy"], true);
    let cl = &rep["closed_loop"];
    assert_eq!(cl["same_controller"], false);
    assert_eq!(cl["trivial_plant_factors"], false);
    assert_eq!(cl["data"].as_array().unwrap().len(), 160);
    let d = &cl["data"][60];
    assert_eq!(d["noisy"]["route"], "mu_bisection");
    // Noisy ≤ noise-free at every datum.
    for d in cl["data"].as_array().unwrap() {
        let v = d["noisy"]["v_min"].as_f64().unwrap();
        assert!(v <= d["delta_bar_norm"].as_f64().unwrap() * (1.0 + 1e-12));
    }
    // μ per datum is consistent with the check: μ > 1 ⇔ consistent.
    for p in rep["data_points"].as_array().unwrap() {
        let mu = p["mu"].as_f64().unwrap();
        let ok = p["consistent"].as_bool().unwrap();
        let ratio = p["r_configured_abs"].as_f64().unwrap() / p["r_min"].as_f64().unwrap_or(0.0);
        if (ratio - 1.0).abs() > 1e-6 {
            assert_eq!(mu > 1.0, ok, "{p}");
        }
    }
    assert_eq!(rep["r_fitted"]["certificate"]["passed"], true);
    let t = svg_text(&out.join("r_vs_delta.svg"));
    assert!(t.contains("Closed loop") && t.contains("Thm 2"), "{t}");
    assert!(svg_text(&out.join("mu.svg")).contains("μ_Δs"));
    assert!(!t.contains("A1 limit"));
    // The closed-loop Bode figure names the measured response Φ, never G.
    let b = svg_text(&out.join("bode.svg"));
    assert!(
        b.contains("|Φ(jω)|") && b.contains("nominal model Φ(jω)"),
        "{b}"
    );
    assert!(!b.contains("G(jω)"), "{b}");
    // The figures and the summary say V and |Δ̄| (the closed-loop names), never r or ‖Δ‖.
    let m = svg_text(&out.join("mu.svg"));
    for want in [
        "|Δ̄| per datum vs |V(jω)|",
        "|V(jω)|, configured V = ",
        "|V(jω)|, fitted V = ",
        "explained by the configured V",
        "FAILING, configured |V(jω)| ≤ |V|_min",
        "|V|_min = 0 at ",
    ] {
        assert!(t.contains(want), "r_vs_delta.svg lacks `{want}`:\n{t}");
    }
    for want in [
        "μ_Δs (dimensionless)",
        "μ_Δs per datum, configured V",
        "μ_Δs ≤ 1",
    ] {
        assert!(m.contains(want), "mu.svg lacks `{want}`:\n{m}");
    }
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("max |V|_min = ") && stdout.contains("  fit       V"),
        "{stdout}"
    );
    for text in [&t, &m, &stdout.to_string()] {
        for bad in [
            "configured r",
            "fitted r",
            "|r(jω)|",
            "r_min",
            "admissible r",
            "μ_Γ",
            "‖Δ",
            "Δ_V",
        ] {
            assert!(
                !text.contains(bad),
                "closed-loop output says `{bad}`:\n{text}"
            );
        }
    }
    // Noise-free: no μ figure.
    let out2 = dir.path().join("same");
    let o = bin()
        .arg("run")
        .arg(cfg("closed_loop_same.toml"))
        .args(["--order", "3", "--out"])
        .arg(&out2)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rep = json(&out2.join("report.json"));
    assert_eq!(rep["method"], "closed_loop_theorem1");
    assert_eq!(rep["consistent"], true);
    assert!(!out2.join("mu.svg").exists());
}

#[test]
fn batch_runs_closed_loop_datasets_and_reports_a_bad_one() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    std::fs::create_dir(&data).unwrap();
    let src = root().join("configs/data/closed_loop");
    for n in ["same", "retuned"] {
        std::fs::copy(src.join(format!("{n}.csv")), data.join(format!("{n}.csv"))).unwrap();
    }
    // R = 0 at one row: this dataset fails, the others go on.
    std::fs::write(
        data.join("zz_bad.csv"),
        "omega_rad_s,re_y,im_y,re_r,im_r\n1,0.1,0,1,0\n2,0.1,0,0,0\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = bin()
        .arg("batch")
        .arg(cfg("closed_loop_same.toml"))
        .arg("--data-dir")
        .arg(&data)
        .args(["--order", "2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    assert!(
        summary.contains("R(ω) = 0") || summary.contains("R(ω)"),
        "{summary}"
    );
    // Both good datasets have the same envelope (Δ̄ belongs to the plant, not the experiment)
    // — but this config has C̄ = C, so the retuned data are read with the wrong C̄ and differ.
    let a = std::fs::read_to_string(out.join("datasets/same/envelope.csv")).unwrap();
    let b = std::fs::read_to_string(out.join("datasets/retuned/envelope.csv")).unwrap();
    assert_ne!(a, b);
}

#[test]
fn compare_works_on_the_open_loop_equivalent() {
    let o = bin()
        .args(["compare", "--json"])
        .arg(cfg("closed_loop_same.toml"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // At 0.1 rad/s the plant recovered from Φ and C̄ is P₀ ≈ 1.15/s² = −115 (true plant of
    // examples/closed_loop_data.rs) and the nominal is P̂ = 1/s² = −100: misfit 0.13.
    let row = &rep["rows"][0];
    assert!((row["omega"].as_f64().unwrap() - 0.1).abs() < 1e-12);
    let d = [
        row["data"][0].as_f64().unwrap(),
        row["data"][1].as_f64().unwrap(),
    ];
    assert!((d[0] + 115.0).abs() < 0.01 && d[1].abs() < 0.1, "{row}");
    assert!(
        (row["model"][0].as_f64().unwrap() + 100.0).abs() < 1e-9,
        "{row}"
    );
    assert!(
        (row["misfit"].as_f64().unwrap() - 15.0 / 115.0).abs() < 1e-3,
        "{row}"
    );
}

fn bad(config: &str, data: Option<&str>) -> (Output, PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let c = dir.path().join("bad.toml");
    std::fs::write(&c, config).unwrap();
    if let Some(d) = data {
        std::fs::write(dir.path().join("d.csv"), d).unwrap();
    }
    let out = dir.path().join("out");
    let o = bin()
        .arg("run")
        .arg(&c)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    (o, out, dir)
}

const GOOD: &str = r#"data = "d.csv"
[closed_loop]
n_hat = [[{ num = [1], den = [1, 1] }]]
d_hat = [[{ num = [1, -1], den = [1, 1] }]]
controller = [[2]]
"#;

#[test]
fn bad_input_is_one_line_exit_2_and_writes_nothing() {
    let spectra_ok = "omega_rad_s,re_y,im_y,re_r,im_r\n1,0.5,0,1,0\n2,0.4,0.1,1,0\n";
    let cases: Vec<(String, Option<&str>, &[&str])> = vec![
        (
            GOOD.replace("controller = [[2]]", "controller = [[0.5]]"),
            Some(spectra_ok),
            &["bad.toml", "controller C does not stabilize"],
        ),
        (
            "data = \"d.csv\"\n[closed_loop]\nplant = [[{ num = [1], den = [1, -1] }]]\ncontroller = [[2]]\n".into(),
            Some(spectra_ok),
            &["bad.toml", "n_hat and d_hat"],
        ),
        (
            "data = \"d.csv\"\n[closed_loop]\nplant = [[{ num = [1], den = [1, 1] }]]\ncontroller = [[{ num = [1, 1], den = [1, -2] }]]\n".into(),
            Some(spectra_ok),
            &["bad.toml", "n_c and d_c"],
        ),
        (
            GOOD.into(),
            Some("omega_rad_s,re_y,im_y,re_r,im_r\n1,0.5,0,1,0\n2,0.4,0.1,0,0\n"),
            &["d.csv:3:", "R(ω) = 0"],
        ),
        (
            GOOD.into(),
            Some("omega_rad_s,re_y,im_y,re_r,im_r\n1,0.5,0,1,0\n2,0.4,0.1,1\n"),
            &["d.csv:3:", "4 fields"],
        ),
        (
            GOOD.into(),
            Some("omega_rad_s,re_1_1,im_1_1,re_1_2,im_1_2\n1,0.5,0,1,0\n"),
            &["d.csv", "1×2", "1×1"],
        ),
    ];
    for (config, data, want) in cases {
        let (o, out, _dir) = bad(&config, data);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        for w in want {
            assert!(err.contains(w), "`{w}` not in: {err}");
        }
        assert!(!out.exists(), "nothing may be written: {err}");
    }
}

#[test]
fn mimo_closed_loop_frf_runs_noise_free_and_refuses_noise() {
    let dir = tempfile::tempdir().unwrap();
    let config = r#"data = "d.csv"
[closed_loop]
plant = [[{ num = [2], den = [1, 1] }, { num = [0.5], den = [1, 3] }],
         [{ num = [0.3], den = [1, 2] }, { num = [1], den = [1, 0.5] }]]
controller = [[{ num = [3, 1], den = [1, 4] }, 0.2],
              [0.1, { num = [2], den = [0.1, 1] }]]
"#;
    let c = dir.path().join("mimo.toml");
    std::fs::write(&c, config).unwrap();
    // Data: the nominal closed loop of a plant with 10 % more gain on output 1.
    let model = rshape::model::Config::load(&c)
        .unwrap()
        .closed_loop
        .unwrap();
    let mut csv =
        String::from("omega_rad_s,re_1_1,im_1_1,re_1_2,im_1_2,re_2_1,im_2_1,re_2_2,im_2_2\n");
    for w in rshape::system::logspace(0.01, 100.0, 30) {
        let at = model.at(w).unwrap();
        let mut p = at.p_hat.clone();
        p.row_mut(0).scale_mut(1.1);
        let s = nalgebra::DMatrix::identity(2, 2) + &p * &at.c_bar;
        let phi = s.lu().solve(&p).unwrap();
        csv.push_str(&format!("{w}"));
        for i in 0..2 {
            for j in 0..2 {
                csv.push_str(&format!(",{},{}", phi[(i, j)].re, phi[(i, j)].im));
            }
        }
        csv.push('\n');
    }
    std::fs::write(dir.path().join("d.csv"), csv).unwrap();
    let out = dir.path().join("out");
    let o = bin()
        .arg("run")
        .arg(&c)
        .args(["--order", "2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rep = json(&out.join("report.json"));
    assert_eq!(rep["method"], "closed_loop_theorem1");
    assert_eq!(rep["size"], serde_json::json!([2, 2]));
    assert!(rep["max_r_min"].as_f64().unwrap() > 0.0);
    let out2 = dir.path().join("out2");
    let o = bin()
        .arg("run")
        .arg(&c)
        .args(["--noise-radius", "0.01", "--out"])
        .arg(&out2)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("SISO"), "{}", stderr(&o));
    assert!(!out2.exists());
}

#[test]
fn figure_symbols_follow_the_kind_of_data() {
    use rshape::plot::{mu_svg_with, r_vs_delta_svg_with, MuInput, RVsDeltaInput, Symbols};
    use rshape::system::TransferFunction;
    let dir = tempfile::tempdir().unwrap();
    let omega = [1.0, 2.0, 5.0, 10.0];
    let r_min = [0.1, 0.0, 0.5, f64::INFINITY];
    let failing = [false, false, true, true];
    let r = TransferFunction::new(vec![0.2, 0.1], vec![1.0, 1.0]);
    let grid: Vec<f64> = (0..50)
        .map(|k| 10f64.powf(-0.2 + k as f64 / 40.0))
        .collect();
    let texts = |sym: &Symbols| {
        let a = r_vs_delta_svg_with(
            &RVsDeltaInput {
                title: "t",
                omega: &omega,
                r_min: &r_min,
                r_min_label: "per datum",
                failing: &failing,
                a1_failing: &[],
                r_configured: Some(&r),
                r_fitted: Some(&r),
                grid: &grid,
                a1_on_grid: None,
            },
            sym,
        )
        .unwrap();
        let b = mu_svg_with(
            &MuInput {
                title: "t",
                omega: &omega,
                mu: &[3.0, 0.5, 1.2, 2.0],
                a1_failing: &[],
            },
            sym,
        )
        .unwrap();
        let (pa, pb) = (dir.path().join("a.svg"), dir.path().join("b.svg"));
        std::fs::write(&pa, a).unwrap();
        std::fs::write(&pb, b).unwrap();
        format!("{}\n{}", svg_text(&pa), svg_text(&pb))
    };
    let open = texts(&Symbols::OPEN_LOOP);
    let closed = texts(&Symbols::CLOSED_LOOP);
    for want in [
        "|r(jω)|, configured r",
        "|r(jω)|, fitted r",
        "configured |r(jω)| ≤ r_min",
        "r_min = ∞: no admissible r",
        "r_min = 0 at 1 data",
        "μ_Γ (dimensionless)",
        "μ_Γ per datum, configured r",
    ] {
        assert!(open.contains(want), "open loop lacks `{want}`:\n{open}");
    }
    for want in [
        "|V(jω)|, configured V",
        "|V(jω)|, fitted V",
        "configured |V(jω)| ≤ |V|_min",
        "|V|_min = ∞: no admissible V",
        "|V|_min = 0 at 1 data",
        "μ_Δs (dimensionless)",
        "μ_Δs per datum, configured V",
    ] {
        assert!(
            closed.contains(want),
            "closed loop lacks `{want}`:\n{closed}"
        );
    }
    for bad in ["configured r", "fitted r", "r_min", "μ_Γ", "admissible r"] {
        assert!(!closed.contains(bad), "closed loop says `{bad}`:\n{closed}");
    }
}

/// `fit` on a closed-loop config imposes A1 as `run` does (`pipeline::closed_loop::
/// a1_factorization`: not for closed-loop configs): the same `r.json`, byte for byte. Before,
/// `fit` imposed the open-loop factors' `σ_min(M̃)`, which vanishes at DC here, and `fit --order
/// 2` failed with "A1 fails … at ω = 1.000000e-3 rad/s" where `run --order 2` certified.
#[test]
fn fit_and_run_fit_a_closed_loop_config_alike() {
    let d = tempfile::tempdir().unwrap();
    let cfg = crate::common::repo("configs/closed_loop_same.toml");
    let mut json = Vec::new();
    for cmd in ["fit", "run"] {
        let out = d.path().join(cmd);
        let o = crate::common::rshape(&[
            cmd,
            cfg.to_str().unwrap(),
            "--order",
            "2",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{cmd}: {}",
            crate::common::stderr(&o)
        );
        json.push(std::fs::read_to_string(out.join("r.json")).unwrap());
    }
    assert_eq!(json[0], json[1]);
    let r: serde_json::Value = serde_json::from_str(&json[0]).unwrap();
    assert_eq!(r["certificate"]["passed"], true);
}

//! `[scaling]` from the command line: bad values refused in one line naming the key (exit
//! 2), `run` and its files say that r refers to the scaled plant, and `synthesize` writes the
//! controller of the plant itself, `K = D_i·K_s·D_o`, with `K_s` the controller a config
//! scaled by hand gives.

use crate::common::{repo, rshape, stderr, stdout};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::path::{Path, PathBuf};

const PLANT: &str = "[plant]\ntf = [[{ num = [1], den = [1, 1, 0] }]]\n";

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Every bad `[scaling]`: exit 2, one line on stderr, the key and what to do named.
#[test]
fn bad_scalings_exit_2_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let data = repo("configs/plant_first.csv");
    let cases: &[(&str, &str, &str)] = &[
        (
            "zero",
            "[scaling]\noutputs = [0]\n",
            "[scaling] outputs[1] = 0: every scaling must be a positive finite number",
        ),
        (
            "negative",
            "[scaling]\ninputs = [-2]\n",
            "[scaling] inputs[1] = -2: every scaling must be a positive finite number",
        ),
        (
            "infinite",
            "[scaling]\ninputs = [inf]\n",
            "[scaling] inputs[1] = inf",
        ),
        (
            "length",
            "[scaling]\noutputs = [1, 2]\n",
            "[scaling] outputs has 2 entries, the plant has 1 outputs: give one positive number per output",
        ),
        (
            "keyword",
            "scaling = \"automatic\"\n",
            "scaling = \"automatic\": write scaling = \"auto\"",
        ),
        (
            "unknown key",
            "[scaling]\noutput = [1]\n",
            "unknown field",
        ),
    ];
    for (what, scaling, want) in cases {
        // A top-level key must precede the tables.
        let text = if scaling.starts_with('[') {
            format!("data = \"{}\"\n{PLANT}{scaling}", data.display())
        } else {
            format!("data = \"{}\"\n{scaling}{PLANT}", data.display())
        };
        let cfg = write(dir.path(), "bad.toml", &text);
        let out = rshape(&[
            "envelope",
            cfg.to_str().unwrap(),
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{what}: {err}");
        assert_eq!(err.lines().count(), 1, "{what}: {err}");
        assert!(err.contains(want), "{what}: {err}");
        assert!(err.contains("bad.toml"), "{what}: {err}");
    }
    // "auto" needs a [plant].
    let model = "scaling = \"auto\"\n[model]\nfactorization = \"standard\"\nm = [[{ num = [1, 2], den = [1, 1] }]]\nn = [[{ num = [1], den = [1, 1] }]]\n";
    let cfg = write(dir.path(), "auto_model.toml", model);
    let out = rshape(&[
        "check",
        cfg.to_str().unwrap(),
        "--data",
        data.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("scaling = \"auto\" needs the model as a [plant]"));
    // A [physical] model takes [scaling] (session 13; it was refused): its factorization
    // takes it in C and J, so its envelope (Theorem 3) is the unscaled one.
    let physical = std::fs::read_to_string(repo("configs/robot_physical.toml")).unwrap();
    let scaled = write(
        dir.path(),
        "phys.toml",
        &format!("{physical}\n[scaling]\noutputs = [2]\ninputs = [0.3]\n"),
    );
    let plain = write(dir.path(), "phys_plain.toml", &physical);
    let mut envelopes = Vec::new();
    for (cfg, name) in [(&plain, "e_plain"), (&scaled, "e_scaled")] {
        let out_dir = dir.path().join(name);
        let out = rshape(&[
            "envelope",
            cfg.to_str().unwrap(),
            "--data",
            repo("configs/robot.csv").to_str().unwrap(),
            "--noise-radius",
            "0",
            "--out",
            out_dir.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let text = std::fs::read_to_string(out_dir.join("envelope.csv")).unwrap();
        let r: Vec<f64> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
            .collect();
        envelopes.push(r);
    }
    assert!(envelopes[0].iter().any(|x| *x > 0.0));
    for (a, b) in envelopes[0].iter().zip(&envelopes[1]) {
        assert!((a - b).abs() <= 1e-9 * a.abs().max(b.abs()), "{a} vs {b}");
    }
    let cl = std::fs::read_to_string(repo("configs/closed_loop_retuned_noisy.toml")).unwrap();
    let cl = cl.replace(
        "data = \"",
        &format!("data = \"{}/", repo("configs").display()),
    );
    let cfg = write(
        dir.path(),
        "cl.toml",
        &format!("{cl}\n[scaling]\noutputs = [2]\n"),
    );
    let out = rshape(&["check", cfg.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("not a [closed_loop] model"), "{err}");
}

/// `run` with `scaling = "auto"` says the scalings and the line to copy; `r.json` and
/// `report.json` carry them; the copied line gives the same envelope as "auto".
#[test]
fn run_reports_the_scaling_and_the_auto_values_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let data = repo("configs/plant_first.csv");
    // 1/(s(s+1)), the model of the data: peak gain about 10 on the model's band.
    let text = format!(
        "data = \"{}\"\nscaling = \"auto\"\n[plant]\ntf = [[{{ num = [1], den = [1, 1, 0] }}]]\n",
        data.display()
    );
    let cfg = write(dir.path(), "auto.toml", &text);
    let out_dir = dir.path().join("out");
    let out = rshape(&[
        "run",
        cfg.to_str().unwrap(),
        "--order",
        "2",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let so = stdout(&out);
    assert!(
        matches!(out.status.code(), Some(0) | Some(1)),
        "{}",
        stderr(&out)
    );
    let line = so
        .lines()
        .find(|l| l.trim_start().starts_with("scaling"))
        .unwrap_or_else(|| panic!("no scaling line: {so}"));
    assert!(
        line.contains("(auto)") && line.contains("G_s = D_o·G·D_i"),
        "{line}"
    );
    let copy = so
        .lines()
        .find_map(|l| {
            l.split_once("replace scaling = \"auto\" by: ")
                .map(|x| x.1.to_string())
        })
        .unwrap_or_else(|| panic!("no line to copy: {so}"));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("report.json")).unwrap())
            .unwrap();
    let s = &report["scaling"];
    assert_eq!(s["auto"], serde_json::Value::Bool(true), "{s}");
    let d_o = s["outputs"][0].as_f64().unwrap();
    let d_i = s["inputs"][0].as_f64().unwrap();
    // SISO auto: d_o = d_i = 1/√(peak gain), the peak of 1/|jω(jω+1)| at the grid's first
    // point, a decade below the slowest nonzero pole (1 rad/s): 1/(0.1·√1.01).
    let peak = 1.0 / (0.1 * (1.0f64 + 0.01).sqrt());
    assert!((d_o * peak.sqrt() - 1.0).abs() < 5e-3 && d_o == d_i, "{s}");
    assert!(s["r_refers_to"].as_str().unwrap().contains("scaled plant"));
    assert!(out_dir.join("r.json").exists(), "the fit failed: {so}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("r.json")).unwrap()).unwrap();
    assert_eq!(&r["scaling"], s);
    for (f, c) in [("r.m", "% "), ("r.py", "# "), ("r.jl", "# ")] {
        let text = std::fs::read_to_string(out_dir.join(f)).unwrap();
        assert!(
            text.starts_with(&format!(
                "{c}r refers to the scaled plant G_s = D_o*G*D_i, D_o = diag("
            )),
            "{f}: {text}"
        );
    }
    // The copied line in place of "auto": the same envelope, datum for datum.
    let fixed = write(
        dir.path(),
        "fixed.toml",
        &text.replace("scaling = \"auto\"", &copy),
    );
    let env = |c: &Path, o: &str| {
        let d = dir.path().join(o);
        let out = rshape(&[
            "envelope",
            c.to_str().unwrap(),
            "--out",
            d.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read_to_string(d.join("envelope.csv")).unwrap()
    };
    assert_eq!(env(&cfg, "e1"), env(&fixed, "e2"));
    // Without [scaling] the envelope differs (normalized factors of another plant).
    let plain = write(
        dir.path(),
        "plain.toml",
        &text.replace("scaling = \"auto\"\n", ""),
    );
    assert_ne!(env(&cfg, "e3"), env(&plain, "e4"));
}

/// `C(jωI − A)⁻¹B + D` of a controller.json.
fn response(path: &Path, w: f64) -> DMatrix<Complex64> {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let m = |k: &str| {
        let rows = v[k].as_array().unwrap();
        let cols = rows.first().map_or(0, |r| r.as_array().unwrap().len());
        DMatrix::from_fn(rows.len(), cols, |i, j| {
            Complex64::new(rows[i][j].as_f64().unwrap(), 0.0)
        })
    };
    let (a, b, c, d) = (m("A"), m("B"), m("C"), m("D"));
    if a.nrows() == 0 {
        return d;
    }
    let lhs = DMatrix::<Complex64>::identity(a.nrows(), a.nrows()) * Complex64::new(0.0, w) - a;
    c * lhs.lu().solve(&b).unwrap() + d
}

/// `synthesize` on a scaled config writes `K = D_i·K_s·D_o`, `K_s` being what synthesize
/// gives for the plant scaled by hand (frequency responses compared at five points); and
/// `stability` on the scaled config with that file proves the same margin.
#[test]
fn synthesize_writes_the_controller_of_the_unscaled_plant() {
    let dir = tempfile::tempdir().unwrap();
    let (d_o, d_i) = ([0.01, 0.5], [4.0, 0.25]);
    let (keyed, hand) = crate::common::scaling_plant_pair(d_o, d_i);
    let keyed = write(dir.path(), "keyed.toml", &keyed);
    let hand = write(dir.path(), "hand.toml", &hand);
    let synth = |cfg: &Path, out: &str| {
        let o = dir.path().join(out);
        let r = rshape(&[
            "synthesize",
            cfg.to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
        ]);
        assert!(
            matches!(r.status.code(), Some(0) | Some(1)),
            "{}",
            stderr(&r)
        );
        o
    };
    let k_dir = synth(&keyed, "k");
    let ks_dir = synth(&hand, "ks");
    for w in [0.01, 0.3, 1.0, 7.0, 100.0] {
        let k = response(&k_dir.join("controller.json"), w);
        let ks = response(&ks_dir.join("controller.json"), w);
        // K is inputs × outputs: K_jk = d_i,j · (K_s)_jk · d_o,k.
        for j in 0..2 {
            for kk in 0..2 {
                let want = ks[(j, kk)] * d_i[j] * d_o[kk];
                let got = k[(j, kk)];
                let scale = k.iter().map(|z| z.norm()).fold(0.0, f64::max);
                assert!(
                    (got - want).norm() <= 1e-6 * scale,
                    "omega {w}, entry ({j},{kk}): {got} vs {want}"
                );
            }
        }
    }
    // The written controller, read back with the scaled config: the synthesized margin.
    let syn: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(k_dir.join("synthesis.json")).unwrap())
            .unwrap();
    let st = rshape(&[
        "stability",
        keyed.to_str().unwrap(),
        "--controller",
        k_dir.join("controller.toml").to_str().unwrap(),
        "--json",
    ]);
    assert!(
        matches!(st.status.code(), Some(0) | Some(1)),
        "{}",
        stderr(&st)
    );
    let st: serde_json::Value = serde_json::from_str(&stdout(&st)).unwrap();
    let b_syn = syn["b_gk"]
        .as_f64()
        .or_else(|| syn["stability"]["b_gk"].as_f64());
    let b_st = st["b_gk"].as_f64().unwrap();
    let b_syn = b_syn.unwrap_or_else(|| panic!("no b_gk in synthesis.json: {syn}"));
    assert!((b_syn - b_st).abs() <= 1e-6 * b_st, "{b_syn} vs {b_st}");
}

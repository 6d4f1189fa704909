//! Every shipped config, every model kind (`[physical]`, `[model]` factor forms, `[plant]`,
//! `[closed_loop]`): `compare` runs on every channel of its data (it needs only G(jω)), and
//! `diagnose` on every config that is not `[physical]` says in one line which way it went:
//! "converted to [physical]" (a modal special factorization), or exit 2 with "cannot be
//! converted (REASON)".

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn rshape(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(args)
        .output()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The shipped configs, sorted.
fn configs() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir("configs")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    v
}

fn is_controller(p: &Path) -> bool {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .any(|l| l.trim() == "[controller]")
}

/// The model kind a config chooses.
fn kind(p: &Path) -> &'static str {
    let s = std::fs::read_to_string(p).unwrap();
    for k in ["physical", "model", "plant", "closed_loop"] {
        if s.lines().any(|l| l.trim() == format!("[{k}]")) {
            return k;
        }
    }
    panic!("{}: no model table", p.display())
}

/// Extra arguments: the data of a config that names none.
fn extra(p: &Path) -> Vec<&'static str> {
    match p.file_name().unwrap().to_str().unwrap() {
        "robot_physical.toml" => vec!["--data", "configs/robot.csv"],
        _ => vec![],
    }
}

/// `(outputs, inputs)` from "the data are 2×3: choose the SISO channel".
fn dims(err: &str) -> Option<(usize, usize)> {
    let at = err.find("the data are ")? + "the data are ".len();
    let rest = &err[at..];
    let (o, rest) = rest.split_once('×')?;
    let i: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    Some((o.parse().ok()?, i.parse().ok()?))
}

/// The channels to run a config on: none (its own) for SISO data, else every one.
fn channels(cfg: &str, extra: &[&str]) -> Vec<Option<String>> {
    let mut args = vec!["compare", cfg];
    args.extend(extra);
    let out = rshape(&args);
    if out.status.success() {
        return vec![None];
    }
    let err = text(&out.stderr);
    let (o, i) = dims(&err).unwrap_or_else(|| panic!("{cfg}: {err}"));
    // A load over 5 s prints a progress notice before the error (a busy machine: ISS).
    let error_lines = err.lines().filter(|l| !l.starts_with("loading ")).count();
    assert!(
        err.contains("--channel OUT,IN") && error_lines == 1,
        "{err}"
    );
    (1..=o)
        .flat_map(|a| (1..=i).map(move |b| Some(format!("{a},{b}"))))
        .collect()
}

#[test]
fn compare_runs_on_every_config_and_every_channel() {
    let mut kinds = std::collections::BTreeMap::new();
    for p in configs() {
        let cfg = p.to_str().unwrap();
        if is_controller(&p) {
            // A controller file is not a model config: one line, exit 2.
            let out = rshape(&["compare", cfg]);
            assert_eq!(out.status.code(), Some(2), "{cfg}");
            assert_eq!(text(&out.stderr).lines().count(), 1, "{cfg}");
            continue;
        }
        *kinds.entry(kind(&p)).or_insert(0) += 1;
        let ex = extra(&p);
        for ch in channels(cfg, &ex) {
            let mut args = vec!["compare", cfg, "--json"];
            args.extend(&ex);
            if let Some(c) = &ch {
                args.extend(["--channel", c]);
            }
            let out = rshape(&args);
            assert!(out.status.success(), "{cfg} {ch:?}: {}", text(&out.stderr));
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            let rms = v["misfit_rms"].as_f64().unwrap();
            assert!(rms.is_finite() && rms >= 0.0, "{cfg} {ch:?}: {rms}");
        }
    }
    println!("{kinds:?}");
    // Every model kind is covered by the shipped configs.
    for k in ["physical", "model", "plant", "closed_loop"] {
        assert!(kinds.get(k).is_some_and(|n| *n >= 2), "{k}: {kinds:?}");
    }
}

#[test]
fn diagnose_on_every_factor_form_says_which_way_it_went() {
    let (mut converted, mut refused) = (Vec::new(), Vec::new());
    for p in configs() {
        if is_controller(&p) || kind(&p) == "physical" {
            continue;
        }
        let cfg = p.to_str().unwrap();
        let ch = channels(cfg, &[]).remove(0);
        let mut args = vec!["diagnose", cfg, "--max-effects", "1", "--beam", "1"];
        if let Some(c) = &ch {
            args.extend(["--channel", c]);
        }
        let out = rshape(&args);
        let (so, se) = (text(&out.stdout), text(&out.stderr));
        let first = so.lines().next().unwrap_or("");
        if first.contains("converted to [physical]") {
            assert!(
                first.contains(cfg) && first.contains("effects are added to that form"),
                "{cfg}: {so}"
            );
            // Then it runs, or stops on the data in one line (noise-free data have no
            // noise radius to diagnose with).
            match out.status.code() {
                Some(0) => {}
                Some(2) => assert!(
                    se.lines().count() == 1 && se.contains("diagnose needs the noise radius"),
                    "{cfg}: {se}"
                ),
                c => panic!("{cfg}: exit {c:?}: {se}"),
            }
            converted.push(cfg.to_string());
        } else {
            assert_eq!(out.status.code(), Some(2), "{cfg}: {so}");
            assert_eq!(se.lines().count(), 1, "{cfg}: {se}");
            assert!(
                se.contains("cannot be converted (") && se.contains(cfg),
                "{cfg}: {se}"
            );
            refused.push(cfg.to_string());
        }
    }
    println!("converted {converted:?}\nrefused {refused:?}");
    for c in [
        "configs/robot.toml",
        "configs/plant_first.toml",
        "configs/closed_loop_retuned_noisy.toml",
    ] {
        assert!(converted.contains(&c.to_string()), "{c}: {converted:?}");
    }
    for c in ["configs/paper_mimo.toml", "configs/iss1r_reduced.toml"] {
        assert!(refused.contains(&c.to_string()), "{c}: {refused:?}");
    }
}

/// A converted closed-loop config is written back with the nominal as [physical] (the
/// controllers kept in [closed_loop]); the revision loads, compares and is better.
#[test]
fn a_converted_closed_loop_config_is_written_as_physical() {
    let dir = tempfile::tempdir().unwrap();
    let new = dir.path().join("rev1.toml");
    let new_s = new.to_str().unwrap();
    let cfg = "configs/closed_loop_retuned_noisy.toml";
    let out = rshape(&[
        "diagnose",
        cfg,
        "--max-effects",
        "1",
        "--apply",
        "1",
        "--write",
        new_s,
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let written = std::fs::read_to_string(&new).unwrap();
    assert!(written.contains("[[physical.rigid_body]]") && written.contains("[closed_loop]"));
    assert!(
        !written.contains("n_hat") && !written.contains("d_hat"),
        "{written}"
    );
    let rms = |c: &str| -> f64 {
        let out = rshape(&["compare", c, "--json"]);
        assert!(out.status.success(), "{c}: {}", text(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["misfit_rms"].as_f64().unwrap()
    };
    let (before, after) = (rms(cfg), rms(new_s));
    println!("{cfg}: misfit_rms {before} -> {after}");
    assert!(after < 0.5 * before, "{before} -> {after}");
}

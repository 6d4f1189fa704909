//! Issue 20, defect 2: `--apply K` refuses a candidate the tool rejected (one-line reason,
//! exit 2, nothing written) unless `--force`; `--apply chosen` writes the chosen set,
//! jointly refit, in one revision.  On the motor bench (configs/twomass_rigid.toml), whose
//! chosen set is mode + friction + delay.

use rshape::data::read_frf_csv;
use rshape::diagnose::{compare, prepare, PlantModel};
use rshape::model::Config;
use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

const CONFIG: &str = "configs/twomass_rigid.toml";

fn diagnose(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(["diagnose", CONFIG, "--json"])
        .args(args)
        .arg("--write")
        .arg(out)
        .output()
        .unwrap()
}

fn misfit(config: &Path) -> (f64, f64) {
    let c = Config::load(config).unwrap();
    let d = read_frf_csv(c.data.as_ref().unwrap()).unwrap();
    let s = prepare(&c, &d, None, None).unwrap();
    let r = compare(&c, &PlantModel::from_config(&c), &s).unwrap();
    (r.misfit_rms, r.invalid_fraction.unwrap())
}

#[test]
fn a_rejected_candidate_is_refused_unless_forced_and_the_chosen_set_is_written() {
    let dir = tempfile::tempdir().unwrap();
    // The chosen set, in one revision.
    let chosen = dir.path().join("chosen.toml");
    let out = diagnose(&["--apply", "chosen"], &chosen);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let d: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(d["verdict"], "effects_found");
    let mut set: Vec<&str> = d["chosen"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    set.sort();
    assert_eq!(set, ["delay", "friction", "mode"]);
    let text = std::fs::read_to_string(&chosen).unwrap();
    assert!(text.contains("--apply chosen"), "{text}");
    let c = Config::load(&chosen).unwrap();
    let p = c.physical.as_ref().unwrap();
    // Every chosen effect is in the revision: the mode, the delay, the friction pole.
    assert_eq!(p.mode.len(), 1);
    assert!(p.rigid_body[0].friction_pole.is_some());
    assert_eq!(p.effect.len(), 1);
    let fe = &d["final_effects"];
    let mode = fe
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["effect"] == "mode");
    let wn = mode.unwrap()["params"]["omega_n"].as_f64().unwrap();
    assert!((p.mode[0].omega_n - wn).abs() < 1e-9 * wn);
    // Its error, by `compare` (an independent route), is the diagnosis' final error, and
    // better than any single candidate's.
    let (rms, inv) = misfit(&chosen);
    let after = d["after"]["misfit_rms"].as_f64().unwrap();
    assert!(
        (rms - after).abs() < 0.02 * after,
        "compare {rms}, diagnose {after}"
    );
    assert!((inv - d["after"]["invalid_fraction"].as_f64().unwrap()).abs() < 0.01);
    let best_single = d["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|c| c["misfit_rms_after"].as_f64())
        .fold(f64::INFINITY, f64::min);
    assert!(rms < best_single, "chosen {rms}, best single {best_single}");

    // A rejected candidate (a plausibility flag) is refused, nothing is written.
    let cands = d["candidates"].as_array().unwrap();
    let (k, rej) = cands
        .iter()
        .enumerate()
        .find(|(_, c)| c["passes"] == false && c["no_fit"].is_null())
        .map(|(i, c)| (i + 1, c))
        .expect("a rejected candidate");
    let refused = dir.path().join("refused.toml");
    let out = diagnose(&["--apply", &k.to_string()], &refused);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("rejected") && err.contains("--force"), "{err}");
    let effect = rej["effect"].as_str().unwrap();
    assert!(err.contains(effect), "{err}");
    assert!(!refused.exists());
    // With --force it is written.
    let out = diagnose(&["--apply", &k.to_string(), "--force"], &refused);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::read_to_string(&refused)
        .unwrap()
        .contains(&format!("--apply {k} --force")));
}

#[test]
fn apply_takes_a_rank_or_chosen() {
    let out = Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(["diagnose", CONFIG, "--apply", "best", "--write", "x.toml"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`chosen`"));
}

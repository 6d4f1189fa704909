//! Issue 33 (stop 44's review): when the final holdout drops part of the chosen set, the
//! chosen path the report prints is the path of the set kept.  On the pyfrf chain at
//! `--max-effects 2` (`tests/data/pyfrf_rev2.toml`, the mass line and three modes), the
//! search chooses two modes (823.5 and 923 Hz) and the holdout drops the first; the report
//! then printed "step 2: + mode" with no step 1 and the figures of the refit that still held
//! the dropped mode, listed the refused two-mode set twice among the runner-ups (once per
//! order of adding) and called "mode" and "mode + mode" a tie at a BIC gap of 2.8e-7 (the
//! refused set against its own re-ordering).

use crate::common::repo;
use serde_json::Value;
use std::process::Command;

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn a_holdout_drop_leaves_a_path_numbered_from_one_with_the_kept_refit() {
    let o = Command::new(env!("CARGO_BIN_EXE_rshape"))
        .arg("diagnose")
        .arg(repo("tests/data/pyfrf_rev2.toml"))
        .args(["--max-effects", "2", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let d: Value = serde_json::from_slice(&o.stdout).unwrap();
    // The premise: the holdout dropped a mode of the chosen set and kept the rest.
    let dropped = d["dropped"].as_array().unwrap();
    assert_eq!(
        dropped.len(),
        1,
        "premise: one effect dropped: {}",
        d["message"]
    );
    let chosen: Vec<&str> = d["chosen"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert_eq!(chosen, ["mode"], "{}", d["message"]);
    // The path: numbered from 1 without gaps, one step per chosen effect.
    let steps = d["steps"].as_array().unwrap();
    assert_eq!(steps.len(), chosen.len());
    let mut prev = 0;
    for s in steps {
        let k = s["step"].as_u64().unwrap();
        assert!(k == prev || k == prev + 1, "step {k} after step {prev}");
        prev = k;
    }
    assert_eq!(steps[0]["step"].as_u64(), Some(1));
    // Its last step is the model kept: the mode it adds is the final model's added mode
    // (0.1 % in ω_n), and its figures are the kept refit's (the final refit of the dampings
    // may lower misfit_rms a little more, never raise it), not the two-mode refit's.
    let last = steps.last().unwrap();
    let w_step = f(&last["params"]["omega_n"]);
    let w_final = f(&d["final_effects"][0]["params"]["omega_n"]);
    assert!(
        (w_step / w_final - 1.0).abs() < 1e-3,
        "{w_step} vs {w_final}"
    );
    let (rms_step, rms_after) = (f(&last["misfit_rms"]), f(&d["after"]["misfit_rms"]));
    assert!(
        rms_after <= rms_step * (1.0 + 1e-9) && rms_after > 0.9 * rms_step,
        "step {rms_step} vs after {rms_after}"
    );
    // No runner-up twice (the same modes added in another order are the same set) and not
    // the set the holdout refused (two modes with the dropped one's figures).
    let sets = d["runner_up"].as_array().unwrap();
    for (i, a) in sets.iter().enumerate() {
        for b in &sets[i + 1..] {
            let same = a["effects"] == b["effects"]
                && (f(&a["misfit_rms"]) / f(&b["misfit_rms"]) - 1.0).abs() < 1e-6;
            assert!(!same, "runner-up listed twice: {a} / {b}");
        }
    }
    // A set tie compares sets of as many effects, never the kept set with the refused one.
    for t in d["ties"].as_array().unwrap() {
        let n = |k: usize| t["effects"][k].as_str().unwrap().split(" + ").count();
        assert_eq!(n(0), n(1), "{t}");
        assert!(f(&t["bic_gap"]) > 1e-3, "a tie of a set with itself: {t}");
    }
}

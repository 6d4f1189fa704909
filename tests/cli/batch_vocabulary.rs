//! `rshape batch` and `rshape merge` print the vocabulary of their data: `V` and `|V|_min`
//! for closed-loop data (Crowder & de Callafon), `r` and `r_min` for open-loop data, as the
//! figures and `rshape run` do (`plot::Symbols`).
use crate::common;

use common::{repo, rshape, stderr, stdout};

/// Two datasets of the closed-loop servo (`configs/closed_loop_same.toml`).
fn closed_loop_datasets() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(repo("configs/data/closed_loop/same.csv")).unwrap();
    std::fs::write(dir.path().join("a.csv"), &src).unwrap();
    std::fs::write(dir.path().join("b.csv"), &src).unwrap();
    dir
}

fn assert_closed_loop_words(text: &str) {
    for want in [
        "configured V explains",
        "max |V|_min = ",
        "fitted V covering",
    ] {
        assert!(text.contains(want), "missing {want:?} in:\n{text}");
    }
    for wrong in ["configured r ", "r_min", "fitted r "] {
        assert!(!text.contains(wrong), "{wrong:?} in:\n{text}");
    }
}

#[test]
fn closed_loop_batch_and_merge_say_v() {
    let data = closed_loop_datasets();
    let out = tempfile::tempdir().unwrap();
    let cfg = repo("configs/closed_loop_same.toml");
    let run = |extra: &[&str], dir: &str| {
        let o = out.path().join(dir);
        let mut args = vec![
            "batch",
            cfg.to_str().unwrap(),
            "--data-dir",
            data.path().to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
            "--order",
            "2",
        ];
        args.extend(extra);
        let r = rshape(&args);
        (r, o)
    };
    let (r, whole) = run(&[], "whole");
    assert_eq!(r.status.code(), Some(0), "{}{}", stdout(&r), stderr(&r));
    assert_closed_loop_words(&stdout(&r));
    let batch: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(whole.join("batch.json")).unwrap()).unwrap();
    assert_eq!(batch["closed_loop"], true);

    let (r0, s0) = run(&["--shard", "0/2"], "s0");
    let (r1, s1) = run(&["--shard", "1/2"], "s1");
    assert_eq!(r0.status.code(), Some(0), "{}", stderr(&r0));
    assert_eq!(r1.status.code(), Some(0), "{}", stderr(&r1));
    let merged = out.path().join("merged");
    let m = rshape(&[
        "merge",
        s0.to_str().unwrap(),
        s1.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
        "--order",
        "2",
    ]);
    assert_eq!(m.status.code(), Some(0), "{}{}", stdout(&m), stderr(&m));
    assert_closed_loop_words(&stdout(&m));
}

#[test]
fn open_loop_batch_says_r() {
    let data = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(repo("configs/paper_mimo.csv")).unwrap();
    std::fs::write(data.path().join("a.csv"), &src).unwrap();
    let out = tempfile::tempdir().unwrap();
    let o = out.path().join("o");
    let r = rshape(&[
        "batch",
        repo("configs/paper_mimo.toml").to_str().unwrap(),
        "--data-dir",
        data.path().to_str().unwrap(),
        "--out",
        o.to_str().unwrap(),
        "--order",
        "1",
    ]);
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    let text = stdout(&r);
    for want in ["configured r explains", "max r_min = ", "fitted r covering"] {
        assert!(text.contains(want), "missing {want:?} in:\n{text}");
    }
    // The output folder is a random temporary name that may itself hold a `V`.
    let words = text.replace(o.to_str().unwrap(), "<out>");
    assert!(!words.contains("V"), "{text}");
    let batch: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o.join("batch.json")).unwrap()).unwrap();
    assert_eq!(batch["closed_loop"], false);
}

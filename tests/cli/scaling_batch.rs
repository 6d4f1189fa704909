//! `[scaling]` in `batch`: `r.json`, `batch.json` and each `datasets/NAME/result.json` carry
//! the same `scaling` entry as `run`'s `r.json` and `report.json`, and a scaled config's
//! JSON files keep the key order of an unscaled one (the `scaling` entry inserted at one
//! place), rather than coming out sorted.

use crate::common::{repo, rshape, stderr, stdout};
use serde_json::Value;
use std::path::Path;

/// The top-level keys of a pretty-printed JSON object, in the order of the text (a parse
/// into `serde_json::Value` would sort them).
fn top_keys(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix("  \""))
        .filter_map(|l| l.split_once("\":").map(|x| x.0.to_string()))
        .collect()
}

/// `keys` with `key` inserted before `before`.
fn with_key(keys: &[String], key: &str, before: &str) -> Vec<String> {
    let at = keys
        .iter()
        .position(|k| k == before)
        .unwrap_or_else(|| panic!("no {before} in {keys:?}"));
    let mut v = keys.to_vec();
    v.insert(at, key.to_string());
    v
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn json(p: &Path) -> Value {
    serde_json::from_str(&read(p)).unwrap()
}

/// Runs `rshape ARGS` and asserts exit 0 or 1 (a verdict, not an error).
fn ok(args: &[&str]) -> String {
    let out = rshape(args);
    assert!(
        matches!(out.status.code(), Some(0) | Some(1)),
        "{args:?}: {}",
        stderr(&out)
    );
    stdout(&out)
}

/// One batch and one run over the same data with the same scaled config: the same
/// `scaling` entry everywhere, the controller-independent note in `r.m`; the key order of
/// `r.json`, `report.json`, `batch.json` and `result.json` is that of the unscaled config
/// with `scaling` inserted (before `order`, after `data`, after `config_digest`, after
/// `path`).
#[test]
fn batch_notes_the_scaling_as_run_does_in_the_unscaled_key_order() {
    let dir = tempfile::tempdir().unwrap();
    let data = repo("configs/plant_first.csv");
    let data_dir = dir.path().join("data");
    std::fs::create_dir(&data_dir).unwrap();
    std::fs::copy(&data, data_dir.join("first.csv")).unwrap();
    let plant = "[plant]\ntf = [[{ num = [1], den = [1, 1, 0] }]]\n";
    let scaled = format!("data = \"{}\"\nscaling = \"auto\"\n{plant}", data.display());
    let plain = format!("data = \"{}\"\n{plant}", data.display());
    let mut outs = Vec::new();
    for (name, text) in [("scaled", &scaled), ("plain", &plain)] {
        let cfg = dir.path().join(format!("{name}.toml"));
        std::fs::write(&cfg, text).unwrap();
        let run = dir.path().join(format!("run_{name}"));
        let batch = dir.path().join(format!("batch_{name}"));
        let cfg = cfg.to_str().unwrap();
        let so = ok(&["run", cfg, "--order", "2", "--out", run.to_str().unwrap()]);
        assert!(run.join("r.json").exists(), "{name}: run fitted no r: {so}");
        let so = ok(&[
            "batch",
            cfg,
            "--data-dir",
            data_dir.to_str().unwrap(),
            "--order",
            "2",
            "--out",
            batch.to_str().unwrap(),
        ]);
        assert!(
            batch.join("r.json").exists(),
            "{name}: batch fitted no r: {so}"
        );
        outs.push((run, batch));
    }
    let (run, batch) = &outs[0];
    let (run_plain, batch_plain) = &outs[1];
    let note = json(&run.join("r.json"))["scaling"].clone();
    assert_eq!(note["auto"], Value::Bool(true), "{note}");
    assert!(note["r_refers_to"]
        .as_str()
        .unwrap()
        .contains("scaled plant"));
    assert_eq!(json(&run.join("report.json"))["scaling"], note);
    let result = batch.join("datasets/first/result.json");
    for p in [
        batch.join("r.json"),
        batch.join("batch.json"),
        result.clone(),
    ] {
        assert_eq!(json(&p)["scaling"], note, "{}", p.display());
    }
    for p in [
        run_plain.join("r.json"),
        run_plain.join("report.json"),
        batch_plain.join("r.json"),
        batch_plain.join("batch.json"),
        batch_plain.join("datasets/first/result.json"),
    ] {
        assert!(json(&p).get("scaling").is_none(), "{}", p.display());
    }
    // A merge of the shards of a scaled batch (its config read back from batch.json): the
    // same note.
    let shard = dir.path().join("shard");
    let merged = dir.path().join("merged");
    let cfg = dir.path().join("scaled.toml");
    let data_dir = data_dir.to_str().unwrap();
    let order = ["--order", "2", "--out"];
    let shard_args = [
        &[
            "batch",
            cfg.to_str().unwrap(),
            "--data-dir",
            data_dir,
            "--shard",
            "0/1",
        ],
        &order[..],
    ]
    .concat();
    ok(&[&shard_args[..], &[shard.to_str().unwrap()]].concat());
    ok(&[
        &["merge", shard.to_str().unwrap()],
        &order[..],
        &[merged.to_str().unwrap()],
    ]
    .concat());
    for p in [merged.join("r.json"), merged.join("batch.json")] {
        assert_eq!(json(&p)["scaling"], note, "{}", p.display());
    }
    // The MATLAB export of the batch says it too, as run's does.
    let first = |p: &Path| read(p).lines().next().unwrap().to_string();
    assert_eq!(first(&batch.join("r.m")), first(&run.join("r.m")));
    assert!(first(&batch.join("r.m")).starts_with("% r refers to the scaled plant"));
    // Key order: the unscaled file's, with one key more.
    let keys = |p: &Path| top_keys(&read(p));
    let cases = [
        (run.join("r.json"), run_plain.join("r.json"), "order"),
        (batch.join("r.json"), batch_plain.join("r.json"), "order"),
        (
            run.join("report.json"),
            run_plain.join("report.json"),
            "n_data",
        ),
        (
            batch.join("batch.json"),
            batch_plain.join("batch.json"),
            "r_configured",
        ),
        (
            result,
            batch_plain.join("datasets/first/result.json"),
            "error",
        ),
    ];
    for (s, p, before) in cases {
        let plain_keys = keys(&p);
        assert!(plain_keys.len() > 5, "{}: {plain_keys:?}", p.display());
        assert_eq!(
            keys(&s),
            with_key(&plain_keys, "scaling", before),
            "{}",
            s.display()
        );
    }
}

//! The output policy on the subcommands beyond envelope/fit/run/batch: `stability --out`
//! and `merge --out` keep `OUT/rshape-outputs.txt` (a re-run deletes only the files the
//! previous run listed), refuse an `--out` that is an input's folder with exit 2 and one
//! line, and leave nothing behind on bad input; `compare --svg`, `history --svg` and
//! `diagnose --write` (single named files, written by temporary file + rename) refuse a
//! path that is one of their inputs or an existing folder.
use crate::common;

use common::{repo, rshape, stderr, stdout};
use std::path::{Path, PathBuf};

const MANIFEST: &str = "rshape-outputs.txt";

fn listed(out: &Path) -> Vec<String> {
    std::fs::read_to_string(out.join(MANIFEST))
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect()
}

/// Every file under `dir`, relative, sorted.
fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Contents of every file under `dir`, to prove a refused run changed nothing.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    listing(dir)
        .into_iter()
        .filter(|p| dir.join(p).is_file())
        .map(|p| {
            let b = std::fs::read(dir.join(&p)).unwrap();
            (p, b)
        })
        .collect()
}

/// Complete outputs: every listed file exists, JSON files parse, and no temporary file is
/// left in the folder.
fn assert_complete(out: &Path) {
    for f in listed(out) {
        let p = out.join(&f);
        assert!(p.is_file(), "{f} listed but missing");
        if f.ends_with(".json") {
            serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&p).unwrap())
                .unwrap_or_else(|e| panic!("{f}: {e}"));
        }
    }
    for p in listing(out) {
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        assert!(!name.starts_with(".tmp"), "temporary file left: {p:?}");
    }
}

fn assert_refused(o: &std::process::Output, needles: &[&str]) {
    assert_eq!(o.status.code(), Some(2), "{}{}", stdout(o), stderr(o));
    let e = stderr(o);
    assert!(e.starts_with("error: "), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    for n in needles {
        assert!(e.contains(n), "{n:?} missing: {e}");
    }
}

/// The paper's MIMO example (config, data, controller) copied into `dir`.
fn paper_inputs(dir: &Path) -> (PathBuf, PathBuf) {
    std::fs::copy(repo("configs/paper_mimo.csv"), dir.join("paper_mimo.csv")).unwrap();
    std::fs::copy(repo("configs/paper_mimo.toml"), dir.join("model.toml")).unwrap();
    std::fs::copy(
        repo("configs/paper_mimo_controller.toml"),
        dir.join("k.toml"),
    )
    .unwrap();
    (dir.join("model.toml"), dir.join("k.toml"))
}

#[test]
fn stability_rerun_clears_only_its_listed_files_and_refuses_the_input_folder() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir(&inputs).unwrap();
    let (cfg, k) = paper_inputs(&inputs);
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "not rshape's").unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "stability",
            cfg.to_str().unwrap(),
            "--controller",
            k.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        rshape(&args)
    };
    // First run: fit r into OUT, then the Theorem 1 report.
    let o = run(&["--fit"]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let first = listed(&out);
    for f in ["r.json", "stability.svg", "stability.json"] {
        assert!(first.iter().any(|l| l == f), "{f} not listed: {first:?}");
    }
    assert_complete(&out);
    // Second run with the r from elsewhere and no fit: the first run's fit exports are
    // gone, the foreign file stays, the manifest lists this run's files only.
    let r = dir.path().join("r.json");
    std::fs::copy(out.join("r.json"), &r).unwrap();
    let o = run(&["--r-json", r.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    assert!(!out.join("r.json").exists());
    for f in &first {
        if !f.starts_with("stability.") {
            assert!(!out.join(f).exists(), "{f} of the first run left behind");
        }
    }
    assert_eq!(
        std::fs::read_to_string(out.join("keep.txt")).unwrap(),
        "not rshape's"
    );
    let mut second = listed(&out);
    second.sort();
    assert_eq!(second, ["stability.json", "stability.svg"]);
    assert_complete(&out);

    // --out = the inputs' folder, or the folder of --r-json: refused, nothing changed.
    let before = snapshot(dir.path());
    let o = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        k.to_str().unwrap(),
        "--out",
        inputs.to_str().unwrap(),
    ]);
    assert_refused(&o, &["--out", "input"]);
    let o = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        k.to_str().unwrap(),
        "--r-json",
        r.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_refused(&o, &["--out", "r.json"]);
    // --out an existing file.
    let o = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        k.to_str().unwrap(),
        "--out",
        r.to_str().unwrap(),
    ]);
    assert_refused(&o, &["--out", "existing file"]);
    assert_eq!(snapshot(dir.path()), before);
}

/// Two shards of a two-dataset batch on the paper example.
fn shards(dir: &Path) -> (PathBuf, PathBuf) {
    let data = dir.join("data");
    std::fs::create_dir(&data).unwrap();
    for n in ["a.csv", "b.csv"] {
        std::fs::copy(repo("configs/paper_mimo.csv"), data.join(n)).unwrap();
    }
    let shard = |k: &str| {
        let o = dir.join(format!("s{k}"));
        let r = rshape(&[
            "batch",
            repo("configs/paper_mimo.toml").to_str().unwrap(),
            "--data-dir",
            data.to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
            "--shard",
            &format!("{k}/2"),
            "--order",
            "1",
        ]);
        assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
        o
    };
    (shard("0"), shard("1"))
}

#[test]
fn merge_rerun_clears_only_its_listed_files_and_refuses_a_shard_folder() {
    let dir = tempfile::tempdir().unwrap();
    let (s0, s1) = shards(dir.path());
    let out = dir.path().join("merged");
    std::fs::create_dir(&out).unwrap();
    // A previous run listed old.txt; keep.txt is someone else's.
    std::fs::write(out.join("old.txt"), "stale").unwrap();
    std::fs::write(out.join("keep.txt"), "mine").unwrap();
    std::fs::write(out.join(MANIFEST), "old.txt\n").unwrap();
    let merge = |out: &Path, shards: &[&Path]| {
        let mut args = vec!["merge".to_string()];
        args.extend(shards.iter().map(|s| s.to_str().unwrap().to_string()));
        args.extend(["--out", out.to_str().unwrap(), "--order", "1"].map(String::from));
        rshape(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let o = merge(&out, &[&s0, &s1]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    assert!(!out.join("old.txt").exists());
    assert_eq!(
        std::fs::read_to_string(out.join("keep.txt")).unwrap(),
        "mine"
    );
    let l = listed(&out);
    for f in [
        "batch.json",
        "summary.csv",
        "combined_envelope.csv",
        "r.json",
    ] {
        assert!(l.iter().any(|x| x == f), "{f} not listed: {l:?}");
    }
    assert!(!l.iter().any(|x| x == "keep.txt"));
    assert_complete(&out);

    // --out = a shard's folder: refused before anything is written there.
    let before = snapshot(dir.path());
    let o = merge(&s0, &[&s0, &s1]);
    assert_refused(&o, &["--out", "input"]);
    // A bad shard: refused, and the new --out is not even created.
    let bad = dir.path().join("not_a_shard");
    std::fs::create_dir(&bad).unwrap();
    let before_bad = snapshot(dir.path());
    let fresh = dir.path().join("fresh");
    let o = merge(&fresh, &[&s0, &bad]);
    assert_refused(&o, &["batch.json"]);
    assert!(!fresh.exists());
    assert_eq!(snapshot(dir.path()), before_bad);
    std::fs::remove_dir(&bad).unwrap();
    assert_eq!(snapshot(dir.path()), before);
}

#[test]
fn single_file_outputs_refuse_an_input_or_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let (cfg, _) = paper_inputs(dir.path());
    let data = dir.path().join("paper_mimo.csv");
    let before = snapshot(dir.path());
    let c = cfg.to_str().unwrap();
    let d = data.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (
            vec!["compare", c, "--channel", "1,1", "--svg", c],
            &["--svg", "input"],
        ),
        (
            vec!["compare", c, "--channel", "1,1", "--svg", d],
            &["--svg", "input"],
        ),
        (
            vec![
                "compare",
                c,
                "--channel",
                "1,1",
                "--svg",
                dir.path().to_str().unwrap(),
            ],
            &["--svg", "folder"],
        ),
        (
            vec!["history", c, "--channel", "1,1", "--svg", d],
            &["--svg", "input"],
        ),
        (
            vec![
                "diagnose",
                c,
                "--channel",
                "1,1",
                "--apply",
                "1",
                "--write",
                c,
            ],
            &["--write", "input"],
        ),
    ];
    for (args, needles) in cases {
        let o = rshape(&args);
        assert_refused(&o, needles);
    }
    assert_eq!(snapshot(dir.path()), before);
    // A new file name is fine, and is written complete.
    let svg = dir.path().join("fig.svg");
    let o = rshape(&[
        "compare",
        c,
        "--channel",
        "1,1",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.code().is_some_and(|c| c < 2), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.trim_end().ends_with("</svg>"));
}

//! Issue 23's batch and merge cases that take more than one command (see
//! tests/cli/bad_input_kinds.rs for the single-command kinds): shards of different configs are
//! not merged, a merge whose fit failed does not claim an `r.json`, and a FIFO in a batch
//! folder is a failed dataset rather than a silently smaller batch.
use std::path::Path;
use std::process::{Command, Output};

const SISO: &str = r#"[model]
factorization = "standard"
m = [[{ num = [1, 2], den = [1, 1] }]]
n = [[{ num = [1], den = [1, 1] }]]
[r]
num = [0.1, 0.3]
den = [1, 1]
"#;

const DATA: &str = "omega_rad_s,re_1_1,im_1_1\n0.1,0.55,-0.1\n1,0.55,-0.1\n10,0.55,-0.1\n";

fn rshape(args: &[&Path]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(args)
        .output()
        .unwrap()
}

fn p(s: &str) -> &Path {
    Path::new(s)
}

fn batch(cfg: &Path, data: &Path, out: &Path, shard: &str) -> Output {
    rshape(&[
        p("batch"),
        cfg,
        p("--data-dir"),
        data,
        p("--out"),
        out,
        p("--shard"),
        p(shard),
        p("--order"),
        p("1"),
    ])
}

#[test]
fn merge_refuses_shards_of_different_configs() {
    let d = tempfile::tempdir().unwrap();
    let data = d.path().join("data");
    std::fs::create_dir(&data).unwrap();
    for name in ["a.csv", "b.csv"] {
        std::fs::write(data.join(name), DATA).unwrap();
    }
    let (c1, c2) = (d.path().join("one.toml"), d.path().join("two.toml"));
    std::fs::write(&c1, SISO).unwrap();
    // The same model, another r: still a different config (every byte counts).
    std::fs::write(&c2, SISO.replace("num = [0.1, 0.3]", "num = [0.2, 0.3]")).unwrap();
    let (s0, s1) = (d.path().join("s0"), d.path().join("s1"));
    assert_eq!(batch(&c1, &data, &s0, "0/2").status.code(), Some(0));
    assert_eq!(batch(&c2, &data, &s1, "1/2").status.code(), Some(0));
    let merged = d.path().join("merged");
    let o = rshape(&[p("merge"), &s0, &s1, p("--out"), &merged]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("two.toml") && err.contains("one.toml") && err.contains("same config"),
        "{err}"
    );
    assert!(!merged.exists(), "a refused merge left {merged:?}");
    // Shards of one config merge as before.
    let s1b = d.path().join("s1b");
    assert_eq!(batch(&c1, &data, &s1b, "1/2").status.code(), Some(0));
    let o = rshape(&[p("merge"), &s0, &s1b, p("--out"), &merged]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(merged.join("r.json").exists());
}

#[test]
fn a_merge_whose_fit_failed_names_no_r_json() {
    let d = tempfile::tempdir().unwrap();
    let data = d.path().join("data");
    std::fs::create_dir(&data).unwrap();
    for name in ["a.csv", "b.csv"] {
        std::fs::write(data.join(name), "omega_rad_s,re_1_1,im_1_1\n1,abc,0\n").unwrap();
    }
    let cfg = d.path().join("c.toml");
    std::fs::write(&cfg, SISO).unwrap();
    let (s0, s1) = (d.path().join("s0"), d.path().join("s1"));
    assert_eq!(batch(&cfg, &data, &s0, "0/2").status.code(), Some(3));
    assert_eq!(batch(&cfg, &data, &s1, "1/2").status.code(), Some(3));
    let merged = d.path().join("merged");
    let o = rshape(&[p("merge"), &s0, &s1, p("--out"), &merged]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(3), "{out}");
    assert!(out.contains("fit failed"), "{out}");
    let wrote = out.lines().find(|l| l.contains("wrote")).unwrap_or("");
    assert!(!merged.join("r.json").exists());
    assert!(
        !wrote.contains("r.json") && !wrote.contains("combined_envelope.csv"),
        "claims files it did not write: {wrote}"
    );
    for f in ["summary.csv", "batch.json"] {
        assert!(wrote.contains(f) && merged.join(f).exists(), "{wrote}");
    }
}

#[test]
fn a_fifo_in_a_batch_folder_is_a_failed_dataset() {
    let d = tempfile::tempdir().unwrap();
    let data = d.path().join("data");
    std::fs::create_dir(&data).unwrap();
    for name in ["a.csv", "c.csv"] {
        std::fs::write(data.join(name), DATA).unwrap();
    }
    let fifo = data.join("b.csv");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let cfg = d.path().join("c.toml");
    std::fs::write(&cfg, SISO).unwrap();
    let out = d.path().join("out");
    let o = batch(&cfg, &data, &out, "0/1");
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(3), "{text}");
    assert!(text.contains("3 of 3 dataset(s)"), "{text}");
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let row = summary.lines().find(|l| l.contains(",b,")).unwrap();
    assert!(
        row.contains("failed") && row.contains("not a regular file"),
        "{row}"
    );
}

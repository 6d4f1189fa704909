//! `rshape batch` and `rshape merge` end to end: order, exit codes, a corrupt dataset among
//! good ones, manifests, shards.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn config() -> PathBuf {
    root().join("configs/paper_mimo.toml")
}

fn rshape(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(args)
        .output()
        .unwrap()
}

fn batch(dir: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
        .arg("batch")
        .arg(config())
        .arg("--data-dir")
        .arg(dir)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// Three good datasets and a corrupt one.
fn datasets(with_bad: bool) -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    for i in 1..=3 {
        std::fs::copy(
            root().join("configs/paper_mimo.csv"),
            d.path().join(format!("exp{i}.csv")),
        )
        .unwrap();
    }
    if with_bad {
        std::fs::write(
            d.path().join("exp2b.csv"),
            "omega_rad_s,re_1_1,im_1_1\n1,not-a-number,0\n",
        )
        .unwrap();
    }
    d
}

fn rows(out: &Path) -> Vec<Vec<String>> {
    let s = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let mut l = s.lines();
    assert_eq!(
        l.next().unwrap(),
        "index,name,status,n_data,max_r_min,consistent,verdict,n_failing,data,error"
    );
    l.map(|r| r.split(',').map(str::to_string).collect())
        .collect()
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn corrupt_dataset_exit_3_others_complete() {
    let d = datasets(true);
    let out = tempfile::tempdir().unwrap();
    let o = batch(d.path(), out.path(), &[]);
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Piped: no progress bar (no control characters), but plain progress lines that end
    // with every dataset done, and a line before the fit.
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!e.contains('\r') && !e.contains('\u{1b}'), "{e}");
    assert!(
        e.lines()
            .all(|l| l.starts_with("batch: ") || l.starts_with("fitting one r")),
        "{e}"
    );
    assert!(e.contains("batch: 4/4 datasets done"), "{e}");
    assert!(
        e.contains("fitting one r above the combined envelope"),
        "{e}"
    );
    let r = rows(out.path());
    let names: Vec<&str> = r.iter().map(|r| r[1].as_str()).collect();
    assert_eq!(names, ["exp1", "exp2", "exp2b", "exp3"]);
    let bad = &r[2];
    assert_eq!(bad[2], "failed");
    assert!(bad[9..].join(",").contains("exp2b.csv"), "{bad:?}");
    for good in [&r[0], &r[1], &r[3]] {
        assert_eq!(good[2], "ok");
        assert_eq!(good[3], "5");
        assert_eq!(good[5], "false");
        assert_eq!(good[6], "inconsistent");
        assert_eq!(good[7], "2");
        assert!((good[4].parse::<f64>().unwrap() - 0.2515853887657883).abs() < 1e-9);
        let dir = out.path().join("datasets").join(&good[1]);
        assert!(dir.join("envelope.csv").is_file() && dir.join("result.json").is_file());
    }
    assert!(!out.path().join("datasets/exp2b").exists());
    let b = json(&out.path().join("batch.json"));
    assert_eq!(b["n_failed"], 1);
    assert_eq!(b["n_ok"], 3);
    assert_eq!(b["n_frequencies"], 5);
    assert_eq!(b["consistent_all"], false);
    assert!(b["r_fitted"]["num"].is_array());
    assert!(out.path().join("r.json").is_file());
    // batch.svg: the 3 good datasets' envelopes, the combined one and the fitted r.
    let svg = std::fs::read_to_string(out.path().join("batch.svg")).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let text: String = doc.descendants().filter_map(|n| n.text()).collect();
    for want in [
        "Batch: 3 datasets",
        "r_min per datum of each of the 3 datasets",
        "combined envelope",
        "fitted r",
        "configured r",
    ] {
        assert!(text.contains(want), "batch.svg lacks `{want}`: {text}");
    }
    let env = std::fs::read_to_string(out.path().join("combined_envelope.csv")).unwrap();
    assert_eq!(env.lines().count(), 6);
}

#[test]
fn all_good_exit_0() {
    let d = datasets(false);
    let out = tempfile::tempdir().unwrap();
    let o = batch(d.path(), out.path(), &["--jobs", "2"]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(rows(out.path()).len(), 3);
}

#[test]
fn manifest_order_names_and_relative_paths() {
    let d = datasets(false);
    let m = d.path().join("manifest.csv");
    std::fs::write(
        &m,
        "# repeated runs\nname,data,noise_radius\nthird,exp3.csv,\nfirst,exp1.csv,\n",
    )
    .unwrap();
    let out = tempfile::tempdir().unwrap();
    let o = rshape(&[
        "batch".as_ref(),
        config().as_os_str(),
        "--manifest".as_ref(),
        m.as_os_str(),
        "--out".as_ref(),
        out.path().as_os_str(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let r = rows(out.path());
    assert_eq!(
        r.iter().map(|r| r[1].as_str()).collect::<Vec<_>>(),
        ["third", "first"]
    );
    // A manifest naming a missing column is a usage error.
    std::fs::write(&m, "path\nexp1.csv\n").unwrap();
    let o = rshape(&[
        "batch".as_ref(),
        config().as_os_str(),
        "--manifest".as_ref(),
        m.as_os_str(),
        "--out".as_ref(),
        out.path().as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn shards_merge_to_the_full_batch() {
    let d = datasets(true);
    let full = tempfile::tempdir().unwrap();
    assert_eq!(batch(d.path(), full.path(), &[]).status.code(), Some(3));
    let s0 = tempfile::tempdir().unwrap();
    let s1 = tempfile::tempdir().unwrap();
    assert_eq!(
        batch(d.path(), s0.path(), &["--shard", "0/2"])
            .status
            .code(),
        Some(3)
    );
    assert_eq!(
        batch(d.path(), s1.path(), &["--shard", "1/2"])
            .status
            .code(),
        Some(0)
    );
    assert_eq!(
        rows(s0.path())
            .iter()
            .map(|r| r[0].as_str())
            .collect::<Vec<_>>(),
        ["0", "2"]
    );
    let m = tempfile::tempdir().unwrap();
    let o = rshape(&[
        "merge".as_ref(),
        s0.path().as_os_str(),
        s1.path().as_os_str(),
        "--out".as_ref(),
        m.path().as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(3));
    assert_eq!(rows(m.path()), rows(full.path()));
    assert_eq!(
        std::fs::read_to_string(m.path().join("combined_envelope.csv")).unwrap(),
        std::fs::read_to_string(full.path().join("combined_envelope.csv")).unwrap()
    );
    // A missing shard is reported with exit 3.
    let m2 = tempfile::tempdir().unwrap();
    let o = rshape(&[
        "merge".as_ref(),
        s0.path().as_os_str(),
        "--out".as_ref(),
        m2.path().as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&o.stdout).contains("MISSING 2 dataset(s)"));
    // The same shard twice is an error.
    let o = rshape(&[
        "merge".as_ref(),
        s0.path().as_os_str(),
        s0.path().as_os_str(),
        "--out".as_ref(),
        m2.path().as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn usage_errors_exit_2() {
    let d = datasets(false);
    let out = tempfile::tempdir().unwrap();
    assert_eq!(
        rshape(&[
            "batch".as_ref(),
            config().as_os_str(),
            "--out".as_ref(),
            out.path().as_os_str()
        ])
        .status
        .code(),
        Some(2)
    );
    assert_eq!(
        batch(d.path(), out.path(), &["--shard", "2/2"])
            .status
            .code(),
        Some(2)
    );
    let empty = tempfile::tempdir().unwrap();
    assert_eq!(batch(empty.path(), out.path(), &[]).status.code(), Some(2));
}

/// The noisy robot model: a manifest with per-dataset noise radii and a corrupt file.
#[test]
fn robot_manifest_with_noise_and_a_corrupt_file() {
    let cfg = root().join("configs/robot.toml");
    if !cfg.exists() {
        eprintln!("configs/robot.toml not present: skipped");
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let data = root().join("configs/robot.csv");
    std::fs::write(
        d.path().join("broken.csv"),
        "omega_rad_s,re_1_1,im_1_1\n1,0.1\n",
    )
    .unwrap();
    let m = d.path().join("runs.csv");
    std::fs::write(
        &m,
        format!(
            "name,data,noise_radius\nA,{0},0.06\nB,broken.csv,\nC,{0},0.08\n",
            data.display()
        ),
    )
    .unwrap();
    let out = tempfile::tempdir().unwrap();
    let o = rshape(&[
        "batch".as_ref(),
        cfg.as_os_str(),
        "--manifest".as_ref(),
        m.as_os_str(),
        "--out".as_ref(),
        out.path().as_os_str(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let r = rows(out.path());
    assert_eq!(
        r.iter().map(|r| r[2].as_str()).collect::<Vec<_>>(),
        ["ok", "failed", "ok"]
    );
    assert_eq!(r[0][3], "211");
    // More noise explains more: the larger radius never needs a larger r.
    let a: f64 = r[0][4].parse().unwrap();
    let c: f64 = r[2][4].parse().unwrap();
    assert!(c <= a, "{c} > {a}");
    let res = json(&out.path().join("datasets/A/result.json"));
    assert_eq!(res["n_data"], 211);
    let b = json(&out.path().join("batch.json"));
    assert_eq!(b["n_frequencies"], 211);
    assert!(b["r_fitted"]["num"].is_array());
}

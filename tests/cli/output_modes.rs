//! Output files respect the umask: `run` (whose files are written by temporary file +
//! rename) leaves 0644 files under umask 022 and 0600 under umask 077, like any program
//! that creates files with `open(…, 0666)`.  Before the fix the temporary file's 0600
//! survived the rename whatever the umask.
#![cfg(unix)]
use crate::common;

use common::{repo, stderr, stdout};
use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::Command;

/// Runs `rshape ARGS` under `umask MASK` (through `sh`, so the test process keeps its own).
fn run_with_umask(mask: &str, args: &[&str]) -> std::process::Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("umask {mask}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_rshape"))
        .args(args)
        .output()
        .expect("run sh")
}

/// Mode bits (permissions only) of every file in `dir`.
fn modes(dir: &Path) -> Vec<(String, u32)> {
    let mut v: Vec<(String, u32)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_file())
        .map(|e| {
            let m = e.metadata().unwrap().permissions().mode() & 0o777;
            (e.file_name().to_string_lossy().into_owned(), m)
        })
        .collect();
    v.sort();
    v
}

#[test]
fn run_outputs_follow_the_umask() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = repo("configs/paper_mimo.toml");
    for (mask, want) in [("022", 0o644), ("077", 0o600), ("002", 0o664)] {
        let out = tmp.path().join(format!("out{mask}"));
        let o = run_with_umask(
            mask,
            &[
                "run",
                cfg.to_str().unwrap(),
                "--order",
                "1",
                "--out",
                out.to_str().unwrap(),
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
        let m = modes(&out);
        for f in [
            "report.json",
            "r.json",
            "r.py",
            "r_vs_delta.svg",
            "envelope.csv",
        ] {
            assert!(m.iter().any(|(n, _)| n == f), "{f} missing: {m:?}");
        }
        for (name, mode) in &m {
            assert_eq!(*mode, want, "umask {mask}: {name} has mode {mode:o}");
        }
    }
}

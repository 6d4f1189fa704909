//! A run killed mid-way (SIGKILL) leaves no truncated file under its final name, and a
//! re-run into an output folder never mixes the previous run's files with its own.
use crate::common;

use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn write_inputs(dir: &Path, n: usize) {
    let mut s = String::from("omega_rad_s,re_1_1,im_1_1,re_1_2,im_1_2,re_1_3,im_1_3,re_2_1,im_2_1,re_2_2,im_2_2,re_2_3,im_2_3\n");
    for k in 0..n {
        let w = 10f64.powf(-3.0 + 8.0 * k as f64 / n as f64);
        let _ = writeln!(s, "{w:.17e},0.5,0.1,0.8,0,-1.6,0,0,0,0.2,0.1,0.9,-0.2");
    }
    std::fs::write(dir.join("d.csv"), s).unwrap();
    let cfg = std::fs::read_to_string(common::repo("configs/paper_mimo.toml"))
        .unwrap()
        .replace("data = \"paper_mimo.csv\"", "data = \"d.csv\"");
    std::fs::write(dir.join("m.toml"), cfg).unwrap();
}

fn envelope(dir: &Path, out: &Path) -> std::process::Output {
    let cfg = dir.join("m.toml");
    common::rshape(&[
        "envelope",
        cfg.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

fn temp_files(out: &Path) -> Vec<String> {
    std::fs::read_dir(out)
        .map(|r| {
            r.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(".tmp"))
                .collect()
        })
        .unwrap_or_default()
}

#[test]
fn sigkill_while_writing_leaves_no_truncated_file() {
    let n = 200_000;
    let dir = tempfile::tempdir().unwrap();
    write_inputs(dir.path(), n);
    let out = dir.path().join("out");
    let mut caught_mid_write = 0;
    for attempt in 0..3 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_rshape"))
            .args([
                "envelope",
                dir.path().join("m.toml").to_str().unwrap(),
                "--out",
            ])
            .arg(&out)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Kill as soon as the output's temporary file exists: the run is mid-write.
        let t = Instant::now();
        let mut mid_write = false;
        while t.elapsed() < Duration::from_secs(120) {
            if child.try_wait().unwrap().is_some() {
                break;
            }
            if !temp_files(&out).is_empty() {
                mid_write = true;
                break;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
        child.kill().unwrap(); // SIGKILL
        let status = child.wait().unwrap();
        let final_file = out.join("envelope.csv");
        if mid_write && status.code().is_none() {
            caught_mid_write += 1;
            assert!(
                !final_file.exists(),
                "attempt {attempt}: killed mid-write but envelope.csv exists"
            );
        } else if final_file.exists() {
            // The run finished before the kill: the file must be whole.
            let env = rshape::data::read_envelope_csv(&final_file).unwrap();
            assert_eq!(env.len(), n);
        }
    }
    assert!(caught_mid_write > 0, "never caught the run mid-write");
    // A complete run afterwards: whole file, every row.
    let o = envelope(dir.path(), &out);
    assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    let env = rshape::data::read_envelope_csv(&out.join("envelope.csv")).unwrap();
    assert_eq!(env.len(), n);
}

#[test]
fn rerun_clears_the_previous_runs_files_only() {
    let dir = tempfile::tempdir().unwrap();
    write_inputs(dir.path(), 5);
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // A previous run's files (listed in the manifest) and a file of the user's.
    std::fs::write(
        out.join("rshape-outputs.txt"),
        "old_figure.svg\nenvelope.csv\n",
    )
    .unwrap();
    std::fs::write(out.join("old_figure.svg"), "<svg/>").unwrap();
    std::fs::write(out.join("envelope.csv"), "stale").unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let o = envelope(dir.path(), &out);
    assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    assert!(!out.join("old_figure.svg").exists(), "stale output kept");
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    assert_eq!(
        rshape::data::read_envelope_csv(&out.join("envelope.csv"))
            .unwrap()
            .len(),
        5
    );
    let listed = std::fs::read_to_string(out.join("rshape-outputs.txt")).unwrap();
    assert_eq!(listed.lines().collect::<Vec<_>>(), ["envelope.csv"]);
    // A manifest cannot make rshape delete outside its folder.
    std::fs::write(dir.path().join("keep.txt"), "x").unwrap();
    std::fs::write(
        out.join("rshape-outputs.txt"),
        "../keep.txt\n/etc/hostname\n",
    )
    .unwrap();
    let o = envelope(dir.path(), &out);
    assert_eq!(o.status.code(), Some(0));
    assert!(dir.path().join("keep.txt").exists());
}

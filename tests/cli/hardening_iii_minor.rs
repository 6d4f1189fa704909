//! Issue 34, minor items: numbers printed with 300 digits in errors, and `--out` folders
//! checked against every file the run reads (not only the config and the data).
use crate::common;

use common::{repo, rshape, stderr, stdout};

/// Exit code 2, one line starting `error: `, every needle present.
fn assert_one_line_error(o: &std::process::Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(
        o.status.code(),
        Some(2),
        "stderr: {err}\nstdout: {}",
        stdout(o)
    );
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in: {err}");
    }
}

/// `fit --margin -1e300` printed the value with 301 digits; it is written `-1e300`.
#[test]
fn errors_print_extreme_numbers_short() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = rshape(&[
        "fit",
        repo("configs/plant_first.toml").to_str().unwrap(),
        "--margin",
        "-1e300",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["--margin -1e300", "≥ 0"]);
    assert!(!stderr(&o).contains("000000000000000000"), "{}", stderr(&o));
    assert!(stderr(&o).len() < 400, "{}", stderr(&o));
    assert!(!out.exists());
}

/// `--out` onto the folder of the noise std file the config reads (not the config's or the
/// data's folder) was accepted, mixing outputs with that input; refused, nothing written.
#[test]
fn out_folder_of_a_noise_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let noise = dir.path().join("noise");
    std::fs::create_dir_all(&noise).unwrap();
    let std_src = repo("configs/data/twomass/frf_multisineA_std.csv");
    std::fs::copy(&std_src, noise.join("std.csv")).unwrap();
    let text = std::fs::read_to_string(repo("configs/twomass_rev1.toml"))
        .unwrap()
        .replace(
            "std_file = \"data/twomass/frf_multisineA_std.csv\"",
            "std_file = \"noise/std.csv\"",
        )
        .replace(
            "\"data/",
            &format!("\"{}/", repo("configs/data").to_str().unwrap()),
        );
    assert!(text.contains("noise/std.csv"));
    let cfg = dir.path().join("tm.toml");
    std::fs::write(&cfg, text).unwrap();
    let before: Vec<_> = std::fs::read_dir(&noise).unwrap().collect();
    for cmd in ["run", "envelope", "fit"] {
        let o = rshape(&[cmd, cfg.to_str().unwrap(), "--out", noise.to_str().unwrap()]);
        assert_one_line_error(&o, &["--out", "std.csv", "is the folder of the input"]);
        assert_eq!(
            std::fs::read_dir(&noise).unwrap().count(),
            before.len(),
            "{cmd} wrote into the input's folder"
        );
    }
}

//! The config-load notice (`src/cli/common.rs`, `load_config`): a load longer than the notice
//! interval says so on stderr, once per interval.  The interval is 5 s; the test-only variable
//! `RSHAPE_TEST_LOAD_NOTICE_MS` shortens it so that the SLICOT CD player (120 states, balanced
//! truncation to 12 and the normalized coprime factors: about 0.1–0.2 s in a debug build) takes
//! several intervals.
use crate::common::{repo, stderr};
use std::process::{Command, Output};

const VAR: &str = "RSHAPE_TEST_LOAD_NOTICE_MS";

fn envelope(interval_ms: Option<&str>, out: &std::path::Path) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rshape"));
    c.args([
        "envelope",
        repo("configs/slicot_cdplayer.toml").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    match interval_ms {
        Some(ms) => c.env(VAR, ms),
        None => c.env_remove(VAR),
    };
    c.output().expect("run rshape")
}

/// The notice lines of a run's stderr.
fn notices(o: &Output) -> Vec<String> {
    stderr(o)
        .lines()
        .filter(|l| l.starts_with("loading "))
        .map(str::to_string)
        .collect()
}

#[test]
fn a_load_longer_than_the_interval_says_so_on_stderr() {
    let d = tempfile::tempdir().unwrap();
    let o = envelope(Some("1"), &d.path().join("a"));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let lines = notices(&o);
    assert!(!lines.is_empty(), "no notice: {}", stderr(&o));
    for l in &lines {
        assert!(
            l.contains("configs/slicot_cdplayer.toml: reading and factoring the model (")
                && l.ends_with(" s)"),
            "{l}"
        );
    }
    // The run itself is unchanged by the notice: the same envelope as without it.
    let quiet = envelope(None, &d.path().join("b"));
    assert_eq!(quiet.status.code(), Some(0), "{}", stderr(&quiet));
    let read = |p: &str| std::fs::read_to_string(d.path().join(p).join("envelope.csv")).unwrap();
    assert_eq!(read("a"), read("b"));
}

#[test]
fn a_load_within_the_interval_prints_nothing() {
    let d = tempfile::tempdir().unwrap();
    // The default 5 s, and a bad value (ignored: the default), are far above this load.
    for v in [None, Some("soon"), Some("0")] {
        let o = envelope(v, &d.path().join("o"));
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(notices(&o).is_empty(), "{v:?}: {}", stderr(&o));
    }
}

//! `--help` of every subcommand states its exit codes (scripts gate on them: `check` and
//! `stability` exit 1 on a negative verdict), and a missing required argument gives one
//! readable line naming the argument and the usage, not clap's lines joined by semicolons.
use crate::common;

use common::{rshape, stderr, stdout};

#[test]
fn every_subcommand_help_states_its_exit_codes() {
    let subs = [
        ("envelope", &["0", "2"][..]),
        (
            "check",
            &[
                "0 consistent",
                "1 inconsistent or not admissible",
                "2 error",
            ],
        ),
        ("run", &["0 the pipeline completed", "2 error"]),
        (
            "batch",
            &["0 every dataset", "3 some datasets failed", "2 error"],
        ),
        ("merge", &["0 every merged", "3 some", "2 error"]),
        ("compare", &["0", "2 error"]),
        ("diagnose", &["0", "2 error"]),
        ("history", &["0", "2 error"]),
        ("fit", &["0", "2 error"]),
        ("stability", &["0 robustly stable", "1 not", "2 error"]),
        (
            "synthesize",
            &["0 proven robust", "1 not proven robust", "2 error"],
        ),
    ];
    for (sub, needles) in subs {
        let o = rshape(&[sub, "--help"]);
        assert_eq!(o.status.code(), Some(0), "{sub}");
        let t = stdout(&o);
        let tail = t
            .split("Exit codes:")
            .nth(1)
            .unwrap_or_else(|| panic!("{sub}: {t}"));
        for n in needles {
            assert!(tail.contains(n), "{sub} --help lacks `{n}`: {tail}");
        }
    }
    let t = stdout(&rshape(&["--help"]));
    assert!(
        t.contains("Exit codes:") && t.contains("3 some datasets failed"),
        "{t}"
    );
}

/// A mistyped option gets "did you mean --out", not clap's "use -- --ouput".
#[test]
fn mistyped_option_is_suggested() {
    let o = rshape(&["run", "configs/robot.toml", "--ouput", "x"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("did you mean --out?"), "{e}");
    assert!(!e.contains("-- --ouput"), "{e}");
    // Where clap has its own suggestion it stays.
    let o = rshape(&["synthesize", "configs/robot.toml", "--metod", "hinf"]);
    assert!(stderr(&o).contains("'--method'"), "{}", stderr(&o));
}

#[test]
fn missing_out_is_one_readable_line() {
    let o = rshape(&["run", "configs/robot.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    assert!(!e.contains(';'), "flattened with semicolons: {e}");
    assert!(
        e.starts_with("error: the following required arguments were not provided: --out <OUT> (usage: rshape run"),
        "{e}"
    );
}

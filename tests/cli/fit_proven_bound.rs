//! `rshape fit --verbose` prints the proven bound of the chosen order (issue 38, ninth step):
//! at order 0 `r` is a constant, so the optimum is `log10(max r_min/min r_min)` in closed
//! form; the printed bound must sit at or just below it, never above the certified max, and
//! the line is `--verbose` only.

use crate::common::{after, rshape, stdout};

#[test]
fn verbose_fit_prints_a_bound_at_the_closed_form() {
    let d = tempfile::tempdir().unwrap();
    let env = d.path().join("env.csv");
    std::fs::write(&env, "omega_rad_s,r_min\n0.1,1\n0.3,3\n1,0.5\n3,2\n").unwrap();
    let run = |verbose: bool| {
        let out = d.path().join(if verbose { "v" } else { "q" });
        let mut args = vec![
            "fit",
            "--envelope",
            env.to_str().unwrap(),
            "--order",
            "0",
            "--out",
            out.to_str().unwrap(),
        ];
        if verbose {
            args.push("--verbose");
        }
        let o = rshape(&args);
        assert_eq!(o.status.code(), Some(0));
        stdout(&o)
    };
    let text = run(true);
    let max = after(&text, "max log10 |r|/r_min ");
    let bound = after(&text, "does better than ");
    let closed = 6f64.log10();
    assert!((max - closed).abs() < 1e-4, "{max} vs {closed}: {text}");
    assert!(bound <= max + 1e-9, "{bound} above {max}");
    assert!(bound >= closed - 1e-4, "{bound} far below {closed}");
    assert!(!run(false).contains("proven bound"));
}

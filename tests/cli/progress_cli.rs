//! Issue 34 item 9: `stability` and `synthesize` print their stage lines on stderr for a
//! large model (from 200 loop states, resp. 100 plant states, by default). On the 20-mode
//! structure of the large-model bench with the hidden `--progress-from-states 0` (so that
//! a small model counts as large): each stage line appears, once and in the order the
//! library runs them, on stderr only (stdout keeps the answer), with the elapsed seconds;
//! without the option the same small model prints no stage line.

use crate::common;
use crate::modes;

use common::{rshape, stderr, stdout};

/// The stage lines (`label: …`) of `err`, without the elapsed time ` (N s)` at their end.
fn stage_lines(err: &str, label: &str) -> Vec<String> {
    err.lines()
        .filter(|l| l.starts_with(&format!("{label}: ")))
        .map(|l| {
            assert!(l.ends_with(" s)"), "no elapsed time: {l}");
            l[..l.rfind(" (").unwrap()].to_string()
        })
        .collect()
}

/// The position of the first line of `lines` starting with `prefix`, each prefix once.
fn positions(lines: &[String], prefixes: &[&str]) -> Vec<usize> {
    prefixes
        .iter()
        .map(|p| {
            let hits: Vec<usize> = (0..lines.len())
                .filter(|i| lines[*i].starts_with(p))
                .collect();
            assert_eq!(hits.len(), 1, "{p:?} in {lines:#?}");
            hits[0]
        })
        .collect()
}

#[test]
fn stability_and_synthesize_print_their_stage_lines_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = modes::write(dir.path(), 20, 30);
    let cfg = cfg.to_str().unwrap();
    let kp = dir.path().join("k.toml");
    std::fs::write(&kp, "[controller]\ntf = [[1e-3]]\n").unwrap();
    let k = kp.to_str().unwrap();

    // stability: the announcement, then each stage of the library in order.
    let o = rshape(&[
        "stability",
        cfg,
        "--controller",
        k,
        "--progress-from-states",
        "0",
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let lines = stage_lines(&stderr(&o), "stability");
    let at = positions(
        &lines,
        &[
            "stability: the loop of a model with about 40 states",
            "stability: the loop's realization",
            "stability: closed-loop poles (80 states)",
            "stability: the grid curve sigma_max(T(jw))",
            "stability: ||T||_inf, exact (Hamiltonian iteration",
            "stability: b(G,K), exact (Hamiltonian iteration",
        ],
    );
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{lines:#?}");
    assert!(!stdout(&o).contains("stability: "), "{}", stdout(&o));
    assert!(stdout(&o).contains("internally stable"), "{}", stdout(&o));
    // The default threshold: this model is small, no stage line.
    let quiet = rshape(&["stability", cfg, "--controller", k]);
    assert_eq!(quiet.status.code(), o.status.code());
    assert!(
        stage_lines(&stderr(&quiet), "stability").is_empty(),
        "{}",
        stderr(&quiet)
    );
    assert_eq!(stdout(&quiet), stdout(&o));

    // synthesize: the factors, the controller, then the proof's stages.
    let out = dir.path().join("syn");
    let o = rshape(&[
        "synthesize",
        cfg,
        "--out",
        out.to_str().unwrap(),
        "--progress-from-states",
        "0",
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let lines = stage_lines(&stderr(&o), "synthesize");
    let at = positions(
        &lines,
        &[
            "synthesize: normalized coprime factors of a plant with about 40 states",
            "synthesize: the Glover–McFarlane controller (40 plant states",
            "synthesize: proof: the loop's realization",
            "synthesize: proof: closed-loop poles (",
            "synthesize: proof: the grid curve sigma_max(T(jw))",
            "synthesize: proof: ||T||_inf, exact",
            "synthesize: proof: b(G,K), exact",
        ],
    );
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{lines:#?}");
    assert!(out.join("controller.toml").is_file());
    let out2 = dir.path().join("syn2");
    let quiet = rshape(&["synthesize", cfg, "--out", out2.to_str().unwrap()]);
    assert_eq!(quiet.status.code(), o.status.code());
    assert!(
        stage_lines(&stderr(&quiet), "synthesize").is_empty(),
        "{}",
        stderr(&quiet)
    );
}

/// A 60-mode loop (240 loop states, above the 200 of the structured routes): `stability`'s
/// stage lines name the structured closed-loop poles and the certified frequency sweep of
/// both exact norms (issue 34 item 9, sixth session), in order, and the verdict is printed.
#[test]
fn stability_names_the_structured_poles_and_the_certified_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = modes::write(dir.path(), 60, 30);
    let cfg = cfg.to_str().unwrap();
    let kp = dir.path().join("k.toml");
    std::fs::write(&kp, "[controller]\ntf = [[1e-3]]\n").unwrap();
    let k = kp.to_str().unwrap();
    let o = rshape(&[
        "stability",
        cfg,
        "--controller",
        k,
        "--progress-from-states",
        "0",
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let lines = stage_lines(&stderr(&o), "stability");
    let at = positions(
        &lines,
        &[
            "stability: the loop of a model with about 120 states",
            "stability: closed-loop poles (240 states: the eigenvalues of the 120 x 120 loop of the cancelled rows, and 120 hidden modes",
            "stability: the grid curve sigma_max(T(jw))",
            "stability: ||T||_inf, exact (certified frequency sweep on the factors, 60 modal coordinates)",
            "stability: b(G,K), exact (certified frequency sweep on the factors, 60 modal coordinates)",
        ],
    );
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{lines:#?}");
    assert!(
        !lines.iter().any(|l| l.contains("Hamiltonian")),
        "{lines:#?}"
    );
    assert!(stdout(&o).contains("internally stable"), "{}", stdout(&o));
}

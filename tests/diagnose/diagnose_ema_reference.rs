//! Issue 33's acceptance on real data, against references computed independently
//! (`tests/data/ema_reference/`: sdypy-EMA's LSCF stabilization diagram and LSFD, with the
//! script that made them).  `rshape diagnose --apply chosen` repeated from a rigid body on
//! pyfrf 20–1200 Hz and the pyuff 1×3 beam 10–990 Hz must end with every mode the diagram
//! finds stable at half of its orders or more (0.1 % in frequency, ζ within 2×), no other
//! in-band mode (a weaker mode of the diagram may be found), no mains mode (other than a mode
//! the diagram finds, as pyfrf's 900 Hz = 18 × 50 Hz), no cancelling pair
//! and no mode far above the data, with `misfit_rms` and the invalid fraction falling at every
//! applied step.
//!
//! Heavy (several minutes at opt-level 1): `cargo test --release --test diagnose
//! diagnose_ema_reference -- --ignored --nocapture`.

use crate::common::repo;
use rshape::model::Config;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const TAU: f64 = std::f64::consts::TAU;

/// A mode of the reference: `(f Hz, ζ, must)`.
fn reference(name: &str) -> Vec<(f64, f64, bool)> {
    let text = std::fs::read_to_string(repo("tests/data/ema_reference").join(name)).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (
                c[0].parse().unwrap(),
                c[1].parse().unwrap(),
                c[4].trim() == "1",
            )
        })
        .collect()
}

/// Runs the chain from `start` (at most `max_steps` applied steps); returns the last config
/// written and the (misfit_rms, invalid_fraction) before and after each step.
fn chain(start: &Path, dir: &Path, max_steps: usize) -> (PathBuf, Vec<[f64; 4]>) {
    let mut input = start.to_path_buf();
    let mut steps = Vec::new();
    for k in 1..=max_steps {
        let out = dir.join(format!("rev{k}.toml"));
        let o = Command::new(env!("CARGO_BIN_EXE_rshape"))
            .arg("diagnose")
            .arg(&input)
            .args(["--apply", "chosen", "--json", "--write"])
            .arg(&out)
            .output()
            .unwrap();
        let d: Value = serde_json::from_slice(&o.stdout).unwrap_or(Value::Null);
        eprintln!(
            "step {k}: {}",
            d["message"]
                .as_str()
                .unwrap_or(&String::from_utf8_lossy(&o.stderr))
        );
        if !o.status.success() || !out.exists() {
            break;
        }
        let m = |a: &str, b: &str| d[a][b].as_f64().unwrap();
        steps.push([
            m("before", "misfit_rms"),
            m("after", "misfit_rms"),
            m("before", "invalid_fraction"),
            m("after", "invalid_fraction"),
        ]);
        input = out;
    }
    (input, steps)
}

/// Checks the chain's end against the reference; returns the failures (empty: accepted).
fn judge(
    last: &Path,
    steps: &[[f64; 4]],
    refs: &[(f64, f64, bool)],
    band: (f64, f64),
) -> Vec<String> {
    let mut bad = Vec::new();
    for (k, s) in steps.iter().enumerate() {
        if s[1].is_nan() || s[1] >= s[0] || s[3] > s[2] {
            bad.push(format!(
                "step {}: misfit_rms {} → {}, invalid {} → {}",
                k + 1,
                s[0],
                s[1],
                s[2],
                s[3]
            ));
        }
    }
    let c = Config::load(last).unwrap();
    let p = c.physical.as_ref().unwrap();
    let modes: Vec<(f64, f64)> = p
        .mode
        .iter()
        .map(|m| (m.omega_n / TAU, m.zeta))
        .filter(|(f, _)| *f >= band.0 && *f <= band.1)
        .collect();
    eprintln!("{}: modes (Hz, ζ) {modes:?}", last.display());
    for (f, z, must) in refs {
        let hit = modes.iter().find(|(fm, _)| (fm / f - 1.0).abs() < 1e-3);
        match (hit, must) {
            (None, true) => bad.push(format!("reference mode {f} Hz (ζ {z}) not found")),
            (Some((fm, zm)), _) if zm / z > 2.0 || z / zm > 2.0 => {
                bad.push(format!("{fm} Hz: ζ {zm} vs reference {z}"))
            }
            _ => {}
        }
    }
    for (fm, zm) in &modes {
        if !refs.iter().any(|(f, _, _)| (fm / f - 1.0).abs() < 1e-3) {
            bad.push(format!("{fm} Hz (ζ {zm}): not in the reference"));
        }
        // A mode the diagram finds stable at half its orders is the structure's, even at a
        // mains harmonic (pyfrf's 900 Hz = 18 × 50 Hz).
        if refs
            .iter()
            .any(|(f, _, must)| *must && (fm / f - 1.0).abs() < 1e-3)
        {
            continue;
        }
        for f0 in [50.0, 60.0] {
            let h = (fm / f0).round().max(1.0);
            if (fm - h * f0).abs() < 0.5 && zm * fm < 1.0 {
                bad.push(format!("{fm} Hz: a mains mode"));
            }
        }
    }
    // Cancelling pairs: overlapping half-power bands with residues that largely cancel.
    let res = |i: usize| -> Vec<f64> {
        let m = &p.mode[i];
        let n_in = p.n_inputs();
        let b = m.input_gain.to_vec(n_in);
        let c = m.output_gain.to_vec(p.n_outputs());
        c.iter()
            .flat_map(|co| b.iter().map(move |bi| co * bi / m.mass))
            .collect()
    };
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    for i in 0..p.mode.len() {
        for j in i + 1..p.mode.len() {
            let (a, b) = (&p.mode[i], &p.mode[j]);
            if (a.omega_n - b.omega_n).abs() < a.zeta * a.omega_n + b.zeta * b.omega_n {
                let (ra, rb) = (res(i), res(j));
                let s: Vec<f64> = ra.iter().zip(&rb).map(|(x, y)| x + y).collect();
                if norm(&s) < 0.5 * norm(&ra).max(norm(&rb)) {
                    bad.push(format!(
                        "cancelling pair at {} and {} Hz",
                        a.omega_n / TAU,
                        b.omega_n / TAU
                    ));
                }
            }
        }
    }
    bad
}

#[test]
#[ignore = "heavy: a discovery chain on real data (minutes)"]
fn pyfrf_chain_ends_with_the_stabilization_diagram_modes() {
    let dir = tempfile::tempdir().unwrap();
    let (last, steps) = chain(&repo("configs/pyfrf_rigid.toml"), dir.path(), 6);
    let bad = judge(
        &last,
        &steps,
        &reference("pyfrf_20_1200.csv"),
        (20.0, 1200.0),
    );
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Fails today (issue 33 open), measured in release (about 45 s for the chain):
/// * 51.5 Hz ends with ζ 1.13e-4, 5.0× below the diagram's 5.67e-4.  The profile
///   likelihood (`lsq::profile`) puts ζ in 7.6e-5–1.7e-4 (95 %) under rshape's model, so
///   the verdict reports it "not identified" and writes the log-midpoint: the data show a
///   phase lag of 9–11° over 25–100 Hz on all three channels that no real-residue term of
///   the catalogue produces, and a local fit 40–64 Hz with a free complex background gives
///   4.2e-4 (1.9–6.0e-4) with a real residue, 5.3e-4 with a complex one (the diagram's LSFD
///   residues there are 15 % imaginary).
/// * The diagram's weak 900.5 Hz pole (stable at 15 of 60 orders) ends at ζ 1.17e-3 ± 7 %
///   (2.3× its 5.1e-4); the half-height width of the imaginary part of channel 3 at
///   899–902 Hz reads ζ ≈ 0.9–1.25e-3, the refit's side.
/// * Step 3 adds a 4.9 µs input delay: not negligible by the rules (removing it and
///   refitting raises misfit_rms 0.835 → 0.881, 5.2 %; ΔBIC 858).
#[test]
#[ignore = "heavy (a minute in release), and fails today: 51.5 Hz ζ 5.0× below the reference (its 95 % profile interval excludes it), 900.8 Hz ζ 2.3× above"]
fn pyuff_chain_ends_with_the_stabilization_diagram_modes() {
    let dir = tempfile::tempdir().unwrap();
    let (last, steps) = chain(&repo("tests/data/pyuff_rigid.toml"), dir.path(), 6);
    let bad = judge(&last, &steps, &reference("pyuff_10_990.csv"), (10.0, 990.0));
    assert!(bad.is_empty(), "{bad:#?}");
}

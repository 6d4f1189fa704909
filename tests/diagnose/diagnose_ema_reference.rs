//! Issue 33's acceptance on real data, against references computed independently
//! (`tests/data/ema_reference/`: sdypy-EMA's LSCF stabilization diagram and LSFD, with the
//! script that made them).  `rshape diagnose --apply chosen` repeated from a rigid body on
//! pyfrf 20–1200 Hz and the pyuff 1×3 beam 10–990 Hz must end with every mode the diagram
//! finds stable at half of its orders or more (0.1 % in frequency, ζ within 2×), no other
//! in-band mode (a weaker mode of the diagram may be found), no mains mode (other than a mode
//! the diagram finds, as pyfrf's 900 Hz = 18 × 50 Hz), no cancelling pair
//! and no mode far above the data, with `misfit_rms` and the invalid fraction falling at every
//! applied step.  A mode the diagram does not stabilize (`must` 0) has its damping judged
//! against a local fit instead (`local_zeta.py`, `pyuff_local_zeta.csv`).
//!
//! Heavy (several minutes at opt-level 1): `cargo test --release --test diagnose
//! diagnose_ema_reference -- --ignored --nocapture`.

use crate::common::repo;
use rshape::model::Config;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const TAU: f64 = std::f64::consts::TAU;

fn rows(name: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(repo("tests/data/ema_reference").join(name)).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(|c| c.trim().to_string()).collect())
        .collect()
}

/// A mode of the reference: `(f Hz, ζ, must)`.
fn reference(name: &str) -> Vec<(f64, f64, bool)> {
    rows(name)
        .iter()
        .map(|c| (c[0].parse().unwrap(), c[1].parse().unwrap(), c[4] == "1"))
        .collect()
}

/// The reference with the damping of every mode the diagram does not stabilize (`must` 0)
/// taken from the local complex-residue fit of `local` (`local_zeta.py`): LSCF's pole of
/// such a mode is not a reference for its damping (pyuff 900.5 Hz: ζ 5.1e-4 at 15 of 60
/// orders, outside the local fit's 95 % interval 1.06–1.34e-3 with either residue).  The
/// local fit of every stabilized mode agrees with LSCF within 2× (checked here).
fn reference_with_local(name: &str, local: &str) -> Vec<(f64, f64, bool)> {
    let local: Vec<(f64, f64)> = rows(local)
        .iter()
        .filter(|c| c[1] == "complex")
        .map(|c| (c[0].parse().unwrap(), c[3].parse().unwrap()))
        .collect();
    reference(name)
        .into_iter()
        .map(|(f, z, must)| {
            let (_, zl) = *local
                .iter()
                .find(|(fl, _)| (fl / f - 1.0).abs() < 1e-6)
                .expect("a local fit of every reference mode");
            if must {
                assert!(
                    zl / z < 2.0 && z / zl < 2.0,
                    "{f} Hz: local ζ {zl} vs LSCF {z}"
                );
                (f, z, must)
            } else {
                (f, zl, must)
            }
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

/// Measured (release, this session): step 1 adds the three modes at once (misfit_rms
/// 129.8 → 5.994, invalid fraction 87.8 % → 53.6 %), step 2 adds nothing.  At
/// `--max-effects 2` step 1 adds two of them and raises the invalid fraction (87.8 % →
/// 94.8 %): the mass line's least-squares compromise with the third mode missing, not a
/// fault of the measure or the noise (`diagnose_pyfrf_invalid.rs`).
#[test]
#[ignore = "heavy: a discovery chain on real data (minutes)"]
fn pyfrf_chain_ends_with_the_stabilization_diagram_modes() {
    let dir = tempfile::tempdir().unwrap();
    let (last, steps) = chain(&repo("configs/pyfrf_rigid.toml"), dir.path(), 6);
    // Both measures must fall at every applied step (`judge`), and there must be one.
    assert!(!steps.is_empty(), "no step applied");
    let bad = judge(
        &last,
        &steps,
        &reference("pyfrf_20_1200.csv"),
        (20.0, 1200.0),
    );
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Fails today (issue 33 open), measured in release (about 75 s for the chain):
/// * 51.5 Hz ends with ζ 2.37e-4, 2.4× below the diagram's 5.67e-4.  Under rshape's modal
///   model (real residues) the likelihood is flat from the record's floor 7.6e-5 to 7.3e-4
///   (95 %, widened by the lack of fit around the mode, `lsq::profile`), so the verdict
///   reports ζ "not identified" and writes the log-midpoint; the reference lies inside the
///   interval.  The data there carry a phase of ≈ 9° on all three channels that no
///   real-residue term makes; a local fit with a complex residue (LSFD's model,
///   `local_zeta.py`) identifies ζ 5.3e-4 (3.4–7.1e-4), but a complex residue of that size is
///   not the damping of a separated mode (see `local_zeta.py`), so it is not offered as an
///   effect.  Over the whole low band (10–200 Hz, `low_band_hypotheses.py`) the real-residue
///   profile rises monotonically from ζ → 0: no estimator inside the interval (the profile's
///   maximum is the floor; the log-midpoint or a likelihood mean is set by where the interval
///   is cut) is the data's, and none is chosen to land on this mode.  No measurement-chain
///   effect tried there identifies ζ: a delay or a response-side high-pass changes nothing, a
///   force-side high-pass (f_c 3.9 Hz) takes 57 % of the excess misfit but leaves ζ at the
///   floor, a close pair does not form, and even a constant (non-causal) phase on every
///   channel (4.1°) leaves ζ at 1.9e-4, 3× below.
/// * The diagram's weak 900.5 Hz pole (stable at 15 of 60 orders) is judged against the local
///   fit (ζ 1.19e-3, 1.06–1.34e-3 with either residue); the chain ends at 1.17e-3.
/// * Step 3 adds a 4.9 µs input delay: not negligible by the rules (removing it and
///   refitting raises misfit_rms 0.835 → 0.881, 5.2 %; ΔBIC 858).
/// * A complex-mode effect (issue 33, disc33x) was measured and not built
///   (`complex_mode_feasibility.py`, whole band, the seven reference modes refit): the
///   causal complex mode `R/(s − λ) + R̄/(s − λ̄)` — a numerator term `σs` beside `ρ` in the
///   receptance — leaves ζ of 51.5 Hz at the floor (1e-6) with a phase of −0.1…−0.3°, while
///   it would pass the admissibility rules on other modes (687 Hz: −1.0…−1.5°, misfit_rms
///   −2.2 %): curve fitting, not this mode's physics.  Only LSFD's own form, a complex residue
///   of the accelerance's pole–residue expansion (`σ s ω_n/d(s)` on the accelerance), takes
///   ζ to 6.2e-4 (within 2× of 5.67e-4; misfit_rms 0.881 → 0.523, +9.4…+10.2° on all three
///   channels, ±0.3°), and that term is the causal one plus `c·s` on the accelerance (`c/s`
///   in the receptance) with `c` tied to it: the integrator that rshape flags as implausible
///   on an accelerance (no structural term gives it).
/// * Record truncation (leakage, each residue × (1 − e^{λT}), `leakage_hypothesis.py`) is
///   refuted at the record's own T = 1/Δf = 1 s (142 Hz V 18 → 1362, total 784 → 3282); only
///   T ≥ 5 s lowers V (8 s: 286, ζ 5.3e-4), where e^{iω_d T} turns a full cycle within the
///   ±0.2 % f_n grid: a free phase per mode, curve fitting.
#[test]
#[ignore = "heavy (a minute in release), and fails today: 51.5 Hz ζ 2.4× below the reference (not identified: its 95 % profile interval 7.6e-5–7.3e-4 contains the reference, the written log-midpoint does not meet 2×)"]
fn pyuff_chain_ends_with_the_stabilization_diagram_modes() {
    let dir = tempfile::tempdir().unwrap();
    let (last, steps) = chain(&repo("tests/data/pyuff_rigid.toml"), dir.path(), 6);
    let refs = reference_with_local("pyuff_10_990.csv", "pyuff_local_zeta.csv");
    let bad = judge(&last, &steps, &refs, (10.0, 990.0));
    assert!(bad.is_empty(), "{bad:#?}");
}

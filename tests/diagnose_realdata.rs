//! Real data, both outputs, from a rough start: the ball-screw feed axis
//! (configs/data/ballscrew, FdiTools) and the motor bench (configs/data/twomass), each
//! validated on the other experiment of the same rig; data-vs-data consistency explains why
//! a linear model cannot reach the noise on the motor bench.

use rshape::data::read_frf_csv;
use rshape::diagnose::agreement::data_vs_data;
use rshape::diagnose::compare::{compare, prepare, PlantModel};
use rshape::diagnose::{diagnose_channels, Channels, Settings};
use rshape::model::Config;
use std::path::Path;
use std::process::Command;

const TAU: f64 = std::f64::consts::TAU;

/// `misfit_rms` of a config on one channel of a data file.
fn rms(config: &str, data: &str, ch: (usize, usize)) -> f64 {
    let c = Config::load(Path::new(config)).unwrap();
    let d = read_frf_csv(Path::new(data)).unwrap();
    let s = prepare(&c, &d, Some(ch), None).unwrap();
    compare(&c, &PlantModel::from_config(&c), &s)
        .unwrap()
        .misfit_rms
}

#[test]
fn ballscrew_from_a_rough_rigid_body_finds_the_axial_mode_in_band() {
    let c = Config::load(Path::new("configs/ballscrew_rigid.toml")).unwrap();
    let a = read_frf_csv(c.data.as_ref().unwrap()).unwrap();
    let data = Channels::all(&c, &a, None).unwrap();
    assert_eq!(data.n_ch(), 2);
    let s = Settings {
        max_effects: 1,
        beam: 2,
    };
    let d = diagnose_channels(c.physical.as_ref().unwrap(), &data, &s).unwrap();
    println!("{}", d.message);
    // The retune fixes the 6× gain error (the issue's "mode at 37 rad/s with ζ = 1e-4 and a
    // negative residue" does not appear).
    assert!(
        d.retuned.misfit_rms < 0.3 * d.before.misfit_rms,
        "{:?}",
        d.retuned
    );
    let m = d
        .final_effects
        .iter()
        .find(|e| e.effect == "mode")
        .expect("a mode");
    let f = m.params["omega_n"] / TAU;
    // The axial mode (SOURCE.md: ≈ 120 Hz on the table side), inside the 11–300 Hz band.
    assert!((110.0..140.0).contains(&f), "mode at {f} Hz");
    assert!(m.params["zeta"] > 1e-3 && m.params["zeta"] < 0.2);
    // One mode for both outputs, with opposite residues on motor angle and table position.
    assert!(
        m.params["rho_1_1"] * m.params["rho_2_1"] < 0.0,
        "{:?}",
        m.params
    );
    for cand in &d.candidates {
        for fl in &cand.flags {
            let bad = |w: &str| w == "inf" || w == "NaN" || w.contains("e+");
            assert!(!fl.split_whitespace().any(bad), "{fl}");
        }
    }
}

#[test]
fn shipped_revisions_lower_the_error_on_both_experiments() {
    let est = "configs/data/ballscrew/frf_hresL_m40pR.csv";
    let val = "configs/data/ballscrew/frf_hres_40n8.csv";
    let revs = [
        "configs/ballscrew_rigid.toml",
        "configs/ballscrew_rev1.toml",
        "configs/ballscrew_rev2.toml",
        "configs/ballscrew_rev3.toml",
    ];
    for ch in [(1, 1), (2, 1)] {
        let e: Vec<f64> = revs.iter().map(|r| rms(r, est, ch)).collect();
        let v: Vec<f64> = revs.iter().map(|r| rms(r, val, ch)).collect();
        println!("ball screw {ch:?}: estimation {e:?}, validation {v:?}");
        assert!(e[3] < 0.2 * e[0], "{e:?}");
        assert!(v[3] < 0.25 * v[0], "{v:?}");
    }
    let revs = [
        "configs/twomass_both_rigid.toml",
        "configs/twomass_both_rev1.toml",
        "configs/twomass_both_rev2.toml",
        "configs/twomass_both_rev3.toml",
    ];
    for ch in [(1, 1), (2, 1)] {
        for data in [
            "configs/data/twomass/frf_multisineA.csv",
            "configs/data/twomass/frf_multisineB.csv",
        ] {
            let e: Vec<f64> = revs.iter().map(|r| rms(r, data, ch)).collect();
            println!("motor bench {ch:?} {data}: {e:?}");
            for w in e.windows(2) {
                assert!(w[1] < w[0], "{e:?}");
            }
            assert!(e[3] < 0.15 * e[0], "{e:?}");
        }
    }
}

/// The motor bench's two experiments disagree by more than their noise on about half of the
/// common frequencies (both outputs): no model, linear or not, reaches the noise on both.
#[test]
fn motor_bench_experiments_disagree_beyond_their_noise() {
    let c = Config::load(Path::new("configs/twomass_both_rigid.toml")).unwrap();
    let a = read_frf_csv(Path::new("configs/data/twomass/frf_multisineA.csv")).unwrap();
    let b = read_frf_csv(Path::new("configs/data/twomass/frf_multisineB.csv")).unwrap();
    for ch in [(1, 1), (2, 1)] {
        let sa = prepare(&c, &a, Some(ch), None).unwrap();
        let sb = prepare(&c, &b, Some(ch), None).unwrap();
        let r = data_vs_data(&sa, &sb).unwrap();
        println!("{ch:?}: {r:?}");
        assert_eq!(r.n_common, 60);
        assert_eq!(r.verdict, "disagree");
        assert!(r.disagree_fraction > 0.3 && r.distance_rms > 2.0, "{r:?}");
    }
}

/// A factor-form config (the robot's eqs. (19)–(21)) is converted to [physical] and
/// diagnosed; `compare` works on it as it is.
#[test]
fn factor_form_configs_compare_and_diagnose() {
    let exe = env!("CARGO_BIN_EXE_rshape");
    let out = Command::new(exe)
        .args(["diagnose", "configs/robot.toml", "--max-effects", "1"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("converted to [physical] (5 modes)"), "{text}");
    let out = Command::new(exe)
        .args(["compare", "configs/paper_mimo.toml", "--channel", "1,1"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The paper's MIMO factors are not modal: diagnose says why, in one line, exit 2.
    let out = Command::new(exe)
        .args(["diagnose", "configs/paper_mimo.toml", "--channel", "1,1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cannot be converted") && err.lines().count() == 1,
        "{err}"
    );
    // Closed-loop configs reach diagnose through the open-loop equivalent (here a standard
    // factorization, which diagnose cannot extend: the same one-line reason).
    let out = Command::new(exe)
        .args([
            "diagnose",
            "configs/closed_loop_retuned_noisy.toml",
            "--max-effects",
            "1",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("standard factorization") && err.lines().count() == 1,
        "{err}"
    );
}

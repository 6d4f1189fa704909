//! Real data, both outputs, from a rough start: the ball-screw feed axis
//! (configs/data/ballscrew, FdiTools) and the motor bench (configs/data/twomass), each
//! validated on the other experiment of the same rig; data-vs-data consistency explains why
//! a linear model cannot reach the noise on the motor bench.

use rshape::data::read_frf_csv;
use rshape::diagnose::data_vs_data;
use rshape::diagnose::{compare, prepare, PlantModel};
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
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
    let s = SearchSettings {
        max_effects: 1,
        beam: 2,
        ..Default::default()
    };
    let d =
        diagnose_channels(c.physical.as_ref().unwrap(), &data, &s, &Default::default()).unwrap();
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
    // Issue 20, defect 10: the 2.5 ms delay on the table encoder (273° of lag at 300 Hz),
    // once the #1 candidate marked pass, is flagged implausible; no candidate that passes
    // is a delay of more than 180° at the band top or a hold with its Nyquist in the band.
    let w_max = *data.omega.last().unwrap();
    let long = d
        .candidates
        .iter()
        .find(|c| c.effect == "delay (output 2)")
        .expect("the table-encoder delay");
    assert!(
        (2.0e-3..3.0e-3).contains(&long.params["tau_s"]),
        "{:?}",
        long.params
    );
    assert!(!long.passes && long.flags.iter().any(|f| f.contains("implausible")));
    for c in d.candidates.iter().filter(|c| c.passes) {
        if let Some(t) = c.params.get("tau_s") {
            assert!(
                t * w_max <= std::f64::consts::PI,
                "{} passes: {t}",
                c.effect
            );
        }
        if let Some(t) = c.params.get("t_s") {
            assert!(
                std::f64::consts::PI / t >= w_max,
                "{} passes: {t}",
                c.effect
            );
        }
    }
}

/// `misfit_rms` per revision on one channel of `est` and of `val`.
fn per_revision(revs: &[&str], ch: (usize, usize), est: &str, val: &str) -> [Vec<f64>; 2] {
    [
        revs.iter().map(|r| rms(r, est, ch)).collect(),
        revs.iter().map(|r| rms(r, val, ch)).collect(),
    ]
}

/// The numbers of the tables in docs/guide/discovery.md (3 significant digits).
fn matches_readme(got: &[f64], readme: &[f64]) {
    for (g, r) in got.iter().zip(readme) {
        assert!(
            (g / r - 1.0).abs() < 6e-3,
            "{got:?} vs docs/guide/discovery.md {readme:?}"
        );
    }
}

/// Ball screw: estimation `hresL_m40pR` (11–300 Hz), validation `hres_40n8` (11–800 Hz),
/// both outputs. The estimation error falls at every revision on both outputs; on the
/// validation data it falls at every revision on the table except the retune (rev 1: a
/// rigid body cannot follow the table above the axial mode, 78.1 → 80.9, both ~80 noise
/// radii off), and on the motor side it falls to rev 2 and then stays within 1 % (5.70,
/// 5.72, 5.75: the validation band holds modes near 475 and 615 Hz that the estimation
/// data never saw).
#[test]
fn ballscrew_revisions_lower_the_error_on_estimation_and_validation() {
    let est = "configs/data/ballscrew/frf_hresL_m40pR.csv";
    let val = "configs/data/ballscrew/frf_hres_40n8.csv";
    let revs = [
        "configs/ballscrew_rigid.toml",
        "configs/ballscrew_rev1.toml",
        "configs/ballscrew_rev2.toml",
        "configs/ballscrew_rev3.toml",
        "configs/ballscrew_rev4.toml",
    ];
    let [me, mv] = per_revision(&revs, (1, 1), est, val);
    let [te, tv] = per_revision(&revs, (2, 1), est, val);
    println!("motor: est {me:?} val {mv:?}\ntable: est {te:?} val {tv:?}");
    for e in [&me, &te] {
        for w in e.windows(2) {
            assert!(w[1] < w[0], "estimation must fall: {e:?}");
        }
    }
    for w in tv[1..].windows(2) {
        assert!(w[1] < w[0], "table validation: {tv:?}");
    }
    assert!(tv[1] < 1.05 * tv[0], "{tv:?}");
    assert!(mv[1] < mv[0] && mv[2] < mv[1], "{mv:?}");
    assert!(mv[3] < 1.01 * mv[2] && mv[4] < 1.01 * mv[3], "{mv:?}");
    matches_readme(&me, &[27.1, 3.84, 2.70, 2.65, 2.51]);
    matches_readme(&mv, &[26.1, 6.35, 5.70, 5.72, 5.75]);
    matches_readme(&te, &[43.5, 11.5, 6.24, 4.46, 2.95]);
    matches_readme(&tv, &[78.1, 80.9, 21.0, 8.86, 6.82]);
    // rev 4 is a sensor effect on the table encoder only (output 2).
    let c = Config::load(Path::new(revs[4])).unwrap();
    let e = c.physical.unwrap().effect;
    assert_eq!(e.len(), 1);
    assert_eq!(e[0].path, rshape::model::physical::EffectPath::Output);
    assert_eq!(e[0].channel, Some(2));
}

/// Motor bench, both outputs, estimation multisine A, validation multisine B: the error
/// falls at every revision on both experiments and both outputs.
#[test]
fn motor_bench_revisions_lower_the_error_on_a_and_b_on_both_outputs() {
    let a = "configs/data/twomass/frf_multisineA.csv";
    let b = "configs/data/twomass/frf_multisineB.csv";
    let revs = [
        "configs/twomass_both_rigid.toml",
        "configs/twomass_both_rev1.toml",
        "configs/twomass_both_rev2.toml",
        "configs/twomass_both_rev3.toml",
    ];
    let readme = [
        [[52.1, 11.4, 7.39, 5.18], [82.8, 20.0, 12.0, 7.99]],
        [[55.1, 9.33, 4.91, 4.64], [85.4, 16.4, 8.48, 7.34]],
    ];
    for (k, ch) in [(1, 1), (2, 1)].into_iter().enumerate() {
        let [ea, eb] = per_revision(&revs, ch, a, b);
        println!("motor bench {ch:?}: A {ea:?} B {eb:?}");
        for e in [&ea, &eb] {
            for w in e.windows(2) {
                assert!(w[1] < w[0], "{ch:?}: {e:?}");
            }
            assert!(e[3] < 0.15 * e[0], "{e:?}");
        }
        matches_readme(&ea, &readme[k][0]);
        matches_readme(&eb, &readme[k][1]);
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
        assert_eq!(r.verdict, rshape::diagnose::AgreementVerdict::Disagree);
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
    // Closed-loop configs reach diagnose through the open-loop equivalent; their nominal
    // N̂·D̂⁻¹ = 1/s² is converted to a [physical] rigid body.
    let out = Command::new(exe)
        .args([
            "diagnose",
            "configs/closed_loop_retuned_noisy.toml",
            "--max-effects",
            "1",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.lines().next().unwrap().contains(
            "the [closed_loop] nominal plant is a sum of physical terms: converted to [physical] (1 rigid body)"
        ),
        "{text}"
    );
    // A state-space [plant] is not converted: the one-line reason, exit 2.
    let out = Command::new(exe)
        .args(["diagnose", "configs/iss1r_reduced.toml", "--channel", "1,1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("a state-space [plant] is not converted") && err.lines().count() == 1,
        "{err}"
    );
}

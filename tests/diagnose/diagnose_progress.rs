//! `diagnose_channels`'s progress (issue 34, item 9): the stages in the order they run, each
//! search level announced, every joint refit counted once (the counts agree with the
//! search's own phase table), and the result the same as without a listener.

use num_complex::Complex64;
use rshape::diagnose::{diagnose_channels, Channels, DiagnoseOptions, DiagnoseProgress};
use rshape::diagnose::{DiagnoseVerdict, SearchSettings, RETUNE_ITERATING, RETUNE_PLACING};
use rshape::model::physical::{Gains, ModeSpec, PhysicalModel};
use std::sync::Mutex;

fn mode(omega_n: f64, output_gain: f64) -> ModeSpec {
    ModeSpec {
        name: None,
        omega_n,
        zeta: 0.02,
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Scalar(output_gain),
    }
}

/// One mode configured; the data have a second one at 1500 rad/s, noise radius 1 %.
fn case() -> (PhysicalModel, Channels) {
    let base = PhysicalModel {
        mode: vec![mode(600.0, 4e5)],
        ..Default::default()
    };
    let truth = PhysicalModel {
        mode: vec![mode(600.0, 4e5), mode(1500.0, 2e6)],
        ..Default::default()
    };
    let omega: Vec<f64> = (0..60).map(|k| 100.0 * 1.05f64.powi(k)).collect();
    let g: Vec<Complex64> = omega.iter().map(|w| truth.eval(*w)[(0, 0)]).collect();
    let radius = g.iter().map(|v| 0.01 * v.norm()).collect();
    let data = Channels {
        path: "two_modes.csv".into(),
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius: vec![radius],
        radius_source: vec!["test".into()],
    };
    (base, data)
}

#[test]
fn progress_reports_stages_levels_and_every_refit() {
    let (base, data) = case();
    let s = SearchSettings {
        max_effects: 2,
        beam: 2,
        ..Default::default()
    };
    let heard = Mutex::new(Vec::new());
    let listen = |p: DiagnoseProgress| heard.lock().unwrap().push(p);
    let d = diagnose_channels(
        &base,
        &data,
        &s,
        &DiagnoseOptions {
            progress: Some(&listen),
        },
    )
    .unwrap();
    assert_ne!(d.verdict, DiagnoseVerdict::Consistent, "{}", d.message);
    let heard = heard.into_inner().unwrap();
    assert_eq!(heard[0], DiagnoseProgress::Stage("retune"), "{heard:?}");
    // Stages after the search, in order, each once.
    let stages: Vec<&str> = heard
        .iter()
        .filter_map(|p| match p {
            DiagnoseProgress::Stage(s) => Some(*s),
            _ => None,
        })
        .collect();
    assert_eq!(
        stages,
        [
            "retune",
            "first level",
            "holdout",
            "backward elimination",
            "final refit",
            "ties",
            "peak account"
        ]
    );
    // Levels 1, 2, … announced in order, the first with the two roots; between two level
    // announcements, that level's refits counted 1..=total (any order: they run in parallel).
    let mut levels = Vec::new();
    let mut refits: Vec<(usize, usize, usize)> = Vec::new();
    for p in &heard {
        match *p {
            DiagnoseProgress::Level { depth, max, nodes } => {
                assert_eq!(max, 2);
                levels.push((depth, nodes));
            }
            DiagnoseProgress::Refits { depth, done, total } => {
                assert_eq!(Some(&depth), levels.last().map(|l| &l.0), "{heard:?}");
                refits.push((depth, done, total));
            }
            _ => {}
        }
    }
    assert_eq!(levels[0], (1, 2), "{heard:?}");
    check_retune_counts(&heard, base.mode.len());
    assert!(
        levels.windows(2).all(|w| w[1].0 == w[0].0 + 1),
        "{levels:?}"
    );
    let mut total_refits = 0;
    for &(depth, _) in &levels {
        let mut done: Vec<usize> = refits
            .iter()
            .filter(|r| r.0 == depth)
            .map(|r| r.1)
            .collect();
        done.sort_unstable();
        let total = refits.iter().find(|r| r.0 == depth).map_or(0, |r| r.2);
        assert_eq!(done, (1..=total).collect::<Vec<_>>(), "level {depth}");
        total_refits += total;
    }
    // The search's own count of joint refits (its phase table).
    let counted = d
        .search
        .phases
        .iter()
        .find(|p| p.phase == "joint refits")
        .map_or(0, |p| p.count);
    assert!(total_refits > 0);
    assert_eq!(total_refits, counted);
    // A listener changes nothing of the result.
    let quiet = diagnose_channels(&base, &data, &s, &Default::default()).unwrap();
    assert_eq!(quiet.chosen, d.chosen);
    assert_eq!(quiet.after.v, d.after.v);
}

/// The counts inside the `retune` stage (issue 34: at 1000 modes it was minutes without a
/// line): each configured mode placed once, in order (the rough placement goes mode by
/// mode), then the joint refit's iterations 1, 2, … of at most 200; all of it after the
/// `retune` stage begins and before the search's first level (or the next stage).
fn check_retune_counts(heard: &[DiagnoseProgress], modes: usize) {
    let start = heard
        .iter()
        .position(|p| *p == DiagnoseProgress::Stage("retune"))
        .unwrap();
    // The search's first level, or the next stage (a retune that explains the data ends
    // the run before any search), or the end.
    let first_level = heard
        .iter()
        .enumerate()
        .position(|(i, p)| {
            i > start
                && matches!(
                    p,
                    DiagnoseProgress::Level { .. } | DiagnoseProgress::Stage(_)
                )
        })
        .unwrap_or(heard.len());
    let (mut placed, mut iterations) = (Vec::new(), Vec::new());
    for (i, p) in heard.iter().enumerate() {
        if let DiagnoseProgress::Retune { what, done, total } = *p {
            assert!(start < i && i < first_level, "{heard:?}");
            match what {
                w if w == RETUNE_PLACING => {
                    assert_eq!(total, modes);
                    assert!(
                        iterations.is_empty(),
                        "placement after the refit: {heard:?}"
                    );
                    placed.push(done);
                }
                w if w == RETUNE_ITERATING => {
                    assert_eq!(total, 200);
                    iterations.push(done);
                }
                w => panic!("unknown retune count {w}"),
            }
        }
    }
    assert_eq!(placed, (1..=modes).collect::<Vec<_>>(), "{heard:?}");
    assert!(!iterations.is_empty(), "{heard:?}");
    assert_eq!(iterations, (1..=iterations.len()).collect::<Vec<_>>());
}

/// Three configured modes: the retune tells each placed in order.
#[test]
fn retune_counts_every_mode_placed_in_order() {
    let base = PhysicalModel {
        mode: vec![mode(300.0, 1e5), mode(600.0, 4e5), mode(1200.0, 1e6)],
        ..Default::default()
    };
    let (_, data) = case();
    let s = SearchSettings {
        max_effects: 1,
        beam: 1,
        ..Default::default()
    };
    let heard = Mutex::new(Vec::new());
    let listen = |p: DiagnoseProgress| heard.lock().unwrap().push(p);
    let options = DiagnoseOptions {
        progress: Some(&listen),
    };
    diagnose_channels(&base, &data, &s, &options).unwrap();
    check_retune_counts(&heard.into_inner().unwrap(), 3);
}

/// More output gains than real data (three modes, one datum: 3 linear slots, 2 rows, as 1000
/// modes on 200 data): the linear slots alone fit the datum, so the retune is their least
/// squares and moves no `ω_n` or `ζ` (before, every grid point and every finite-difference
/// Jacobian column was a full rank-deficient least squares: hours at 1000 modes). The cost,
/// recomputed from the model, is that exact fit's.
#[test]
fn retune_settles_when_the_linear_slots_already_fit_the_data() {
    let base = PhysicalModel {
        mode: vec![mode(300.0, 1e5), mode(600.0, 4e5), mode(1200.0, 1e6)],
        ..Default::default()
    };
    let (_, full) = case();
    let k = 20;
    let one = Channels {
        path: full.path.clone(),
        omega: vec![full.omega[k]],
        entries: full.entries.clone(),
        g: vec![vec![full.g[0][k]]],
        radius: vec![vec![full.radius[0][k]]],
        radius_source: full.radius_source.clone(),
    };
    let r = rshape::diagnose::retune(&base, &one, None, true);
    assert!(r.v_before > 1.0, "{}", r.v_before);
    assert!(r.v_after < 1e-2, "{}", r.v_after);
    assert!((rshape::diagnose::cost(&r.model, &one, &[0]) - r.v_after).abs() < 1e-6);
    for (a, b) in r.model.mode.iter().zip(&base.mode) {
        assert_eq!((a.omega_n, a.zeta), (b.omega_n, b.zeta));
    }
}

//! `diagnose_channels`'s progress (issue 34, item 9): the stages in the order they run, each
//! search level announced, every joint refit counted once (the counts agree with the
//! search's own phase table), and the result the same as without a listener.

use num_complex::Complex64;
use rshape::diagnose::{diagnose_channels, Channels, DiagnoseOptions, DiagnoseProgress};
use rshape::diagnose::{DiagnoseVerdict, SearchSettings};
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

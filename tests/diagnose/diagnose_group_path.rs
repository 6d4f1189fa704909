//! Issue 33 (stop 42's open point): the constructed two-mode group of `search::multi_mode`'s
//! tests (1 Hz lines 50–400 Hz, a configured mode at 100 Hz, missing modes at 137.3 and
//! 263.7 Hz), noise-free data, diagnosed with the noise radius ∝ |G| with and without a
//! floor.

use num_complex::Complex64;
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
use rshape::model::physical::{Gains, ModeSpec, PhysicalModel};

const TAU: f64 = std::f64::consts::TAU;

fn with_modes(modes: &[(f64, f64, f64)]) -> PhysicalModel {
    PhysicalModel {
        mode: modes
            .iter()
            .map(|&(f, zeta, rho)| ModeSpec {
                omega_n: TAU * f,
                zeta,
                mass: 1.0,
                output_gain: Gains::Scalar(rho),
                input_gain: Gains::Scalar(1.0),
                name: None,
            })
            .collect(),
        ..Default::default()
    }
}

fn data(rel: f64, floor: f64) -> Channels {
    let truth = with_modes(&[(100.0, 0.01, 1e5), (137.3, 0.005, 5e4), (263.7, 0.005, 1e5)]);
    let omega: Vec<f64> = (50..=400).map(|k| TAU * k as f64).collect();
    let g: Vec<Complex64> = omega.iter().map(|w| truth.eval(*w)[(0, 0)]).collect();
    let radius = g.iter().map(|x| rel * x.norm() + floor).collect();
    Channels {
        path: "group".into(),
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius: vec![radius],
        radius_source: vec!["test".into()],
    }
}

/// Stop 42 saw the group accepted at depth 1 and the search then choose another path when
/// the noise was ∝ |G| with no floor.  Traced on this tree (beam 3, three effects, release):
/// without a floor the group is chosen at step 1 and the best other set, three modes, is 19.7
/// behind in BIC; with the floor the next sets are single modes, far behind.  Holdout and
/// elimination keep both modes.  (Since stop 42, 55de43a stopped expanding nodes at the
/// effect budget; whether that is what changed the path is not traced here.)
#[test]
fn the_two_mode_group_is_chosen_with_and_without_a_noise_floor() {
    let truth = [(100.0, 0.01), (137.3, 0.005), (263.7, 0.005)];
    for (rel, floor) in [(0.01, 0.0), (0.01, 0.02)] {
        let d = diagnose_channels(
            &with_modes(&[(100.0, 0.01, 1e5)]),
            &data(rel, floor),
            &SearchSettings::default(),
            &Default::default(),
        )
        .unwrap();
        let ctx = format!("rel {rel} floor {floor}: {}", d.message);
        assert_eq!(d.chosen, ["mode", "mode"], "{ctx}");
        // One step: the two modes proposed together.
        assert!(d.steps.iter().all(|s| s.step == 1), "{ctx}");
        assert!(d.dropped.is_empty() && d.eliminated.is_empty(), "{ctx}");
        assert!(d.after.consistent(), "{ctx}");
        let m = &d.final_model.mode;
        assert_eq!(m.len(), 3, "{ctx}");
        for (f, z) in truth {
            assert!(
                m.iter().any(|x| (x.omega_n / (TAU * f) - 1.0).abs() < 1e-3
                    && (x.zeta / z - 1.0).abs() < 1e-2),
                "{f} Hz not found: {ctx}"
            );
        }
    }
}

//! The final-set holdout compares each chosen effect against the set *without it*.  With two
//! added modes both labelled "mode", the model "without the 810 Hz mode" must be the search's
//! node holding the 900 Hz mode, not the one holding the 810 Hz mode (issue 20 item 3: the
//! 810 Hz mode of an impact test passed with ΔBIC 5e6, then the holdout dropped it).

use num_complex::Complex64;
use rshape::diagnose::Cand;
use rshape::diagnose::Channels;
use rshape::diagnose::ErrorMeasures as Measures;
use rshape::diagnose::Node;
use rshape::diagnose::{model_of, same_set};
use rshape::model::physical::{Feedthrough, PhysicalModel};

const TAU: f64 = std::f64::consts::TAU;

use crate::common::mode_hz as mode;

fn model(modes: &[(f64, f64)]) -> PhysicalModel {
    PhysicalModel {
        feedthrough: Some(Feedthrough::Scalar(-1.2)),
        mode: modes.iter().map(|(f, r)| mode(*f, 1e-3, *r)).collect(),
        ..Default::default()
    }
}

fn theta(f_hz: f64, rho: f64) -> Vec<f64> {
    vec![(TAU * f_hz).ln(), 1e-3f64.ln(), rho]
}

fn node(effects: Vec<(Cand, Vec<f64>)>, model: PhysicalModel, v_fit: f64) -> Node {
    Node {
        effects,
        model,
        measures: Measures {
            v: v_fit,
            misfit_rms: 1.0,
            invalid_fraction: 0.5,
        },
        v_fit,
        n_params: 4,
        bic: 2.0 * v_fit,
        steps: vec![],
        configured: false,
    }
}

fn data(truth: &PhysicalModel) -> Channels {
    let omega: Vec<f64> = (0..400).map(|k| TAU * (700.0 + k as f64 * 0.75)).collect();
    let g: Vec<Complex64> = omega.iter().map(|w| truth.eval_siso(*w)).collect();
    Channels {
        path: "synthetic".into(),
        radius: vec![g.iter().map(|x| 1e-3 * x.norm()).collect()],
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius_source: vec!["synthetic".into()],
    }
}

#[test]
fn the_model_without_one_added_mode_keeps_the_other() {
    let (r810, r900) = (-8.4e6, -3.5e7);
    let d = data(&model(&[(810.0, r810), (900.0, r900)]));
    // The search kept both one-mode sets; the 810 Hz one has the lower cost.
    let nodes = vec![
        node(
            vec![(Cand::Mode, theta(810.0, r810))],
            model(&[(810.0, r810)]),
            1.0,
        ),
        node(
            vec![(Cand::Mode, theta(900.0, r900))],
            model(&[(900.0, r900)]),
            2.0,
        ),
    ];
    // Without the 810 Hz mode: the set {mode at 900 Hz}.
    let wo = model_of(&model(&[]), &[(Cand::Mode, theta(900.1, r900))], &nodes, &d);
    let f: Vec<f64> = wo.mode.iter().map(|m| m.omega_n / TAU).collect();
    assert_eq!(f.len(), 1, "{f:?}");
    assert!(
        (f[0] - 900.0).abs() < 1.0,
        "the model without the 810 Hz mode holds {f:?} Hz"
    );
    // Without the 900 Hz mode: the 810 Hz node.
    let wo = model_of(&model(&[]), &[(Cand::Mode, theta(810.2, r810))], &nodes, &d);
    assert!((wo.mode[0].omega_n / TAU - 810.0).abs() < 1.0);
}

#[test]
fn a_set_the_search_did_not_keep_is_assembled_and_refit() {
    let (r810, r900) = (-8.4e6, -3.5e7);
    let d = data(&model(&[(810.0, r810), (900.0, r900)]));
    let nodes = vec![node(
        vec![(Cand::Mode, theta(810.0, r810))],
        model(&[(810.0, r810)]),
        1.0,
    )];
    // {mode at 900 Hz} is not among the nodes: built on the root, not taken from the 810 one.
    let wo = model_of(&model(&[]), &[(Cand::Mode, theta(900.0, r900))], &nodes, &d);
    assert_eq!(wo.mode.len(), 1);
    assert!(
        (wo.mode[0].omega_n / TAU - 900.0).abs() < 2.0,
        "{:?}",
        wo.mode
    );
}

#[test]
fn same_set_is_order_free_and_tells_close_modes_apart() {
    let a = vec![
        (Cand::Mode, theta(810.0, 1.0)),
        (Cand::Mode, theta(851.0, 1.0)),
    ];
    let b = vec![
        (Cand::Mode, theta(852.0, 1.0)),
        (Cand::Mode, theta(810.5, 1.0)),
    ];
    assert!(same_set(&a, &b));
    // Close modes 5 % apart are different effects.
    let c = vec![
        (Cand::Mode, theta(810.0, 1.0)),
        (Cand::Mode, theta(810.0, 1.0)),
    ];
    assert!(!same_set(&a, &c));
    assert!(!same_set(&a, &a[..1]));
    let e = vec![
        (Cand::Mode, theta(810.0, 1.0)),
        (Cand::Feedthrough, vec![0.1]),
    ];
    assert!(!same_set(&a, &e));
}

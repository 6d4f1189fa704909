#![cfg(test)]
//! Every registered effect (a new one is covered by its registration line): its parameter
//! vectors agree in length, its name is listed once, and the model it writes (`apply_to`,
//! evaluated by `model::physical`) is the model its `modify` computes (two routes).

use crate::diagnose::effects::candidates::{Cand, Sel};
use crate::diagnose::effects::{tried, EFFECT_NAMES};
use crate::model::physical::{Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec};
use num_complex::Complex64;

/// One output, two inputs: a mode and a rigid body without friction.
fn base() -> PhysicalModel {
    PhysicalModel {
        mode: vec![ModeSpec {
            name: None,
            omega_n: 300.0,
            zeta: 0.02,
            mass: 1.0,
            input_gain: Gains::Vector(vec![1.0, -0.5]),
            output_gain: Gains::Scalar(2e4),
        }],
        rigid_body: vec![PoleAtZeroSpec {
            friction_pole: None,
            name: None,
            mass: 2.0,
            input_gain: Gains::Vector(vec![1.0, 0.3]),
            output_gain: Gains::Scalar(1.0),
        }],
        ..Default::default()
    }
}

/// Every candidate tried on `base`, and those the search does not try (gain, sign, mode
/// shift, damping), on several channel selections.
fn every_candidate(base: &PhysicalModel) -> Vec<Cand> {
    let mut v = tried(base, &[Sel::All, Sel::Input(1), Sel::Output(0)]);
    v.extend([
        Cand::Gain(Sel::Input(0)),
        Cand::Sign(Sel::All),
        Cand::ModeShift(0),
        Cand::Damping(0),
    ]);
    v
}

/// Parameters inside the candidate's box (37 % of the way up), residues of a few thousand.
fn theta(c: &Cand, n_ch: usize, w: (f64, f64)) -> Vec<f64> {
    c.bounds(n_ch, w.0, w.1, 1e-4)
        .iter()
        .enumerate()
        .map(|(i, (lo, hi))| {
            if lo.is_finite() && hi.is_finite() {
                lo + 0.37 * (hi - lo)
            } else {
                1.5e3 * (i as f64 + 1.0) * if i % 2 == 0 { 1.0 } else { -1.0 }
            }
        })
        .collect()
}

#[test]
fn every_effect_is_registered_once_with_consistent_parameters() {
    let b = base();
    let all = every_candidate(&b);
    let names: Vec<&str> = EFFECT_NAMES[1..].to_vec();
    let mut sorted = names.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!(
        sorted.len(),
        names.len(),
        "a name registered twice: {names:?}"
    );
    for name in &names {
        assert!(
            all.iter().any(|c| c.name() == *name),
            "{name} not exercised"
        );
    }
    for c in &all {
        let n = c.n_params(2);
        let th = theta(c, 2, (10.0, 3000.0));
        assert_eq!(c.bounds(2, 10.0, 3000.0, 1e-4).len(), n, "{c:?} bounds");
        assert_eq!(c.typ(&th, 3000.0).len(), n, "{c:?} typ");
        let mut nat = Vec::new();
        c.natural(&th, &mut nat);
        assert_eq!(nat.len(), n, "{c:?} natural");
        assert!(c.label().starts_with(c.name()));
        let path_effect = matches!(
            c,
            Cand::Delay(_)
                | Cand::Lag(_)
                | Cand::NmpZero(_)
                | Cand::Zoh(_)
                | Cand::Gain(_)
                | Cand::Sign(_)
        );
        assert_eq!(c.multiplicative(), path_effect, "{c:?}");
        assert!(c
            .si_params(&th, &[(0, 0), (0, 1)])
            .iter()
            .all(|p| p.1.is_finite()));
    }
}

#[test]
fn the_written_model_is_the_modified_model() {
    let b = base();
    let entries = [(0, 0), (0, 1)];
    for c in every_candidate(&b) {
        let th = theta(&c, 2, (10.0, 3000.0));
        let mut written = b.clone();
        c.apply_to(
            &th,
            &entries,
            &mut written,
            "added by rshape diagnose: test",
        );
        for omega in [12.0, 95.0, 310.0, 2400.0] {
            let g0 = b.eval_core(omega);
            let g1 = written.eval(omega);
            for (ch, e) in entries.iter().enumerate() {
                // The base has no path effect and is a receptance: path = 1.
                let (mut core, mut path) = (g0[*e], Complex64::new(1.0, 0.0));
                c.modify(&th, &b, omega, ch, *e, &mut core, &mut path);
                let (a, w) = (core * path, g1[*e]);
                assert!(
                    (a - w).norm() <= 1e-9 * a.norm().max(w.norm()),
                    "{c:?} at ω = {omega}, entry {e:?}: modify gives {a}, the written model {w}"
                );
            }
        }
    }
}

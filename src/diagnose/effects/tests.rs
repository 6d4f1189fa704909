#![cfg(test)]
//! Every registered effect (a new one is covered by its registration line): its parameter
//! vectors agree in length, its name is listed once, and the model it writes (`apply_to`,
//! evaluated by `model::physical`) is the model its `modify` computes (two routes).

use crate::diagnose::effects::candidates::{Cand, Sel};
use crate::diagnose::effects::effect::Param;
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
/// shift, damping) or not on `base` (the pseudo-mode above the band), on several channel
/// selections.
fn every_candidate(base: &PhysicalModel) -> Vec<Cand> {
    let mut v = tried(base, &[Sel::All, Sel::Input(1), Sel::Output(0)]);
    v.extend([
        Cand::Gain(Sel::Input(0)),
        Cand::Sign(Sel::All),
        Cand::ModeShift(0),
        Cand::Damping(0),
        // Tried only once the model has the upper residual.
        Cand::ResidualMode,
    ]);
    // The pseudo-mode below the band is tried: `base` has a rigid body (the lower residual).
    assert!(v.contains(&Cand::ResidualModeBelow));
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

/// True when parameter `p` exists in the written model `w` and is new or changed against
/// the base `b` (read from the two models, not from the effect).
fn new_or_changed(p: Param, b: &PhysicalModel, w: &PhysicalModel) -> bool {
    let mode = |m: &PhysicalModel, i: usize| m.mode.get(i).cloned();
    let rigid = |m: &PhysicalModel, i: usize| m.rigid_body.get(i).cloned();
    let int = |m: &PhysicalModel, i: usize| m.integrator.get(i).cloned();
    match p {
        Param::ModeOmega(i) => {
            mode(w, i).is_some_and(|x| mode(b, i).is_none_or(|y| x.omega_n != y.omega_n))
        }
        Param::ModeZeta(i) => {
            mode(w, i).is_some_and(|x| mode(b, i).is_none_or(|y| x.zeta != y.zeta))
        }
        Param::ModeInputs(i) | Param::ModeResidues(i) => {
            mode(w, i).is_some() && mode(b, i).is_none()
        }
        Param::RigidInputs(i) | Param::RigidResidues(i) => {
            rigid(w, i).is_some() && rigid(b, i).is_none()
        }
        Param::IntegratorInputs(i) | Param::IntegratorResidues(i) => {
            int(w, i).is_some() && int(b, i).is_none()
        }
        Param::FrictionPole(i) => rigid(w, i).is_some_and(|x| {
            x.friction_pole.is_some() && rigid(b, i).is_some_and(|y| y.friction_pole.is_none())
        }),
        Param::PathEffect(i) => i < w.effect.len() && i >= b.effect.len(),
        Param::Feedthrough => w.feedthrough.is_some() && b.feedthrough.is_none(),
    }
}

/// What the admissibility rules and the hold-out read of an effect (`its_mode`,
/// `term_alone`, `owns`, `apart`) is what the effect wrote: read again from the difference
/// between the written and the base model.
#[test]
fn what_admissibility_reads_is_what_the_effect_wrote() {
    let b = base();
    let entries = [(0, 0), (0, 1)];
    for c in every_candidate(&b) {
        let th = theta(&c, 2, (10.0, 3000.0));
        let mut w = b.clone();
        c.apply_to(&th, &entries, &mut w, "added by rshape diagnose: test");
        // The mode it added or changed, from the models.
        let changed = (0..w.mode.len()).find(|i| b.mode.get(*i) != Some(&w.mode[*i]));
        // A pseudo-mode above or below the band is a residual term: it writes a mode that the
        // mode rules do not judge, and owns no parameter the covariance rules would judge.
        let residual_term = matches!(c, Cand::ResidualMode | Cand::ResidualModeBelow);
        if residual_term {
            assert!(changed.is_some() && c.its_mode(&w).is_none());
        } else {
            assert_eq!(c.its_mode(&w), changed, "{c:?}");
        }
        for p in c.owns(&w) {
            assert!(
                new_or_changed(p, &b, &w),
                "{c:?} owns {p:?}, which it did not write"
            );
        }
        // Every effect with a refit parameter owns one (gain and sign have none the refit
        // moves: `lsq::slots` has no slot for them).
        let refit_free = matches!(c, Cand::Gain(_) | Cand::Sign(_));
        assert_eq!(c.owns(&w).is_empty(), refit_free || residual_term, "{c:?}");
        // Its term alone: the rigid body, integrator or friction it wrote, and nothing else.
        let term_changed = w.rigid_body != b.rigid_body || w.integrator != b.integrator;
        match c.term_alone(&w) {
            Some(alone) => {
                assert!(term_changed, "{c:?}");
                assert_eq!(alone.mode.len() + alone.effect.len(), 0, "{c:?}");
                assert_eq!(alone.rigid_body.len() + alone.integrator.len(), 1, "{c:?}");
                let g = alone.eval(50.0)[(0, 0)];
                assert!(g.is_finite() && g.norm() > 0.0, "{c:?}: {g}");
            }
            None => assert!(!term_changed, "{c:?} wrote a term it does not give alone"),
        }
        assert_eq!(c.apart(&th, &th), 0.0, "{c:?}");
    }
    // Two added modes are apart by their |Δ ln ω_n|; other effects by their target alone.
    assert_eq!(Cand::Mode.apart(&[5.0, -3.0], &[5.5, -3.0]), 0.5);
    assert_eq!(Cand::Lag(Sel::All).apart(&[5.0], &[7.0]), 0.0);
}

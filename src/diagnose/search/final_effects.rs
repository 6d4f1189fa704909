//! The chosen effects as they stand in the final, jointly refit model: one entry per chosen
//! effect, in the order added, with its refit parameters and their standard deviations
//! (`cov = (2JᵀJ)⁻¹` over every refit parameter, [`crate::diagnose::changes`]).
//!
//! Added terms and path effects follow the configured ones in every list (the modes put there
//! by [`crate::diagnose::search::assign::align`], matched to the configured modes by frequency and shape, never
//! by slot); the k-th chosen effect with a label is the k-th **added** term with that note.  A
//! term the input already had is never reported as added, whatever its note says (a revision
//! written by `diagnose` keeps the notes of its earlier steps).  Effects that change a
//! configured term (mode shift, damping, friction) are read from that term; a feedthrough
//! from `D`.  A gain or sign effect has no refit parameter of its own (a gain error is
//! absorbed in the residues), so no σ.  MIMO residues `ρ_oi = c_o b_i / m` get the σ of
//! `c_o` (the input gain's share is left out).

use crate::diagnose::changes::slot_sigmas;
use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::effects::candidates::ADDED_NOTE;
use crate::diagnose::effects::effect::Stands;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::slots::{slots, Lin, Nl, Term};
use crate::diagnose::report::FinalEffect;
use crate::model::physical::{EffectKind, Feedthrough, PhysicalModel};
use std::collections::BTreeMap;

/// σ of the slots of a model, looked up by slot.
struct Sigmas {
    lin: Vec<Lin>,
    nl: Vec<Nl>,
    sig: Vec<f64>,
}

impl Sigmas {
    fn of_lin(&self, f: impl Fn(&Lin) -> bool) -> Option<f64> {
        self.lin.iter().position(f).map(|j| self.sig[j])
    }
    fn of_nl(&self, f: impl Fn(&Nl) -> bool) -> Option<f64> {
        self.nl
            .iter()
            .position(f)
            .map(|j| self.sig[self.lin.len() + j])
    }
}

fn note_is(note: &Option<String>, label: &str) -> bool {
    note.as_deref()
        .and_then(|n| n.strip_prefix(ADDED_NOTE))
        .is_some_and(|n| n.trim_start_matches(": ") == label)
}

/// The chosen `effects` (in the order added) with their parameters in the final model `m`
/// (SI, rad/s), and with `with_sigma` their standard deviations on `data`; `base` is the
/// configured model (its terms and effects are not the added ones).
pub fn final_effects(
    m: &PhysicalModel,
    base: &PhysicalModel,
    effects: &[Cand],
    data: &Channels,
    with_sigma: bool,
) -> Vec<FinalEffect> {
    let sig = with_sigma.then(|| {
        let (lin, nl) = slots(m, data);
        let sig = slot_sigmas(m, &lin, &nl, data);
        Sigmas { lin, nl, sig }
    });
    let (p, n_in) = (m.n_outputs(), m.n_inputs());
    let siso = p * n_in == 1;
    let mut out = Vec::new();
    for (k, c) in effects.iter().enumerate() {
        let label = c.label();
        // The occurrence of this label among the chosen effects.
        let nth = effects[..k].iter().filter(|x| x.label() == label).count();
        let mut params = BTreeMap::new();
        let mut sigma = BTreeMap::new();
        let mut put = |name: String, v: f64, s: Option<f64>| {
            if let Some(s) = s.filter(|s| s.is_finite()) {
                sigma.insert(name.clone(), s.abs());
            }
            params.insert(name, v);
        };
        let mode_params = |i: usize, put: &mut dyn FnMut(String, f64, Option<f64>)| {
            let md = &m.mode[i];
            let sw = sig
                .as_ref()
                .and_then(|s| s.of_nl(|x| matches!(x, Nl::ModeW(j) if *j == i)));
            let sz = sig
                .as_ref()
                .and_then(|s| s.of_nl(|x| matches!(x, Nl::ModeZ(j) if *j == i)));
            put("omega_n".into(), md.omega_n, sw.map(|s| s * md.omega_n));
            put("zeta".into(), md.zeta, sz.map(|s| s * md.zeta));
        };
        let residues = |t: Term, put: &mut dyn FnMut(String, f64, Option<f64>), name: &str| {
            let (cg, bg, mass) = crate::diagnose::lsq::slots::gains_of(m, t);
            let (cv, bv) = (cg.to_vec(p), bg.to_vec(n_in));
            for (o, co) in cv.iter().enumerate() {
                let so = sig.as_ref().and_then(|s| {
                    s.of_lin(|x| matches!(x, Lin::Out(tt, oo) if *tt == t && *oo == o))
                });
                for (i, bi) in bv.iter().enumerate() {
                    let n = if siso {
                        name.to_string()
                    } else {
                        format!("{name}_{}_{}", o + 1, i + 1)
                    };
                    put(n, co * bi / mass, so.map(|s| s * bi / mass));
                }
            }
        };
        match c.stands() {
            Stands::AddedMode => {
                let idx = m
                    .mode
                    .iter()
                    .enumerate()
                    .skip(base.mode.len())
                    .filter(|(_, x)| note_is(&x.name, &label));
                if let Some((i, _)) = idx.clone().nth(nth) {
                    mode_params(i, &mut put);
                    residues(Term::Mode(i), &mut put, "rho");
                }
            }
            Stands::ConfiguredMode(i) => {
                if i < m.mode.len() {
                    put("mode".into(), (i + 1) as f64, None);
                    mode_params(i, &mut put);
                }
            }
            Stands::FrictionPole(i) => {
                put("rigid_body".into(), (i + 1) as f64, None);
                if let Some(x) = m.rigid_body.get(i).and_then(|r| r.friction_pole) {
                    let s = sig
                        .as_ref()
                        .and_then(|s| s.of_nl(|y| matches!(y, Nl::RigidPole(j) if *j == i)));
                    put("pole".into(), x, s.map(|s| s * x));
                }
            }
            Stands::AddedPoleAtZero(order) => {
                let (list, term, n_base): (&[_], fn(usize) -> Term, _) = if order == 2 {
                    (&m.rigid_body, Term::Rigid, base.rigid_body.len())
                } else {
                    (&m.integrator, Term::Int, base.integrator.len())
                };
                let found = list
                    .iter()
                    .enumerate()
                    .skip(n_base)
                    .filter(|(_, r)| note_is(&r.name, &label))
                    .nth(nth);
                if let Some((i, _)) = found {
                    put("order".into(), order as f64, None);
                    residues(term(i), &mut put, "c");
                }
            }
            Stands::Feedthrough => {
                let d = |o: usize, i: usize| match &m.feedthrough {
                    Some(Feedthrough::Scalar(x)) => *x,
                    Some(Feedthrough::Matrix(r)) => r[o][i],
                    None => 0.0,
                };
                for (o, i) in &data.entries {
                    let s = sig.as_ref().and_then(|s| {
                        s.of_lin(|x| matches!(x, Lin::Feed(oo, ii) if (*oo, *ii) == (*o, *i)))
                    });
                    let n = if siso {
                        "d".to_string()
                    } else {
                        format!("d_{}_{}", o + 1, i + 1)
                    };
                    put(n, d(*o, *i), s);
                }
            }
            Stands::AddedPathEffect => {
                let found = m
                    .effect
                    .iter()
                    .enumerate()
                    .skip(base.effect.len())
                    .filter(|(_, e)| note_is(&e.note, &label))
                    .nth(nth);
                if let Some((i, e)) = found {
                    let s = sig.as_ref().and_then(|s| {
                        s.of_nl(|x| matches!(x, Nl::Delay(j) | Nl::LogEffect(j) if *j == i))
                    });
                    let (name, v, log) = match e.kind {
                        EffectKind::Delay => ("tau_s", e.tau_s, false),
                        EffectKind::Lag => ("omega_c", e.omega_c, true),
                        EffectKind::NmpZero => ("z", e.z, true),
                        EffectKind::Zoh => ("t_s", e.t_s, true),
                        EffectKind::Gain => ("k", e.k, false),
                        EffectKind::Sign => ("k", Some(-1.0), false),
                    };
                    let v = v.unwrap_or(f64::NAN);
                    let s = match e.kind {
                        EffectKind::Gain | EffectKind::Sign => None,
                        _ if log => s.map(|s| s * v),
                        _ => s,
                    };
                    put(name.into(), v, s);
                }
            }
        }
        if matches!(c, Cand::ResidualMode | Cand::ResidualModeBelow) {
            // A residual term: its damping is where the refit left it above the band, not a
            // measured damping; it is not reported.
            params.remove("zeta");
            sigma.remove("zeta");
        }
        out.push(FinalEffect {
            effect: label,
            params,
            sigma,
        });
    }
    out
}

//! The covariance rules of [`super::check`]: a defining parameter of the effect (its own
//! parameters, [`crate::diagnose::effects::effect::Effect::owns`]) that the refit's
//! covariance `(2JᵀJ)⁻¹` does not determine, or that is correlated with another term's.

use super::{Child, MAX_CORRELATION, MAX_REL_SIGMA, MIN_LINES_IN_BAND};
use crate::diagnose::changes::slot_covariance;
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::effects::effect::Param;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::slots::{slots, Lin, Nl, Term};
use crate::model::physical::PhysicalModel;

/// The model parameter a nonlinear slot fits.
fn nl_param(s: &Nl) -> Param {
    match *s {
        Nl::ModeW(i) => Param::ModeOmega(i),
        Nl::ModeZ(i) => Param::ModeZeta(i),
        Nl::RigidPole(i) => Param::FrictionPole(i),
        Nl::In(Term::Mode(i), _) => Param::ModeInputs(i),
        Nl::In(Term::Rigid(i), _) => Param::RigidInputs(i),
        Nl::In(Term::Int(i), _) => Param::IntegratorInputs(i),
        Nl::Delay(i) | Nl::LogEffect(i) => Param::PathEffect(i),
    }
}

/// The model parameter a linear slot fits.
fn lin_param(s: &Lin) -> Param {
    match *s {
        Lin::Out(Term::Mode(i), _) => Param::ModeResidues(i),
        Lin::Out(Term::Rigid(i), _) => Param::RigidResidues(i),
        Lin::Out(Term::Int(i), _) => Param::IntegratorResidues(i),
        Lin::Feed(..) => Param::Feedthrough,
    }
}

/// The defining parameters of a slot (the ones whose relative σ decides): frequencies,
/// dampings, poles and delays (not the gains of an input).
fn defining(s: &Nl) -> bool {
    matches!(
        s,
        Nl::ModeW(_) | Nl::ModeZ(_) | Nl::RigidPole(_) | Nl::Delay(_) | Nl::LogEffect(_)
    )
}

fn slot_name(m: &PhysicalModel, s: &Nl) -> String {
    match s {
        Nl::ModeW(i) => format!(
            "ω_n of the mode at {} Hz",
            sig(m.mode[*i].omega_n / std::f64::consts::TAU)
        ),
        Nl::ModeZ(i) => format!(
            "ζ of the mode at {} Hz",
            sig(m.mode[*i].omega_n / std::f64::consts::TAU)
        ),
        Nl::RigidPole(i) => format!("the friction pole of rigid body {}", i + 1),
        Nl::Delay(i) => format!("the delay of effect {}", i + 1),
        Nl::LogEffect(i) => format!("the corner of effect {}", i + 1),
        Nl::In(..) => "an input gain".into(),
    }
}

/// The covariance rules (see the module docs).
pub(super) fn not_identified(c: &Child<'_>, data: &Channels) -> Option<String> {
    let m = c.model;
    let (lin, nl) = slots(m, data);
    let (sigma, corr) = slot_covariance(m, &lin, &nl, data);
    let nlin = lin.len();
    let owns = c.cand.owns(m);
    let own_nl = |s: &Nl| owns.contains(&nl_param(s));
    let own_lin = |s: &Lin| owns.contains(&lin_param(s));
    // A mode narrower than the lines (fewer than 3 in its half-power band, seen on its flanks,
    // else `check` refused it as unresolved): its ζ is bounded by the record, not measured;
    // the mode is defined by ω_n and its residues.
    let zeta_unresolved = |i: usize| {
        let md = &m.mode[i];
        let (lo, hi) = (md.omega_n * (1.0 - md.zeta), md.omega_n * (1.0 + md.zeta));
        data.omega.iter().filter(|x| **x >= lo && **x <= hi).count() < MIN_LINES_IN_BAND
    };
    for (j, s) in nl.iter().enumerate() {
        if !own_nl(s) || !defining(s) {
            continue;
        }
        if matches!(s, Nl::ModeZ(i) if zeta_unresolved(*i)) {
            continue;
        }
        // Log-parameters: σ is relative already; a delay's is divided by τ.
        let rel = match s {
            Nl::Delay(i) => sigma[nlin + j] / m.effect[*i].tau_s.unwrap_or(0.0).abs(),
            _ => sigma[nlin + j],
        };
        if rel.is_nan() || rel > MAX_REL_SIGMA {
            return Some(format!(
                "{} has a relative σ of {} (> 1/3): the data do not determine it",
                slot_name(m, s),
                if rel.is_finite() {
                    sig(rel)
                } else {
                    "∞".into()
                }
            ));
        }
        let Some(corr) = &corr else { continue };
        for (q, t) in nl.iter().enumerate() {
            if own_nl(t) {
                continue;
            }
            let r = corr[(nlin + j, nlin + q)];
            if r.abs() > MAX_CORRELATION {
                return Some(format!(
                    "{} is correlated {} with {}: the data cannot tell them apart",
                    slot_name(m, s),
                    sig(r),
                    slot_name(m, t)
                ));
            }
        }
        for (q, t) in lin.iter().enumerate() {
            if own_lin(t) {
                continue;
            }
            let r = corr[(nlin + j, q)];
            if r.abs() > MAX_CORRELATION {
                return Some(format!(
                    "{} is correlated {} with a residue of another term: the data cannot tell them apart",
                    slot_name(m, s),
                    sig(r),
                ));
            }
        }
    }
    None
}

//! What a retune moved: the configured parameters whose refit value differs from the
//! configured one by more than 3σ, with σ from the Fisher information of the complex-Gaussian
//! likelihood at the refit, `cov = (2JᵀJ)⁻¹` (`V = ‖r(θ)‖²` is `−ln L`, `J = ∂r/∂θ` over
//! every refit parameter, linear and nonlinear, so the σ of a configured parameter accounts
//! for its correlation with every other one, added effects included).
//!
//! Parameter paths are 1-based: `rigid_body[1].mass` (SISO: the effective mass `m/(c·b)` of
//! the line `1/(m s²)`), `integrator[1].gain`, `mode[2].omega_n`, `mode[1].zeta`,
//! `mode[1].rho` (SISO residue `c·b/m` of `ρ/(s² + 2ζω_n s + ω_n²)`), `mode[1].output_gain[2]`
//! (MIMO), `feedthrough`, `effect[1].tau_s`…
//!
//! "More than 3σ" is family-wise: with `n` configured parameters tested, the threshold is
//! `k σ` with `P(|z| > k) = 0.0027/n` (3σ for one parameter, 3.55σ for seven, 3.82σ for twenty), so the right
//! model moves nothing with the one-parameter 3σ false-alarm rate, 0.27 %; the threshold
//! used is reported as `threshold_sigmas`.  σ is calibrated: on the motor of
//! `tests/diagnose_retune_changes.rs`, 200 noise draws give a spread of ζ₁ of 6.8e-5 against
//! σ = 7.5e-5 (noise uniform in the disks, whose variance `r²/2` the likelihood assumes).
//!
//! When every gain of the model (rigid-body masses, integrator gains, mode residues) moved
//! by one common factor `k`, the move is one effect, a gain error: it is reported once as
//! `gain` (before 1, after `k`) with the parameters it covers in [`CommonGain`].

use crate::diagnose::lsq::channels::Channels;
pub(crate) use crate::diagnose::lsq::covariance::{slot_covariance, slot_sigmas};
use crate::diagnose::lsq::slots::{gains_of, get_lin, get_nl, slots, Lin, Nl, Term};
use crate::model::physical::PhysicalModel;
use serde::Serialize;

/// A configured parameter the refit moved by more than 3σ (family-wise).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ParamChange {
    /// Path such as `rigid_body[1].mass`, `mode[2].omega_n` or `gain` (a common factor).
    pub parameter: String,
    /// Configured value.
    pub before: f64,
    /// Refit value.
    pub after: f64,
    /// One standard deviation of the refit value.
    pub sigma: f64,
}

/// Every gain of the model moved by one factor.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct CommonGain {
    /// The factor (refit gain over configured gain).
    pub factor: f64,
    /// Its standard deviation.
    pub sigma: f64,
    /// The gain parameters it covers.
    pub parameters: Vec<String>,
}

/// The moves of a refit: `changes` (the common gain, if any, as one entry `gain`).
#[derive(Debug, Clone, Serialize, Default, PartialEq)]
pub struct Changes {
    /// Configured parameters moved by more than `threshold_sigmas` σ (and 0.1 %).
    pub changes: Vec<ParamChange>,
    /// The common gain factor, when every gain moved by one (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub common_gain: Option<CommonGain>,
    /// The threshold in σ a move had to exceed (3σ corrected for the number of parameters).
    pub threshold_sigmas: f64,
    /// Said when the refit's output gains (linear slots) are at least as many as the data's
    /// real values: they alone fit the data, so the refit identified no frequency or
    /// damping (the retune is "settled" on them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settled: Option<String>,
}

/// The two-sided tail of 3σ: the false-alarm rate of one parameter.
const TAIL_3SIGMA: f64 = 0.0027;

/// `erfc(x)` for `x ≥ 0` (Numerical Recipes' Chebyshev fit, relative error < 1.2e-7).
fn erfc(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.5 * x);
    let p = -x * x - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398
                                + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    t * p.exp()
}

/// The threshold in σ that keeps the family-wise false-alarm rate of `n` parameters at the
/// one-parameter 3σ rate (Bonferroni: `P(|z| > k) = 0.0027/n`); 3 for one parameter.
pub fn threshold_sigmas(n: usize) -> f64 {
    let target = TAIL_3SIGMA / n.max(1) as f64;
    let (mut lo, mut hi) = (2.5f64, 10.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if erfc(mid / std::f64::consts::SQRT_2) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Moves smaller than this (relative) are numerical, whatever σ says (noise-free data).
const MIN_REL_MOVE: f64 = 1e-3;
/// Gains agreeing with the common factor within this (relative) or 3σ share it.
const COMMON_REL_TOL: f64 = 0.01;

/// One slot of `m` as a named physical parameter.
struct Param {
    name: String,
    /// Physical value.
    value: f64,
    /// `d value / d slot coordinate`.
    dvalue: f64,
    /// A gain (proportional to its slot, a mass inversely).
    gain: bool,
}

fn siso(m: &PhysicalModel) -> bool {
    m.n_outputs() * m.n_inputs() == 1
}

fn term_name(t: Term) -> String {
    match t {
        Term::Rigid(i) => format!("rigid_body[{}]", i + 1),
        Term::Int(i) => format!("integrator[{}]", i + 1),
        Term::Mode(i) => format!("mode[{}]", i + 1),
    }
}

fn lin_param(m: &PhysicalModel, s: Lin) -> Param {
    let x = get_lin(m, s);
    match s {
        Lin::Out(t, o) => {
            let (_, b, mass) = gains_of(m, t);
            let b = b.to_vec(m.n_inputs())[0];
            if siso(m) {
                match t {
                    Term::Rigid(_) => {
                        let v = mass / (x * b);
                        Param {
                            name: format!("{}.mass", term_name(t)),
                            value: v,
                            dvalue: -v / x,
                            gain: true,
                        }
                    }
                    Term::Int(_) => Param {
                        name: format!("{}.gain", term_name(t)),
                        value: x * b / mass,
                        dvalue: b / mass,
                        gain: true,
                    },
                    Term::Mode(_) => Param {
                        name: format!("{}.rho", term_name(t)),
                        value: x * b / mass,
                        dvalue: b / mass,
                        gain: true,
                    },
                }
            } else {
                Param {
                    name: format!("{}.output_gain[{}]", term_name(t), o + 1),
                    value: x,
                    dvalue: 1.0,
                    gain: true,
                }
            }
        }
        Lin::Feed(o, i) => Param {
            name: if siso(m) {
                "feedthrough".into()
            } else {
                format!("feedthrough[{}][{}]", o + 1, i + 1)
            },
            value: x,
            dvalue: 1.0,
            gain: false,
        },
    }
}

fn nl_param(m: &PhysicalModel, s: Nl) -> Param {
    let x = get_nl(m, s);
    let log = |name: String| Param {
        name,
        value: x.exp(),
        dvalue: x.exp(),
        gain: false,
    };
    match s {
        Nl::ModeW(i) => log(format!("mode[{}].omega_n", i + 1)),
        Nl::ModeZ(i) => log(format!("mode[{}].zeta", i + 1)),
        Nl::RigidPole(i) => log(format!("rigid_body[{}].friction_pole", i + 1)),
        Nl::In(t, i) => Param {
            name: format!("{}.input_gain[{}]", term_name(t), i + 1),
            value: x,
            dvalue: 1.0,
            gain: false,
        },
        Nl::Delay(i) => Param {
            name: format!("effect[{}].tau_s", i + 1),
            value: x,
            dvalue: 1.0,
            gain: false,
        },
        Nl::LogEffect(i) => log(format!(
            "effect[{}].{}",
            i + 1,
            m.effect[i].log_param_name().unwrap_or("parameter")
        )),
    }
}

/// True when slot `s` of the refit model is a configured parameter of `base` (configured
/// terms and effects come first in every list; added ones are named [`crate::diagnose::effects::candidates::ADDED_NOTE`]).
fn configured_lin(base: &PhysicalModel, s: Lin) -> bool {
    match s {
        Lin::Out(t, _) => configured_term(base, t),
        Lin::Feed(..) => base.feedthrough.is_some(),
    }
}

fn configured_term(base: &PhysicalModel, t: Term) -> bool {
    match t {
        Term::Rigid(i) => i < base.rigid_body.len(),
        Term::Int(i) => i < base.integrator.len(),
        Term::Mode(i) => i < base.mode.len(),
    }
}

fn configured_nl(base: &PhysicalModel, m: &PhysicalModel, s: Nl) -> bool {
    match s {
        Nl::ModeW(i) | Nl::ModeZ(i) => i < base.mode.len(),
        Nl::RigidPole(i) => base
            .rigid_body
            .get(i)
            .is_some_and(|r| r.friction_pole.is_some_and(|p| p > 0.0)),
        Nl::In(t, _) => configured_term(base, t),
        Nl::Delay(i) | Nl::LogEffect(i) => base
            .effect
            .get(i)
            .is_some_and(|e| e.kind == m.effect[i].kind && get_nl(base, s).is_finite()),
    }
}

/// The configured parameters of `base` that the refit model `refit` (configured terms first,
/// possibly with added effects) moved by more than 3σ, σ at `refit` on `data`.
pub fn changes(base: &PhysicalModel, refit: &PhysicalModel, data: &Channels) -> Changes {
    let (lin, nl) = slots(refit, data);
    let values = 2 * data.len() * data.n_ch();
    let settled = (!nl.is_empty() && lin.len() >= values).then(|| {
        format!(
            "the model has {} output gains for {values} real data values: the refit solved for the gains alone (least norm) and identified no frequency or damping (ω_n and ζ kept as configured); more lines, or fewer modes, would identify them",
            lin.len()
        )
    });
    let sig = slot_sigmas(refit, &lin, &nl, data);
    // (param after, param before, σ of the physical value, relative σ of the gain).
    let mut rows: Vec<(Param, f64, f64, f64)> = Vec::new();
    for (j, s) in lin.iter().enumerate() {
        if !configured_lin(base, *s) {
            continue;
        }
        let after = lin_param(refit, *s);
        let sd = (after.dvalue * sig[j]).abs();
        let rel = sig[j] / get_lin(refit, *s).abs();
        rows.push((after, lin_param(base, *s).value, sd, rel));
    }
    for (j, s) in nl.iter().enumerate() {
        if !configured_nl(base, refit, *s) {
            continue;
        }
        let after = nl_param(refit, *s);
        let sd = (after.dvalue * sig[lin.len() + j]).abs();
        rows.push((after, nl_param(base, *s).value, sd, f64::INFINITY));
    }
    let k_sig = threshold_sigmas(rows.len());
    let moved = |p: &Param, before: f64, sd: f64| {
        let d = (p.value - before).abs();
        d.is_finite()
            && d > k_sig * sd
            && d > MIN_REL_MOVE * p.value.abs().max(before.abs())
            && before.is_finite()
    };
    // A common gain factor: every gain (as a ratio to its configured value, a mass as the
    // inverse ratio) agrees with their weighted mean.
    let gains: Vec<(String, f64, f64)> = rows
        .iter()
        .filter(|r| r.0.gain)
        .map(|(p, before, _, rel)| {
            let ratio = if p.name.ends_with(".mass") {
                before / p.value
            } else {
                p.value / before
            };
            (p.name.clone(), ratio, rel * ratio.abs())
        })
        .collect();
    let mut common = None;
    if gains.len() >= 2 && gains.iter().all(|g| g.1.is_finite() && g.2.is_finite()) {
        let wsum: f64 = gains.iter().map(|g| 1.0 / g.2.powi(2).max(1e-300)).sum();
        let k = gains
            .iter()
            .map(|g| g.1 / g.2.powi(2).max(1e-300))
            .sum::<f64>()
            / wsum;
        let sk = wsum.sqrt().recip();
        let agree = gains
            .iter()
            .all(|g| (g.1 - k).abs() <= (3.0 * g.2).max(COMMON_REL_TOL * k.abs()));
        if agree && (k - 1.0).abs() > (k_sig * sk).max(MIN_REL_MOVE) {
            common = Some(CommonGain {
                factor: k,
                sigma: sk,
                parameters: gains.iter().map(|g| g.0.clone()).collect(),
            });
        }
    }
    let mut out = Vec::new();
    if let Some(c) = &common {
        out.push(ParamChange {
            parameter: "gain".into(),
            before: 1.0,
            after: c.factor,
            sigma: c.sigma,
        });
    }
    for (p, before, sd, _) in rows {
        if (common.is_some() && p.gain) || !moved(&p, before, sd) {
            continue;
        }
        out.push(ParamChange {
            parameter: p.name,
            before,
            after: p.value,
            sigma: sd,
        });
    }
    Changes {
        changes: out,
        common_gain: common,
        threshold_sigmas: k_sig,
        settled,
    }
}

impl Changes {
    /// One line: `gain ×1.15 (…); mode[2].omega_n 1194 → 1265 (σ 0.4)`.
    pub fn summary(&self) -> String {
        self.changes
            .iter()
            .map(|c| match (&self.common_gain, c.parameter.as_str()) {
                (Some(g), "gain") => format!(
                    "gain ×{} ± {} (common to {})",
                    crate::report::fmt::sig(g.factor),
                    crate::report::fmt::sig(g.sigma),
                    g.parameters.join(", ")
                ),
                _ => format!(
                    "{} {} → {} (σ {})",
                    c.parameter,
                    crate::report::fmt::sig(c.before),
                    crate::report::fmt::sig(c.after),
                    crate::report::fmt::sig(c.sigma)
                ),
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}

#[cfg(test)]
mod tests {
    use super::{changes, threshold_sigmas};
    use crate::diagnose::lsq::channels::Channels;
    use crate::model::physical::{Gains, ModeSpec, PhysicalModel};

    /// Three modes on two lines (4 real values, 3 output gains): not settled; on one line
    /// (2 real values): settled, and said so (no frequency or damping identified).
    #[test]
    fn a_refit_with_more_gains_than_data_values_says_it_identified_no_frequency() {
        let mode = |w: f64| ModeSpec {
            name: None,
            omega_n: w,
            zeta: 0.02,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(1e4),
        };
        let m = PhysicalModel {
            mode: vec![mode(100.0), mode(300.0), mode(900.0)],
            ..Default::default()
        };
        let data =
            |omega: Vec<f64>| Channels::of_model(&m, omega, vec![(0, 0)], 1.05, (0.01, 1e-6));
        let two = changes(&m, &m, &data(vec![150.0, 600.0]));
        assert!(two.settled.is_none(), "{:?}", two.settled);
        let one = changes(&m, &m, &data(vec![150.0]));
        let note = one.settled.expect("settled");
        assert!(
            note.contains("3 output gains for 2 real data values")
                && note.contains("identified no frequency or damping"),
            "{note}"
        );
    }

    /// Against scipy's `norm.isf(0.0027/n/2)`: 2.99998, 3.54967, 3.81715.
    #[test]
    fn family_wise_threshold_matches_the_normal_quantile() {
        for (n, k) in [(1, 2.999_977), (7, 3.549_67), (20, 3.817_15)] {
            assert!(
                (threshold_sigmas(n) - k).abs() < 2e-3,
                "{n}: {}",
                threshold_sigmas(n)
            );
        }
    }
}

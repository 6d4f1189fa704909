//! Physical admissibility of an effect, checked on the **joint refit** that would add it
//! (issue 33): a term the likelihood wants but no structure has is refused, and the
//! refusal names its rule.  The rules (shared/design/physical-modes.md):
//!
//! * **mains** — a mode within the frequency resolution (half the local line spacing, or its
//!   own half-power half-width) of 50 or 60 Hz or a harmonic, narrower than one line: probable
//!   electrical interference, applied only when asked (`allow_mains`);
//! * **broad** — a "resonance" with `ζ > 0.2` is a broad term (a residual, a compromise
//!   between bands), not a mode;
//! * **unresolved** — fewer than 3 data lines in the half-power band `ω_n(1 ± ζ)`: `ζ` and
//!   `ω_n` are not identified there; measure denser lines around `f`;
//! * **artefact** — two modes whose half-power bands overlap and whose residues largely
//!   cancel (`‖ρ_a + ρ_b‖ < ½ max ‖ρ‖`) model a derivative (a shifted or broadened peak), not
//!   two modes; a mode whose contribution at the lines around it exceeds the data's magnitude
//!   there by more than 10× is not what the data show;
//! * **artefact** (terms) — a rigid body, integrator or friction term whose own contribution
//!   exceeds the data's largest magnitude 10× (it fits only by cancelling another term);
//! * **negligible** — a delay whose phase `ω_max τ` at the band top (a lag's, an NMP zero's,
//!   a hold's phase there) is below the noise's phase resolution there (`asin(r/|G|)`,
//!   median over the top n lines (5 % of them, at most 20), divided by √n), a friction pole whose
//!   relative effect at the band bottom `p/ω_min` is below the noise's relative resolution
//!   there (`r/|G|`), or any effect whose removal changes `misfit_rms` by less than 1 %
//!   (unless it is what makes the model consistent), whatever its ΔBIC;
//! * **not identified** — from the refit's covariance `(2JᵀJ)⁻¹`: a defining parameter of
//!   the effect (`ω_n`, `ζ`, a pole, a delay) with relative σ > 1/3, or correlated above 0.99
//!   with a parameter of another term.  The `ζ` of a mode narrower than the lines (seen on its
//!   flanks only) is not judged: the record bounds it, it cannot measure it.

use crate::diagnose::changes::slot_covariance;
use crate::diagnose::effects::candidates::{sig, Cand};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::slots::{slots, Lin, Nl, Term};
use crate::model::physical::PhysicalModel;
use serde::Serialize;

/// A mode above this damping is a broad term.
pub const BROAD_ZETA: f64 = 0.2;
/// Fewest data lines in a mode's half-power band.
pub use super::lsq::resolution::MIN_LINES_IN_BAND;
/// A mode's peak may exceed the data's magnitude there by at most this factor.
pub const MAX_PEAK_OVER_DATA: f64 = 10.0;
/// Residues of overlapping modes cancel when `‖ρ_a + ρ_b‖` is below this share of the larger.
pub const CANCEL_SHARE: f64 = 0.5;
/// An effect whose removal changes `misfit_rms` by less than this share is negligible
/// (unless it makes the model consistent).
pub const NEGLIGIBLE_RMS: f64 = 0.01;
/// Largest relative σ of a defining parameter.
pub const MAX_REL_SIGMA: f64 = 1.0 / 3.0;
/// Largest correlation with another term's parameter.
pub const MAX_CORRELATION: f64 = 0.99;
/// Mains frequencies, Hz.
pub const MAINS_HZ: [f64; 2] = [50.0, 60.0];

/// The rule a refusal falls under.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Rule {
    /// Probable electrical interference.
    Mains,
    /// ζ > 0.2.
    Broad,
    /// Fewer than 3 lines in the half-power band.
    Unresolved,
    /// A cancelling pair, or a peak far above the data.
    Artefact,
    /// Too small to matter.
    Negligible,
    /// The covariance does not determine it.
    NotIdentified,
}

impl Rule {
    /// The word the report uses.
    pub fn word(&self) -> &'static str {
        match self {
            Rule::Mains => "mains",
            Rule::Broad => "broad term",
            Rule::Unresolved => "unresolved",
            Rule::Artefact => "modelling artefact",
            Rule::Negligible => "negligible",
            Rule::NotIdentified => "not identified",
        }
    }
}

/// Why an effect was not added.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Refusal {
    /// The effect (`mode`, `delay (input 2)`, …).
    pub effect: String,
    /// Its frequency (Hz) when it is a mode (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency_hz: Option<f64>,
    /// The rule.
    pub rule: Rule,
    /// The reason, in words.
    pub reason: String,
}

/// What [`check`] needs.
pub struct Child<'a> {
    /// The effect added.
    pub cand: Cand,
    /// The jointly refit model with it (modes aligned: configured first, the new one last).
    pub model: &'a PhysicalModel,
    /// Its measures.
    pub measures: &'a Measures,
    /// The measures of the model it is compared against (the parent, or the retune).
    pub reference: &'a Measures,
    /// Write modes at mains frequencies anyway.
    pub allow_mains: bool,
}

/// The index of the added mode of `c` in the model, when it adds or changes one.
fn mode_index(c: &Child<'_>) -> Option<usize> {
    match c.cand {
        Cand::Mode => c.model.mode.len().checked_sub(1),
        Cand::ModeShift(i) | Cand::Damping(i) => Some(i),
        _ => None,
    }
}

/// Median of a non-empty list (NaN for an empty one).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The local line spacing at `w` (rad/s): the gap between the lines around it.
fn spacing_at(omega: &[f64], w: f64) -> f64 {
    let k = omega.partition_point(|x| *x < w);
    match (k.checked_sub(1).map(|j| omega[j]), omega.get(k)) {
        (Some(a), Some(b)) => b - a,
        (Some(a), None) if k >= 2 => a - omega[k - 2],
        (None, Some(b)) if omega.len() > k + 1 => omega[k + 1] - b,
        _ => f64::INFINITY,
    }
}

/// The refusal of the child, if any (see the module docs), cheapest rules first.
pub fn check(c: &Child<'_>, data: &Channels) -> Option<Refusal> {
    let label = c.cand.label();
    let refuse = |f: Option<f64>, rule: Rule, reason: String| {
        Some(Refusal {
            effect: label.clone(),
            frequency_hz: f,
            rule,
            reason,
        })
    };
    let om = &data.omega;
    if let Some(k) = mode_index(c) {
        let md = &c.model.mode[k];
        let (w, z) = (md.omega_n, md.zeta);
        let f = w / std::f64::consts::TAU;
        let fo = Some(f);
        // Mains: a line-narrow resonance at 50/60 Hz or a harmonic.
        let df = spacing_at(om, w) / std::f64::consts::TAU;
        if !c.allow_mains && z * f < df {
            let tol = (0.5 * df).max(z * f);
            for f0 in MAINS_HZ {
                let h = (f / f0).round().max(1.0);
                if (f - h * f0).abs() <= tol {
                    return refuse(
                        fo,
                        Rule::Mains,
                        format!(
                            "at {} Hz, within the resolution ({} Hz) of {} Hz ({}× {f0} Hz mains) and narrower than a line: probable electrical interference, not a mode of the structure (--allow-mains writes it)",
                            sig(f),
                            sig(tol),
                            sig(h * f0),
                            h
                        ),
                    );
                }
            }
        }
        if z > BROAD_ZETA {
            return refuse(
                fo,
                Rule::Broad,
                format!(
                    "ζ = {} > {BROAD_ZETA} at {} Hz: a broad term absorbing misfit over a band, not a resonance",
                    sig(z),
                    sig(f)
                ),
            );
        }
        let (lo, hi) = (w * (1.0 - z), w * (1.0 + z));
        let n_in = om.iter().filter(|x| **x >= lo && **x <= hi).count();
        if n_in < MIN_LINES_IN_BAND && !residual_peaks_at(c.model, k, data) {
            return refuse(
                fo,
                Rule::Unresolved,
                format!(
                    "{n_in} data line{} in its half-power band {}–{} Hz (ζ = {}; needs {MIN_LINES_IN_BAND}) and no peak of the residual at the lines around it: measure denser lines around {} Hz",
                    if n_in == 1 { "" } else { "s" },
                    sig(lo / std::f64::consts::TAU),
                    sig(hi / std::f64::consts::TAU),
                    sig(z),
                    sig(f)
                ),
            );
        }
        if let Some(r) = cancelling_pair(c.model, k) {
            return refuse(fo, Rule::Artefact, r);
        }
        if let Some(r) = peak_over_data(c.model, k, data) {
            return refuse(fo, Rule::Artefact, r);
        }
    }
    if let Some(r) = term_over_data(c, data) {
        return refuse(None, Rule::Artefact, r);
    }
    if let Some(r) = negligible(c, data) {
        return refuse(
            mode_index(c).map(|k| c.model.mode[k].omega_n / std::f64::consts::TAU),
            Rule::Negligible,
            r,
        );
    }
    if let Some(r) = not_identified(c, data) {
        return refuse(
            mode_index(c).map(|k| c.model.mode[k].omega_n / std::f64::consts::TAU),
            Rule::NotIdentified,
            r,
        );
    }
    None
}

/// True when the residual of the model without mode `k` (`Σ_ch |G_d − G_rest|²/r̃²`, `r̃`
/// the channel's median radius) has a
/// local maximum above the noise (`> 9`, i.e. 3 radii) at one of the two lines around
/// `ω_n` (within ±3 lines): the lines see the resonance on its flanks even when none falls
/// in its half-power band (a lightly damped mode between 1 Hz lines), so `ω_n` and the
/// residue are identified there and `ζ` is bounded by the record ([`crate::diagnose::lsq::slots`]).
fn residual_peaks_at(m: &PhysicalModel, k: usize, data: &Channels) -> bool {
    let om = &data.omega;
    let w = m.mode[k].omega_n;
    let j = om.partition_point(|x| *x < w);
    let (lo, hi) = (j.saturating_sub(4), (j + 4).min(om.len()));
    if hi <= lo + 2 {
        return false;
    }
    let mut rest = m.clone();
    rest.mode.remove(k);
    // Each channel scaled by its median radius, as the peak account does: `|e|/r` would
    // flatten where the radius grows with |G| (at the resonance itself).
    let scale: Vec<f64> = data.radius.iter().map(|r| median(r.clone())).collect();
    let e: Vec<f64> = (lo..hi)
        .map(|i| {
            let g = rest.eval(om[i]);
            data.entries
                .iter()
                .enumerate()
                .map(|(ch, en)| ((data.g[ch][i] - g[*en]).norm() / scale[ch]).powi(2))
                .sum()
        })
        .collect();
    let top = e.iter().cloned().fold(0.0f64, f64::max);
    [j.wrapping_sub(1), j]
        .iter()
        .filter(|i| (lo..hi).contains(*i))
        .any(|&i| e[i - lo] == top && top > 9.0)
}

/// The residue vector `c_o b_i / m` of mode `k` over every (output, input).
fn residues(m: &PhysicalModel, k: usize) -> Vec<f64> {
    let md = &m.mode[k];
    let (c, b) = (
        md.output_gain.to_vec(m.n_outputs()),
        md.input_gain.to_vec(m.n_inputs()),
    );
    c.iter()
        .flat_map(|co| b.iter().map(move |bi| co * bi / md.mass))
        .collect()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Mode `k` and another mode of `m` with overlapping half-power bands whose residues cancel.
fn cancelling_pair(m: &PhysicalModel, k: usize) -> Option<String> {
    let (a, ra) = (&m.mode[k], residues(m, k));
    for (j, b) in m.mode.iter().enumerate() {
        if j == k {
            continue;
        }
        let overlap = (a.omega_n - b.omega_n).abs() < a.zeta * a.omega_n + b.zeta * b.omega_n;
        if !overlap {
            continue;
        }
        let rb = residues(m, j);
        let sum: Vec<f64> = ra.iter().zip(&rb).map(|(x, y)| x + y).collect();
        if norm(&sum) < CANCEL_SHARE * norm(&ra).max(norm(&rb)) {
            return Some(format!(
                "with the mode at {} Hz it forms a cancelling pair (half-power bands overlap, residues {} and {}): a modelling artefact (a shifted or broadened peak), not two modes",
                sig(b.omega_n / std::f64::consts::TAU),
                sig(ra[0]),
                sig(rb[0])
            ));
        }
    }
    None
}

/// Mode `k`'s contribution at the data lines around it (within its half-power band, and
/// three lines each side) more than 10× the data's largest magnitude at those lines: the
/// lines see a response the data do not have (the peak itself, between lines, is not
/// compared: a lightly damped mode may rise far above the lines beside it).
fn peak_over_data(m: &PhysicalModel, k: usize, data: &Channels) -> Option<String> {
    let md = &m.mode[k];
    let w = md.omega_n;
    let alone = PhysicalModel {
        mode: vec![md.clone()],
        rigid_body: vec![],
        integrator: vec![],
        feedthrough: None,
        effect: vec![],
        inputs: Some(m.n_inputs()),
        outputs: Some(m.n_outputs()),
        ..m.clone()
    };
    let om = &data.omega;
    let j = om.partition_point(|x| *x < w);
    let half = md.zeta * w;
    let near: Vec<usize> = (0..om.len())
        .filter(|&i| (om[i] - w).abs() <= half || (i + 3 >= j && i <= j + 2))
        .collect();
    let g: Vec<_> = near.iter().map(|&i| alone.eval(om[i])).collect();
    let mut worst: Option<(f64, f64, f64)> = None;
    for (ch, e) in data.entries.iter().enumerate() {
        let peak = g.iter().map(|x| x[*e].norm()).fold(0.0f64, f64::max);
        let there = near
            .iter()
            .map(|&i| data.g[ch][i].norm())
            .fold(0.0f64, f64::max);
        if there > 0.0 && peak > MAX_PEAK_OVER_DATA * there {
            let ratio = peak / there;
            if worst.is_none_or(|x| ratio > x.0) {
                worst = Some((ratio, peak, there));
            }
        }
    }
    worst.map(|(ratio, peak, there)| {
        format!(
            "its contribution at the lines around it ({}) exceeds the data's magnitude there ({}) {}×: a modelling artefact, not a resonance of the data",
            sig(peak),
            sig(there),
            sig(ratio)
        )
    })
}

/// A rigid body, integrator or friction term whose own contribution somewhere in the band
/// exceeds the data's largest magnitude 10×: it only fits by cancelling another term.
fn term_over_data(c: &Child<'_>, data: &Channels) -> Option<String> {
    let m = c.model;
    let mut alone = PhysicalModel {
        mode: vec![],
        rigid_body: vec![],
        integrator: vec![],
        feedthrough: None,
        effect: vec![],
        inputs: Some(m.n_inputs()),
        outputs: Some(m.n_outputs()),
        ..m.clone()
    };
    match c.cand {
        Cand::Integrator(2) => alone.rigid_body.push(m.rigid_body.last()?.clone()),
        Cand::Integrator(_) => alone.integrator.push(m.integrator.last()?.clone()),
        Cand::Friction(i) => alone.rigid_body.push(m.rigid_body.get(i)?.clone()),
        _ => return None,
    }
    let (mut term, mut top) = (0.0f64, 0.0f64);
    for (k, w) in data.omega.iter().enumerate() {
        let g = alone.eval(*w);
        for (ch, e) in data.entries.iter().enumerate() {
            term = term.max(g[*e].norm());
            top = top.max(data.g[ch][k].norm());
        }
    }
    (top > 0.0 && term > MAX_PEAK_OVER_DATA * top).then(|| {
        format!(
            "its own contribution reaches {}, {}× the data's largest magnitude ({}): it fits only by cancelling another term, a modelling artefact",
            sig(term),
            sig(term / top),
            sig(top)
        )
    })
}

/// The negligible-size rules (see the module docs).
fn negligible(c: &Child<'_>, data: &Channels) -> Option<String> {
    let om = &data.omega;
    let (w_lo, w_hi) = (om[0], *om.last()?);
    // The noise's relative resolution `r/|G|` over the `n` lines at one end of the band, as
    // resolved by all `n` together (÷√n: an effect acts coherently on every line there).
    let rel = |top: bool| -> f64 {
        let n = (om.len() / 20).clamp(1, 20);
        let coherent = (n as f64).sqrt();
        let idx: Vec<usize> = if top {
            (om.len() - n..om.len()).collect()
        } else {
            (0..n).collect()
        };
        median(
            idx.iter()
                .flat_map(|&i| {
                    (0..data.entries.len())
                        .map(move |ch| (data.radius[ch][i] / data.g[ch][i].norm()).min(1.0))
                })
                .collect(),
        ) / coherent
    };
    match c.cand {
        Cand::Delay(_) => {
            let tau = c.model.effect.last()?.tau_s?.abs();
            let phase = w_hi * tau;
            let res = rel(true).asin();
            if phase < res {
                return Some(format!(
                    "a delay of {} s lags {}° at the band top, below the noise's phase resolution there ({}°)",
                    sig(tau),
                    sig(phase.to_degrees()),
                    sig(res.to_degrees())
                ));
            }
        }
        Cand::Lag(_) | Cand::NmpZero(_) | Cand::Zoh(_) => {
            // The phase the effect adds at the band top.
            let e = c.model.effect.last()?;
            let phase = match c.cand {
                Cand::Lag(_) => (w_hi / e.omega_c?).atan() * e.order.unwrap_or(1) as f64,
                Cand::NmpZero(_) => 2.0 * (w_hi / e.z?).atan(),
                _ => 0.5 * w_hi * e.t_s?,
            };
            let res = rel(true).asin();
            if phase < res {
                return Some(format!(
                    "it shifts the phase by {}° at the band top, below the noise's phase resolution there ({}°)",
                    sig(phase.to_degrees()),
                    sig(res.to_degrees())
                ));
            }
        }
        Cand::Friction(i) => {
            let p = c.model.rigid_body.get(i)?.friction_pole?;
            let res = rel(false);
            if p / w_lo < res {
                return Some(format!(
                    "a friction pole at {} rad/s changes the response at the band bottom ({} rad/s) by {}, below the noise's relative resolution there ({})",
                    sig(p),
                    sig(w_lo),
                    sig(p / w_lo),
                    sig(res)
                ));
            }
        }
        _ => {}
    }
    let (before, after) = (c.reference, c.measures);
    let d_rms = (before.misfit_rms - after.misfit_rms) / before.misfit_rms;
    let d_inv = (before.invalid_fraction - after.invalid_fraction).abs();
    if d_rms.abs() < NEGLIGIBLE_RMS && !after.consistent() {
        return Some(format!(
            "removing it changes misfit_rms by {:.2} % ({} → {}) and the invalid fraction by {:.2} points: too small to be a physical effect",
            100.0 * d_rms,
            sig(before.misfit_rms),
            sig(after.misfit_rms),
            100.0 * d_inv
        ));
    }
    None
}

/// True when slot `s` belongs to the effect `c` added (or changed) in `m`.
fn own_nl(c: &Child<'_>, s: &Nl) -> bool {
    let m = c.model;
    match (c.cand, s) {
        (Cand::Mode, Nl::ModeW(i) | Nl::ModeZ(i)) => *i + 1 == m.mode.len(),
        (Cand::Mode, Nl::In(Term::Mode(i), _)) => *i + 1 == m.mode.len(),
        (Cand::ModeShift(k), Nl::ModeW(i)) | (Cand::Damping(k), Nl::ModeZ(i)) => *i == k,
        (Cand::Friction(k), Nl::RigidPole(i)) => *i == k,
        (
            Cand::Delay(_) | Cand::Lag(_) | Cand::NmpZero(_) | Cand::Zoh(_),
            Nl::Delay(i) | Nl::LogEffect(i),
        ) => *i + 1 == m.effect.len(),
        _ => false,
    }
}

fn own_lin(c: &Child<'_>, s: &Lin) -> bool {
    let m = c.model;
    match (c.cand, s) {
        (Cand::Mode, Lin::Out(Term::Mode(i), _)) => *i + 1 == m.mode.len(),
        (Cand::Integrator(2), Lin::Out(Term::Rigid(i), _)) => *i + 1 == m.rigid_body.len(),
        (Cand::Integrator(_), Lin::Out(Term::Int(i), _)) => *i + 1 == m.integrator.len(),
        (Cand::Feedthrough, Lin::Feed(..)) => true,
        _ => false,
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
fn not_identified(c: &Child<'_>, data: &Channels) -> Option<String> {
    let m = c.model;
    let (lin, nl) = slots(m, data);
    let (sigma, corr) = slot_covariance(m, &lin, &nl, data);
    let nlin = lin.len();
    // A mode narrower than the lines (fewer than 3 in its half-power band, seen on its flanks,
    // else `check` refused it as unresolved): its ζ is bounded by the record, not measured;
    // the mode is defined by ω_n and its residues.
    let zeta_unresolved = |i: usize| {
        let md = &m.mode[i];
        let (lo, hi) = (md.omega_n * (1.0 - md.zeta), md.omega_n * (1.0 + md.zeta));
        data.omega.iter().filter(|x| **x >= lo && **x <= hi).count() < MIN_LINES_IN_BAND
    };
    for (j, s) in nl.iter().enumerate() {
        if !own_nl(c, s) || !defining(s) {
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
            if own_nl(c, t) {
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
            if own_lin(c, t) {
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

#[cfg(test)]
#[path = "admissible_tests.rs"]
mod tests;

//! Physical admissibility of an effect, checked on the **joint refit** that would add it
//! (issue 33): a term the likelihood wants but no structure has is refused, and the
//! refusal names its rule.  The rules (shared/design/physical-modes.md):
//!
//! * **mains** — a mode narrower than one line within the frequency resolution (half the
//!   local line spacing, or its own half-power half-width) of 50 or 60 Hz or a harmonic is
//!   probable electrical interference (applied only when asked, `allow_mains`) when the
//!   lines outside that resolution do not support it (its ΔBIC there ≤ 10: a spectral line,
//!   no resonance skirts), or when the harmonic is low enough to stay on its line while the
//!   fundamental wanders by 0.05 Hz (`h·0.05 Hz` ≤ the resolution: there a tone off a line's
//!   centre leaks like a resonance's skirts).  A mode with skirts at a higher harmonic
//!   (2640 Hz = 44 × 60 Hz on 1 Hz lines) is judged by the other rules (`mains`);
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
//!
//! What each rule reads of an effect, the effect says in its own file
//! (the `Effect` trait of `diagnose/effects/effect.rs`: `its_mode`, `term_alone`,
//! `below_resolution`, `owns`); the rules are here: the mode rules in [`check`] and `modes`,
//! the size rules in `size`, the covariance rules in `identified`.

mod identified;
pub(crate) mod mains;
mod modes;
mod size;

use crate::diagnose::effects::candidates::{sig, Cand};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
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
    /// The ΔBIC the search requires of an effect
    /// ([`crate::diagnose::SearchSettings::min_delta_bic`]); the mains rule requires the same of
    /// a mode's evidence on the lines beside a harmonic.
    pub min_delta_bic: f64,
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
    if let Some(k) = c.cand.its_mode(c.model) {
        let md = &c.model.mode[k];
        let (w, z) = (md.omega_n, md.zeta);
        let f = w / std::f64::consts::TAU;
        let fo = Some(f);
        // Mains: a line-narrow mode at 50/60 Hz or a harmonic that the lines beside it do
        // not support, or at a harmonic stable enough for a tone to mimic its skirts.
        if !c.allow_mains {
            if let Some(r) = mains::refusal(c.model, k, data, c.min_delta_bic) {
                return refuse(fo, Rule::Mains, r);
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
        if n_in < MIN_LINES_IN_BAND && !modes::residual_peaks_at(c.model, k, data) {
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
        if let Some(r) = modes::cancelling_pair(c.model, k) {
            return refuse(fo, Rule::Artefact, r);
        }
        if let Some(r) = modes::peak_over_data(c.model, k, data) {
            return refuse(fo, Rule::Artefact, r);
        }
    }
    if let Some(r) = size::term_over_data(c, data) {
        return refuse(None, Rule::Artefact, r);
    }
    if let Some(r) = size::negligible(c, data) {
        return refuse(
            c.cand
                .its_mode(c.model)
                .map(|k| c.model.mode[k].omega_n / std::f64::consts::TAU),
            Rule::Negligible,
            r,
        );
    }
    if let Some(r) = identified::not_identified(c, data) {
        return refuse(
            c.cand
                .its_mode(c.model)
                .map(|k| c.model.mode[k].omega_n / std::f64::consts::TAU),
            Rule::NotIdentified,
            r,
        );
    }
    None
}

#[cfg(test)]
mod tests;

//! The size rules of [`super::check`]: a term too large for the data (its own contribution
//! far above them: an artefact) and an effect too small to matter (below what the noise
//! resolves, or a negligible change of `misfit_rms`).  What an effect's size is, each effect
//! says ([`crate::diagnose::effects::effect::Effect::below_resolution`],
//! [`crate::diagnose::effects::effect::Effect::term_alone`]).

use super::{median, Child, MAX_PEAK_OVER_DATA, NEGLIGIBLE_RMS};
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::effects::effect::Resolution;
use crate::diagnose::lsq::channels::Channels;

/// A rigid body, integrator or friction term whose own contribution somewhere in the band
/// exceeds the data's largest magnitude 10×: it only fits by cancelling another term.
pub(super) fn term_over_data(c: &Child<'_>, data: &Channels) -> Option<String> {
    let alone = c.cand.term_alone(c.model)?;
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
pub(super) fn negligible(c: &Child<'_>, data: &Channels) -> Option<String> {
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
    let r = Resolution {
        w_lo,
        w_hi,
        phase_top: rel(true).asin(),
        rel_bottom: rel(false),
    };
    if let Some(why) = c.cand.below_resolution(c.model, &r) {
        return Some(why);
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

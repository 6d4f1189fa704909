//! The size rules of [`super::check`]: a term too large for the data (its own contribution
//! far above them: an artefact) and an effect too small to matter (below what the noise
//! resolves, or a negligible change of `misfit_rms`).  What an effect's size is, each effect
//! says ([`crate::diagnose::effects::effect::Effect::below_resolution`],
//! [`crate::diagnose::effects::effect::Effect::term_alone`]).

use super::{median, spacing_at, Child, MAX_PEAK_OVER_DATA, NEGLIGIBLE_RMS};
use crate::diagnose::effects::candidates::{sig, Cand};
use crate::diagnose::effects::effect::Resolution;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::measures_of;
use crate::diagnose::lsq::problem::{Mods, Problem};
use crate::model::physical::PhysicalModel;

/// A mode's size is judged on the lines within this many half-power bandwidths `2ζω_n` of
/// it, on each side ([`local_lines`]).
pub const LOCAL_BANDWIDTHS: f64 = 5.0;
/// … and on at least this many line spacings on each side.
pub const LOCAL_MIN_LINES: f64 = 3.0;

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

/// The lines where mode `k` of `m` acts: `|ω − ω_n| ≤ max(5·2ζω_n, 3 line spacings)`.
pub fn local_lines(m: &PhysicalModel, k: usize, data: &Channels) -> Vec<usize> {
    let md = &m.mode[k];
    let w = md.omega_n;
    let dw = spacing_at(&data.omega, w);
    let half = (LOCAL_BANDWIDTHS * 2.0 * md.zeta * w).max(if dw.is_finite() {
        LOCAL_MIN_LINES * dw
    } else {
        0.0
    });
    (0..data.len())
        .filter(|&i| (data.omega[i] - w).abs() <= half)
        .collect()
}

/// `misfit_rms` of `m` over the lines `idx` (every channel), or `None` when `m` cannot be
/// evaluated on the data.
fn misfit_rms_at(m: &PhysicalModel, data: &Channels, idx: &[usize]) -> Option<f64> {
    let c = Problem::new(m, data).ok()?.misfits(&Mods::default());
    let local: Vec<Vec<f64>> = c
        .iter()
        .map(|row| idx.iter().map(|&i| row[i]).collect())
        .collect();
    Some(measures_of(&local).misfit_rms)
}

/// The size rule of a **mode** (see [`negligible`]): `misfit_rms` over the lines where it
/// acts ([`local_lines`]) with it (`c.model`) and without it (`c.reference_model`, the
/// parent the joint refit started from; the refit with mode `k` removed when absent).
/// `Some((before, after, lines))`.
fn local_change(c: &Child<'_>, k: usize, data: &Channels) -> Option<(f64, f64, Vec<usize>)> {
    let idx = local_lines(c.model, k, data);
    if idx.is_empty() {
        return None;
    }
    let after = misfit_rms_at(c.model, data, &idx)?;
    let before = match c.reference_model {
        Some(r) => misfit_rms_at(r, data, &idx)?,
        None => {
            let mut without = c.model.clone();
            without.mode.remove(k);
            misfit_rms_at(&without, data, &idx)?
        }
    };
    Some((before, after, idx))
}

/// The negligible-size rules (see the module docs).
///
/// The "removal changes `misfit_rms` by < 1 %" rule (issue 33: *"a term whose removal changes
/// misfit_rms by < 1 %"*) is about the term's physical **size**.  A delay, a lag, friction,
/// a residual term or a feedthrough acts over the whole band, and is judged there.  A
/// **mode** acts within a few half-power bandwidths of `ω_n`: judged on the whole band's
/// `misfit_rms`, its size is diluted by the band's width and by every other misfit in it —
/// the more modes a record holds (and the more are still missing), the more real modes
/// would be "negligible" (pyfrf 20–5000 Hz: the 3664.4 Hz shoulder mode, ΔBIC 46,639, moves
/// the whole band's `misfit_rms` by 0.45 %).  So a mode added by a [`Cand::Mode`] is judged
/// over the lines within `max(5·2ζω_n, 3 lines)` of it ([`local_lines`]), with and
/// without it, with the same 1 % threshold; other effects, modes' shifts included, keep the
/// whole band.
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
    if let (Cand::Mode, Some(k)) = (c.cand, c.cand.its_mode(c.model)) {
        let (b, a, idx) = local_change(c, k, data)?;
        let d_rms = (b - a) / b;
        let f = |i: usize| sig(data.omega[i] / std::f64::consts::TAU);
        return (d_rms < NEGLIGIBLE_RMS && !after.consistent()).then(|| {
            format!(
                "removing it changes misfit_rms by {:.2} % ({} → {}) over the {} lines where it acts ({}–{} Hz, five half-power bandwidths each side): too small to be a physical mode",
                100.0 * d_rms,
                sig(b),
                sig(a),
                idx.len(),
                f(idx[0]),
                f(*idx.last().expect("non-empty"))
            )
        });
    }
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

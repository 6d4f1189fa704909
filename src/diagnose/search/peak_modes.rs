//! Every peak proposed (issue 33): the screen's one mode candidate goes to the start with
//! the lowest cost, so when its joint refit is refused (a peak the lines cannot resolve, a
//! mains line) the next step proposes the same peak again and the other peaks are never
//! tried.  Here every unexplained peak of the node's residual ([`super::peaks::find_peaks`])
//! gets a mode fitted at it alone ([`super::peaks::fit_at`]); those that would pass the
//! screen (ΔBIC above the threshold, plausible, fewer invalid data or a lower `misfit_rms`,
//! the fit staying in the peak's window) are proposed as mode candidates of their own, each
//! refit jointly by the search, so a refused candidate never hides the others.
//!
//! Peaks at a mode the model already has (what is left of its fit: a retune's job, or a
//! cancelling pair if a second mode were put there) and at the screen's own mode candidate
//! are skipped.

use super::peaks::{find_peaks, fit_at, residual, MAX_PEAKS};
use super::rank::{improves, plausibility, Screened};
use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::problem::Problem;
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;

/// Most mode proposals from peaks per node.
pub const MAX_PEAK_MODES: usize = 4;

/// The mode candidates at the peaks of the residual of `model` that would pass the screen
/// (see the module docs), highest ΔBIC first; `taken`: ω_n (rad/s) of the screen's own mode
/// candidates.
pub(super) fn peak_modes(
    model: &PhysicalModel,
    data: &Channels,
    cur: Measures,
    taken: &[f64],
    min_delta_bic: f64,
) -> Result<Vec<Screened>> {
    let pb = Problem::new(model, data)?;
    let (s, e) = residual(model, data)?;
    let peaks: Vec<_> = find_peaks(&data.omega, &s, &e)
        .into_iter()
        .take(MAX_PEAKS)
        .filter(|p| {
            let inside = |w: f64| (p.lo..=p.hi).contains(&w);
            !taken.iter().any(|w| inside(*w)) && !model.mode.iter().any(|m| inside(m.omega_n))
        })
        .collect();
    let ln2f = (2.0 * data.n_data() as f64).ln();
    let n_new = Cand::Mode.n_params(data.n_ch());
    let w_band = (data.omega[0], *data.omega.last().expect("data"));
    let mut out: Vec<Screened> = peaks
        .par_iter()
        .filter_map(|p| {
            let (mods, v, jtj) = fit_at(&pb, p, data)?;
            let w = mods.theta[0].exp();
            if !(p.lo..=p.hi).contains(&w) {
                return None;
            }
            let measures = pb.measures(&mods);
            let delta_bic = 2.0 * (cur.v - v) - n_new as f64 * ln2f;
            let (flags, no_fit) = plausibility(
                &Cand::Mode,
                &mods.theta,
                v,
                &data.entries,
                w_band,
                pb.zeta_floor,
                model.quantity,
            );
            let passes = no_fit.is_none()
                && flags.is_empty()
                && delta_bic > min_delta_bic
                && improves(&measures, &cur);
            passes.then_some(Screened {
                cand: Cand::Mode,
                mods,
                v,
                measures,
                delta_bic,
                flags,
                no_fit,
                jtj,
            })
        })
        .collect();
    out.sort_by(|a, b| b.delta_bic.total_cmp(&a.delta_bic));
    // One proposal per resonance: two peaks' fits that met at one frequency are one.
    let mut kept: Vec<Screened> = Vec::new();
    for sc in out {
        let w = sc.mods.theta[0].exp();
        if !kept
            .iter()
            .any(|k| (k.mods.theta[0].exp() / w - 1.0).abs() < 1e-3)
        {
            kept.push(sc);
        }
    }
    kept.truncate(MAX_PEAK_MODES);
    Ok(kept)
}

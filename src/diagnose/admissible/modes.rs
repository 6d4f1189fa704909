//! The mode rules of [`super::check`] beyond a mode's own `ζ` and lines: whether the
//! residual shows it between lines, and the artefacts (a cancelling pair, a peak far above
//! the data).

use super::{median, CANCEL_SHARE, MAX_PEAK_OVER_DATA};
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::effects::effect::bare;
use crate::diagnose::lsq::channels::Channels;
use crate::model::physical::PhysicalModel;

/// True when the residual of the model without mode `k` (`Σ_ch |G_d − G_rest|²/r̃²`, `r̃`
/// the channel's median radius) has a
/// local maximum above the noise (`> 9`, i.e. 3 radii) at one of the two lines around
/// `ω_n` (within ±3 lines): the lines see the resonance on its flanks even when none falls
/// in its half-power band (a lightly damped mode between 1 Hz lines), so `ω_n` and the
/// residue are identified there and `ζ` is bounded by the record ([`crate::diagnose::lsq::slots`]).
pub(super) fn residual_peaks_at(m: &PhysicalModel, k: usize, data: &Channels) -> bool {
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
pub(super) fn cancelling_pair(m: &PhysicalModel, k: usize) -> Option<String> {
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
pub(super) fn peak_over_data(m: &PhysicalModel, k: usize, data: &Channels) -> Option<String> {
    let md = &m.mode[k];
    let w = md.omega_n;
    let mut alone = bare(m);
    alone.mode.push(md.clone());
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

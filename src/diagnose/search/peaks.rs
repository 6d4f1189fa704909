//! The per-peak account of a diagnosis (issue 20 item 8): every peak of the residual
//! `|G_data − G_model|` that stands out of the noise, and what became of it.
//!
//! **Detection rule** ([`find_peaks`]). The residual in noise units is
//! `e_k = max_ch |G_d − Ĝ|/r` (1 = the edge of the noise disk).  Peaks are located on the
//! residual itself, `s_k = max_ch |G_d − Ĝ|/r̄_ch` (`r̄_ch` the channel's median radius, a
//! scale only): a missing resonance is a peak of `|G_d − Ĝ|`, while `e` also peaks wherever
//! the radius dips (a radius proportional to `|G|` dips at every anti-resonance, and a
//! coherence-based one jitters line by line, which cuts one resonance into dozens of maxima
//! of `e`).  A line `k` is a peak when
//! 1. `s_k` is a local maximum and `e_k ≥` [`MIN_HEIGHT`] (3: well outside the disks);
//! 2. it is prominent: walking away from it on each side until `s` rises above `s_k` again
//!    (or the band ends), the lowest `s` met is at most `s_k /` [`MIN_PROMINENCE`] on at
//!    least one side (topographic prominence, as a ratio: the peak rises at least twice
//!    above the dip that separates it from higher ground);
//! 3. its window is the run of lines around it with `s ≥ s_k/2` (for a resonance of damping
//!    ζ that is `2√3 ζω` wide), widened to at least ±[`MIN_WINDOW_REL`]·ω; a lower peak
//!    inside a higher peak's window is merged into it.
//!
//! Peaks are found on the residual of the retuned model (before this run added anything)
//! and of the final model (a peak the refit created), merged, and the [`MAX_PEAKS`] highest
//! listed.
//!
//! **Fate**, in this order: *added* (a mode this run added lies in the window; the reason
//! says whether it brought the residual down to half or into the noise), *modelled*
//! (a mode already in the model lies there: the rest of its fit), *lowered* (the chosen set
//! brought the residual down to half or below [`MIN_HEIGHT`]), *rejected* (a mode candidate
//! of this run was fitted in the window and rejected, with the candidate's reason), or
//! *not proposed*.  For every peak left unexplained a **probe** fits one mode started at
//! the peak (ζ from the window, residues by linear least squares) on top of the final model
//! and says whether it would pass the screen (ΔBIC > 10, plausible, [`improves`]); this
//! does not depend on how the search proposes candidates, so it also tells whether a
//! proposer missed a mode the data support.

use crate::diagnose::effects::candidates::{sig, Cand};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::{Mods, Problem};
use crate::diagnose::report::{CandidateReport, Peak, PeakFate, PeakProbe};
use crate::diagnose::search::rank::{improves, plausibility};
use crate::diagnose::search::recheck::removed_at;
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;

/// Lowest residual peak listed, in noise units (`|e|/r`).
pub const MIN_HEIGHT: f64 = 3.0;
/// Least ratio of a peak to the dip separating it from higher ground.
pub const MIN_PROMINENCE: f64 = 2.0;
/// Least half-width of a peak's window, relative to its frequency.
pub const MIN_WINDOW_REL: f64 = 3e-3;
/// Most peaks listed (the highest).
pub const MAX_PEAKS: usize = 16;

const TAU: f64 = std::f64::consts::TAU;

/// A peak of a residual: its line, height, and window `[lo, hi]` (rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawPeak {
    /// Line index.
    pub k: usize,
    /// `e_k`.
    pub height: f64,
    /// Window, rad/s.
    pub lo: f64,
    /// Window, rad/s.
    pub hi: f64,
}

impl RawPeak {
    fn contains(&self, w: f64) -> bool {
        (self.lo..=self.hi).contains(&w)
    }
}

/// The peaks of the residual over the lines `omega` (rule in the module docs), highest
/// first: `s` locates them, `e` (in noise units) must reach [`MIN_HEIGHT`] there.
pub fn find_peaks(omega: &[f64], s: &[f64], e: &[f64]) -> Vec<RawPeak> {
    let n = s.len();
    let mut maxima: Vec<usize> = (0..n)
        .filter(|&k| {
            e[k] >= MIN_HEIGHT && (k == 0 || s[k] >= s[k - 1]) && (k + 1 == n || s[k] > s[k + 1])
        })
        .collect();
    maxima.sort_by(|a, b| s[*b].total_cmp(&s[*a]));
    // Lowest `s` met walking from k in direction `dir` until it exceeds s[k].
    let dip = |k: usize, dir: isize| -> f64 {
        let mut lowest = s[k];
        let mut j = k as isize + dir;
        while j >= 0 && (j as usize) < n && s[j as usize] <= s[k] {
            lowest = lowest.min(s[j as usize]);
            j += dir;
        }
        lowest
    };
    let mut out: Vec<RawPeak> = Vec::new();
    for k in maxima {
        let sep = dip(k, -1).min(dip(k, 1));
        if s[k] < MIN_PROMINENCE * sep {
            continue;
        }
        let w = omega[k];
        if out.iter().any(|p| p.contains(w)) {
            continue;
        }
        let (mut a, mut b) = (k, k);
        while a > 0 && s[a - 1] >= s[k] / 2.0 {
            a -= 1;
        }
        while b + 1 < n && s[b + 1] >= s[k] / 2.0 {
            b += 1;
        }
        out.push(RawPeak {
            k,
            height: e[k],
            lo: omega[a].min(w * (1.0 - MIN_WINDOW_REL)),
            hi: omega[b].max(w * (1.0 + MIN_WINDOW_REL)),
        });
    }
    out
}

/// `(s, e)` of model `m` per line: `max_ch |G_d − Ĝ|` over the channel's median radius, and
/// over the radius itself.
pub(super) fn residual(m: &PhysicalModel, data: &Channels) -> Result<(Vec<f64>, Vec<f64>)> {
    let gm = Problem::new(m, data)?.response(&Mods::default());
    let (mut s, mut e) = (vec![0.0f64; data.len()], vec![0.0f64; data.len()]);
    for ((g, gm), radius) in data.g.iter().zip(&gm).zip(&data.radius) {
        let mut r = radius.clone();
        r.sort_by(f64::total_cmp);
        let med = r[r.len() / 2];
        for k in 0..data.len() {
            let a = (g[k] - gm[k]).norm();
            s[k] = s[k].max(a / med);
            e[k] = e[k].max(a / radius[k]);
        }
    }
    Ok((s, e))
}

/// What the run did, for the account: the model before it added anything (retuned), the
/// final model, the chosen labels, the first-level candidates and the effects the holdout
/// and the backward elimination dropped.
pub(crate) struct Outcome<'a> {
    pub retuned: &'a PhysicalModel,
    pub final_model: &'a PhysicalModel,
    pub chosen: &'a [String],
    pub candidates: &'a [CandidateReport],
    /// Effects the final holdout dropped.
    pub dropped: &'a [String],
    /// Effects the backward elimination dropped.
    pub eliminated: &'a [String],
    /// Effects the re-check of the reduced set refused and removed.
    pub refused_in_kept: &'a [crate::diagnose::admissible::Refusal],
    /// The ΔBIC an effect must exceed ([`crate::diagnose::SearchSettings::min_delta_bic`]):
    /// what a probe's "would pass the screen" is judged by.
    pub min_delta_bic: f64,
}

/// The per-peak account (module docs) and the number of peaks not listed.
pub(crate) fn account(o: &Outcome<'_>, data: &Channels) -> Result<(Vec<Peak>, usize)> {
    let (s0, e0) = residual(o.retuned, data)?;
    let (s1, e1) = residual(o.final_model, data)?;
    let mut raw = find_peaks(&data.omega, &s0, &e0);
    for p in find_peaks(&data.omega, &s1, &e1) {
        let w = data.omega[p.k];
        if !raw
            .iter()
            .any(|q| q.contains(w) || p.contains(data.omega[q.k]))
        {
            raw.push(RawPeak {
                height: e0[p.k],
                ..p
            });
        }
    }
    raw.sort_by(|a, b| b.height.max(e1[b.k]).total_cmp(&a.height.max(e1[a.k])));
    let not_listed = raw.len().saturating_sub(MAX_PEAKS);
    raw.truncate(MAX_PEAKS);
    let probe_on = Problem::new(o.final_model, data)?;
    let final_measures = probe_on.measures(&Mods::default());
    let n_root = o.retuned.mode.len();
    // Each peak's account (and its probe fit) is independent of the others: in parallel (the
    // indexed collect keeps the order).
    let out: Vec<Peak> = raw.par_iter().map(|&p| {
        let w = data.omega[p.k];
        let (after, width) = (e1[p.k], p.hi - p.lo);
        let mode_in = |modes: &[crate::model::physical::ModeSpec]| {
            modes
                .iter()
                .map(|m| m.omega_n)
                .filter(|x| p.contains(*x))
                .min_by(|a, b| (a - w).abs().total_cmp(&(b - w).abs()))
        };
        let added = o.final_model.mode.get(n_root..).and_then(mode_in);
        let modelled = mode_in(&o.retuned.mode);
        let proposed = o.candidates.iter().find(|c| {
            c.cand == Some(Cand::Mode) && c.params.get("omega_n").is_some_and(|x| p.contains(*x))
        });
        let mut probe = None;
        // A peak is explained when the final model brings it down to half or into the noise;
        // a mode added inside a broad window need not do that (a residual that stays or
        // grows there is not that mode's alone), and the account must not say it does.
        let brought_down = after <= 0.5 * p.height || after < MIN_HEIGHT;
        let (fate, effect, reason) = if let Some(x) = added {
            (
                PeakFate::Added,
                Some(format!("mode {} Hz", sig(x / TAU))),
                if brought_down {
                    format!(
                        "explained by the mode this run added at {} Hz",
                        sig(x / TAU)
                    )
                } else {
                    format!(
                        "the mode this run added at {} Hz lies in this peak's window, but the residual here stays at {} (was {}): not that mode's alone, more is missing here",
                        sig(x / TAU),
                        sig(after),
                        sig(p.height)
                    )
                },
            )
        } else if let Some(x) = modelled {
            (
                PeakFate::Modelled,
                Some(format!("mode {} Hz", sig(x / TAU))),
                format!(
                    "at the mode {} Hz already in the model: what is left of its fit",
                    sig(x / TAU)
                ),
            )
        } else if !o.chosen.is_empty() && brought_down {
            (
                PeakFate::Lowered,
                Some(o.chosen.join(" + ")),
                format!(
                    "lowered {} → {} by the chosen set ({}) and its joint refit",
                    sig(p.height),
                    sig(after),
                    o.chosen.join(" + ")
                ),
            )
        } else {
            probe = probe_mode(&probe_on, &final_measures, &p, data, o.min_delta_bic);
            let verdict = match &probe {
                Some(pr) => pr.verdict(&p, o.min_delta_bic),
                None => "one mode started here did not converge".into(),
            };
            match (proposed, removed_at(o.refused_in_kept, |w| p.contains(w))) {
                (_, Some((effect, why))) => (
                    PeakFate::Rejected,
                    Some(effect),
                    format!("{why}; probe on the final model: {verdict}"),
                ),
                (Some(c), None) => (
                    PeakFate::Rejected,
                    Some(format!(
                        "mode {} Hz",
                        sig(c.params.get("omega_n").copied().unwrap_or(0.0) / TAU)
                    )),
                    format!(
                        "a mode candidate was fitted here and {}; probe on the final model: {verdict}",
                        match c.rejection() {
                            Some(why) => format!("rejected: {why}"),
                            None if o.dropped.iter().any(|d| d == "mode") => "passed the screen, but a mode of the chosen set failed the holdout (fitted on 3 of every 4 lines it did not predict the fourth better) and was dropped".into(),
                            None if o.eliminated.iter().any(|d| d == "mode") => format!("passed the screen, but the backward elimination dropped a mode of the chosen set (ΔBIC ≤ {} without it)", o.min_delta_bic),
                            None => "passed the screen but is not in the chosen set (another set has the lower BIC)".into(),
                        }
                    ),
                ),
                (None, None) => (
                    PeakFate::NotProposed,
                    None,
                    format!(
                        "no mode candidate of this run was fitted here ({}); probe on the final model: {verdict}",
                        mode_candidates(o.candidates)
                    ),
                ),
            }
        };
        Peak {
            frequency_hz: w / TAU,
            height: p.height,
            height_after: after,
            window_hz: [p.lo / TAU, p.hi / TAU],
            width_hz: width / TAU,
            fate,
            effect,
            reason,
            probe,
        }
    }).collect();
    Ok((out, not_listed))
}

/// Where this run's mode candidates went (`the mode candidate went to 5000 Hz`).
fn mode_candidates(c: &[CandidateReport]) -> String {
    let f: Vec<String> = c
        .iter()
        .filter(|c| c.cand == Some(Cand::Mode))
        .filter_map(|c| c.params.get("omega_n"))
        .map(|w| format!("{} Hz", sig(w / TAU)))
        .collect();
    if f.is_empty() {
        "no mode candidate was fitted".into()
    } else {
        format!("the mode candidate went to {}", f.join(", "))
    }
}

/// One mode started at peak `p` and fitted on top of the model of `pb` (the model fixed):
/// `ζ` from the window (the half-height width of a resonance is `2√3 ζω`), three starts
/// (ζ, 3ζ, ζ/3) with residues by weighted linear least squares, the best refit by
/// Levenberg–Marquardt.  It would pass the screen with no flag, a ΔBIC above
/// `min_delta_bic` and a better fit.
fn probe_mode(
    pb: &Problem<'_>,
    cur: &crate::diagnose::lsq::measures::Measures,
    p: &RawPeak,
    data: &Channels,
    min_delta_bic: f64,
) -> Option<PeakProbe> {
    let AtPeak { fit, v, .. } = fit_at(pb, p, data)?;
    let ln2f = (2.0 * data.n_data() as f64).ln();
    let delta_bic = 2.0 * (cur.v - v) - Cand::Mode.n_params(data.n_ch()) as f64 * ln2f;
    let (mut flags, no_fit) = plausibility(
        &Cand::Mode,
        &fit.theta,
        v,
        &data.entries,
        (data.omega[0], *data.omega.last().expect("data")),
        pb.zeta_floor,
        pb.base.quantity,
    );
    flags.extend(no_fit);
    let better = improves(&pb.measures(&fit), cur);
    Some(PeakProbe {
        frequency_hz: fit.theta[0].exp() / TAU,
        zeta: fit.theta[1].exp(),
        would_pass: flags.is_empty() && delta_bic > min_delta_bic && better,
        delta_bic,
        flags,
        improves: better,
    })
}

/// Lines of a peak's local fit: its window widened by [`LOCAL_WIDTHS`] times its width
/// on each side, and by at least [`LOCAL_MIN_REL`]`·ω`.
pub const LOCAL_WIDTHS: f64 = 2.0;
/// Least half-width of a local fit's lines, relative to the peak's frequency.
pub const LOCAL_MIN_REL: f64 = 0.02;

/// The lines of peak `p`'s local fit (see [`LOCAL_WIDTHS`]).
pub(super) fn local_lines(p: &RawPeak, data: &Channels) -> Vec<usize> {
    let w = data.omega[p.k];
    let pad = (LOCAL_WIDTHS * (p.hi - p.lo)).max(LOCAL_MIN_REL * w);
    let (lo, hi) = (p.lo - pad, p.hi + pad);
    (0..data.len())
        .filter(|&k| (lo..=hi).contains(&data.omega[k]))
        .collect()
}

/// A mode fitted at a peak ([`fit_at`]).
pub(super) struct AtPeak {
    /// The mode.
    pub fit: Mods,
    /// The cost with it on all lines.
    pub v: f64,
    /// What it lowers the cost on the lines of its local fit.
    pub local_gain: f64,
    /// `JᵀJ` of the local fit.
    pub jtj: nalgebra::DMatrix<f64>,
}

/// One mode started at peak `p` and fitted on top of the model of `pb` (see
/// [`probe_mode`]).  The fit is local (issue 33): starts and refit use the lines around the
/// peak only ([`local_lines`]).  Fitted on the whole band, the lone mode also answers for
/// the other missing modes' tails, and where the radius is proportional to `|G|` (small at
/// the data's anti-resonances) those tails can pull it out of its peak (measured: 263.7 →
/// 265.5 Hz); a mode is a local feature, and the joint refit places it among the others.
pub(super) fn fit_at(pb: &Problem<'_>, p: &RawPeak, data: &Channels) -> Option<AtPeak> {
    let w = data.omega[p.k];
    let all: Vec<usize> = (0..data.len()).collect();
    let local = local_lines(p, data);
    let z0 = ((p.hi - p.lo) / (2.0 * 3f64.sqrt() * w)).clamp(2e-4, 0.3);
    let empty = Mods::default();
    let resp = pb.response(&empty);
    let mut best: Option<(Mods, f64, nalgebra::DMatrix<f64>)> = None;
    for z in [z0, 3.0 * z0, z0 / 3.0] {
        let th = pb.mode_theta(&empty, &resp, w, z, &local);
        let m = empty.with(Cand::Mode, &th);
        let (fit, v_local, jtj) = pb.refit(&m, &local);
        if v_local.is_finite() && best.as_ref().is_none_or(|b| v_local < b.1) {
            best = Some((fit, v_local, jtj));
        }
    }
    best.map(|(fit, v_local, jtj)| AtPeak {
        v: pb.v(&fit, &all),
        local_gain: pb.v(&empty, &local) - v_local,
        fit,
        jtj,
    })
}

impl PeakProbe {
    /// One line: what the probe found, and whether it would pass the screen (ΔBIC above
    /// `min_delta_bic`).
    fn verdict(&self, p: &RawPeak, min_delta_bic: f64) -> String {
        let at = format!(
            "one mode started here refits to {} Hz (ζ {}), ΔBIC {}",
            sig(self.frequency_hz),
            sig(self.zeta),
            sig(self.delta_bic)
        );
        let left = !p.contains(TAU * self.frequency_hz);
        if self.would_pass && !left {
            format!("{at}: it would pass the screen (the search did not reach it)")
        } else if !self.flags.is_empty() {
            format!("{at}: rejected: {}", self.flags.join("; "))
        } else if self.delta_bic <= min_delta_bic {
            format!("{at}: too small a gain (needs ΔBIC > {min_delta_bic})")
        } else if !self.improves {
            format!("{at}: more invalid data and misfit_rms not lower")
        } else {
            format!("{at}: it leaves the peak's window (the peak is not one resonance)")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A probe's verdict judges its gain by the search's threshold, not a constant: ΔBIC 25
    /// is too small a gain under 30 and not under 10.
    #[test]
    fn a_probe_is_judged_by_the_threshold_of_the_settings() {
        let p = RawPeak {
            k: 0,
            height: 8.0,
            lo: 90.0,
            hi: 110.0,
        };
        let probe = PeakProbe {
            frequency_hz: 100.0 / TAU,
            zeta: 0.01,
            delta_bic: 25.0,
            flags: vec![],
            improves: true,
            would_pass: false,
        };
        let strict = probe.verdict(&p, 30.0);
        assert!(
            strict.ends_with("too small a gain (needs ΔBIC > 30)"),
            "{strict}"
        );
        let loose = probe.verdict(&p, 10.0);
        assert!(!loose.contains("too small a gain"), "{loose}");
    }

    /// Two resonance bumps and a rippled plateau on a noise floor of 1: three peaks, the
    /// resonances with windows of the half-height width `2√3 ζω`, the ripple's maxima
    /// (below the prominence ratio) merged into one peak.
    #[test]
    fn peaks_of_a_synthetic_residual() {
        let omega: Vec<f64> = (0..2000).map(|k| 100.0 + k as f64).collect();
        let bump = |w: f64, w0: f64, zeta: f64, h: f64| {
            let x = (w / w0).powi(2);
            h * 2.0 * zeta / ((1.0 - x).powi(2) + (2.0 * zeta * w / w0).powi(2)).sqrt()
        };
        // A plateau 950–1050 rad/s at 3.5 with a ±0.5 ripple (ratio 1.3 between its
        // maxima and minima): one peak, its window the whole plateau.
        let ripple = |w: f64| {
            if (w - 1000.0).abs() < 50.0 {
                2.5 + 0.5 * ((w - 1000.0) / 3.0).cos()
            } else {
                0.0
            }
        };
        let e: Vec<f64> = omega
            .iter()
            .map(|w| 1.0 + bump(*w, 600.0, 0.01, 50.0) + bump(*w, 1500.0, 0.005, 20.0) + ripple(*w))
            .collect();
        let p = find_peaks(&omega, &e, &e);
        assert_eq!(p.len(), 3, "{p:?}");
        assert!((omega[p[0].k] - 600.0).abs() <= 1.0);
        assert!((omega[p[1].k] - 1500.0).abs() <= 1.0);
        // One of the ripple's maxima (the resonances' tails tilt the plateau).
        assert!((omega[p[2].k] - 1000.0).abs() < 50.0, "{p:?}");
        assert!(p[2].lo <= 951.0 && p[2].hi >= 1049.0, "{p:?}");
        // Half-height width of a resonance: ≈ 2√3 ζ ω0 (20.8 and 26.0 rad/s).
        let width = |q: &RawPeak| q.hi - q.lo;
        assert!(
            (width(&p[0]) - 2.0 * 3f64.sqrt() * 0.01 * 600.0).abs() < 3.0,
            "{p:?}"
        );
        assert!(
            (width(&p[1]) - 2.0 * 3f64.sqrt() * 0.005 * 1500.0).abs() < 3.0,
            "{p:?}"
        );
        // Below the height threshold: nothing.
        let flat: Vec<f64> = e.iter().map(|x| x / 100.0).collect();
        assert!(find_peaks(&omega, &e, &flat).is_empty());
    }
}

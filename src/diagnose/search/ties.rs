//! Ties: two candidates, or two effect sets, whose information criteria lie within
//! [`TIE_BIC`] of each other (the data do not choose between them: a BIC difference below 6
//! is at most "positive" evidence, Kass & Raftery 1995), and where a measurement would tell
//! them apart.
//!
//! Two fitted models are told apart at `ω` when they differ there by more than the data's
//! (median) relative noise on some channel, `|G_a − G_b| > (r/|G|)_med · |G_a|`: one datum
//! measured there as well as the band was measured separates them by a noise radius.  The
//! search runs outward from the band, up to two decades above and below it, and reports the
//! first such frequency on each side.

use crate::diagnose::effects::candidates::fmt_w;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::report::{CandidateReport, Tie};
use crate::diagnose::search::beam::SearchResult;
use crate::diagnose::search::node::Node;
use crate::diagnose::search::rank::TIE_BIC;
use crate::model::physical::PhysicalModel;

/// The nearest frequencies (rad/s) outside the measured band where two fitted models differ
/// by more than the noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Separation {
    /// Above the band.
    pub above: Option<f64>,
    /// Below the band.
    pub below: Option<f64>,
}

/// Where models `a` and `b` (fitted to `data`) can be told apart (see the module docs).
pub fn separation(a: &PhysicalModel, b: &PhysicalModel, data: &Channels) -> Separation {
    let (wmin, wmax) = (data.omega[0], *data.omega.last().expect("data"));
    let mut rel: Vec<f64> = (0..data.n_ch())
        .flat_map(|ch| (0..data.len()).map(move |k| (ch, k)))
        .map(|(ch, k)| data.radius[ch][k] / data.g[ch][k].norm().max(1e-300))
        .collect();
    rel.sort_by(|x, y| x.total_cmp(y));
    let rel_noise = rel[rel.len() / 2];
    let differs = |w: f64| {
        let (ga, gb) = (a.eval(w), b.eval(w));
        data.entries.iter().any(|e| {
            let (x, y) = (ga[*e], gb[*e]);
            (x - y).norm() > rel_noise * x.norm()
        })
    };
    // 100 steps per decade, two decades each way.
    let step = |i: usize| 10f64.powf(i as f64 / 100.0);
    Separation {
        above: (1..=200).map(|i| wmax * step(i)).find(|w| differs(*w)),
        below: (1..=200).map(|i| wmin / step(i)).find(|w| differs(*w)),
    }
}

/// The sentence that says where to measure.
pub fn disambiguation(s: &Separation) -> String {
    let tail = "measure there to tell them apart";
    match (s.above, s.below) {
        (Some(h), Some(l)) => format!(
            "the two fitted models differ by more than the noise above {} and below {}: {tail}",
            fmt_w(h),
            fmt_w(l)
        ),
        (Some(h), None) => format!(
            "the two fitted models differ by more than the noise above {}: {tail}",
            fmt_w(h)
        ),
        (None, Some(l)) => format!(
            "the two fitted models differ by more than the noise below {}: {tail}",
            fmt_w(l)
        ),
        (None, None) => "the two fitted models agree within the noise from a hundredth of the lowest to a hundred times the highest measured frequency: lower the noise (more periods or averages) to tell them apart".into(),
    }
}

fn tie(
    effects: [String; 2],
    bic_gap: f64,
    a: &PhysicalModel,
    b: &PhysicalModel,
    data: &Channels,
) -> Tie {
    let s = separation(a, b, data);
    Tie {
        effects,
        bic_gap,
        disambiguation: disambiguation(&s),
        separates_above: s.above,
        separates_below: s.below,
    }
}

/// Ties of the chosen set (`chosen_model`, its labels `chosen_labels`) with the other sets
/// of as many effects that the search kept within [`TIE_BIC`] of it.
pub fn set_ties(
    res: &SearchResult,
    chosen_labels: &[String],
    chosen_model: &PhysicalModel,
    data: &Channels,
) -> Vec<Tie> {
    let chosen = &res.nodes[res.chosen];
    res.nodes
        .iter()
        .enumerate()
        .filter(|(i, nd)| {
            *i != res.chosen
                && (nd.bic - chosen.bic).abs() < TIE_BIC
                && nd.effects.len() == chosen.effects.len()
                && !nd.effects.is_empty()
                // The same effects added in another order refit to the same model: not a
                // rival (the gap is the refit's rounding).
                && !same_fit(nd, chosen)
        })
        .map(|(_, nd)| {
            tie(
                [chosen_labels.join(" + "), nd.labels().join(" + ")],
                (nd.bic - chosen.bic).abs(),
                chosen_model,
                &nd.model,
                data,
            )
        })
        .collect()
}

/// Two nodes of the search are the same fit: the same effects (in any order), the same BIC
/// up to the refits' convergence (relative 1e-6) and their modes at the same frequencies
/// (relative 1e-3).
pub fn same_fit(a: &Node, b: &Node) -> bool {
    let sorted = |n: &Node| {
        let mut l = n.labels();
        l.sort();
        l
    };
    let modes = |n: &Node| {
        let mut w: Vec<f64> = n.model.mode.iter().map(|m| m.omega_n).collect();
        w.sort_by(f64::total_cmp);
        w
    };
    let (wa, wb) = (modes(a), modes(b));
    (a.bic - b.bic).abs() <= 1e-6 * a.bic.abs().max(1.0)
        && sorted(a) == sorted(b)
        && wa.len() == wb.len()
        && wa.iter().zip(&wb).all(|(x, y)| (x / y - 1.0).abs() < 1e-3)
}

/// Marks the first-level candidates tied with the best one (both passing, within
/// [`TIE_BIC`]) and returns those ties, leaving out pairs already in `known`.
pub fn candidate_ties(
    candidates: &mut [CandidateReport],
    known: &[Tie],
    data: &Channels,
) -> Vec<Tie> {
    let Some(best) = candidates.first().cloned() else {
        return vec![];
    };
    let seen = |a: &str, b: &str| {
        known.iter().any(|t| {
            (t.effects[0] == a && t.effects[1] == b) || (t.effects[0] == b && t.effects[1] == a)
        })
    };
    let mut out = Vec::new();
    for c in candidates.iter_mut().skip(1) {
        c.tie_with_best = c.passes && best.passes && (best.delta_bic - c.delta_bic).abs() < TIE_BIC;
        if c.tie_with_best && !seen(&best.effect, &c.effect) {
            out.push(tie(
                [best.effect.clone(), c.effect.clone()],
                (best.delta_bic - c.delta_bic).abs(),
                &best.model,
                &c.model,
                data,
            ));
        }
    }
    out
}

//! The final-set holdout of `diagnose` (see [`super::engine`]): per effect of the chosen
//! set, fitted on 3 of every 4 data, the held-out quarter's `V` must be lower with the effect
//! than without it; for a multiplicative effect, also fitted below 70 % of the band (log
//! frequency), the top 30 % must be predicted better.
//!
//! The models with and without the effect are the search's own jointly refit models of
//! those effect sets when it kept one (the lowest-cost node of that set), else the set
//! assembled on the configured model and refit from a rough start.  Each is then refit (LM
//! from there) on the part: an effect the part does not see keeps its all-data value
//! instead of drifting.

use super::candidates::Cand;
use super::channels::Channels;
use super::rank::{EXTRAPOLATION_SPLIT, MIN_SPLIT_DATA};
use super::report::Holdout;
use super::retune::{cost, retune_within};
use super::search::{add_effect, Node};
use crate::model::physical::PhysicalModel;

/// The effects of a set with its `j`-th left out (the set the holdout and the backward
/// elimination compare against).
pub fn without(effects: &[(Cand, Vec<f64>)], j: usize) -> Vec<(Cand, Vec<f64>)> {
    effects
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != j)
        .map(|(_, e)| e.clone())
        .collect()
}

/// The model of the effect set `effects` on the configured model `root`: the search's
/// lowest-cost node of that set, else the set assembled on `root` (parameters as fitted when
/// added) and refit jointly from a rough start.
pub fn model_of(
    root: &PhysicalModel,
    effects: &[(Cand, Vec<f64>)],
    nodes: &[Node],
    data: &Channels,
) -> PhysicalModel {
    let mut key: Vec<String> = effects.iter().map(|e| e.0.label()).collect();
    key.sort();
    let found = nodes
        .iter()
        .filter(|n| {
            let mut k = n.labels();
            k.sort();
            k == key && !n.configured
        })
        .min_by(|a, b| a.v_fit.total_cmp(&b.v_fit));
    if let Some(n) = found {
        return n.model.clone();
    }
    let mut m = root.clone();
    for (c, th) in effects {
        m = add_effect(&m, c, th, data);
    }
    retune_within(&m, root, data, None, true).model
}

/// Final-set holdout of every effect of `node` (see the module docs); `nodes` are the
/// search's nodes.
pub fn holdouts(
    root: &PhysicalModel,
    node: &Node,
    nodes: &[Node],
    data: &Channels,
) -> Vec<Holdout> {
    let f = data.len();
    let fit: Vec<usize> = (0..f).filter(|k| k % 4 != 3).collect();
    let ho: Vec<usize> = (0..f).filter(|k| k % 4 == 3).collect();
    let cut = {
        let (lo, hi) = (data.omega[0].ln(), data.omega[f - 1].ln());
        (lo + EXTRAPOLATION_SPLIT * (hi - lo)).exp()
    };
    let (low, high): (Vec<usize>, Vec<usize>) = (0..f).partition(|k| data.omega[*k] < cut);
    let extrap = low.len() >= MIN_SPLIT_DATA && high.len() >= MIN_SPLIT_DATA;
    let part = |m: &PhysicalModel, mask: &[usize], test: &[usize]| {
        cost(
            &retune_within(m, root, data, Some(mask), false).model,
            data,
            test,
        )
    };
    let full = node.model.clone();
    let full_ho = part(&full, &fit, &ho);
    let full_hi = extrap.then(|| part(&full, &low, &high));
    (0..node.effects.len())
        .map(|j| {
            let others = without(&node.effects, j);
            let c = node.effects[j].0;
            let wo = model_of(root, &others, nodes, data);
            let wo_ho = part(&wo, &fit, &ho);
            let extrapolation_ok = (extrap && c.multiplicative())
                .then(|| full_hi.unwrap_or(f64::INFINITY) < part(&wo, &low, &high));
            Holdout {
                effect: c.label(),
                interleaved_ok: full_ho < wo_ho,
                extrapolation_ok,
            }
        })
        .collect()
}

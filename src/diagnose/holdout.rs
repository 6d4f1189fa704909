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

/// Two added modes are the same effect when their frequencies (as fitted when added) agree
/// within this relative distance (`|ln ω_a − ln ω_b|`); close modes 5 % apart are distinct.
pub const SAME_MODE_LN: f64 = 0.01;

/// True when `a` and `b` hold the same effects in any order: each effect of `a` pairs with
/// an equal candidate of `b`, and an added mode only with a mode at the same frequency
/// (within [`SAME_MODE_LN`]).  Labels alone do not tell two added modes apart: a set
/// `{mode 900 Hz}` must not be taken for `{mode 810 Hz}` (issue 20 item 3).
pub fn same_set(a: &[(Cand, Vec<f64>)], b: &[(Cand, Vec<f64>)]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut used = vec![false; b.len()];
    for (ca, ta) in a {
        let best = b
            .iter()
            .enumerate()
            .filter(|(i, (cb, _))| !used[*i] && cb == ca)
            .map(|(i, (_, tb))| {
                let d = match ca {
                    Cand::Mode => (ta[0] - tb[0]).abs(),
                    _ => 0.0,
                };
                (i, d)
            })
            .filter(|(_, d)| *d <= SAME_MODE_LN)
            .min_by(|x, y| x.1.total_cmp(&y.1));
        match best {
            Some((i, _)) => used[i] = true,
            None => return false,
        }
    }
    true
}

/// The model of the effect set `effects` on the configured model `root`: the search's
/// lowest-cost node of that set ([`same_set`]: the same effects, added modes at the same
/// frequencies), else the set assembled on `root` (parameters as fitted when added) and
/// refit jointly from a rough start.
pub fn model_of(
    root: &PhysicalModel,
    effects: &[(Cand, Vec<f64>)],
    nodes: &[Node],
    data: &Channels,
) -> PhysicalModel {
    let found = nodes
        .iter()
        .filter(|n| !n.configured && same_set(&n.effects, effects))
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

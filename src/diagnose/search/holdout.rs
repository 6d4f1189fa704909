//! The final-set holdout of `diagnose` (see [`crate::diagnose::engine`]): per effect of the chosen
//! set, fitted on 3 of every 4 data, the held-out quarter's `V` must be lower with the effect
//! than without it; for a multiplicative effect, also fitted below 70 % of the band (log
//! frequency), the top 30 % must be predicted better.
//!
//! The models with and without the effect are the search's own jointly refit models of
//! those effect sets when it kept one (the lowest-cost node of that set), else the set
//! assembled on the configured model and refit from a rough start.  Each is then refit (LM
//! from there) on the part: an effect the part does not see keeps its all-data value
//! instead of drifting.

use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::lsq::retune::{cost, retune_within};
use crate::diagnose::report::Holdout;
use crate::diagnose::search::node::{add_effect, Node};
use crate::diagnose::search::rank::{EXTRAPOLATION_SPLIT, MIN_SPLIT_DATA};
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;

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
/// an equal candidate of `b` whose fit is not apart from its own (`Cand::apart` within
/// `SAME_MODE_LN`: an added mode only with a mode at the same frequency).  Labels alone do
/// not tell two added modes apart: a set
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
            .map(|(i, (_, tb))| (i, ca.apart(ta, tb)))
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
    fit_of(root, effects, nodes, data).0
}

/// [`model_of`] with the least-squares cost `V` of its fit (the node's `v_fit`, or the
/// refit's).
pub fn fit_of(
    root: &PhysicalModel,
    effects: &[(Cand, Vec<f64>)],
    nodes: &[Node],
    data: &Channels,
) -> (PhysicalModel, f64) {
    let found = nodes
        .iter()
        .filter(|n| !n.configured && same_set(&n.effects, effects))
        .min_by(|a, b| a.v_fit.total_cmp(&b.v_fit));
    if let Some(n) = found {
        return (n.model.clone(), n.v_fit);
    }
    let mut m = root.clone();
    for (c, th) in effects {
        m = add_effect(&m, c, th, data);
    }
    let r = retune_within(&m, root, data, None, true);
    (r.model, r.v_after)
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
    let (full_ho, full_hi) = rayon::join(
        || part(&full, &fit, &ho),
        || extrap.then(|| part(&full, &low, &high)),
    );
    // Each effect's refits are independent of the others': in parallel (indexed collect,
    // the same rows in the same order).
    (0..node.effects.len())
        .into_par_iter()
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

/// The final holdout ([`crate::diagnose::search::holdout`]) of the chosen set; an effect that fails it is
/// dropped and the rest refit.  A fit below 70 % of the band cannot place an additive effect
/// (a mode, a feedthrough) that acts above it, so the extrapolation test decides only for
/// sets of multiplicative effects; otherwise it is reported.  Returns the holdout rows and
/// the labels dropped.
pub(crate) fn drop_failing_holdout(
    base: &PhysicalModel,
    node: &mut Node,
    nodes: &[Node],
    data: &Channels,
) -> Result<(Vec<Holdout>, Vec<String>)> {
    let holdout = holdouts(base, node, nodes, data);
    let all_mult = node.effects.iter().all(|e| e.0.multiplicative());
    let failing: Vec<usize> = holdout
        .iter()
        .enumerate()
        .filter(|(_, h)| !h.interleaved_ok || (all_mult && h.extrapolation_ok == Some(false)))
        .map(|(i, _)| i)
        .collect();
    if failing.is_empty() {
        return Ok((holdout, Vec::new()));
    }
    let keep: Vec<_> = node
        .effects
        .iter()
        .enumerate()
        .filter(|(i, _)| !failing.contains(i))
        .map(|(_, e)| e.clone())
        .collect();
    let dropped: Vec<String> = failing.iter().map(|i| node.effects[*i].0.label()).collect();
    let model = model_of(base, &keep, nodes, data);
    node.measures = Problem::new(&model, data)?.measures(&Default::default());
    node.v_fit = node.measures.v;
    node.model = model;
    // Steps and effects are parallel (one effect per step): drop the failing ones by
    // position, not by label (a dropped mode is not every mode).
    let mut k = 0;
    node.steps.retain(|_| {
        k += 1;
        !failing.contains(&(k - 1))
    });
    node.effects = keep;
    Ok((holdout, dropped))
}

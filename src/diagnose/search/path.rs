//! The chosen path and the runner-up sets once the final holdout or the backward elimination
//! dropped effects of the chosen set (issue 33): the path is the set kept's, numbered from 1,
//! and the runner-ups are the other fits of the search, one per fit.

use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::lsq::slots::slots;
use crate::diagnose::report::EffectSet;
use crate::diagnose::search::beam::SearchResult;
use crate::diagnose::search::final_effects::final_effects;
use crate::diagnose::search::holdout::{model_of, same_set};
use crate::diagnose::search::node::{add_effect, Node};
use crate::diagnose::search::ties::same_fit;
use crate::error::Result;
use crate::model::physical::PhysicalModel;

/// The chosen path after the holdout or the backward elimination dropped effects of the
/// chosen set (issue 33, stop 44: a dropped first mode left "step 2" without a step 1, with
/// the figures of the refit that still held the dropped mode).  When a search node holds
/// the same set, its own path, BIC and parameter count; else the kept steps numbered 1, 2, …
/// (the modes of a group keep sharing their number), the last step's figures and parameters
/// those of the refit kept (before the refit: its effects, as fitted alone, written into the
/// refit of the steps before it), its BIC `2V + n_θ ln 2F` with `n_θ` counted on its slots.
/// Returns the node of the same set, if any.
pub(crate) fn restate_path(
    node: &mut Node,
    nodes: &[Node],
    base: &PhysicalModel,
    data: &Channels,
) -> Result<Option<usize>> {
    let same = nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| !n.configured && same_set(&n.effects, &node.effects))
        .min_by(|a, b| a.1.v_fit.total_cmp(&b.1.v_fit));
    if let Some((i, n)) = same {
        node.steps = n.steps.clone();
        node.n_params = n.n_params;
        node.bic = n.bic;
        return Ok(Some(i));
    }
    let (lin, nl) = slots(&node.model, data);
    node.n_params = lin.len() + nl.len();
    node.bic = 2.0 * node.v_fit + node.n_params as f64 * (2.0 * data.n_data() as f64).ln();
    let (mut last, mut k) = (None, 0);
    for s in node.steps.iter_mut() {
        if last != Some(s.step) {
            k += 1;
            last = Some(s.step);
        }
        s.step = k;
    }
    // The last step's "before the refit": its effects written, as fitted alone, into the
    // refit of the steps before it.
    let first = node.steps.iter().position(|s| s.step == k).unwrap_or(0);
    let mut with = model_of(base, &node.effects[..first], nodes, data);
    for (c, th) in &node.effects[first..] {
        with = add_effect(&with, c, th, data);
    }
    let before = Problem::new(&with, data)?.measures(&Default::default());
    let cands: Vec<_> = node.effects.iter().map(|e| e.0).collect();
    let finals = final_effects(&node.model, base, &cands, data, false);
    for (s, fe) in node.steps.iter_mut().zip(finals) {
        if s.step == k {
            s.params = fe.params;
            s.misfit_rms = node.measures.misfit_rms;
            s.invalid_fraction = node.measures.invalid_fraction;
            s.misfit_rms_before_refit = before.misfit_rms;
            s.invalid_fraction_before_refit = before.invalid_fraction;
            s.n_refit = node.n_params;
        }
    }
    Ok(None)
}

/// The four best other effect sets of the search, by BIC, with their gap to the chosen one
/// (`chosen`, the set kept): one per fit (the same effects added in another order refit to
/// the same model, [`same_fit`]), neither the chosen set nor `rejected` (the node whose set
/// the holdout refused).
pub(crate) fn runner_ups(
    res: &SearchResult,
    chosen: &Node,
    rejected: Option<&Node>,
) -> Vec<EffectSet> {
    let chosen_bic = chosen.bic;
    let mut order: Vec<usize> = (0..res.nodes.len()).collect();
    order.sort_by(|a, b| res.nodes[*a].bic.total_cmp(&res.nodes[*b].bic));
    let mut kept: Vec<usize> = Vec::new();
    for i in order {
        let nd = &res.nodes[i];
        let seen = kept.iter().any(|j| same_fit(&res.nodes[*j], nd));
        if !seen && !same_fit(nd, chosen) && !rejected.is_some_and(|r| same_fit(nd, r)) {
            kept.push(i);
        }
    }
    let mut runner_up: Vec<EffectSet> = kept
        .into_iter()
        .map(|i| &res.nodes[i])
        .map(|nd| EffectSet {
            effects: nd.labels(),
            bic: nd.bic,
            bic_gap: nd.bic - chosen_bic,
            misfit_rms: nd.measures.misfit_rms,
            invalid_fraction: nd.measures.invalid_fraction,
            consistent: nd.measures.consistent(),
        })
        .collect();
    runner_up.sort_by(|a, b| a.bic.total_cmp(&b.bic));
    runner_up.truncate(4);
    runner_up
}

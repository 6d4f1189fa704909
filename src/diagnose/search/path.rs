//! The chosen path and the runner-up sets once the final holdout or the backward elimination
//! dropped effects of the chosen set (issue 33): the path is the set kept's, numbered from 1,
//! and the runner-ups are the other fits of the search, one per fit.

use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::lsq::slots::slots;
use crate::diagnose::report::EffectSet;
use crate::diagnose::search::assign::align_from;
use crate::diagnose::search::beam::SearchResult;
use crate::diagnose::search::final_effects::final_effects;
use crate::diagnose::search::holdout::{fit_of, same_set};
use crate::diagnose::search::node::{add_effect, Node};
use crate::diagnose::search::ties::same_fit;
use crate::error::Result;
use crate::model::physical::PhysicalModel;

/// The chosen path after the holdout or the backward elimination dropped effects of the
/// chosen set `orig` (issue 33, stop 44: a dropped first mode left "step 2" without a step 1,
/// with the figures of the refit that still held the dropped mode).  When a search node holds
/// the same set, its own path, BIC and parameter count; else the kept steps numbered 1, 2, …
/// (the modes of a group keep sharing their number) and every step from the first one whose
/// predecessors changed (at least the last) restated ([`restate_step`]): its figures and
/// parameters those of the refit of the kept steps up to it, its ΔBIC against the refit of
/// the kept steps before it; the node's BIC `2V + n_θ ln 2F` with `n_θ` counted on its slots.
/// Returns the node of the same set, if any.
pub(crate) fn restate_path(
    node: &mut Node,
    orig: &Node,
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
    node.bic = crate::diagnose::lsq::measures::bic(node.v_fit, node.n_params, data.n_data());
    let (mut last, mut k) = (None, 0);
    for s in node.steps.iter_mut() {
        if last != Some(s.step) {
            k += 1;
            last = Some(s.step);
        }
        s.step = k;
    }
    // The first kept effect whose predecessors in the path are not the original ones (the
    // effects are clones of the original's, compared exactly).
    let first_changed = node
        .effects
        .iter()
        .zip(&orig.effects)
        .position(|(a, b)| a.0 != b.0 || a.1 != b.1)
        .unwrap_or(node.effects.len());
    let from = node.steps.get(first_changed).map_or(k, |s| s.step).min(k);
    for step in from..=k {
        restate_step(node, step, nodes, base, data)?;
    }
    Ok(None)
}

/// Restates step `step` of `node`'s path: its parameters and figures those of the refit of
/// the kept effects up to it (the node's own refit for the last step), the figures "before
/// the refit" those of its effects, as fitted alone, written into the refit of the steps
/// before it, and its ΔBIC `2(V_before − V) − n_new ln 2F` against that refit (for step 1,
/// the better of the configured model and its retune, as the search measures it).
fn restate_step(
    node: &mut Node,
    step: usize,
    nodes: &[Node],
    base: &PhysicalModel,
    data: &Channels,
) -> Result<()> {
    let first = node.steps.iter().position(|s| s.step == step).unwrap_or(0);
    let end = node
        .steps
        .iter()
        .rposition(|s| s.step == step)
        .map_or(node.effects.len(), |i| i + 1);
    let retuned = nodes.iter().find(|n| !n.configured && n.effects.is_empty());
    let anchors: Vec<&PhysicalModel> = std::iter::once(base)
        .chain(retuned.map(|n| &n.model))
        .collect();
    let (prev, v_prev) = if first == 0 {
        let v_root = nodes
            .iter()
            .filter(|n| n.effects.is_empty())
            .map(|n| n.v_fit)
            .fold(f64::INFINITY, f64::min);
        let m = retuned.map_or_else(|| base.clone(), |n| n.model.clone());
        let v = if v_root.is_finite() {
            v_root
        } else {
            Problem::new(&m, data)?.measures(&Default::default()).v
        };
        (m, v)
    } else {
        fit_of(base, &node.effects[..first], nodes, data)
    };
    let (model, measures, v) = if end == node.effects.len() {
        (node.model.clone(), node.measures, node.v_fit)
    } else {
        let (m, v) = fit_of(base, &node.effects[..end], nodes, data);
        let m = align_from(&anchors, &m, &node.effects[..end]);
        let measures = Problem::new(&m, data)?.measures(&Default::default());
        (m, measures, v)
    };
    let mut with = prev;
    for (c, th) in &node.effects[first..end] {
        with = add_effect(&with, c, th, data);
    }
    let before = Problem::new(&with, data)?.measures(&Default::default());
    let (lin, nl) = slots(&model, data);
    let n_new: usize = node.effects[first..end]
        .iter()
        .map(|e| e.0.n_params(data.n_ch()))
        .sum();
    let d_bic = crate::diagnose::lsq::measures::delta_bic(v_prev - v, n_new, data.n_data());
    let cands: Vec<_> = node.effects[..end].iter().map(|e| e.0).collect();
    let finals = final_effects(&model, base, &cands, data, false);
    for (s, fe) in node.steps[first..end].iter_mut().zip(&finals[first..]) {
        s.params = fe.params.clone();
        s.misfit_rms = measures.misfit_rms;
        s.invalid_fraction = measures.invalid_fraction;
        s.misfit_rms_before_refit = before.misfit_rms;
        s.invalid_fraction_before_refit = before.invalid_fraction;
        s.n_refit = lin.len() + nl.len();
        s.delta_bic = d_bic;
    }
    Ok(())
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

//! A child of a search node, judged: one proposal (an effect fitted alone, or several modes
//! proposed together, [`super::multi_mode`]) written into the node's model and jointly refit
//! is a child when its joint ΔBIC against the node exceeds the threshold, it improves on the
//! node ([`super::rank::improves`]), the refit left no new mode at a band edge, and it is
//! physically admissible ([`crate::diagnose::admissible`]).  Steps and effects stay
//! parallel: one step per effect added, the modes of a group sharing their step number.

use super::multi_mode::check_each;
use super::node::Node;
use super::rank::{improves, modes_at_band_edge, si_map, Screened};
use crate::diagnose::admissible::{check, Child, Refusal};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::{delta_bic, Measures};
use crate::diagnose::report::Step;
use crate::diagnose::search::final_effects::final_effects;
use crate::model::physical::PhysicalModel;

/// A joint refit: the model, its measures, its least-squares cost and number of parameters.
pub(super) type Refit = (PhysicalModel, Measures, f64, usize);

/// What a child is judged against.
pub(super) struct Judge<'a> {
    pub data: &'a Channels,
    /// ΔBIC a child must exceed.
    pub min_delta_bic: f64,
    /// Write modes at mains frequencies anyway.
    pub allow_mains: bool,
    /// The configured model (the anchor of every refit's boxes).
    pub anchor: &'a PhysicalModel,
    /// The retuned root's model.
    pub retuned: &'a PhysicalModel,
    /// The measures admissibility compares against (the node's, or the better retune's).
    pub reference: &'a Measures,
    /// The cost ΔBIC is measured against.
    pub ref_v: f64,
    pub depth: usize,
}

/// The child of `node` made of `added` (fitted alone on it) and its joint `refit`
/// (`before`: the measures with `added` written in, before the refit), or the refusal of an
/// admissibility rule (`None, None`: it failed the likelihood or the band-edge test).
pub(super) fn judge(
    j: &Judge<'_>,
    node: &Node,
    added: &[&Screened],
    refit: Refit,
    before: Measures,
) -> (Option<Node>, Option<Refusal>) {
    let data = j.data;
    let (model, m, v_fit, n_refit) = refit;
    let n_new: usize = added.iter().map(|sc| sc.cand.n_params(data.n_ch())).sum();
    let d_bic = delta_bic(j.ref_v - v_fit, n_new, data.n_data());
    // A mode the joint refit pushed to a band edge is not a resonance of the data (it would
    // be written at exactly the band top).
    let (w_lo, w_hi) = (data.omega[0], *data.omega.last().expect("data"));
    let at_edge =
        modes_at_band_edge(&model, w_lo, w_hi) > modes_at_band_edge(&node.model, w_lo, w_hi);
    let mut effects = node.effects.clone();
    effects.extend(added.iter().map(|sc| (sc.cand, sc.mods.theta.clone())));
    // The configured modes first, matched by frequency and shape, then the added ones in the
    // order chosen (never read by slot).  Matched against the retuned root (the configured
    // modes where the retune put them): from a rough start a configured mode may lie nearer
    // the added one than where it belongs.
    let model = super::assign::align_from(&[j.anchor, j.retuned], &model, &effects);
    let likely = d_bic > j.min_delta_bic && improves(&m, &node.measures) && !at_edge;
    if !likely {
        return (None, None);
    }
    let refusal = match added {
        [one] => check(
            &Child {
                cand: one.cand,
                model: &model,
                measures: &m,
                reference: j.reference,
                allow_mains: j.allow_mains,
                min_delta_bic: j.min_delta_bic,
            },
            data,
        ),
        _ => check_each(
            &model,
            added.len(),
            &m,
            j.allow_mains,
            j.min_delta_bic,
            data,
        ),
    };
    if refusal.is_some() {
        return (None, refusal);
    }
    let cands: Vec<_> = effects.iter().map(|e| e.0).collect();
    let finals = final_effects(&model, j.anchor, &cands, data, false);
    let first_new = finals.len().saturating_sub(added.len());
    let mut steps = node.steps.clone();
    for (sc, fe) in added.iter().zip(finals.into_iter().skip(first_new)) {
        let mut explanation = crate::diagnose::effects::explain::explain(
            &sc.cand,
            &sc.mods.theta,
            &data.entries,
            &node.model,
            &data.omega,
        );
        if added.len() > 1 {
            explanation += &format!(
                " (one of {} modes proposed together at the residual's peaks and refit jointly; ΔBIC and the measures are the group's)",
                added.len()
            );
        }
        steps.push(Step {
            step: j.depth,
            effect: sc.cand.label(),
            params: fe.params,
            params_fitted_alone: si_map(&sc.cand, &sc.mods.theta, &data.entries),
            explanation,
            misfit_rms: m.misfit_rms,
            invalid_fraction: m.invalid_fraction,
            delta_bic: d_bic,
            misfit_rms_before_refit: before.misfit_rms,
            invalid_fraction_before_refit: before.invalid_fraction,
            n_refit,
            ties: vec![],
        });
    }
    let child = Node {
        effects,
        bic: crate::diagnose::lsq::measures::bic(v_fit, n_refit, data.n_data()),
        model,
        measures: m,
        v_fit,
        n_params: n_refit,
        steps,
        configured: false,
    };
    (Some(child), None)
}

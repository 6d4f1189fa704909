//! Backward elimination after the forward search: an effect of the chosen set that the data
//! do not need — removing it (and refitting the rest jointly) costs no more than the
//! acceptance threshold, `ΔBIC = 2(V_without − V) − n_e·ln(2F) ≤ min_delta_bic` (10) — is dropped, the
//! weakest first, until every remaining effect is needed.  This removes vacuous effects the
//! forward search kept, such as a lag whose corner refit far above the band (it contributes
//! nothing there once other effects were added).

use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::lsq::retune::retune_within;
use crate::diagnose::search::holdout::{model_of, without};
use crate::diagnose::search::node::Node;
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;

/// Drops the effects of `node` the data do not need (see the module docs), refitting the
/// rest; `nodes` are the search's nodes (reused models of the smaller sets).  Returns the
/// labels dropped, in order.
pub fn eliminate(
    base: &PhysicalModel,
    node: &mut Node,
    nodes: &[Node],
    data: &Channels,
    min_delta_bic: f64,
) -> Result<Vec<String>> {
    let ln2f = (2.0 * data.n_data() as f64).ln();
    let mut dropped = Vec::new();
    while !node.effects.is_empty() {
        // The refits without each effect are independent: in parallel (rayon's indexed
        // collect keeps their order, so the weakest is picked as in a serial loop).
        let refits: Vec<_> = (0..node.effects.len())
            .into_par_iter()
            .map(|j| {
                let others = without(&node.effects, j);
                let wo = model_of(base, &others, nodes, data);
                retune_within(&wo, base, data, None, false)
            })
            .collect();
        let mut worst: Option<(usize, f64, PhysicalModel, f64)> = None;
        for (j, r) in refits.into_iter().enumerate() {
            let n_e = node.effects[j].0.n_params(data.n_ch());
            let d_bic = 2.0 * (r.v_after - node.v_fit) - n_e as f64 * ln2f;
            if d_bic <= min_delta_bic && worst.as_ref().is_none_or(|w| d_bic < w.1) {
                worst = Some((j, d_bic, r.model, r.v_after));
            }
        }
        let Some((j, _, model, v)) = worst else {
            break;
        };
        dropped.push(node.effects[j].0.label());
        node.effects.remove(j);
        // Steps and effects are parallel: remove this one's step, not every step of its label.
        if j < node.steps.len() {
            node.steps.remove(j);
        }
        node.measures = Problem::new(&model, data)?.measures(&Default::default());
        node.model = model;
        node.v_fit = v;
    }
    Ok(dropped)
}

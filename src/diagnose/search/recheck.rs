//! The reduced set re-checked for physical admissibility (issue 33, stop 46): when the final
//! holdout or the backward elimination drops part of the chosen set, the set left is a
//! **refit** subset of an admissible one, and its refit can move a mode onto a bound, make
//! two modes cancel, or leave a term negligible.  Every rule of
//! [`crate::diagnose::admissible`] is applied again to each of its effects, on the set's own
//! refit, as if that effect had been added last: its terms moved to the end of their lists
//! (the rules read the last mode, path effect, integrator or rigid body), the measures the
//! set's, and the reference the refit of the set without it (a term whose removal changes
//! `misfit_rms` by less than 1 % is negligible, as the issue words the rule).
//!
//! The search's own nodes are judged one step at a time against their parent; this is the
//! whole set judged at once, as [`super::multi_mode::check_each`] judges a group.

use crate::diagnose::admissible::{check, Child, Refusal};
use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::search::assign::align_from;
use crate::diagnose::search::holdout::{fit_of, model_of, without};
use crate::diagnose::search::node::{add_effect, Node};
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;
use std::ops::Range;

/// The entries an effect appends to a model's lists: modes, path effects, integrators,
/// rigid bodies (empty for an effect that changes a configured term in place).
type Footprint = [Range<usize>; 4];

fn lens(m: &PhysicalModel) -> [usize; 4] {
    [
        m.mode.len(),
        m.effect.len(),
        m.integrator.len(),
        m.rigid_body.len(),
    ]
}

/// Where each effect of `effects`, written in order into `base`, puts its terms.
fn footprints(
    base: &PhysicalModel,
    effects: &[(Cand, Vec<f64>)],
    data: &Channels,
) -> Vec<Footprint> {
    let mut m = base.clone();
    effects
        .iter()
        .map(|(c, th)| {
            let before = lens(&m);
            m = add_effect(&m, c, th, data);
            let after = lens(&m);
            std::array::from_fn(|i| before[i]..after[i])
        })
        .collect()
}

/// Moves the entries `r` of `v` to its end, keeping the order of the rest.
fn to_end<T>(v: &mut Vec<T>, r: &Range<usize>) {
    let tail: Vec<T> = v.drain(r.clone()).collect();
    v.extend(tail);
}

/// `m` with the terms of the effect whose footprint is `fp` last in their lists.
fn as_last(m: &PhysicalModel, fp: &Footprint) -> PhysicalModel {
    let mut out = m.clone();
    to_end(&mut out.mode, &fp[0]);
    to_end(&mut out.effect, &fp[1]);
    to_end(&mut out.integrator, &fp[2]);
    to_end(&mut out.rigid_body, &fp[3]);
    out
}

/// What the re-check needs of the search.
pub(crate) struct Recheck<'a> {
    /// The configured model.
    pub base: &'a PhysicalModel,
    /// The search's nodes (models of the smaller sets are reused).
    pub nodes: &'a [Node],
    pub data: &'a Channels,
    /// Write modes at mains frequencies anyway.
    pub allow_mains: bool,
    /// The search's acceptance threshold ([`crate::diagnose::SearchSettings::min_delta_bic`]).
    pub min_delta_bic: f64,
}

impl Recheck<'_> {
    /// The first effect of `node` (in path order) that an admissibility rule refuses on the
    /// node's refit (see the module docs), with the refusal; `None` when every one passes.
    pub fn first_refusal(&self, node: &Node) -> Result<Option<(usize, Refusal)>> {
        let (base, data) = (self.base, self.data);
        if node.effects.is_empty() {
            return Ok(None);
        }
        let retuned = self
            .nodes
            .iter()
            .find(|n| !n.configured && n.effects.is_empty());
        let refs: Vec<&PhysicalModel> = std::iter::once(base)
            .chain(retuned.map(|n| &n.model))
            .collect();
        // Modes in the order of their effects (configured first), then each effect's terms
        // moved last.  A model whose lists do not have the replayed lengths (the search's
        // node of the same set, reached in another order, with path effects of two kinds) is
        // read as it is.
        let model = align_from(&refs, &node.model, &node.effects);
        let fps = footprints(base, &node.effects, data);
        let same_shape = fps
            .last()
            .is_some_and(|fp| std::array::from_fn::<usize, 4, _>(|i| fp[i].end) == lens(&model));
        let refusals: Vec<Result<Option<Refusal>>> = (0..node.effects.len())
            .into_par_iter()
            .map(|j| {
                let cand = node.effects[j].0;
                let last = if same_shape {
                    as_last(&model, &fps[j])
                } else {
                    model.clone()
                };
                let wo = model_of(base, &without(&node.effects, j), self.nodes, data);
                let reference = Problem::new(&wo, data)?.measures(&Default::default());
                Ok(check(
                    &Child {
                        cand,
                        model: &last,
                        measures: &node.measures,
                        reference: &reference,
                        allow_mains: self.allow_mains,
                        min_delta_bic: self.min_delta_bic,
                    },
                    data,
                ))
            })
            .collect();
        for (j, r) in refusals.into_iter().enumerate() {
            if let Some(mut r) = r? {
                r.reason = format!(
                    "{} (re-checked on the refit of the set the holdout and the backward elimination left)",
                    r.reason
                );
                return Ok(Some((j, r)));
            }
        }
        Ok(None)
    }

    /// Removes effect `j` of `node` and its step, the rest refit ([`fit_of`]: the search's
    /// node of that set, or a joint refit).
    pub fn remove(&self, node: &mut Node, j: usize) -> Result<()> {
        let keep = without(&node.effects, j);
        let (model, v) = fit_of(self.base, &keep, self.nodes, self.data);
        node.measures = Problem::new(&model, self.data)?.measures(&Default::default());
        node.v_fit = v;
        node.model = model;
        if j < node.steps.len() {
            node.steps.remove(j);
        }
        node.effects = keep;
        Ok(())
    }
}

/// For the peak account: the first mode among `refused` (the re-check's refusals) whose
/// frequency the peak's window `contains` (rad/s), named, and why it is not in the model.
pub(crate) fn removed_at(
    refused: &[Refusal],
    contains: impl Fn(f64) -> bool,
) -> Option<(String, String)> {
    let r = refused.iter().find(|r| {
        r.frequency_hz
            .is_some_and(|f| contains(std::f64::consts::TAU * f))
    })?;
    Some((
        format!("mode {} Hz", crate::report::fmt::sig(r.frequency_hz?)),
        format!(
            "a mode of the chosen set stood here; the set the holdout and the backward elimination left was refit and re-checked, and this mode was refused there ({}: {}) and removed",
            r.rule.word(),
            r.reason
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::effects::candidates::Sel;
    use crate::model::physical::{Gains, ModeSpec};

    const TAU: f64 = std::f64::consts::TAU;

    fn mode(f: f64, z: f64, rho: f64) -> ModeSpec {
        ModeSpec {
            name: None,
            omega_n: TAU * f,
            zeta: z,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(rho),
        }
    }

    /// The footprints of a mode, a delay and a second mode written into a model with one
    /// configured mode, and the model with the first added mode moved last (the path effect
    /// and the configured mode where they were).
    #[test]
    fn an_effect_is_moved_last_in_its_own_list_only() {
        let base = PhysicalModel {
            mode: vec![mode(100.0, 0.01, 1e4)],
            ..Default::default()
        };
        let omega: Vec<f64> = (50..=400).map(|k| TAU * k as f64).collect();
        let data = Channels::of_model(&base, omega, vec![(0, 0)], 1.0, (0.01, 0.02));
        let effects = vec![
            (Cand::Mode, vec![(TAU * 150.0).ln(), 0.01f64.ln(), 1e4]),
            (Cand::Delay(Sel::All), vec![1e-5]),
            (Cand::Mode, vec![(TAU * 250.0).ln(), 0.01f64.ln(), 1e4]),
        ];
        let fps = footprints(&base, &effects, &data);
        assert_eq!(fps[0], [1..2, 0..0, 0..0, 0..0]);
        assert_eq!(fps[1], [2..2, 0..1, 0..0, 0..0]);
        assert_eq!(fps[2], [2..3, 1..1, 0..0, 0..0]);
        let mut m = base.clone();
        for (c, th) in &effects {
            m = add_effect(&m, c, th, &data);
        }
        let hz: Vec<f64> = as_last(&m, &fps[0])
            .mode
            .iter()
            .map(|x| (x.omega_n / TAU).round())
            .collect();
        assert_eq!(hz, [100.0, 250.0, 150.0]);
        assert_eq!(as_last(&m, &fps[1]).effect.len(), 1);
    }
}

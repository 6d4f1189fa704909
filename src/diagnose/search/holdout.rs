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
use crate::diagnose::lsq::retune::{cost, retune_within};
use crate::diagnose::report::Holdout;
use crate::diagnose::search::node::{add_effect, Node};
use crate::diagnose::search::rank::{EXTRAPOLATION_SPLIT, MIN_SPLIT_DATA};
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;

/// How many next-best effect sets are tried when the holdout drops part of the chosen one.
pub const MAX_ALTERNATIVES: usize = 3;

/// The chosen set after the holdout, or a next-best set when the holdout drops part of it.
#[derive(Debug, Clone)]
pub struct Passing {
    /// The node kept (its model refit without what the holdout dropped).
    pub node: Node,
    /// The holdout rows of the kept set.
    pub holdout: Vec<Holdout>,
    /// Labels the holdout dropped from the search's chosen set.
    pub dropped: Vec<String>,
    /// The index in the search's nodes of the set kept instead of the chosen one, when one
    /// was (issue 20: a spurious chosen mode must not cost a whole step).
    pub replaced_by: Option<usize>,
}

/// The next-best effect sets after `chosen`: the search's nodes with effects, by BIC, not
/// the chosen set ([`same_set`]), one per set, at most `cap`.
pub fn alternatives(nodes: &[Node], chosen: usize, cap: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..nodes.len())
        .filter(|i| *i != chosen && !nodes[*i].configured && !nodes[*i].effects.is_empty())
        .filter(|i| !same_set(&nodes[*i].effects, &nodes[chosen].effects))
        .collect();
    order.sort_by(|a, b| nodes[*a].bic.total_cmp(&nodes[*b].bic));
    let mut out: Vec<usize> = Vec::new();
    for i in order {
        if !out
            .iter()
            .any(|o| same_set(&nodes[*o].effects, &nodes[i].effects))
        {
            out.push(i);
        }
    }
    out.truncate(cap);
    out
}

/// Runs the final holdout `check` (which drops failing effects from a node and returns its
/// rows and the labels dropped) on the chosen node; when it drops something, tries the next
/// [`MAX_ALTERNATIVES`] sets of [`alternatives`] in BIC order and keeps the first whose
/// holdout drops nothing and that holds more effects than the reduced chosen set.  Without
/// this a spurious chosen mode (one the data do not confirm on held-out lines) made
/// `diagnose` report "no candidate passes" though a next-best set passed: a whole step lost.
pub fn first_passing<F>(nodes: &[Node], chosen: usize, mut check: F) -> Result<Passing>
where
    F: FnMut(&mut Node) -> Result<(Vec<Holdout>, Vec<String>)>,
{
    let mut node = nodes[chosen].clone();
    let (holdout, dropped) = check(&mut node)?;
    if dropped.is_empty() {
        return Ok(Passing {
            node,
            holdout,
            dropped,
            replaced_by: None,
        });
    }
    for i in alternatives(nodes, chosen, MAX_ALTERNATIVES) {
        if nodes[i].effects.len() <= node.effects.len() {
            continue;
        }
        let mut alt = nodes[i].clone();
        let (alt_holdout, alt_dropped) = check(&mut alt)?;
        if alt_dropped.is_empty() {
            return Ok(Passing {
                node: alt,
                holdout: alt_holdout,
                dropped,
                replaced_by: Some(i),
            });
        }
    }
    Ok(Passing {
        node,
        holdout,
        dropped,
        replaced_by: None,
    })
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::lsq::measures::Measures;

    /// A node holding one added mode at `f_hz` with BIC `bic`.
    fn node(f_hz: f64, bic: f64) -> Node {
        Node {
            effects: vec![(Cand::Mode, vec![(std::f64::consts::TAU * f_hz).ln(), -7.0])],
            model: PhysicalModel::default(),
            measures: Measures {
                v: bic,
                misfit_rms: 2.0,
                invalid_fraction: 0.5,
            },
            v_fit: bic,
            n_params: 3,
            bic,
            steps: vec![],
            configured: false,
        }
    }

    fn f_of(n: &Node) -> f64 {
        (n.effects[0].1[0].exp() / std::f64::consts::TAU).round()
    }

    /// The fake holdout: drops every effect of a node whose mode is not at a frequency in
    /// `pass` (as `drop_failing_holdout` does), and records the nodes it saw.
    fn check<'a>(
        pass: &'a [f64],
        seen: &'a mut Vec<f64>,
    ) -> impl FnMut(&mut Node) -> Result<(Vec<Holdout>, Vec<String>)> + 'a {
        move |n: &mut Node| {
            let f = f_of(n);
            seen.push(f);
            let ok = pass.contains(&f);
            let rows = vec![Holdout {
                effect: "mode".into(),
                interleaved_ok: ok,
                extrapolation_ok: None,
            }];
            if ok {
                Ok((rows, vec![]))
            } else {
                n.effects.clear();
                Ok((rows, vec!["mode".into()]))
            }
        }
    }

    /// A chosen mode the holdout drops: the next sets are tried in BIC order (a duplicate of
    /// the chosen set and the roots skipped) and the first that passes is kept.
    #[test]
    fn a_dropped_chosen_mode_gives_way_to_the_next_passing_set() {
        let mut root = node(1.0, 50.0);
        root.effects.clear();
        root.configured = true;
        let nodes = vec![
            root,
            node(824.0, 0.0),
            node(1000.0, 1.0),
            node(824.5, 1.5), // the chosen set again (within 1 % in frequency)
            node(500.0, 2.0),
            node(300.0, 3.0),
        ];
        let mut seen = Vec::new();
        let p = first_passing(&nodes, 1, check(&[500.0, 300.0], &mut seen)).unwrap();
        assert_eq!(p.replaced_by, Some(4));
        assert_eq!(f_of(&p.node), 500.0);
        assert_eq!(p.dropped, vec!["mode".to_string()]);
        assert!(p.holdout.iter().all(|h| h.interleaved_ok));
        assert_eq!(seen, vec![824.0, 1000.0, 500.0]);
    }

    /// At most [`MAX_ALTERNATIVES`] sets are tried; when none passes the chosen set stays,
    /// reduced, and a chosen set that passes is kept without trying anything else.
    #[test]
    fn alternatives_are_capped_and_a_passing_chosen_set_is_kept() {
        let nodes: Vec<Node> = [824.0, 1000.0, 700.0, 600.0, 500.0]
            .iter()
            .enumerate()
            .map(|(k, f)| node(*f, k as f64))
            .collect();
        assert_eq!(alternatives(&nodes, 0, MAX_ALTERNATIVES), vec![1, 2, 3]);
        let mut seen = Vec::new();
        let p = first_passing(&nodes, 0, check(&[500.0], &mut seen)).unwrap();
        assert_eq!(p.replaced_by, None);
        assert!(p.node.effects.is_empty());
        assert_eq!(seen, vec![824.0, 1000.0, 700.0, 600.0]);
        let mut seen = Vec::new();
        let p = first_passing(&nodes, 0, check(&[824.0, 500.0], &mut seen)).unwrap();
        assert_eq!((p.replaced_by, p.dropped.len()), (None, 0));
        assert_eq!(seen, vec![824.0]);
    }
}

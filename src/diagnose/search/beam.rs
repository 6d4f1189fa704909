//! The search over effect sets: a beam search over effect sequences with a joint refit of
//! every parameter at every node.
//!
//! * **Root**: the configured model retuned from a rough start ([`crate::diagnose::lsq::retune::retune`] with the mode
//!   grid). When it explains the data, nothing is added.
//! * **Expansion** of a node: every candidate is fitted alone on the node's model and
//!   scored by `ΔBIC = 2(V_node − V) − n·ln(2F)`; the best `beam + 1` that pass the screen
//!   (ΔBIC > 10, plausible: no parameter at a bound, a mode inside the band) are written into
//!   the model and **every** parameter is refit jointly (the node's own and the new
//!   effect's). Besides the screen's candidates, a mode is proposed at every other peak of
//!   the residual that would pass the screen ([`super::peak_modes`]), and all those modes
//!   together, in one step ([`super::multi_mode`]; each mode counts against
//!   `max_effects`). A child is kept when its joint ΔBIC against the node exceeds 10, it
//!   improves on the node ([`crate::diagnose::search::rank::improves`]: no more invalid data, or a lower
//!   `misfit_rms`), and the refit left no new mode at a band edge.
//! * **Level**: the children of all nodes, one per effect set (the best of the orders that
//!   reach it), the `beam` lowest `BIC = 2V + n_θ·ln(2F)` kept.
//! * **Stop** at the first level with a consistent node (fewest effects that explain the
//!   data), when no child passes, or after `max_effects` levels. The chosen set is the best
//!   consistent node of that level, else the lowest BIC of all; among the nodes within 6 of
//!   that BIC (a tie: the data do not choose) the one with the fewest parameters, then the
//!   catalogue's prior order ([`prior`]: a delay before a ZOH before an NMP zero). The other
//!   nodes are its runner-ups, those within 6 of its BIC are ties.
//! * **Consistency** of a node is judged on its consistency polish ([`settle`]): a
//!   least-squares fit within the noise in rms, with a few data just outside their disks, is
//!   moved inside its own 95 % confidence region towards the disks.  The BIC stays that of
//!   the least-squares fit.

use crate::diagnose::admissible::Refusal;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::lsq::retune::retune_or_give_up;
use crate::diagnose::report::Phases;
use crate::diagnose::search::child::{judge as judge_child, Judge, Refit};
use crate::diagnose::search::expand::expand;
pub(crate) use crate::diagnose::search::expand::screen_configured;
use crate::diagnose::search::holdout::same_set;
use crate::diagnose::search::node::{add_effect, Node};
use crate::diagnose::search::polish::settle;
use crate::diagnose::search::rank::{prior, Screened, TIE_BIC};
pub use crate::diagnose::search::settings::SearchSettings;
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use rayon::prelude::*;

/// A child's joint refit whose cost is still above this many times its reference (the
/// node's, or the better root's for the configured model) after
/// [`GIVE_UP_AFTER`](crate::diagnose::lsq::retune::GIVE_UP_AFTER)
/// iterations is given up: a child counts only below its reference (ΔBIC > 10) and the
/// cost of a least-squares fit never rises.  Across the diagnose suites (5840 child refits,
/// 2167 of them of the configured root), every refit that ended able to pass and ran past
/// 10 iterations (1264) was already below its reference there (at most 0.9995 of it); 115
/// were above 3 times it, and none of those could pass.
pub const GIVE_UP_FACTOR: f64 = 3.0;

/// BICs closer than this are the same fit: each least-squares cost is within
/// [`V_TOL`](crate::diagnose::lsq::lm::V_TOL) of its minimum, a BIC (`2V + …`) within twice that.
const SAME_FIT_BIC: f64 = 4.0 * crate::diagnose::lsq::lm::V_TOL;

/// `a`'s steps explain more than `b`'s: the first step where their ΔBICs differ is larger
/// in `a`.
fn steps_explain_more(a: &Node, b: &Node) -> bool {
    a.steps
        .iter()
        .zip(&b.steps)
        .map(|(x, y)| x.delta_bic.total_cmp(&y.delta_bic))
        .find(|o| o.is_ne())
        .is_some_and(|o| o.is_gt())
}

/// The outcome of a search.
pub struct SearchResult {
    /// Every node kept, the root first.
    pub nodes: Vec<Node>,
    /// Index of the chosen node.
    pub chosen: usize,
    /// The root's screened candidates (first level) and the children made of them.
    pub(crate) first_level: Vec<(Screened, Option<Node>, Option<Refusal>)>,
    /// Effects whose joint refit passed the likelihood but not physical admissibility
    /// ([`crate::diagnose::admissible`]), one per (effect, rule, frequency), in the order met.
    pub refused: Vec<(usize, Refusal)>,
    /// Nodes expanded.
    pub expanded: usize,
    /// Joint refits.
    pub joint_refits: usize,
    /// Joint refits given up (`GIVE_UP_FACTOR`).
    pub gave_up: usize,
    /// Wall time of the screens and of the joint refits.
    pub phases: Phases,
    /// Frequencies (Hz) of the modes proposed at residual peaks and refit jointly
    /// (`search::peak_modes`), whatever became of them.
    pub peak_modes_hz: Vec<f64>,
    /// Frequencies (Hz) of each group of modes proposed together and refit jointly
    /// (`search::multi_mode`), whatever became of them.
    pub multi_modes_hz: Vec<Vec<f64>>,
}

impl SearchResult {
    /// The result of a search done elsewhere (or constructed): its `nodes` (the configured
    /// model and its retune first, as `search::beam::roots` makes them) and the index of the chosen one;
    /// no first-level screen, refusal or statistics.
    pub fn of_nodes(nodes: Vec<Node>, chosen: usize) -> Self {
        SearchResult {
            nodes,
            chosen,
            first_level: vec![],
            refused: vec![],
            expanded: 0,
            joint_refits: 0,
            gave_up: 0,
            phases: Phases::default(),
            peak_modes_hz: vec![],
            multi_modes_hz: vec![],
        }
    }
}

fn bic(v: f64, n: usize, data: &Channels) -> f64 {
    crate::diagnose::lsq::measures::bic(v, n, data.n_data())
}

/// The two roots: the configured model as it is, and retuned from a rough start (its
/// counts told to `options`' listener, [`crate::diagnose::DiagnoseProgress::Retune`]).
pub fn roots(
    base: &PhysicalModel,
    data: &Channels,
    options: &crate::diagnose::progress::DiagnoseOptions<'_>,
) -> Result<[Node; 2]> {
    use crate::diagnose::progress::DiagnoseProgress::Retune;
    let tell = |what, done, total| options.tell(Retune { what, done, total });
    let r = crate::diagnose::lsq::retune::retune_telling(base, data, true, &tell);
    let m0 = Problem::new(base, data)?.measures(&Default::default());
    let v_fit = r.v_after;
    let (model, measures) = settle(
        crate::diagnose::search::assign::align(base, &r.model, &[]),
        base,
        data,
    )?;
    Ok([
        Node {
            effects: vec![],
            bic: bic(m0.v, r.n_params, data),
            model: base.clone(),
            measures: m0,
            v_fit: m0.v,
            n_params: r.n_params,
            steps: vec![],
            configured: true,
        },
        Node {
            effects: vec![],
            bic: bic(v_fit, r.n_params, data),
            model,
            measures,
            v_fit,
            n_params: r.n_params,
            steps: vec![],
            configured: false,
        },
    ])
}

/// Runs the beam search from the roots (the first one's screen is the first level;
/// `first_screen`, when given, is that screen done beforehand by [`screen_configured`]).
pub fn search(
    roots: Vec<Node>,
    data: &Channels,
    s: &SearchSettings,
    mut first_screen: Option<Vec<Screened>>,
    options: &crate::diagnose::progress::DiagnoseOptions<'_>,
) -> Result<SearchResult> {
    use crate::diagnose::progress::DiagnoseProgress::{Level, Refits};
    s.validate()?;
    let mut level: Vec<usize> = (0..roots.len()).collect();
    // The configured model: the anchor of every refit's boxes.
    let anchor = roots[0].model.clone();
    let mut nodes = roots;
    let mut first_level = Vec::new();
    let mut refused: Vec<(usize, Refusal)> = Vec::new();
    let mut peak_modes_hz: Vec<f64> = Vec::new();
    let mut multi_modes_hz: Vec<Vec<f64>> = Vec::new();
    let (mut expanded, mut joint_refits, mut gave_up) = (0, 0, 0);
    let mut phases = Phases::default();
    for depth in 1..=s.max_effects {
        if level.iter().any(|i| nodes[*i].measures.consistent()) {
            break;
        }
        options.tell(Level {
            depth,
            max: s.max_effects,
            nodes: level.len(),
        });
        let mut children: Vec<Node> = Vec::new();
        // Every node of the level is screened, then the children of all of them are refit in
        // one batch: independent computations in parallel (rayon's indexed collects keep
        // their order, so the result does not depend on the scheduling).
        let t_screen = std::time::Instant::now();
        let pre: Vec<Option<Vec<Screened>>> = level
            .iter()
            .map(|&ni| {
                (depth == 1 && ni == 0)
                    .then(|| first_screen.take())
                    .flatten()
            })
            .collect();
        let n_screened = pre.iter().filter(|p| p.is_none()).count();
        let expansions = level
            .par_iter()
            .zip(pre)
            .map(|(&ni, pre)| expand(&nodes, ni, data, s, pre))
            .collect::<Result<Vec<_>>>()?;
        // A screen done beforehand was timed where it ran.
        phases.add("screen", t_screen.elapsed().as_secs_f64(), n_screened);
        expanded += level.len();
        // Per node: its single proposals in screen order, then its modes proposed together.
        let jobs: Vec<(usize, Option<usize>)> = expansions
            .iter()
            .enumerate()
            .flat_map(|(li, e)| {
                e.refit
                    .iter()
                    .enumerate()
                    .filter(|(_, go)| **go)
                    .map(move |(j, _)| (li, Some(j)))
                    .chain(e.multi.iter().map(move |_| (li, None)))
            })
            .collect();
        // Each job's judge (likelihood, admissibility): against the node, or, for the
        // configured model, the better of it and its retune.
        let reference_of = |li: usize| {
            let node = &nodes[level[li]];
            if node.configured && nodes[1].v_fit < node.v_fit {
                nodes[1].measures
            } else {
                node.measures
            }
        };
        let t_refit = std::time::Instant::now();
        let finished = std::sync::atomic::AtomicUsize::new(0);
        // Each job refit and judged (the child and the refusal), `None` when the refit gave
        // up; the judges are independent too, so they run beside the refits.
        type Judged = Option<(Option<Node>, Option<Refusal>)>;
        let done: Vec<Result<Judged>> = jobs
            .par_iter()
            .map(|&(li, j)| {
                let node = &nodes[level[li]];
                let e = &expansions[li];
                let group: Vec<&Screened> = match j {
                    Some(j) => vec![&e.screened[j]],
                    None => e.multi.iter().flatten().collect(),
                };
                let mut added = node.model.clone();
                for sc in &group {
                    added = add_effect(&added, &sc.cand, &sc.mods.theta, data);
                }
                let before = match group.as_slice() {
                    [one] => one.measures,
                    _ => Problem::new(&added, data)?.measures(&Default::default()),
                };
                let give_up = Some(GIVE_UP_FACTOR * e.ref_v);
                let (r, gave_up) =
                    retune_or_give_up(&added, &anchor, data, None, node.configured, give_up);
                if gave_up {
                    return Ok(None);
                }
                let (v_fit, n_params) = (r.v_after, r.n_params);
                let (model, m) = settle(r.model, &anchor, data)?;
                let refit: Refit = (model, m, v_fit, n_params);
                let reference = reference_of(li);
                let judge = Judge {
                    data,
                    min_delta_bic: s.min_delta_bic,
                    allow_mains: s.allow_mains,
                    anchor: &anchor,
                    retuned: &nodes[1].model,
                    reference: &reference,
                    ref_v: e.ref_v,
                    depth,
                };
                Ok(Some(judge_child(&judge, node, &group, refit, before)))
            })
            .inspect(|_| {
                let n = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                options.tell(Refits {
                    depth,
                    done: n,
                    total: jobs.len(),
                });
            })
            .collect();
        phases.add("joint refits", t_refit.elapsed().as_secs_f64(), jobs.len());
        // The judged refits in job order: node by node, candidate by candidate, then the
        // group.
        let mut done = done.into_iter();
        for (&ni, e) in level.iter().zip(&expansions) {
            let mut note = |refusal: &Option<Refusal>| {
                if let Some(r) = refusal {
                    let seen = refused.iter().any(|(_, x): &(usize, Refusal)| {
                        x.effect == r.effect
                            && x.rule == r.rule
                            && match (x.frequency_hz, r.frequency_hz) {
                                (Some(a), Some(b)) => (a - b).abs() <= 1e-3 * a,
                                (a, b) => a.is_none() && b.is_none(),
                            }
                    });
                    if !seen {
                        refused.push((depth, r.clone()));
                    }
                }
            };
            for (j, (sc, go)) in e.screened.iter().zip(&e.refit).enumerate() {
                // A peak's own mode proposal is a search child only (the first-level
                // candidates stay the screen's).
                let extra = j >= e.n_screen;
                if extra && *go {
                    peak_modes_hz.push(sc.mods.theta[0].exp() / std::f64::consts::TAU);
                }
                let mut child_node = None;
                let mut first_refusal = None;
                if let Some(judged) = go.then(|| done.next()).flatten() {
                    joint_refits += 1;
                    let Some((child, refusal)) = judged? else {
                        gave_up += 1;
                        if depth == 1 && ni == 0 && !extra {
                            first_level.push((sc.clone(), None, None));
                        }
                        continue;
                    };
                    note(&refusal);
                    first_refusal = refusal;
                    if let Some(c) = child {
                        child_node = Some(c.clone());
                        children.push(c);
                    }
                }
                if depth == 1 && ni == 0 && !extra {
                    first_level.push((sc.clone(), child_node, first_refusal));
                }
            }
            if let Some(group) = &e.multi {
                let judged = done.next().expect("a refit per job");
                joint_refits += 1;
                let Some((child, refusal)) = judged? else {
                    gave_up += 1;
                    continue;
                };
                multi_modes_hz.push(
                    group
                        .iter()
                        .map(|sc| sc.mods.theta[0].exp() / std::f64::consts::TAU)
                        .collect(),
                );
                note(&refusal);
                children.extend(child);
            }
        }
        // One node per effect set (the best order; added modes at different frequencies
        // are different sets), the `beam` best kept.
        children.sort_by(|a, b| a.bic.total_cmp(&b.bic));
        let mut kept: Vec<Node> = Vec::new();
        for c in children {
            match kept.iter_mut().find(|k| same_set(&k.effects, &c.effects)) {
                // Two orders that reach the same fit (BICs equal within what the fits'
                // tolerance leaves, 2·V_TOL each): the path whose earlier steps explained
                // more is the one reported.
                Some(k) if c.bic - k.bic < SAME_FIT_BIC && steps_explain_more(&c, k) => *k = c,
                Some(_) => {}
                None => kept.push(c),
            }
        }
        let mut children = kept;
        children.truncate(s.beam.max(1));
        if children.is_empty() {
            break;
        }
        level = (nodes.len()..nodes.len() + children.len()).collect();
        nodes.extend(children);
    }
    // The chosen node: the best consistent one with the fewest effects, else the lowest BIC.
    let consistent_depth = nodes
        .iter()
        .filter(|n| n.measures.consistent())
        .map(|n| n.effects.len())
        .min();
    let eligible: Vec<usize> = (0..nodes.len())
        .filter(|i| {
            consistent_depth
                .is_none_or(|d| nodes[*i].effects.len() == d && nodes[*i].measures.consistent())
        })
        .collect();
    // Within a BIC tie of the best, the data do not choose: fewer parameters, then the
    // catalogue's prior order (a delay before a ZOH before an NMP zero) decide, and the tie
    // is reported.
    let best_bic = eligible
        .iter()
        .map(|i| nodes[*i].bic)
        .fold(f64::INFINITY, f64::min);
    let chosen = eligible
        .iter()
        .copied()
        .filter(|i| nodes[*i].bic - best_bic < TIE_BIC)
        .min_by(|a, b| {
            let key = |i: usize| {
                let n = &nodes[i];
                (
                    n.n_params,
                    n.effects.iter().map(|e| prior(&e.0)).sum::<usize>(),
                )
            };
            key(*a)
                .cmp(&key(*b))
                .then(nodes[*a].bic.total_cmp(&nodes[*b].bic))
        })
        .unwrap_or(0);
    Ok(SearchResult {
        nodes,
        chosen,
        first_level,
        refused,
        expanded,
        joint_refits,
        gave_up,
        phases,
        peak_modes_hz,
        multi_modes_hz,
    })
}

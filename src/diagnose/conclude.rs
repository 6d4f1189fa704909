//! The end of `diagnose` after the search ([`crate::diagnose::engine`]): the first-level
//! candidates, the set kept ([`crate::diagnose::search::choice`]: final holdout, backward
//! elimination, a next-best set when they drop part of the chosen one), the last refit, the
//! runner-ups and ties, the peak account and the verdict.

use crate::diagnose::admissible::Refusal;
use crate::diagnose::changes::changes;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::progress::{DiagnoseOptions, DiagnoseProgress::Stage};
use crate::diagnose::report::{DiagnoseVerdict, Diagnosis, Holdout, Phases, Retuned, SearchStats};
use crate::diagnose::search::beam::{SearchResult, SearchSettings};
use crate::diagnose::search::choice::{keep, Passing, Rules};
use crate::diagnose::search::final_effects::final_effects;
use crate::diagnose::search::first_level::{ranked_candidates, Root};
use crate::diagnose::search::holdout::drop_failing_holdout;
use crate::diagnose::search::node::Node;
use crate::diagnose::search::path::{restate_path, runner_ups};
use crate::diagnose::search::recheck::Recheck;
use crate::diagnose::search::ties::{candidate_ties, set_ties};
use crate::diagnose::verdict::{
    residual_account, stop_explanation, unreached_modes, verdict_message,
};
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use std::time::Instant;

/// The search's statistics.
pub(crate) fn stats(
    s: &SearchSettings,
    t0: Instant,
    res: Option<&SearchResult>,
    phases: Phases,
) -> SearchStats {
    SearchStats {
        beam: s.beam,
        nodes_expanded: res.map_or(0, |r| r.expanded),
        joint_refits: res.map_or(0, |r| r.joint_refits),
        refits_given_up: res.map_or(0, |r| r.gave_up),
        mode_groups_hz: res.map_or_else(Vec::new, |r| r.multi_modes_hz.clone()),
        seconds: t0.elapsed().as_secs_f64(),
        phases: phases.0,
    }
}

/// The rules of [`keep`] on real fits, each timed in its phase and its stage told once.
struct Fits<'a, 'o> {
    base: &'a PhysicalModel,
    nodes: &'a [Node],
    data: &'a Channels,
    min_delta_bic: f64,
    allow_mains: bool,
    options: &'a DiagnoseOptions<'o>,
    phases: &'a mut Phases,
    told: [bool; 2],
}

impl Fits<'_, '_> {
    fn stage(&mut self, k: usize, name: &'static str) {
        if !self.told[k] {
            self.told[k] = true;
            self.options.tell(Stage(name));
        }
    }
}

impl Rules for Fits<'_, '_> {
    fn holdout(&mut self, node: &mut Node) -> Result<(Vec<Holdout>, Vec<String>)> {
        self.stage(0, "holdout");
        let (base, nodes, data) = (self.base, self.nodes, self.data);
        self.phases
            .time("holdout", || drop_failing_holdout(base, node, nodes, data))
    }
    fn eliminate(&mut self, node: &mut Node) -> Result<Vec<String>> {
        self.stage(1, "backward elimination");
        let (base, nodes, data, min) = (self.base, self.nodes, self.data, self.min_delta_bic);
        self.phases.time("backward elimination", || {
            crate::diagnose::search::backward::eliminate(base, node, nodes, data, min)
        })
    }
    fn restate(&mut self, node: &mut Node, orig: &Node) -> Result<Option<usize>> {
        let (base, nodes, data) = (self.base, self.nodes, self.data);
        self.phases
            .time("holdout", || restate_path(node, orig, nodes, base, data))
    }
    fn refusal(&mut self, node: &Node) -> Result<Option<(usize, Refusal)>> {
        let r = self.recheck();
        self.phases
            .time("admissibility re-check", || r.first_refusal(node))
    }
    fn remove(&mut self, node: &mut Node, j: usize) -> Result<()> {
        let r = self.recheck();
        self.phases
            .time("admissibility re-check", || r.remove(node, j))
    }
}

impl<'a> Fits<'a, '_> {
    fn recheck(&self) -> Recheck<'a> {
        Recheck {
            base: self.base,
            nodes: self.nodes,
            data: self.data,
            allow_mains: self.allow_mains,
            min_delta_bic: self.min_delta_bic,
        }
    }
}

/// Concludes a diagnosis from the search's result `res` (its first two nodes the configured
/// model and its retune, as `search::beam::roots` makes them): the
/// first-level candidates, the set kept, its last refit and the report.  `phases` holds the
/// time spent before the search; `t0` when the diagnosis began.
pub fn conclude(
    base: &PhysicalModel,
    data: &Channels,
    s: &SearchSettings,
    options: &DiagnoseOptions<'_>,
    mut res: SearchResult,
    mut phases: Phases,
    t0: Instant,
) -> Result<Diagnosis> {
    let n = data.n_data();
    let before = Problem::new(base, data)?.measures(&Default::default());
    let root_model = res.nodes[1].model.clone();
    let retuned = res.nodes[1].measures;
    let moved = changes(base, &root_model, data);
    // Information criteria use the least-squares costs (the polish may raise `measures.v`).
    let v_ret = res.nodes[1].v_fit;
    for p in &res.phases.0 {
        phases.add(p.phase, p.seconds, p.count);
    }
    // First-level candidates: the retune, and each effect on top of it.
    let root = Root {
        base,
        before,
        model: &root_model,
        retuned,
        v_ret,
        min_delta_bic: s.min_delta_bic,
    };
    options.tell(Stage("first level"));
    let mut candidates = phases.time("first level", || ranked_candidates(&root, &res, data))?;
    // The set kept: the chosen set through the final holdout and the backward elimination,
    // or a next-best set when they drop part of it.
    let rejected = res.chosen;
    let kept = keep(
        &res.nodes,
        res.chosen,
        &mut Fits {
            base,
            nodes: &res.nodes,
            data,
            min_delta_bic: s.min_delta_bic,
            allow_mains: s.allow_mains,
            options,
            phases: &mut phases,
            told: [false; 2],
        },
    )?;
    // The set the rules reduced is not offered as a runner-up.
    let rejected = kept.reduced().then(|| res.nodes[rejected].clone());
    let Passing {
        mut node,
        holdout,
        dropped,
        eliminated,
        replaced_by: _,
        set_node,
        refused: refused_in_kept,
    } = kept;
    // Runner-ups and ties are relative to the set kept: a node of the search (its own path,
    // BIC and ties), or no node (then no set tie can be stated against it: `set_ties`
    // compares nodes).
    res.chosen = set_node.unwrap_or(res.chosen);
    options.tell(Stage("final refit"));
    let dampings_not_identified = phases.time("final refit", || {
        crate::diagnose::search::final_refit::final_refit(&mut node, base, data)
    })?;
    // What the written model has and the input did not: the modes read by an assignment.
    node.model = crate::diagnose::search::assign::align_from(
        &[base, &root_model],
        &node.model,
        &node.effects,
    );
    let runner_up = runner_ups(&res, &node, rejected.as_ref());
    let chosen_labels = node.labels();
    options.tell(Stage("ties"));
    let ties = phases.time("ties", || {
        let mut ties = match set_node {
            Some(_) => set_ties(&res, &chosen_labels, &node.model, data),
            None => vec![],
        };
        ties.extend(candidate_ties(&mut candidates, &ties, data));
        ties
    });
    let after = node.measures;
    options.tell(Stage("peak account"));
    let (peaks, peaks_not_listed) = phases.time("peak account", || {
        crate::diagnose::search::peaks::account(
            &crate::diagnose::search::peaks::Outcome {
                retuned: &root_model,
                final_model: &node.model,
                chosen: &chosen_labels,
                candidates: &candidates,
                dropped: &dropped,
                eliminated: &eliminated,
                refused_in_kept: &refused_in_kept
                    .iter()
                    .map(|r| r.1.clone())
                    .collect::<Vec<_>>(),
                min_delta_bic: s.min_delta_bic,
            },
            data,
        )
    })?;
    let verdict = if !node.effects.is_empty() {
        DiagnoseVerdict::EffectsFound
    } else if retuned.consistent() {
        DiagnoseVerdict::Retuned
    } else {
        DiagnoseVerdict::NoEffectFound
    };
    let mut message = verdict_message(verdict, [&before, &retuned, &after], &moved, &chosen_labels)
        + &unreached_modes(
            &peaks,
            &res.peak_modes_hz
                .iter()
                .chain(res.multi_modes_hz.iter().flatten())
                .copied()
                .collect::<Vec<_>>(),
        );
    for d in &dampings_not_identified {
        message += "; ";
        message += &d.reason;
    }
    let mut residual = None;
    if verdict == DiagnoseVerdict::NoEffectFound {
        let z = crate::diagnose::lsq::whiteness::normalized_residual(&node.model, data);
        let white =
            crate::diagnose::lsq::whiteness::whiteness(&z, node.n_params, (data.len() / 50).max(5));
        // Clamped: the explanation reads the lines beside an outlier line.
        let hz = |k: usize| data.omega[k.min(data.len() - 1)] / std::f64::consts::TAU;
        message += &stop_explanation(&res.refused, &white, hz);
        residual = white
            .level
            .is_finite()
            .then(|| residual_account(&white, hz));
    }
    Ok(Diagnosis {
        verdict,
        message,
        n_data: n,
        n_channels: data.n_ch(),
        before,
        retuned: Retuned {
            measures: retuned,
            moved,
        },
        after,
        candidates,
        ties,
        steps: node.steps.clone(),
        chosen: chosen_labels,
        runner_up,
        holdout,
        dropped,
        eliminated,
        final_effects: final_effects(
            &node.model,
            base,
            &node.effects.iter().map(|e| e.0).collect::<Vec<_>>(),
            data,
            true,
        ),
        retuned_in_chosen: changes(base, &node.model, data),
        refused: res
            .refused
            .iter()
            .map(|(step, r)| (step, r, false))
            .chain(refused_in_kept.iter().map(|(step, r)| (step, r, true)))
            .map(
                |(step, r, in_kept_set)| crate::diagnose::report::RefusedEffect {
                    step: *step,
                    refusal: r.clone(),
                    in_kept_set,
                },
            )
            .collect(),
        dampings_not_identified,
        residual,
        cost_test: Some([n as f64 - node.n_params as f64 / 2.0, after.v]),
        peaks,
        peaks_not_listed,
        search: stats(s, t0, Some(&res), phases),
        final_model: node.model,
    })
}

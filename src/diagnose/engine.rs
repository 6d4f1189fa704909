//! `diagnose`: retune the configured model, then search effect sets (several effects at
//! once), check the final set on held-out data, and report.
//!
//! * Noise: `σ = r/√2` (noise uniform in the disk of radius `r`); the cost is
//!   `V = Σ|G_d − Ĝ(θ)|²/σ²` over every channel (`E V ≈ F` for a right model), the
//!   complex-Gaussian `−ln L`.
//! * [`crate::diagnose::lsq::retune`]: the configured parameters, refit with wide bounds (residues by
//!   least squares, modes placed by a grid from a rough start): the `retune` candidate.
//! * [`crate::diagnose::search::beam`]: beam search over effect sequences with a joint refit at every node.
//! * Final holdout ([`crate::diagnose::search::holdout`]), per effect of the chosen set: fitted on 3 of every
//!   4 data, the held-out quarter's `V` must be lower with the effect than without it; for a
//!   multiplicative effect, also fitted below 70 % of the band (log frequency), the top 30 %
//!   must be predicted better. An effect that fails is dropped and the rest refit. The
//!   extrapolation test decides only for a set of multiplicative effects (a fit below the
//!   split cannot place a mode or a feedthrough that acts above it); otherwise it is
//!   reported.
//! * Ties ([`crate::diagnose::search::ties`]): sets within 6 of the chosen set's BIC, with where to measure to
//!   tell them apart.
//! * Consistent: `invalid_fraction ≤ 5 %` and `misfit_rms ≤ 1`, judged on the model's
//!   consistency polish ([`crate::diagnose::search::polish`]).

use crate::diagnose::changes::changes;
use crate::diagnose::compare::Siso;
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::progress::{DiagnoseOptions, DiagnoseProgress::Stage};
use crate::diagnose::report::{DiagnoseVerdict, Diagnosis, Holdout, Phases, Retuned, SearchStats};
use crate::diagnose::search::beam::{roots, screen_configured, search, SearchSettings};
use crate::diagnose::search::final_effects::final_effects;
use crate::diagnose::search::first_level::{ranked_candidates, Root};
use crate::diagnose::search::holdout::{holdouts, model_of};
use crate::diagnose::search::node::Node;
use crate::diagnose::search::path::{restate_path, runner_ups};
use crate::diagnose::search::ties::{candidate_ties, set_ties};
use crate::diagnose::verdict::{
    residual_account, stop_explanation, unreached_modes, verdict_message,
};
use crate::error::{Error, Result};
use crate::model::physical::PhysicalModel;
use crate::report::fmt::fmt_pct;
use std::time::Instant;

/// Diagnoses one SISO channel (see [`diagnose_channels`]).
pub fn diagnose(base: &PhysicalModel, siso: &Siso, max_effects: usize) -> Result<Diagnosis> {
    let data = Channels::from_siso(siso)?;
    diagnose_channels(
        base,
        &data,
        &SearchSettings {
            max_effects,
            ..Default::default()
        },
        &Default::default(),
    )
}

fn measures(m: &PhysicalModel, data: &Channels) -> Result<Measures> {
    Ok(Problem::new(m, data)?.measures(&Default::default()))
}

/// Diagnoses the channels `data` jointly: retune, search, final holdout, report.
/// `options.progress` hears of each stage and search level as it begins.
pub fn diagnose_channels(
    base: &PhysicalModel,
    data: &Channels,
    s: &SearchSettings,
    options: &DiagnoseOptions<'_>,
) -> Result<Diagnosis> {
    let t0 = Instant::now();
    // Settings first: a bad one is an error even where the search would not run.
    s.validate()?;
    if data.is_empty() {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: "no data".into(),
        });
    }
    let before = measures(base, data)?;
    let n = data.n_data();
    let mk_stats =
        |expanded, joint_refits, refits_given_up, mode_groups_hz, phases: Phases| SearchStats {
            beam: s.beam,
            nodes_expanded: expanded,
            joint_refits,
            refits_given_up,
            mode_groups_hz,
            seconds: t0.elapsed().as_secs_f64(),
            phases: phases.0,
        };
    if before.consistent() {
        return Ok(Diagnosis {
            verdict: DiagnoseVerdict::Consistent,
            message: format!(
                "the model explains the data within the noise (misfit_rms = {}, invalid_fraction = {}): nothing needs to be added",
                sig(before.misfit_rms),
                fmt_pct(before.invalid_fraction)
            ),
            n_data: n,
            n_channels: data.n_ch(),
            before,
            retuned: Retuned {
                measures: before,
                moved: Default::default(),
            },
            after: before,
            candidates: vec![],
            ties: vec![],
            steps: vec![],
            chosen: vec![],
            runner_up: vec![],
            holdout: vec![],
            dropped: vec![],
            eliminated: vec![],
            final_effects: vec![],
            retuned_in_chosen: Default::default(),
            refused: vec![],
            dampings_not_identified: vec![],
            residual: None,
            cost_test: Some([n as f64, before.v]),
            peaks: vec![],
            peaks_not_listed: 0,
            search: mk_stats(0, 0, 0, Vec::new(), Phases::default()),
            final_model: base.clone(),
        });
    }
    let mut phases = Phases::default();
    // The configured model's screen does not need the retune: both at once.
    options.tell(Stage("retune"));
    let (roots, first_screen) = phases.time("retune", || {
        rayon::join(
            || roots(base, data, options),
            || screen_configured(base, data),
        )
    });
    let [configured, retuned_node] = roots?;
    let first_screen = first_screen?;
    let root_model = retuned_node.model.clone();
    let retuned = retuned_node.measures;
    let moved = changes(base, &root_model, data);
    // Information criteria use the least-squares costs (the polish may raise `measures.v`).
    let v_ret = retuned_node.v_fit;
    let mut res = search(
        vec![configured, retuned_node],
        data,
        s,
        Some(first_screen),
        options,
    )?;
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
    // The chosen set, its final holdout, backward elimination, last refit, runner-ups, ties.
    // When the holdout drops part of the chosen set, the next-best sets are tried.
    options.tell(Stage("holdout"));
    let crate::diagnose::search::holdout::Passing {
        mut node,
        holdout,
        dropped,
        replaced_by,
    } = phases.time("holdout", || {
        crate::diagnose::search::holdout::first_passing(&res.nodes, res.chosen, |n| {
            drop_failing_holdout(base, n, &res.nodes, data)
        })
    })?;
    // Runner-ups and ties are then relative to the set kept.
    let rejected = res.chosen;
    res.chosen = replaced_by.unwrap_or(res.chosen);
    let mut restated = None;
    if !dropped.is_empty() && replaced_by.is_none() {
        restated = Some(restate_path(&mut node, &res.nodes, base, data)?);
    }
    options.tell(Stage("backward elimination"));
    let eliminated = phases.time("backward elimination", || {
        crate::diagnose::search::backward::eliminate(
            base,
            &mut node,
            &res.nodes,
            data,
            s.min_delta_bic,
        )
    })?;
    if !eliminated.is_empty() {
        restated = Some(restate_path(&mut node, &res.nodes, base, data)?);
    }
    // The kept set is a node of the search (its own path, BIC and ties), or no node is: then
    // no set tie can be stated against it (`set_ties` compares nodes).
    let set_node = match restated {
        None => Some(res.chosen),
        Some(found) => found,
    };
    res.chosen = set_node.unwrap_or(res.chosen);
    let rejected = (!dropped.is_empty()).then(|| res.nodes[rejected].clone());
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
        let hz = |k: usize| data.omega[k] / std::f64::consts::TAU;
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
            .map(|(step, r)| crate::diagnose::report::RefusedEffect {
                step: *step,
                refusal: r.clone(),
            })
            .collect(),
        dampings_not_identified,
        residual,
        cost_test: Some([n as f64 - node.n_params as f64 / 2.0, after.v]),
        peaks,
        peaks_not_listed,
        search: mk_stats(
            res.expanded,
            res.joint_refits,
            res.gave_up,
            res.multi_modes_hz.clone(),
            phases,
        ),
        final_model: node.model,
    })
}

/// The final holdout ([`crate::diagnose::search::holdout`]) of the chosen set; an effect that fails it is
/// dropped and the rest refit.  A fit below 70 % of the band cannot place an additive effect
/// (a mode, a feedthrough) that acts above it, so the extrapolation test decides only for
/// sets of multiplicative effects; otherwise it is reported.  Returns the holdout rows and
/// the labels dropped.
fn drop_failing_holdout(
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
    node.measures = measures(&model, data)?;
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

/// The revised model of first-level candidate `rank` (1-based): the retuned model with the
/// candidate added and every parameter refit jointly.  A candidate the diagnosis rejected
/// (not `passes`: a plausibility flag, too small a ΔBIC, more invalid data) is refused with
/// its reason unless `force`; a candidate with no fit always is.
pub fn apply_candidate(
    _base: &PhysicalModel,
    d: &Diagnosis,
    rank: usize,
    force: bool,
) -> Result<PhysicalModel> {
    let c = d
        .candidates
        .get(rank.wrapping_sub(1))
        .ok_or_else(|| Error::Argument {
            arg: format!("--apply {rank}"),
            msg: format!(
                "there are {} candidates (1..={})",
                d.candidates.len(),
                d.candidates.len()
            ),
        })?;
    if let Some(why) = &c.no_fit {
        return Err(Error::Argument {
            arg: format!("--apply {rank}"),
            msg: format!("{} has no fit ({why})", c.effect),
        });
    }
    if let (Some(why), false) = (c.rejection(), force) {
        return Err(Error::Argument {
            arg: format!("--apply {rank}"),
            msg: format!(
                "{} was rejected: {why}; add --force to write it anyway",
                c.effect
            ),
        });
    }
    Ok(c.model.clone())
}

/// The revised model of the chosen effect set (`--apply chosen`): every chosen effect
/// written into the model and every parameter refit jointly, as `final_model`; with no
/// effect chosen, the retuned model when the retune explains the data.
pub fn apply_chosen(d: &Diagnosis) -> Result<PhysicalModel> {
    match d.verdict {
        DiagnoseVerdict::EffectsFound | DiagnoseVerdict::Retuned => Ok(d.final_model.clone()),
        DiagnoseVerdict::Consistent => Err(Error::Invalid(
            "--apply chosen: the model already explains the data within the noise; nothing to write"
                .into(),
        )),
        DiagnoseVerdict::NoEffectFound => Err(Error::Argument {
            arg: "--apply chosen".into(),
            msg: format!("no effect set was chosen ({}); nothing to write", d.message),
        }),
    }
}

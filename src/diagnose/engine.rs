//! `diagnose`: retune the configured model, then search effect sets (several effects at
//! once), check the final set on held-out data, and report.
//!
//! * Noise: `σ = r/√2` (noise uniform in the disk of radius `r`); the cost is
//!   `V = Σ|G_d − Ĝ(θ)|²/σ²` over every channel (`E V ≈ F` for a right model), the
//!   complex-Gaussian `−ln L`.
//! * [`super::retune`]: the configured parameters, refit with wide bounds (residues by
//!   least squares, modes placed by a grid from a rough start): the `retune` candidate.
//! * [`super::search`]: beam search over effect sequences with a joint refit at every node.
//! * Final holdout ([`super::holdout`]), per effect of the chosen set: fitted on 3 of every
//!   4 data, the held-out quarter's `V` must be lower with the effect than without it; for a
//!   multiplicative effect, also fitted below 70 % of the band (log frequency), the top 30 %
//!   must be predicted better. An effect that fails is dropped and the rest refit. The
//!   extrapolation test decides only for a set of multiplicative effects (a fit below the
//!   split cannot place a mode or a feedthrough that acts above it); otherwise it is
//!   reported.
//! * Ties ([`super::ties`]): sets within 6 of the chosen set's BIC, with where to measure to
//!   tell them apart.
//! * Consistent: `invalid_fraction ≤ 5 %` and `misfit_rms ≤ 1`, judged on the model's
//!   consistency polish ([`super::polish`]).

use super::candidates::{explain, sig};
use super::changes::changes;
use super::channels::Channels;
use super::compare::{bands, Siso};
pub use super::final_effects::final_effects;
use super::holdout::{holdouts, model_of};
use super::polish::settle;
pub use super::problem::Measures as ErrorMeasures;
use super::problem::{Measures, Problem};
pub use super::rank::candidate_list;
use super::rank::{prior, si_map, MIN_DELTA_BIC, TIE_BIC};
pub use super::report::{
    CandidateReport, Diagnosis, EffectSet, FinalEffect, Holdout, Retuned, SearchStats, Tie,
};
use super::retune::retune_within;
use super::search::{add_effect, roots, search, Settings};
use super::ties::{candidate_ties, set_ties};
use crate::error::{Error, Result};
use crate::model::physical::PhysicalModel;
use crate::report::fmt::fmt_pct;
use std::collections::BTreeMap;
use std::time::Instant;

/// Diagnoses one SISO channel (see [`diagnose_channels`]).
pub fn diagnose(base: &PhysicalModel, siso: &Siso, max_effects: usize) -> Result<Diagnosis> {
    let data = Channels::from_siso(siso)?;
    diagnose_channels(
        base,
        &data,
        &Settings {
            max_effects,
            ..Default::default()
        },
    )
}

fn measures(m: &PhysicalModel, data: &Channels) -> Result<Measures> {
    Ok(Problem::new(m, data)?.measures(&Default::default()))
}

/// Diagnoses the channels `data` jointly: retune, search, final holdout, report.
pub fn diagnose_channels(base: &PhysicalModel, data: &Channels, s: &Settings) -> Result<Diagnosis> {
    let t0 = Instant::now();
    if data.is_empty() {
        return Err(Error::Invalid(format!("{}: no data", data.path.display())));
    }
    let before = measures(base, data)?;
    let n = data.n_data();
    let ln2f = (2.0 * n as f64).ln();
    let mk_stats = |expanded, joint_refits| SearchStats {
        beam: s.beam,
        nodes_expanded: expanded,
        joint_refits,
        seconds: t0.elapsed().as_secs_f64(),
    };
    if before.consistent() {
        return Ok(Diagnosis {
            verdict: "consistent".into(),
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
            cost_test: Some([n as f64, before.v]),
            search: mk_stats(0, 0),
            final_model: base.clone(),
        });
    }
    let [configured, retuned_node] = roots(base, data)?;
    let root_model = retuned_node.model.clone();
    let retuned = retuned_node.measures;
    let moved = changes(base, &root_model, data);
    // Information criteria use the least-squares costs (the polish may raise `measures.v`).
    let v_ret = retuned_node.v_fit;
    let res = search(vec![configured, retuned_node], data, s)?;
    // First-level candidates: the retune, and each effect on top of it.
    let (_, flags0) = Problem::new(base, data)?.invalid_flags(&Default::default());
    let explained = |m: &PhysicalModel| -> Vec<super::compare::Band> {
        let Ok(p) = Problem::new(m, data) else {
            return vec![];
        };
        let (c1, f1) = p.invalid_flags(&Default::default());
        let fixed: Vec<bool> = flags0.iter().zip(&f1).map(|(a, b)| *a && !*b).collect();
        bands(&data.omega, &c1, &fixed)
    };
    let mut candidates = vec![CandidateReport {
        rank: 0,
        effect: "retune".into(),
        params: BTreeMap::new(),
        uncertainty_2sigma: BTreeMap::new(),
        v_before: before.v,
        v_after: v_ret,
        misfit_rms_before: before.misfit_rms,
        misfit_rms_after: retuned.misfit_rms,
        invalid_fraction_before: before.invalid_fraction,
        invalid_fraction_after: retuned.invalid_fraction,
        delta_bic: 2.0 * (before.v - v_ret),
        delta_bic_vs_retune: 0.0,
        n_params: 0,
        joint_refit: true,
        passes: 2.0 * (before.v - v_ret) > MIN_DELTA_BIC,
        tie_with_best: false,
        flags: vec![],
        no_fit: None,
        explanation: format!(
            "refit of the configured model's own parameters (residues and gains over four decades, every ω_n, ζ, pole and delay; modes placed by a grid from a rough start): misfit_rms {} → {}",
            sig(before.misfit_rms),
            sig(retuned.misfit_rms)
        ),
        explained_bands: explained(&root_model),
        cand: None,
        model: root_model.clone(),
    }];
    for (sc, child) in &res.first_level {
        let nn = sc.cand.n_params(data.n_ch());
        let th = &sc.mods.theta;
        let (model, m, v, joint) = match child {
            Some(c) => (c.model.clone(), c.measures, c.v_fit, true),
            None => (
                add_effect(&root_model, &sc.cand, th, data),
                sc.measures,
                sc.v,
                false,
            ),
        };
        let mut unc = BTreeMap::new();
        if sc.no_fit.is_none() {
            if let Some(cov) = (sc.jtj.clone() * 2.0).try_inverse() {
                for (j, (name, _, fac)) in sc.cand.si_params(th, &data.entries).iter().enumerate() {
                    let idx = j.saturating_sub(sc.cand.si_params(th, &data.entries).len() - nn);
                    if *fac != 0.0 && idx < nn {
                        let sd = 2.0 * cov[(idx, idx)].max(0.0).sqrt() * fac;
                        if sd.is_finite() {
                            unc.insert(name.clone(), sd);
                        }
                    }
                }
            }
        }
        let d_root = 2.0 * (v_ret - v) - nn as f64 * ln2f;
        candidates.push(CandidateReport {
            rank: 0,
            effect: sc.cand.label(),
            params: if sc.no_fit.is_none() {
                si_map(&sc.cand, th, &data.entries)
            } else {
                BTreeMap::new()
            },
            uncertainty_2sigma: unc,
            v_before: before.v,
            v_after: v,
            misfit_rms_before: before.misfit_rms,
            misfit_rms_after: m.misfit_rms,
            invalid_fraction_before: before.invalid_fraction,
            invalid_fraction_after: m.invalid_fraction,
            delta_bic: 2.0 * (before.v - v) - nn as f64 * ln2f,
            delta_bic_vs_retune: d_root,
            n_params: nn,
            joint_refit: joint,
            passes: sc.no_fit.is_none()
                && sc.flags.is_empty()
                && d_root > MIN_DELTA_BIC
                && m.invalid_fraction <= retuned.invalid_fraction,
            tie_with_best: false,
            flags: sc.flags.clone(),
            no_fit: sc.no_fit.clone(),
            explanation: match &sc.no_fit {
                Some(why) => format!("no fit: {why}"),
                None => explain(&sc.cand, th, &data.entries, &root_model, &data.omega),
            },
            explained_bands: if sc.no_fit.is_none() {
                explained(&model)
            } else {
                vec![]
            },
            cand: Some(sc.cand),
            model,
        });
    }
    // Rank: usable fits by ΔBIC (near-ties by fewer parameters, then the catalogue's prior
    // order), no-fits last.
    candidates.sort_by(|a, b| {
        (a.no_fit.is_some())
            .cmp(&b.no_fit.is_some())
            .then(b.delta_bic.total_cmp(&a.delta_bic))
    });
    if let Some(best) = candidates.first().map(|c| c.delta_bic) {
        let n_tied = candidates
            .iter()
            .take_while(|c| c.no_fit.is_none() && best - c.delta_bic < TIE_BIC)
            .count();
        candidates[..n_tied]
            .sort_by_key(|c| (c.n_params, c.cand.as_ref().map_or(0, |c| 1 + prior(c))));
    }
    for (k, c) in candidates.iter_mut().enumerate() {
        c.rank = k + 1;
    }
    // The chosen set, its final holdout, runner-ups and ties.
    let mut node = res.nodes[res.chosen].clone();
    let holdout = holdouts(base, &node, &res.nodes, data);
    // A fit below 70 % of the band cannot place an additive effect (a mode, a feedthrough)
    // that acts above it, so the extrapolation test decides only for sets of multiplicative
    // effects; otherwise it is reported.
    let all_mult = node.effects.iter().all(|e| e.0.multiplicative());
    let failing: Vec<usize> = holdout
        .iter()
        .enumerate()
        .filter(|(_, h)| !h.interleaved_ok || (all_mult && h.extrapolation_ok == Some(false)))
        .map(|(i, _)| i)
        .collect();
    let mut dropped = Vec::new();
    if !failing.is_empty() {
        let keep: Vec<_> = node
            .effects
            .iter()
            .enumerate()
            .filter(|(i, _)| !failing.contains(i))
            .map(|(_, e)| e.clone())
            .collect();
        dropped = failing.iter().map(|i| node.effects[*i].0.label()).collect();
        let model = model_of(base, &keep, &res.nodes, data);
        node.measures = measures(&model, data)?;
        node.v_fit = node.measures.v;
        node.model = model;
        node.steps.retain(|st| !dropped.contains(&st.effect));
        node.effects = keep;
    }
    // Backward elimination: effects the data do not need (vacuous ones) are dropped.
    let eliminated = super::backward::eliminate(base, &mut node, &res.nodes, data)?;
    // A last joint refit of the chosen model, and its consistency polish.
    let refit = retune_within(&node.model, base, data, None, false);
    if refit.v_after < node.v_fit {
        node.v_fit = refit.v_after;
        node.model = refit.model;
    }
    (node.model, node.measures) = settle(node.model, base, data)?;
    let chosen_bic = res.nodes[res.chosen].bic;
    let mut runner_up: Vec<EffectSet> = res
        .nodes
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != res.chosen)
        .map(|(_, nd)| EffectSet {
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
    let chosen_labels = node.labels();
    let mut ties = set_ties(&res, &chosen_labels, &node.model, data);
    ties.extend(candidate_ties(&mut candidates, &ties, data));
    let after = node.measures;
    let verdict = if !node.effects.is_empty() {
        "effects_found"
    } else if retuned.consistent() {
        "retuned"
    } else {
        "no_effect_found"
    };
    let status = if after.consistent() {
        " (now consistent with the data within the noise)"
    } else {
        " (still not consistent: more is missing)"
    };
    let message = match verdict {
        "retuned" => format!(
            "the configured model explains the data once its own parameters are refit (retune{}): misfit_rms {} → {}, invalid_fraction {} → {}; nothing added",
            if moved.changes.is_empty() {
                String::new()
            } else {
                format!(": {}", moved.summary())
            },
            sig(before.misfit_rms),
            sig(retuned.misfit_rms),
            fmt_pct(before.invalid_fraction),
            fmt_pct(retuned.invalid_fraction)
        ),
        "effects_found" => format!(
            "retune + {}: misfit_rms {} → {} (retune alone {}), invalid_fraction {} → {}{status}",
            chosen_labels.join(" + "),
            sig(before.misfit_rms),
            sig(after.misfit_rms),
            sig(retuned.misfit_rms),
            fmt_pct(before.invalid_fraction),
            fmt_pct(after.invalid_fraction)
        ),
        _ => format!(
            "the model does not explain the data even retuned (misfit_rms {} → {}), and no candidate effect passes (ΔBIC > 10, plausible, fewer invalid data, holdout): the missing dynamics are not in the catalogue, or the noise radius is too small",
            sig(before.misfit_rms),
            sig(retuned.misfit_rms)
        ),
    };
    Ok(Diagnosis {
        verdict: verdict.into(),
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
            &node.effects.iter().map(|e| e.0).collect::<Vec<_>>(),
            data,
            true,
        ),
        retuned_in_chosen: changes(base, &node.model, data),
        cost_test: Some([n as f64 - node.n_params as f64 / 2.0, after.v]),
        search: mk_stats(res.expanded, res.joint_refits),
        final_model: node.model,
    })
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
    let c = d.candidates.get(rank.wrapping_sub(1)).ok_or_else(|| {
        Error::Invalid(format!(
            "--apply {rank}: there are {} candidates (1..={})",
            d.candidates.len(),
            d.candidates.len()
        ))
    })?;
    if let Some(why) = &c.no_fit {
        return Err(Error::Invalid(format!(
            "--apply {rank}: {} has no fit ({why})",
            c.effect
        )));
    }
    if let (Some(why), false) = (c.rejection(), force) {
        return Err(Error::Invalid(format!(
            "--apply {rank}: {} was rejected: {why}; add --force to write it anyway",
            c.effect
        )));
    }
    Ok(c.model.clone())
}

/// The revised model of the chosen effect set (`--apply chosen`): every chosen effect
/// written into the model and every parameter refit jointly, as `final_model`; with no
/// effect chosen, the retuned model when the retune explains the data.
pub fn apply_chosen(d: &Diagnosis) -> Result<PhysicalModel> {
    match d.verdict.as_str() {
        "effects_found" | "retuned" => Ok(d.final_model.clone()),
        "consistent" => Err(Error::Invalid(
            "--apply chosen: the model already explains the data within the noise; nothing to write"
                .into(),
        )),
        _ => Err(Error::Invalid(format!(
            "--apply chosen: no effect set was chosen ({}); nothing to write",
            d.message
        ))),
    }
}

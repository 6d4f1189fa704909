//! The first-level candidates of `diagnose`: the retune, and each catalogue effect on top of
//! it (fitted alone, or jointly refit when the search expanded it), with ΔBIC, the bands each
//! explains, 2σ uncertainties, and the ranking the report shows.

use crate::diagnose::compare::{bands, Band};
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::effects::explain::explain;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::report::CandidateReport;
use crate::diagnose::search::beam::SearchResult;
use crate::diagnose::search::node::add_effect;
use crate::diagnose::search::rank::{improves, prior, si_map, TIE_BIC};
use crate::error::Result;
use crate::model::physical::PhysicalModel;
use std::collections::BTreeMap;

/// The root the candidates are measured against: the configured model's measures `before`,
/// the retuned model and its measures, and the retune's least-squares cost `v_ret`.
pub(crate) struct Root<'a> {
    /// The configured model.
    pub base: &'a PhysicalModel,
    /// Its measures.
    pub before: Measures,
    /// The retuned model.
    pub model: &'a PhysicalModel,
    /// Its measures.
    pub retuned: Measures,
    /// The retune's least-squares cost (the BIC's; the polish may raise `retuned.v`).
    pub v_ret: f64,
    /// The ΔBIC a candidate must exceed.
    pub min_delta_bic: f64,
}

/// The ranked first-level candidates: usable fits by ΔBIC (near-ties by fewer parameters,
/// then the catalogue's prior order), no-fits last; ranks from 1.
pub(crate) fn ranked_candidates(
    root: &Root<'_>,
    res: &SearchResult,
    data: &Channels,
) -> Result<Vec<CandidateReport>> {
    let (base, before, root_model, retuned, v_ret) =
        (root.base, root.before, root.model, root.retuned, root.v_ret);
    let min_delta_bic = root.min_delta_bic;
    let ln2f = (2.0 * data.n_data() as f64).ln();
    let (_, flags0) = Problem::new(base, data)?.invalid_flags(&Default::default());
    let explained = |m: &PhysicalModel| -> Vec<Band> {
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
    passes: 2.0 * (before.v - v_ret) > min_delta_bic,
    tie_with_best: false,
    flags: vec![],
    no_fit: None,
    min_delta_bic,
    explanation: format!(
        "refit of the configured model's own parameters (residues and gains over four decades, every ω_n, ζ, pole and delay; modes placed by a grid from a rough start): misfit_rms {} → {}",
        sig(before.misfit_rms),
        sig(retuned.misfit_rms)
    ),
    explained_bands: explained(root_model),
    cand: None,
    model: root_model.clone(),
}];
    for (sc, child, refusal) in &res.first_level {
        let nn = sc.cand.n_params(data.n_ch());
        let th = &sc.mods.theta;
        let (model, m, v, joint) = match child {
            Some(c) => (c.model.clone(), c.measures, c.v_fit, true),
            None => (
                add_effect(root_model, &sc.cand, th, data),
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
                && refusal.is_none()
                && d_root > min_delta_bic
                && improves(&m, &retuned),
            tie_with_best: false,
            // A refusal of the joint refit (physical admissibility) is named like a flag.
            flags: sc
                .flags
                .iter()
                .cloned()
                .chain(
                    refusal
                        .iter()
                        .map(|r| format!("{}: {}", r.rule.word(), r.reason)),
                )
                .collect(),
            no_fit: sc.no_fit.clone(),
            min_delta_bic,
            explanation: match &sc.no_fit {
                Some(why) => format!("no fit: {why}"),
                None => explain(&sc.cand, th, &data.entries, root_model, &data.omega),
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
    Ok(candidates)
}

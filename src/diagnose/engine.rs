//! `diagnose`: rank candidate missing effects by how much each lowers the error once fitted,
//! and add them greedily.
//!
//! * Noise: `σ_k = r_k/√2` (noise uniform in the disk of radius `r_k`); the cost is
//!   `V = Σ|G_d − Ĝ(θ)|²/σ_k²` (`E V ≈ F` for a right model), the complex-Gaussian `−ln L`.
//! * Each candidate is fitted by Levenberg–Marquardt from the best points of a grid or a
//!   closed-form estimate (effects.md), jointly with every effect accepted before.
//! * Score: `ΔBIC = 2(V₀ − V) − n_θ·ln(2F)`. A candidate **passes** when ΔBIC > 10, the
//!   invalid fraction does not rise, and the holdout checks pass: fit on 3 of every 4 data,
//!   the held-out quarter's `V` must fall too; for a global (multiplicative) candidate, also
//!   fit below 70 % of the band (log frequency) and the top 30 %'s `V` must fall.
//! * Stop when the model is consistent (`invalid_fraction ≤ 5 %` and `misfit_rms ≤ 1`), when no
//!   candidate passes, or after `max_effects` effects. Candidates within 6 of the best BIC are
//!   reported as ties, with the frequency range where the two fitted models differ by more
//!   than the noise.

use super::compare::Siso;
use super::nominal::refit_nominal;
pub use super::problem::Measures;
use super::problem::{Mods, Problem};
use super::rank::si_map;
pub use super::rank::{candidate_list, MIN_DELTA_BIC, TIE_BIC};
pub use super::report::{CandidateReport, Diagnosis, Step, Tie};
use crate::error::{Error, Result};
use crate::model::physical::PhysicalModel;

/// Runs the greedy diagnosis.
pub fn diagnose(base: &PhysicalModel, siso: &Siso, max_effects: usize) -> Result<Diagnosis> {
    let p = Problem::new(base, siso)?;
    let mut cur = Mods::default();
    let before = p.measures(&cur);
    let mut cur_m = before;
    let mut steps = Vec::new();
    let mut first: Option<(Vec<CandidateReport>, Vec<Tie>)> = None;
    if before.consistent() {
        return Ok(Diagnosis {
            verdict: "consistent".into(),
            message: format!(
                "the model explains the data within the noise (misfit_rms = {:.3}, invalid_fraction = {:.1} %): nothing needs to be added",
                before.misfit_rms,
                100.0 * before.invalid_fraction
            ),
            n_data: p.f(),
            before,
            after: before,
            candidates: vec![],
            ties: vec![],
            steps,
            cost_test: Some([p.f() as f64, before.v]),
            final_model: base.clone(),
        });
    }
    let before_f = p.f() as f64;
    drop(p);
    // After each accepted effect the model is rebuilt with the effect written into it, and
    // every parameter (the configured ones and the accepted effects') is refit jointly
    // (bounded LM, `nominal::refit_nominal`); the next step ranks candidates on that model.
    let radius = siso.radius.clone().expect("checked by Problem::new");
    let mut model = base.clone();
    let mut n_fitted = 0usize;
    for step in 0..max_effects {
        let p = Problem::new(&model, siso)?;
        let ranked = p.rank(&cur, cur_m);
        let ties = p.ties(&ranked);
        let accept = ranked.iter().find(|c| c.passes).cloned();
        if first.is_none() {
            first = Some((ranked, ties.clone()));
        }
        let Some(acc) = accept else { break };
        let with_effect = p.measures(&acc.mods);
        let n = acc.cand.n_params();
        let th = &acc.mods.theta[acc.mods.theta.len() - n..];
        let params = si_map(&acc.cand, th);
        let mut next = model.clone();
        acc.cand.apply_to(
            th,
            &mut next,
            &format!("added by rshape diagnose: {}", acc.effect),
        );
        let refit = refit_nominal(&next, &siso.omega, &siso.g, &radius);
        n_fitted = refit.n_params;
        model = refit.model;
        cur = Mods::default();
        cur_m = Problem::new(&model, siso)?.measures(&cur);
        steps.push(Step {
            step: step + 1,
            effect: acc.effect.clone(),
            params,
            explanation: acc.explanation.clone(),
            misfit_rms: cur_m.misfit_rms,
            invalid_fraction: cur_m.invalid_fraction,
            delta_bic: acc.delta_bic,
            misfit_rms_before_refit: with_effect.misfit_rms,
            invalid_fraction_before_refit: with_effect.invalid_fraction,
            n_refit: refit.n_params,
            ties,
        });
        if cur_m.consistent() {
            break;
        }
    }
    let (candidates, ties) = first.unwrap_or_default();
    let verdict = if steps.is_empty() {
        "no_effect_found"
    } else {
        "effects_found"
    };
    let message = if steps.is_empty() {
        "the model does not explain the data, but no candidate effect passes (ΔBIC > 10, fewer invalid data, holdout): the missing dynamics are not in the catalogue, or the noise radius is too small".to_string()
    } else {
        let list: Vec<String> = steps.iter().map(|s| s.effect.clone()).collect();
        format!(
            "added {}: misfit_rms {:.3} → {:.3}, invalid_fraction {:.1} % → {:.1} %{}",
            list.join(" + "),
            before.misfit_rms,
            cur_m.misfit_rms,
            100.0 * before.invalid_fraction,
            100.0 * cur_m.invalid_fraction,
            if cur_m.consistent() {
                " (now consistent with the data within the noise)"
            } else {
                " (still not consistent: more is missing)"
            }
        )
    };
    let n_theta = n_fitted as f64;
    Ok(Diagnosis {
        verdict: verdict.into(),
        message,
        n_data: siso.omega.len(),
        before,
        after: cur_m,
        candidates,
        ties,
        steps,
        cost_test: Some([before_f - n_theta / 2.0, cur_m.v]),
        final_model: model,
    })
}

/// The base model with candidate `rank` (1-based) of the first step added.
pub fn apply_candidate(base: &PhysicalModel, d: &Diagnosis, rank: usize) -> Result<PhysicalModel> {
    let c = d.candidates.get(rank.wrapping_sub(1)).ok_or_else(|| {
        Error::Invalid(format!(
            "--apply {rank}: there are {} candidates (1..={})",
            d.candidates.len(),
            d.candidates.len()
        ))
    })?;
    let mut m = base.clone();
    let n = c.cand.n_params();
    let th = &c.mods.theta[c.mods.theta.len() - n..];
    c.cand.apply_to(
        th,
        &mut m,
        &format!("added by rshape diagnose: {}", c.effect),
    );
    Ok(m)
}

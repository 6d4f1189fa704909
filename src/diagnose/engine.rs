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
//!   reported.  Backward elimination ([`crate::diagnose::search::backward`]) follows; when
//!   either drops part of the chosen set, the set kept is the best of the reduced set and the
//!   next-best sets that pass both ([`crate::diagnose::search::choice`]).  All after the
//!   search is in [`crate::diagnose::conclude`].
//! * Ties ([`crate::diagnose::search::ties`]): sets within 6 of the chosen set's BIC, with where to measure to
//!   tell them apart.
//! * Consistent: `invalid_fraction ≤ 5 %` and `misfit_rms ≤ 1`, judged on the model's
//!   consistency polish ([`crate::diagnose::search::polish`]).

use crate::diagnose::compare::Siso;
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::progress::{DiagnoseOptions, DiagnoseProgress::Stage};
use crate::diagnose::report::{DiagnoseVerdict, Diagnosis, Phases, Retuned};
use crate::diagnose::search::beam::{roots, screen_configured, search, SearchSettings};
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
            search: crate::diagnose::conclude::stats(s, t0, None, Phases::default()),
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
    let res = search(
        vec![configured, retuned_node],
        data,
        s,
        Some(first_screen),
        options,
    )?;
    crate::diagnose::conclude::conclude(base, data, s, options, res, phases, t0)
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

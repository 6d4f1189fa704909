//! `rshape diagnose CONFIG [--data FILE] [--noise-radius X] [--channel OUT,IN] [--json]
//! [--band FMIN:FMAX] [--apply K|chosen [--force] --write NEW.toml]`.

use super::common::{fmt_g, InputArgs};
use super::compare::channel_arg;
use crate::diagnose::physical_from_config;
use crate::diagnose::{
    diagnose_channels, prepare, Channels, DiagnoseOptions, DiagnoseProgress, DiagnoseVerdict,
    Diagnosis, SearchSettings,
};
use crate::diagnose::{params_text, write_revision, Apply, Revise};
use crate::report::fmt::{fmt_pct, sig};
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `rshape diagnose`.
#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// Model and data.
    #[command(flatten)]
    pub input: InputArgs,
    /// SISO channel of MIMO data, `OUT,IN` (1-based); without it (and without [channel])
    /// every channel of the data is diagnosed jointly.
    #[arg(long, value_delimiter = ',')]
    pub channel: Option<Vec<usize>>,
    /// Most effects to add.
    #[arg(long, default_value_t = 3, allow_negative_numbers = true)]
    pub max_effects: usize,
    /// Effect sets kept per level of the search.
    #[arg(long, default_value_t = 3, allow_negative_numbers = true)]
    pub beam: usize,
    /// Write a revised config (with --write): `K` adds the K-th ranked candidate (1-based;
    /// a candidate the tool rejected is refused unless --force), `chosen` the chosen effect
    /// set, jointly refit, in one revision.
    #[arg(long, requires = "write", value_parser = parse_apply, value_name = "K|chosen", allow_negative_numbers = true)]
    pub apply: Option<Apply>,
    /// With --apply K: write the candidate even though the tool rejected it.
    #[arg(long, requires = "apply")]
    pub force: bool,
    /// Where to write the revised config.
    #[arg(long, requires = "apply")]
    pub write: Option<PathBuf>,
    /// Diagnose only the lines with FMIN ≤ f ≤ FMAX (Hz), e.g. `--band 20:1200`.
    #[arg(long, value_parser = parse_band, value_name = "FMIN:FMAX", allow_hyphen_values = true)]
    pub band: Option<(f64, f64)>,
    /// Write modes at 50/60 Hz or a harmonic (refused by default as probable electrical
    /// interference).
    #[arg(long)]
    pub allow_mains: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also print where the time went: a table of the search's phases.
    #[arg(long)]
    pub verbose: bool,
    /// From this many modes on, progress lines on stderr (a test lowers it to see them on a
    /// small model).
    #[arg(long, default_value_t = LARGE_MODEL_MODES, hide = true)]
    pub progress_from_modes: usize,
}

fn parse_apply(s: &str) -> std::result::Result<Apply, String> {
    if s == "chosen" {
        return Ok(Apply::Chosen);
    }
    s.parse::<usize>()
        .ok()
        .filter(|k| *k >= 1)
        .map(Apply::Rank)
        .ok_or_else(|| format!("`{s}`: give a candidate rank (1, 2, …) or `chosen`"))
}

pub(super) fn parse_band(s: &str) -> std::result::Result<(f64, f64), String> {
    let bad = || format!("`{s}`: give FMIN:FMAX in Hz with 0 ≤ FMIN < FMAX (e.g. 20:1200)");
    let (a, b) = s.split_once(':').ok_or_else(bad)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if a.is_finite() && b.is_finite() && 0.0 <= a && a < b {
        Ok((a, b))
    } else {
        Err(bad())
    }
}

/// The data channels to diagnose: the selected one, or every channel of MIMO data.
fn channels(
    a: &DiagnoseArgs,
    inputs: &super::common::Inputs,
    noise: Option<f64>,
) -> Result<Channels> {
    let config = &inputs.config;
    let data = &inputs.data;
    let chan = channel_arg(&a.channel)?;
    if chan.is_none() && config.raw.channel.is_none() && (data.outputs() > 1 || data.inputs() > 1) {
        return Ok(Channels::all(config, data, noise)?);
    }
    let siso = prepare(config, data, chan, noise)?;
    Ok(Channels::from_siso(&siso)?)
}

/// From this many modes on, `diagnose` announces its long search (200 modes: 15 s).
const LARGE_MODEL_MODES: usize = 100;

/// Renders one report of the library: a stage or a level as it begins at once (a few lines
/// in all), the joint refits of a level rate-limited (one line every few seconds).
fn show_progress(v: &super::progress::FitProgressView, p: DiagnoseProgress) {
    match p {
        DiagnoseProgress::Stage(what) => v.stage(what),
        DiagnoseProgress::Level { depth, max, nodes } => v.stage(&format!(
            "search level {depth} of at most {max}: screening {nodes} effect set{}",
            if nodes == 1 { "" } else { "s" }
        )),
        DiagnoseProgress::Retune { what, done, total } => {
            v.count(&format!("retune, {what}"), done, total)
        }
        DiagnoseProgress::Refits { depth, done, total } => {
            v.count(&format!("search level {depth}, joint refit"), done, total)
        }
    }
}

/// Runs `rshape diagnose`.
pub fn run(a: &DiagnoseArgs) -> Result<i32> {
    // 0 was silently taken as 1: say so instead.
    for (flag, v) in [("--max-effects", a.max_effects), ("--beam", a.beam)] {
        if v == 0 {
            return Err(anyhow::anyhow!(
                "{flag} 0: must be at least 1 (the default is 3)"
            ));
        }
    }
    if let Some(w) = &a.write {
        super::common::check_out_file("--write", w, &a.input.files())?;
    }
    let loaded = a.input.load()?;
    // Closed-loop data (issue 9, item 6): diagnose the plant P₀ recovered from Φ and C̄,
    // with the noise radii carried over to it, through the hook `compare` uses too.
    let found = crate::pipeline::closed_loop::discovery_inputs(
        loaded.config,
        loaded.data,
        a.input.noise_radius,
    )?;
    let noise = found.noise_radius;
    let raw = found.raw;
    let inputs = super::common::Inputs {
        config: found.config,
        data: found.data,
    };
    let config = &inputs.config;
    let base = match &config.physical {
        Some(p) => p.clone(),
        None => {
            let (p, how) = physical_from_config(config).map_err(|why| {
                anyhow!(
                    "{}: diagnose adds effects to a [physical] model, and this model cannot be converted ({why}); `rshape compare` works on it as it is. To diagnose, write the plant as [physical] (configs/robot_physical.toml is the robot's factor form written by its physics)",
                    config.path.display()
                )
            })?;
            if !a.json {
                println!(
                    "{}: {how}; effects are added to that form (--write writes [physical])",
                    config.path.display(),
                );
            }
            p
        }
    };
    let mut data = channels(a, &inputs, noise)?;
    if let Some((lo, hi)) = a.band {
        data = data.band(lo, hi)?;
    }
    let settings = SearchSettings {
        max_effects: a.max_effects.max(1),
        beam: a.beam.max(1),
        allow_mains: a.allow_mains,
        ..Default::default()
    };
    // A model of hundreds of modes refits two parameters per mode in every candidate of the
    // search, silent for minutes (issue 34: 1000 modes ran 300 s without a line): say so.
    let view = (base.mode.len() >= a.progress_from_modes).then(|| {
        let v = super::progress::FitProgressView::new("diagnose");
        v.stage(&format!(
            "a model of {} modes: the retune of every configured parameter, then the candidate search (each candidate refits them jointly; minutes at this size)",
            base.mode.len()
        ));
        v
    });
    let tell = |p: DiagnoseProgress| {
        if let Some(v) = &view {
            show_progress(v, p);
        }
    };
    let options = DiagnoseOptions {
        progress: view.is_some().then_some(&tell as _),
    };
    let d = diagnose_channels(&base, &data, &settings, &options)?;
    drop(view);
    if let (Some(what), Some(out)) = (a.apply, &a.write) {
        let rev = write_revision(
            &Revise {
                config,
                raw: &raw,
                data: &data,
                diagnosis: &d,
                base: &base,
                what,
                force: a.force,
            },
            out,
        )?;
        if !a.json {
            println!(
                "wrote {} (--apply {}: {})",
                out.display(),
                rev.flag,
                rev.label
            );
        }
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
        return Ok(0);
    }
    print_text(config, &data, &d, a.apply.is_none());
    if a.verbose {
        print_phases(&d.search);
    }
    Ok(0)
}

/// The text report of `diagnose`, section by section.
fn print_text(config: &crate::model::Config, data: &Channels, d: &Diagnosis, hint_apply: bool) {
    print_header(config, data, d);
    if d.verdict == DiagnoseVerdict::Consistent {
        println!("\nverdict: {}: {}", d.verdict, d.message);
        return;
    }
    println!(
        "retune (every configured parameter refit, nothing added): misfit_rms = {}, invalid_fraction = {}",
        fmt_g(d.retuned.misfit_rms),
        fmt_pct(d.retuned.invalid_fraction)
    );
    print_changes(&d.retuned.moved, "the retune moved");
    if let Some(note) = &d.retuned.moved.settled {
        println!("  note: {note}");
    }
    print_candidates(d);
    print_path(d);
    if !d.chosen.is_empty() {
        print_changes(
            &d.retuned_in_chosen,
            "with the chosen set, the joint refit moved",
        );
    }
    print_dropped(d);
    print_refused(d);
    print_alternatives(d);
    print_peaks(d);
    let given_up = match d.search.refits_given_up {
        0 => String::new(),
        k => format!(" ({k} given up, far above their reference)"),
    };
    println!(
        "\nsearch: {} nodes expanded, {} joint refits{given_up}, {} s (beam {})",
        d.search.nodes_expanded,
        d.search.joint_refits,
        sig(d.search.seconds),
        d.search.beam
    );
    println!("verdict: {}: {}", d.verdict, d.message);
    if hint_apply && !d.candidates.is_empty() {
        println!(
            "write the chosen set with: rshape diagnose {} --apply chosen --write NEW.toml (or one candidate that passes: --apply K)",
            config.path.display()
        );
    }
}

/// What was compared (model, data, channels, noise) and the misfit before any change.
fn print_header(config: &crate::model::Config, data: &Channels, d: &Diagnosis) {
    let chans = data
        .entries
        .iter()
        .map(|(o, i)| format!("{},{}", o + 1, i + 1))
        .collect::<Vec<_>>()
        .join(" ");
    println!(
        "model: {}   data: {} (channel{} {chans}; {} frequencies; noise: {})",
        config.path.display(),
        data.path.display(),
        if data.n_ch() > 1 { "s, jointly" } else { "" },
        data.len(),
        data.radius_source.join("; ")
    );
    println!(
        "before: misfit_rms = {}, invalid_fraction = {}",
        fmt_g(d.before.misfit_rms),
        fmt_pct(d.before.invalid_fraction)
    );
}

/// The candidates on the configured model, ranked by ΔBIC, with their parameters.
fn print_candidates(d: &Diagnosis) {
    if d.candidates.is_empty() {
        return;
    }
    println!("\ncandidates on the configured model (ranked by ΔBIC = 2ΔV − n·ln 2F; each with every parameter refit jointly when marked *; pass = ΔBIC > 10 against the retune, plausible, and no more invalid data or a lower misfit_rms):");
    for c in &d.candidates {
        if let Some(why) = &c.no_fit {
            println!("{:>2}. {:<18} no fit: {why}", c.rank, c.effect);
            continue;
        }
        let params = c
            .params
            .iter()
            .map(|(n, v)| match c.uncertainty_2sigma.get(n) {
                Some(u) if u.is_finite() && *u > 0.0 => {
                    format!("{n} = {} ± {}", sig(*v), sig(*u))
                }
                _ => format!("{n} = {}", sig(*v)),
            })
            .collect::<Vec<_>>()
            .join(", ");
        println!(
            "{:>2}. {:<18} ΔBIC {:>10}{}  misfit_rms {} → {}  invalid {} → {}  {}{}",
            c.rank,
            c.effect,
            sig(c.delta_bic),
            if c.joint_refit { "*" } else { " " },
            sig(c.misfit_rms_before),
            sig(c.misfit_rms_after),
            fmt_pct(c.invalid_fraction_before),
            fmt_pct(c.invalid_fraction_after),
            if c.passes { "pass" } else { "-" },
            if c.tie_with_best {
                "  (tie with #1)"
            } else {
                ""
            }
        );
        if !params.is_empty() {
            println!("    {params}");
        }
        for f in &c.flags {
            println!("    flag: {f}");
        }
        println!("    {}", c.explanation);
    }
}

/// The chosen path of the beam search and the effects of the final model.
fn print_path(d: &Diagnosis) {
    if !d.steps.is_empty() {
        println!("\nchosen path (beam search, joint refit of every parameter at each node):");
        for s in &d.steps {
            println!(
                "  step {}: + {} ({}, after the refit) → misfit_rms {}, invalid {} (joint refit of {} parameters; before the refit {}, {})",
                s.step,
                s.effect,
                params_text(&s.params),
                sig(s.misfit_rms),
                fmt_pct(s.invalid_fraction),
                s.n_refit,
                sig(s.misfit_rms_before_refit),
                fmt_pct(s.invalid_fraction_before_refit)
            );
        }
    }
    if !d.final_effects.is_empty() {
        println!("\nchosen effects in the final model (every parameter refit jointly; ± 1σ):");
        for e in &d.final_effects {
            let p = e
                .params
                .iter()
                .map(|(n, v)| match e.sigma.get(n) {
                    Some(u) => format!("{n} = {} ± {}", sig(*v), sig(*u)),
                    None => format!("{n} = {}", sig(*v)),
                })
                .collect::<Vec<_>>()
                .join(", ");
            println!("  {}: {p}", e.effect);
        }
    }
}

/// The holdout verdicts and the effects dropped by the backward elimination or the holdout.
fn print_dropped(d: &Diagnosis) {
    for h in &d.holdout {
        println!(
            "holdout {}: interleaved {}{}",
            h.effect,
            if h.interleaved_ok { "ok" } else { "FAILS" },
            match h.extrapolation_ok {
                Some(true) => ", extrapolation ok",
                Some(false) => ", extrapolation fails",
                None => "",
            }
        );
    }
    if !d.eliminated.is_empty() {
        println!(
            "dropped by the backward elimination (the data do not need them): {}",
            d.eliminated.join(", ")
        );
    }
    if !d.dropped.is_empty() {
        println!("dropped by the holdout: {}", d.dropped.join(", "));
    }
}

/// The effects the likelihood wanted but physical admissibility refused, with the rule and
/// the reason.
fn print_refused(d: &Diagnosis) {
    if d.refused.is_empty() {
        return;
    }
    println!("refused on their joint refit (ΔBIC passed, not physical):");
    for r in &d.refused {
        let at = r
            .refusal
            .frequency_hz
            .map(|f| format!(" {} Hz", sig(f)))
            .unwrap_or_default();
        println!(
            "  step {}: {}{at}: {}: {}",
            r.step,
            r.refusal.effect,
            r.refusal.rule.word(),
            r.refusal.reason
        );
    }
}

/// The runner-up sets and the ties between effects.
fn print_alternatives(d: &Diagnosis) {
    if !d.runner_up.is_empty() {
        println!("\nrunner-up sets (BIC gap to the chosen set):");
        for r in &d.runner_up {
            println!(
                "  {:<40} {}{}  misfit_rms {}, invalid {}{}",
                if r.effects.is_empty() {
                    "(retune only)".to_string()
                } else {
                    r.effects.join(" + ")
                },
                // A runner-up in a tie may have the lower BIC (the prior order chose).
                if r.bic_gap >= 0.0 { "+" } else { "" },
                sig(r.bic_gap),
                sig(r.misfit_rms),
                fmt_pct(r.invalid_fraction),
                if r.consistent { " (consistent)" } else { "" }
            );
        }
    }
    for t in &d.ties {
        println!(
            "\ntie: {} and {} (BIC gap {}): {}",
            t.effects[0],
            t.effects[1],
            sig(t.bic_gap),
            t.disambiguation
        );
    }
}

/// The per-peak account: every peak of the residual and what became of it.
fn print_peaks(d: &Diagnosis) {
    if d.peaks.is_empty() {
        return;
    }
    println!("\npeaks of the residual (|data − model|/r ≥ 3 and at least twice the dip to higher ground; height on the retuned model → the final one):");
    for p in &d.peaks {
        println!(
            "  {:>9} Hz {:>9} → {:<9} {}: {}",
            sig(p.frequency_hz),
            sig(p.height),
            sig(p.height_after),
            p.fate.as_str().replace('_', " "),
            p.reason
        );
    }
    if d.peaks_not_listed > 0 {
        println!("  ({} lower peaks not listed)", d.peaks_not_listed);
    }
}

/// Where the time went (`--verbose`): the wall time of each phase of the search.
fn print_phases(s: &crate::diagnose::SearchStats) {
    println!("\ntime per phase (wall clock):");
    println!("  {:<22} {:>9} {:>6} {:>7}", "phase", "s", "runs", "share");
    let total = s.seconds.max(1e-12);
    let mut sum = 0.0;
    for p in &s.phases {
        sum += p.seconds;
        println!(
            "  {:<22} {:>9.3} {:>6} {:>6.1}%",
            p.phase,
            p.seconds,
            p.count,
            100.0 * p.seconds / total
        );
    }
    println!(
        "  {:<22} {:>9.3} {:>6} {:>6.1}%",
        "other (report, σ)",
        (s.seconds - sum).max(0.0),
        "",
        100.0 * (s.seconds - sum).max(0.0) / total
    );
    println!("  {:<22} {:>9.3}", "total", s.seconds);
}

/// The configured parameters a refit moved, as a table (a common gain as one row).
fn print_changes(c: &crate::diagnose::Changes, what: &str) {
    if c.changes.is_empty() {
        return;
    }
    println!("  {what} (by more than 3σ):");
    println!(
        "    {:<28} {:>12} {:>12} {:>10}",
        "parameter", "before", "after", "σ"
    );
    for ch in &c.changes {
        println!(
            "    {:<28} {:>12} {:>12} {:>10}",
            if ch.parameter == "gain" {
                "gain (common factor)".to_string()
            } else {
                ch.parameter.clone()
            },
            sig(ch.before),
            sig(ch.after),
            sig(ch.sigma)
        );
    }
    if let Some(g) = &c.common_gain {
        println!(
            "    gain ×{}: one factor on {}",
            sig(g.factor),
            g.parameters.join(", ")
        );
    }
}

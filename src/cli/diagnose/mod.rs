//! `rshape diagnose CONFIG [--data FILE] [--noise-radius X] [--channel OUT,IN] [--json]
//! [--band FMIN:FMAX] [--exclude FMIN:FMAX]… [--apply K|chosen [--force] --write NEW.toml]`.

use super::common::InputArgs;
use super::compare::channel_arg;
use crate::diagnose::physical_from_config;
use crate::diagnose::{
    diagnose_channels, prepare, Channels, DiagnoseOptions, DiagnoseProgress, SearchSettings,
};
use crate::diagnose::{write_revision, Apply, Revise};
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::PathBuf;

mod text;

use text::{print_phases, print_text};

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
    /// Leave out the lines with FMIN ≤ f ≤ FMAX (Hz), e.g. a mains line: `--exclude
    /// 2639.5:2640.5`; repeat it for several ranges.
    #[arg(long, value_parser = parse_band, value_name = "FMIN:FMAX", allow_hyphen_values = true)]
    pub exclude: Vec<(f64, f64)>,
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
    // In the data file's units: the misfit |G_d − G_m|/L of every channel is the same in
    // the units of [scaling] (data, model and noise radius scale alike), and the [physical]
    // model a revision writes is in the data's units; [scaling] goes into it unchanged.
    let (loaded, scaling) = a.input.load_in_file_units()?;
    // Closed-loop data (issue 9, item 6): diagnose the plant P₀ recovered from Φ and C̄,
    // with the noise radii carried over to it, through the hook `compare` uses too.
    let found = crate::pipeline::closed_loop::discovery_inputs(
        loaded.config,
        loaded.data,
        a.input.noise_radius,
    )?;
    let noise = found.noise_radius;
    let mut raw = found.raw;
    raw.scaling = scaling.as_ref().map(crate::model::Scaling::spec);
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
    if let (Some(s), false) = (&scaling, a.json) {
        println!(
            "{}: [scaling] {}: diagnosed in the data file's units (the noise-normalized misfit is the same in the scaled ones); --write keeps [scaling]",
            config.path.display(),
            s.describe()
        );
    }
    let mut data = channels(a, &inputs, noise)?;
    if let Some((lo, hi)) = a.band {
        data = data.band(lo, hi)?;
    }
    for (lo, hi) in &a.exclude {
        data = data.exclude(*lo, *hi)?;
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

//! `rshape batch CONFIG (--data-dir DIR | --manifest FILE) --out OUT [--shard K/N]`:
//! many datasets on one model, in parallel, with `OUT/summary.csv`.
//! Exit 0 when every dataset succeeded, 3 when some failed, 2 on a usage error.

use super::common::fmt_g;
use crate::batch::{
    self, combine, discover_dir, discover_manifest, run_all, BatchSettings, FinishInput, Shard,
    SummaryRow,
};
use anyhow::{anyhow, Result};
use clap::{ArgGroup, Args};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

/// Seconds between the progress lines of a batch whose stderr is not a terminal.
pub const PROGRESS_EVERY: f64 = 5.0;

/// Arguments of `rshape batch`.
#[derive(Debug, Args)]
#[command(group(ArgGroup::new("source").required(true).args(["data_dir", "manifest"])))]
pub struct BatchArgs {
    /// The TOML config (model and r); its `data` entry is ignored.
    pub config: PathBuf,
    /// Every *.csv file of this directory is a dataset (sorted by name).
    #[arg(long)]
    pub data_dir: Option<PathBuf>,
    /// A manifest CSV with columns name,data,noise_radius (only data required).
    #[arg(long)]
    pub manifest: Option<PathBuf>,
    /// Output directory (created if needed).
    #[arg(long)]
    pub out: PathBuf,
    /// Noise radius for datasets without one in the manifest.
    #[arg(long, allow_negative_numbers = true)]
    pub noise_radius: Option<f64>,
    /// Process every N-th dataset starting at K (0-based), e.g. --shard $SLURM_ARRAY_TASK_ID/8.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Worker threads (default: all cores; at most 1024, and never more than datasets).
    #[arg(long, allow_negative_numbers = true)]
    pub jobs: Option<i64>,
    /// Order of the r fitted above the combined envelope, or `auto` (sweep 0..8).
    #[arg(long, default_value = "auto", allow_negative_numbers = true)]
    pub order: crate::fit::OrderChoice,
    /// Do not write OUT/datasets/NAME/ (only summary.csv, the combined envelope and r).
    #[arg(long)]
    pub no_dataset_files: bool,
}

/// Largest `--jobs`: beyond this, threads cost memory and start-up time and buy nothing.
pub const MAX_JOBS: i64 = 1024;

/// Runs `rshape batch`.
pub fn run(a: &BatchArgs) -> Result<i32> {
    let t0 = Instant::now();
    if let Some(j) = a.jobs {
        if !(1..=MAX_JOBS).contains(&j) {
            return Err(anyhow!(
                "--jobs {j}: give a number of worker threads from 1 to {MAX_JOBS} (default: all cores)"
            ));
        }
    }
    let config = super::common::load_config(&a.config)?;
    if let Some(x) = a.noise_radius {
        if !(x.is_finite() && x >= 0.0) {
            return Err(anyhow!("--noise-radius {x}: must be a finite number ≥ 0"));
        }
    }
    let all = match (&a.data_dir, &a.manifest) {
        (Some(d), _) => discover_dir(d)?,
        (None, Some(m)) => discover_manifest(m)?,
        (None, None) => unreachable!("clap requires one source"),
    };
    let shard = a
        .shard
        .as_deref()
        .map(Shard::parse)
        .transpose()?
        .unwrap_or(Shard::ALL);
    let datasets = shard.select(&all, |d| d.index);
    let sources: Vec<&std::path::Path> = [
        Some(a.config.as_path()),
        a.data_dir.as_deref(),
        a.manifest.as_deref(),
    ]
    .into_iter()
    .flatten()
    .collect();
    let _manifest = super::common::prepare_out(&a.out, &sources)?;
    let opts = BatchSettings {
        noise_radius: a.noise_radius,
        per_dataset_files: !a.no_dataset_files,
    };

    let bar = if std::io::stderr().is_terminal() {
        let b = ProgressBar::with_draw_target(
            Some(datasets.len() as u64),
            ProgressDrawTarget::stderr(),
        );
        b.set_style(
            ProgressStyle::with_template(
                "{bar:40} {pos}/{len} datasets  {elapsed_precise} (eta {eta})",
            )
            .expect("valid template"),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    // Off a terminal (a log file, a pipe, a cluster job) the bar is hidden: a line on
    // stderr every PROGRESS_EVERY seconds, and at the end, says how far the batch is.
    let periodic = !std::io::stderr().is_terminal();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let last = std::sync::Mutex::new(Instant::now());
    let n_sets = datasets.len();
    let tick = || {
        bar.inc(1);
        let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if periodic {
            let mut l = last.lock().unwrap_or_else(|e| e.into_inner());
            if k == n_sets || l.elapsed().as_secs_f64() >= PROGRESS_EVERY {
                *l = Instant::now();
                eprintln!(
                    "batch: {k}/{n_sets} datasets done ({:.0} s)",
                    t.elapsed().as_secs_f64()
                );
            }
        }
    };
    let work = || run_all(&config, &datasets, &opts, &a.out, &tick);
    let results = match a.jobs {
        // More threads than datasets only cost memory (each has its own stack).
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads((n as usize).min(datasets.len()).max(1))
            .build()?
            .install(work),
        None => work(),
    };
    bar.finish_and_clear();
    let mut timings = BTreeMap::new();
    timings.insert("load".to_string(), load_ms);
    timings.insert("datasets".to_string(), t.elapsed().as_secs_f64() * 1e3);
    let t = Instant::now();
    let combined = combine(results.iter().filter_map(|r| r.envelope.as_ref()));
    timings.insert("combine".to_string(), t.elapsed().as_secs_f64() * 1e3);
    let rows: Vec<SummaryRow> = results.iter().map(SummaryRow::from).collect();
    if let Some(c) = &combined {
        // The fit may take seconds: say so on a terminal and in a log alike.
        eprintln!(
            "fitting one {} above the combined envelope ({} frequencies)…",
            crate::plot::Symbols::of(config.closed_loop.is_some()).weight,
            c.len()
        );
    }
    let rep = batch::finish(
        &a.out,
        &rows,
        combined.as_ref(),
        FinishInput {
            config: config.path.clone(),
            config_digest: batch::config_digest(&config.path),
            scaling: crate::report::ScalingNote::of_opt(config.scaling.as_ref()),
            r_configured: config.r.as_ref(),
            n_total: all.len(),
            shard,
            merged_from: Vec::new(),
            timings_ms: timings,
            order: a.order,
            factorization: crate::pipeline::closed_loop::a1_factorization(&config),
            closed_loop: config.closed_loop.is_some(),
            datasets: results.iter().filter_map(|r| r.envelope.as_ref()).collect(),
        },
    )?;
    print_summary(&rep, &rows, &a.out, t0.elapsed().as_secs_f64());
    Ok(if rep.n_failed > 0 {
        batch::EXIT_SOME_FAILED
    } else {
        batch::EXIT_OK
    })
}

/// Prints the result of a batch or a merge, with the symbols of its data (`r`, `r_min` for
/// open-loop data; `V`, `|V|_min` for closed-loop data, as the figures and `run`).
pub fn print_summary(
    rep: &batch::BatchReport,
    rows: &[SummaryRow],
    out: &std::path::Path,
    secs: f64,
) {
    let shard = if rep.shard.n > 1 {
        format!(" (shard {}/{})", rep.shard.k, rep.shard.n)
    } else {
        String::new()
    };
    outln!(
        "rshape batch: {} of {} dataset(s) processed{shard}, {} ok, {} failed, in {:.2} s",
        rep.n_datasets,
        rep.n_total,
        rep.n_ok,
        rep.n_failed,
        secs
    );
    let sym = crate::plot::Symbols::of(rep.closed_loop);
    let (w, wmin) = (sym.weight, sym.weight_min);
    if rep.r_configured.is_some() {
        outln!(
            "  configured {w} explains {} of {} successful dataset(s)",
            rep.n_consistent,
            rep.n_ok
        );
    }
    outln!(
        "  combined envelope: {} frequencies, max {wmin} = {}",
        rep.n_frequencies,
        rep.max_r_min.map_or("-".into(), fmt_g)
    );
    match (&rep.r_fitted, &rep.fit_error) {
        (Some(j), _) => outln!(
            "  fitted {w} covering all datasets: {} (coefficients in r.json)",
            super::run::fit_tag(j)
        ),
        (None, Some(e)) => outln!("  fit failed: {e}"),
        _ => {}
    }
    for r in rows.iter().filter(|r| !r.ok).take(10) {
        outln!("  FAILED {}: {}", r.name, r.error);
    }
    if rep.n_failed > 10 {
        outln!(
            "  ... and {} more failed dataset(s): see summary.csv",
            rep.n_failed - 10
        );
    }
    // Name only what exists: no combined envelope without a successful dataset, no r.json
    // when the fit failed.
    let mut files = vec!["summary.csv", "batch.json"];
    if rep.n_frequencies > 0 {
        files.push("combined_envelope.csv");
        files.push("batch.svg");
    }
    if rep.r_fitted.is_some() {
        files.push("r.json");
    }
    outln!("  wrote {}/{}", out.display(), files.join(", "));
}

//! Arguments and loading shared by the subcommands that read a model and data.

use crate::consistency::Envelope;
use crate::data::FrfData;
use crate::model::Config;
use crate::util::OutputManifest;
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::PathBuf;

/// Model and data arguments.
#[derive(Debug, Args, Clone)]
pub struct InputArgs {
    /// The TOML config (model, r, data file, noise).
    pub config: PathBuf,
    /// Data file overriding the one named in the config.
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Global noise-disk radius L_a overriding the config (noisy SISO data, Theorem 4).
    #[arg(long, allow_negative_numbers = true)]
    pub noise_radius: Option<f64>,
}

/// A loaded config with its data.
pub struct Inputs {
    /// The config.
    pub config: Config,
    /// The data.
    pub data: FrfData,
}

impl InputArgs {
    /// The files this input reads: the config, `--data` and the data file the config names
    /// (an output the subcommand writes may not be one of them, [`check_out_file`]).
    pub fn files(&self) -> Vec<PathBuf> {
        let mut files = vec![self.config.clone()];
        if let Some(d) = &self.data {
            files.extend(data_and_siblings(d));
        }
        files.extend(config_files(&self.config));
        files
    }

    /// Loads the config and the data (from `--data` or the config).
    pub fn load(&self) -> Result<Inputs> {
        let config = load_config(&self.config)?;
        let path = self.data_path(&config)?;
        let data = crate::pipeline::envelope::load_data(&config, &path)?;
        self.check_noise_radius()?;
        Ok(Inputs { config, data })
    }

    /// As [`InputArgs::load`], in the data file's own units: a config with `[scaling]` is
    /// loaded without it ([`Config::without_scaling`]), its scaling returned beside (for
    /// `diagnose`, which revises a `[physical]` model written in the data's units).
    pub fn load_in_file_units(&self) -> Result<(Inputs, Option<crate::model::Scaling>)> {
        let config = load_config(&self.config)?;
        let scaling = config.scaling.clone();
        let config = match scaling {
            Some(_) => config.without_scaling()?,
            None => config,
        };
        let path = self.data_path(&config)?;
        let data = crate::pipeline::envelope::load_data(&config, &path)?;
        self.check_noise_radius()?;
        Ok((Inputs { config, data }, scaling))
    }

    /// The data file: `--data`, else the config's `data`.
    fn data_path(&self, config: &Config) -> Result<PathBuf> {
        self.data
            .clone()
            .or_else(|| config.data.clone())
            .ok_or_else(|| {
                anyhow!(
                    "{}: no data file: add `data = \"FILE.csv\"` to the config or pass --data FILE",
                    self.config.display()
                )
            })
    }

    fn check_noise_radius(&self) -> Result<()> {
        match self.noise_radius {
            Some(x) if !(x.is_finite() && x >= 0.0) => {
                Err(anyhow!("--noise-radius {x}: must be a finite number ≥ 0"))
            }
            _ => Ok(()),
        }
    }

    /// The envelope alone, streamed when the noise-free theorems apply
    /// ([`crate::pipeline::envelope::envelope_of_file`]), with the config it was computed for.
    pub fn envelope_only(&self) -> Result<(Config, Envelope)> {
        let config = load_config(&self.config)?;
        self.check_noise_radius()?;
        let path = self.data_path(&config)?;
        let env = crate::pipeline::envelope::envelope_of_file(&config, &path, self.noise_radius)?;
        Ok((config, env))
    }

    /// Loads inputs and computes their envelope ([`crate::pipeline::envelope::envelope`]).
    pub fn envelope(&self) -> Result<(Inputs, Envelope)> {
        let inputs = self.load()?;
        let env = self.envelope_of(&inputs)?;
        Ok((inputs, env))
    }

    /// The envelope of inputs already loaded by [`InputArgs::load`].
    pub fn envelope_of(&self, inputs: &Inputs) -> Result<Envelope> {
        let options = crate::pipeline::RunOptions::noise_radius(self.noise_radius);
        Ok(crate::pipeline::envelope::envelope(&inputs.config, &inputs.data, &options)?.envelope)
    }
}

/// Seconds of loading after which, and between which, [`load_config`] says it is still busy.
const LOAD_NOTICE: std::time::Duration = std::time::Duration::from_secs(5);

/// The environment variable that shortens [`LOAD_NOTICE`] to a number of milliseconds, for
/// the tests only (tests/cli/load_notice.rs: a load of a few hundred ms shows the notice);
/// not a user option, so neither a flag nor in `--help`.  Unset, not a whole number or 0:
/// the 5 s.
const LOAD_NOTICE_ENV: &str = "RSHAPE_TEST_LOAD_NOTICE_MS";

/// [`LOAD_NOTICE`], or the test's shorter interval from [`LOAD_NOTICE_ENV`].
fn load_notice() -> std::time::Duration {
    std::env::var(LOAD_NOTICE_ENV)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .filter(|&ms| ms > 0)
        .map_or(LOAD_NOTICE, std::time::Duration::from_millis)
}

/// [`Config::load`], with a line on stderr every 5 s while it lasts longer than that: a
/// `[plant] file` of a large state space (the 1412-state SLICOT ISS 12A model, its balanced
/// truncation and its normalized coprime factors) takes minutes with no other sign of life.
/// A load within 5 s prints nothing.
pub fn load_config(path: &std::path::Path) -> Result<Config> {
    use std::sync::mpsc;
    let (done, wait) = mpsc::channel::<()>();
    let every = load_notice();
    std::thread::scope(|s| {
        s.spawn(move || {
            let start = std::time::Instant::now();
            // Ends when the sender is dropped (the load finished, or failed).
            while let Err(mpsc::RecvTimeoutError::Timeout) = wait.recv_timeout(every) {
                eprintln!(
                    "loading {}: reading and factoring the model ({:.0} s)",
                    path.display(),
                    start.elapsed().as_secs_f64()
                );
            }
        });
        let config = Config::load(path);
        drop(done);
        Ok(config?)
    })
}

pub use crate::report::fmt::{fmt_g, fmt_omegas};

/// Checks `--out DIR` before any work and clears the previous run's files there (see
/// [`OutputManifest`]).  `DIR` must not be an existing file, nor the folder of an input
/// (outputs would mix with inputs): of the given paths and of every file they make the run
/// read (a config's data, noise std or coherence and plant files, [`config_files`]; the
/// noise files beside a data file, [`data_and_siblings`]).  Keep the guard alive while the
/// run writes.
pub fn prepare_out(out: &std::path::Path, inputs: &[&std::path::Path]) -> Result<OutputManifest> {
    check_out(out, inputs)?;
    Ok(OutputManifest::begin(out)?)
}

/// The checks of [`prepare_out`] alone, touching nothing: for commands that do their work
/// before clearing the folder (so that a refusal leaves the previous run's files), yet must
/// refuse a bad `--out` before that work.
pub fn check_out(out: &std::path::Path, inputs: &[&std::path::Path]) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(anyhow!(
            "--out {}: is an existing file; give a folder (it is created if needed)",
            out.display()
        ));
    }
    let mut every: Vec<PathBuf> = Vec::new();
    for input in inputs {
        every.push(input.to_path_buf());
        match input.extension().and_then(|e| e.to_str()) {
            Some("toml") if input.is_file() => every.extend(config_files(input)),
            Some("csv") => every.extend(data_and_siblings(input)),
            _ => {}
        }
    }
    if let Ok(o) = out.canonicalize() {
        for input in &every {
            let folder = match input.canonicalize() {
                Ok(p) if p.is_dir() => p,
                Ok(p) => p.parent().map(|p| p.to_path_buf()).unwrap_or(p),
                Err(_) => continue,
            };
            if folder == o {
                return Err(anyhow!(
                    "--out {}: is the folder of the input {}; outputs would mix with inputs: choose a new folder such as {}",
                    out.display(),
                    input.display(),
                    out.join("out").display()
                ));
            }
        }
    }
    Ok(())
}

/// Checks a single output file given by `flag` (`--svg FILE`, `--write FILE`) before any
/// work: it must not be an existing folder nor one of the inputs (a figure or a revised
/// config written over the config or the data would destroy it).  The file itself is
/// written atomically (temporary file + rename) by the writer.
pub fn check_out_file(
    flag: &str,
    path: &std::path::Path,
    inputs: &[impl AsRef<std::path::Path>],
) -> Result<()> {
    if path.is_dir() {
        return Err(anyhow!(
            "{flag} {}: is an existing folder; give a file name",
            path.display()
        ));
    }
    crate::util::check_not_special(path)?;
    if let Ok(p) = path.canonicalize() {
        for input in inputs.iter().map(|i| i.as_ref()) {
            if input.canonicalize().is_ok_and(|i| i == p) {
                return Err(anyhow!(
                    "{flag} {}: is the input {}; writing there would destroy it: choose a new file name",
                    path.display(),
                    input.display()
                ));
            }
        }
    }
    Ok(())
}

/// Every file a config makes a run read (itself, its data, noise std or coherence file,
/// plant file: [`Config::files_read`]), for the output checks; just the path when it does
/// not parse.  From the TOML alone: the model is not built again (its load, which may factor
/// a large state space, happens once, in the subcommand).
pub fn config_files(config: &std::path::Path) -> Vec<PathBuf> {
    let raw = std::fs::read_to_string(config)
        .ok()
        .and_then(|text| toml::from_str::<crate::model::RawConfig>(&text).ok());
    match raw {
        Some(r) => r.files_read(config),
        None => vec![config.to_path_buf()],
    }
}

/// A `--data` file and the per-frequency noise files a run may read beside it
/// (`<stem>_std.csv`, `<stem>_coherence.csv`).
pub fn data_and_siblings(data: &std::path::Path) -> Vec<PathBuf> {
    let stem = data
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    vec![
        data.to_path_buf(),
        data.with_file_name(format!("{stem}_std.csv")),
        data.with_file_name(format!("{stem}_coherence.csv")),
    ]
}

/// A bound `r` with its label (`configured`, `fitted`).
pub type LabelledBound = (String, crate::system::TransferFunction);

/// Loaded inputs with their envelope, for `--fit`.
pub type FitInput = (Inputs, Envelope);

/// The bounds `r` a controller is proved with besides the config's `[r]` (`stability`,
/// `synthesize`): the flags are defined once here and flattened into both subcommands.
#[derive(Debug, Args)]
pub struct BoundArgs {
    /// A fitted r (the r.json written by `rshape run` or `rshape fit`).
    #[arg(long)]
    pub r_json: Option<PathBuf>,
    /// Fit r from the config's data first (as `rshape fit`; exports go to --out).
    #[arg(long, conflicts_with = "r_json")]
    pub fit: bool,
    /// Data file overriding the one in the config.
    #[arg(long)]
    pub data: Option<PathBuf>,
}

impl BoundArgs {
    /// The input files these flags name (`--r-json`, `--data`), for the output-folder policy.
    pub fn files(&self) -> impl Iterator<Item = &std::path::Path> {
        [self.r_json.as_deref(), self.data.as_deref()]
            .into_iter()
            .flatten()
    }

    /// The bounds a controller is judged with: the config's `[r]`, then `--r-json` as
    /// `fitted`; with `--fit`, the inputs whose envelope will be fitted, read before any
    /// output folder is touched.  A `[closed_loop]` config refuses `--fit` (it would fit its
    /// weight `V`, not a factor bound `r`).
    pub fn bounds(
        &self,
        config_path: &std::path::Path,
        config: &Config,
    ) -> Result<(Vec<LabelledBound>, Option<FitInput>)> {
        // --data only shapes the figure's grid here: a missing file was silently ignored.
        if let Some(d) = &self.data {
            if !d.is_file() {
                return Err(anyhow!(
                    "--data {}: no such file (or not a regular file); check the path",
                    d.display()
                ));
            }
        }
        if config.closed_loop.is_some() && self.fit {
            return Err(anyhow!(
                "{}: --fit on a [closed_loop] config would fit its weight V, not a factor bound r: give --r-json r.json",
                config_path.display()
            ));
        }
        let given = self
            .r_json
            .as_deref()
            .map(crate::pipeline::stability::read_r_json)
            .transpose()?;
        let rs = crate::pipeline::stability::bounds(config, given);
        let fit_input = if self.fit {
            let input = InputArgs {
                config: config_path.to_path_buf(),
                data: self.data.clone(),
                noise_radius: None,
            };
            Some(input.envelope()?)
        } else {
            None
        };
        Ok((rs, fit_input))
    }
}

/// Fits `r` above the envelope of `fit_input` as `rshape fit --order auto` does (exports into
/// `out`), with progress shown under `label`; returns the fit's text (with its work line)
/// and the fitted `r`.
pub fn fit_bound(
    label: &str,
    input: &FitInput,
    out: &std::path::Path,
) -> Result<(String, crate::system::TransferFunction)> {
    let outcome = fit_bound_in_memory(label, input)?;
    write_fit_text(outcome, out, input.0.config.scaling.as_ref())
}

/// As [`fit_bound`], writing nothing: the caller checks the rest, then writes the fit and
/// prints its text with [`write_fit_text`].
pub fn fit_bound_in_memory(
    label: &str,
    (inputs, env): &FitInput,
) -> Result<crate::fit::FitOutcome> {
    // A1 as `run` imposes it: none for closed-loop data (the pipeline's rule).
    let model = crate::pipeline::A1Model::of_config(&inputs.config);
    let (a1, settings) = (model.limit(), model.settings(Default::default()));
    let view = super::progress::FitProgressView::new(label);
    let progress = |p| view.update(p);
    let outcome = crate::fit::run_fit(
        env,
        a1,
        &settings,
        crate::fit::OrderChoice::Auto { max: 8 },
        Some(&progress),
    );
    view.finish();
    Ok(outcome?)
}

/// Writes the fit's exports into `out` (`pipeline::write_fit_exports`) and returns its
/// printable text (the files written, the work line) and the fitted `r`; a config's
/// `[scaling]` is noted in them.
pub fn write_fit_text(
    outcome: crate::fit::FitOutcome,
    out: &std::path::Path,
    scaling: Option<&crate::model::Scaling>,
) -> Result<(String, crate::system::TransferFunction)> {
    let mut text = outcome.text.clone();
    for f in crate::pipeline::write_fit_exports(&outcome, out, scaling)? {
        text.push_str(&format!("wrote {}\n", f.display()));
    }
    text.push_str(&crate::fit::work_line(&outcome.result, outcome.seconds));
    Ok((text, outcome.result.r))
}

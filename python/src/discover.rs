//! Model discovery: `compare` (misfit of the model against the data) and `diagnose` (which
//! physical effect is missing), with the CLI's loading steps (the closed-loop hook
//! [`rshape::pipeline::closed_loop::discovery_inputs`], the channel choice) and the library's
//! entry points; results go to Python as the JSON of `--json`.

use crate::core::{config_data, noise_arg};
use crate::data::{Config, Frf};
use crate::errors::{guarded, input, OrRaise};
use pyo3::prelude::*;
use rshape::diagnose::{
    compare, diagnose_channels, physical_from_config, prepare, write_revision, Apply, Channels,
    Diagnosis, PlantModel, Revise, SearchSettings,
};
use rshape::model::physical::PhysicalModel;
use rshape::pipeline::closed_loop::discovery_inputs;
use std::path::{Path, PathBuf};

fn channel_arg(c: Option<(usize, usize)>) -> PyResult<Option<(usize, usize)>> {
    match c {
        Some((o, i)) if o == 0 || i == 0 => Err(input("channel=(OUT, IN): two 1-based indices")),
        c => Ok(c),
    }
}

/// `rshape compare --json`: misfit per frequency, failing bands, error measures.
#[pyfunction]
#[pyo3(signature = (config, frf=None, channel=None, noise_radius=None))]
pub fn _compare(
    py: Python<'_>,
    config: &Config,
    frf: Option<&Frf>,
    channel: Option<(usize, usize)>,
    noise_radius: Option<f64>,
) -> PyResult<String> {
    let cfg = config.inner.clone();
    guarded(py, || {
        noise_arg(noise_radius)?;
        let channel = channel_arg(channel)?;
        let data = config_data(&cfg, frf)?;
        let inputs = discovery_inputs((*cfg).clone(), data, noise_radius).py()?;
        let siso = prepare(&inputs.config, &inputs.data, channel, inputs.noise_radius).py()?;
        let model = PlantModel::from_config(&inputs.config);
        let rep = compare(&inputs.config, &model, &siso).py()?;
        serde_json::to_string(&rep).map_err(|e| input(e.to_string()))
    })
}

/// A diagnosis with what `apply` needs to write a revised config.
#[pyclass(module = "rshape", frozen)]
pub struct DiagnosisHandle {
    config: rshape::Config,
    raw: rshape::model::RawConfig,
    data: Channels,
    diagnosis: Diagnosis,
    base: PhysicalModel,
    /// JSON of the diagnosis (`rshape diagnose --json`).
    #[pyo3(get)]
    json: String,
    /// How the model was converted to `[physical]` (None when it was one).
    #[pyo3(get)]
    converted: Option<String>,
}

#[pymethods]
impl DiagnosisHandle {
    /// The revised config text (`--apply K|chosen --write PATH`) and the effect added.
    /// With `path` the file is written there, as the CLI writes it; without, the text is
    /// that of a revision beside the diagnosed config (its data paths relative to that
    /// folder), made in a temporary file there that is removed again.
    #[pyo3(signature = (what, force=false, path=None))]
    fn apply(
        &self,
        py: Python<'_>,
        what: &Bound<'_, PyAny>,
        force: bool,
        path: Option<PathBuf>,
    ) -> PyResult<(String, String)> {
        let what = if what.extract::<String>().is_ok_and(|s| s == "chosen") {
            Apply::Chosen
        } else {
            match what.extract::<i64>() {
                Ok(k) if k >= 1 => Apply::Rank(k as usize),
                _ => {
                    return Err(input(format!(
                        "apply({what}): give a candidate rank (1, 2, …) or \"chosen\""
                    )))
                }
            }
        };
        guarded(py, || {
            let write = |out: &Path| -> PyResult<(String, String)> {
                let rev = write_revision(
                    &Revise {
                        config: &self.config,
                        raw: &self.raw,
                        data: &self.data,
                        diagnosis: &self.diagnosis,
                        base: &self.base,
                        what,
                        force,
                    },
                    out,
                )
                .py()?;
                let text = std::fs::read_to_string(out)
                    .map_err(|e| input(format!("{}: {e}", out.display())))?;
                Ok((text, rev.label))
            };
            if let Some(p) = &path {
                return write(p);
            }
            let beside = self
                .config
                .path
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            let tmp = tempfile::Builder::new()
                .prefix(".rshape-revision-")
                .suffix(".toml")
                .tempfile_in(beside)
                .or_else(|_| tempfile::NamedTempFile::new())
                .map_err(|e| input(format!("a temporary file: {e}")))?;
            write(tmp.path())
        })
    }
}

/// `rshape diagnose --json`: candidates, chosen set, changes, peaks.
#[pyfunction]
#[pyo3(signature = (config, frf=None, channel=None, noise_radius=None, max_effects=3, beam=3, band=None, allow_mains=false, exclude=None))]
#[allow(clippy::too_many_arguments)]
pub fn _diagnose(
    py: Python<'_>,
    config: &Config,
    frf: Option<&Frf>,
    channel: Option<(usize, usize)>,
    noise_radius: Option<f64>,
    max_effects: usize,
    beam: usize,
    band: Option<(f64, f64)>,
    allow_mains: bool,
    exclude: Option<Vec<(f64, f64)>>,
) -> PyResult<DiagnosisHandle> {
    let cfg = config.inner.clone();
    guarded(py, move || {
        for (flag, v) in [("max_effects", max_effects), ("beam", beam)] {
            if v == 0 {
                return Err(input(format!(
                    "{flag} 0: must be at least 1 (the default is 3)"
                )));
            }
        }
        noise_arg(noise_radius)?;
        let chan = channel_arg(channel)?;
        // In the data file's units, as the CLI's diagnose: the config without [scaling] (the
        // misfit is the same in either units), whose [scaling] the revision carries.
        let scaling = cfg.scaling.clone();
        let cfg = match scaling {
            Some(_) => std::sync::Arc::new(cfg.without_scaling().py()?),
            None => cfg,
        };
        let data = config_data(&cfg, frf)?;
        let found = discovery_inputs((*cfg).clone(), data, noise_radius).py()?;
        let noise = found.noise_radius;
        let config = found.config;
        let mut raw = found.raw;
        raw.scaling = scaling.as_ref().map(rshape::model::Scaling::spec);
        let (base, converted) = match &config.physical {
            Some(p) => (p.clone(), None),
            None => {
                let (p, how) = physical_from_config(&config).map_err(|why| {
                    input(format!(
                        "{}: diagnose adds effects to a [physical] model, and this model cannot be converted ({why}); compare works on it as it is. To diagnose, write the plant as [physical]",
                        config.path.display()
                    ))
                })?;
                (p, Some(how.to_string()))
            }
        };
        let d = &found.data;
        let mut channels = if chan.is_none()
            && config.raw.channel.is_none()
            && (d.outputs() > 1 || d.inputs() > 1)
        {
            Channels::all(&config, d, noise).py()?
        } else {
            let siso = prepare(&config, d, chan, noise).py()?;
            Channels::from_siso(&siso).py()?
        };
        if let Some((lo, hi)) = band {
            channels = channels.band(lo, hi).py()?;
        }
        for (lo, hi) in exclude.unwrap_or_default() {
            channels = channels.exclude(lo, hi).py()?;
        }
        let settings = SearchSettings {
            max_effects,
            beam,
            allow_mains,
            ..Default::default()
        };
        let diagnosis = diagnose_channels(&base, &channels, &settings, &Default::default()).py()?;
        let json = serde_json::to_string(&diagnosis).map_err(|e| input(e.to_string()))?;
        Ok(DiagnosisHandle {
            config,
            raw,
            data: channels,
            diagnosis,
            base,
            json,
            converted,
        })
    })
}

//! The TOML config: the nominal factorization, the bound `r`, the data file and the noise
//! (the format is in [`Config`]'s documentation).

use super::factorization::Factorization;
use crate::error::{Error, Result};
use crate::system::TransferFunction;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

mod noise_section;

pub use noise_section::NoiseSection;

/// One entry of a transfer-function matrix in the config: a number or `{num, den}`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(untagged)]
pub enum TfEntry {
    /// A constant gain.
    Constant(f64),
    /// A rational transfer function, coefficients in descending powers of `s`.
    Rational(RationalEntry),
}

/// `{ num = [...], den = [...] }`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RationalEntry {
    /// Numerator coefficients, descending powers of `s`.
    pub num: Vec<f64>,
    /// Denominator coefficients, descending powers of `s`.
    pub den: Vec<f64>,
}

impl TfEntry {
    pub(crate) fn to_tf(&self, what: &str) -> std::result::Result<TransferFunction, String> {
        match self {
            TfEntry::Constant(k) if k.is_finite() => Ok(TransferFunction::gain(*k)),
            TfEntry::Constant(_) => Err(format!("{what}: coefficient is not finite")),
            TfEntry::Rational(r) => {
                if r.num.iter().chain(&r.den).any(|c| !c.is_finite()) {
                    return Err(format!("{what}: a coefficient is not finite"));
                }
                if r.den.iter().all(|c| *c == 0.0) {
                    return Err(format!("{what}: the denominator is zero"));
                }
                if r.num.is_empty() {
                    return Err(format!(
                        "{what}: the numerator is empty; write [0] for zero"
                    ));
                }
                Ok(TransferFunction::new(r.num.clone(), r.den.clone()))
            }
        }
    }
}

/// The `[model]` table.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSection {
    /// `"standard"` (G = M̃⁻¹Ñ) or `"special"` (G = C·M̃⁻¹·Ñ·J).
    pub factorization: super::FactorizationKind,
    /// `M̃` as rows of entries (or use `m_diag`).
    #[serde(default)]
    pub m: Option<Vec<Vec<TfEntry>>>,
    /// Diagonal of `M̃`, for modal models.
    #[serde(default)]
    pub m_diag: Option<Vec<TfEntry>>,
    /// `Ñ` as rows of entries.
    pub n: Vec<Vec<TfEntry>>,
    /// `C` (special factorization only), rows of numbers.
    #[serde(default)]
    pub c: Option<Vec<Vec<f64>>>,
    /// Diagonal of `J` (special factorization only); default all ones.
    #[serde(default)]
    pub j: Option<Vec<TfEntry>>,
}

/// The `[r]` table: the unit bounding the factor perturbations.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RSection {
    /// Numerator coefficients, descending powers of `s`.
    pub num: Vec<f64>,
    /// Denominator coefficients, descending powers of `s`.
    pub den: Vec<f64>,
}

/// The `[channel]` table: the SISO channel of MIMO data to compare with (1-based).
#[derive(Debug, Clone, Copy, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelSection {
    /// Output (row), 1-based.
    pub output: usize,
    /// Input (column), 1-based.
    pub input: usize,
}

/// The whole file as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawConfig {
    /// Free-text name of the model.
    #[serde(default)]
    pub name: Option<String>,
    /// Data file, relative to the config file.
    #[serde(default)]
    pub data: Option<PathBuf>,
    /// Sampling time `Ts` in seconds when the data files' frequency column is normalized
    /// (cycles/sample as `freq_hz`, rad/sample as `omega_rad_s`): frequencies are divided by
    /// `Ts` ([`crate::data::denormalize_frf`]).  Applies to the FRF, std and coherence files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_time: Option<f64>,
    /// The nominal factorization (or give `[physical]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelSection>,
    /// The model described by its physics (alternative to `[model]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub physical: Option<super::physical::PhysicalModel>,
    /// A plain plant whose normalized coprime factors are computed (alternative to `[model]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plant: Option<super::plant::PlantSection>,
    /// The SISO channel of the data to use.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<ChannelSection>,
    /// The bound `r(s)`.
    #[serde(default)]
    pub r: Option<RSection>,
    /// The noise model.
    #[serde(default)]
    pub noise: NoiseSection,
    /// The closed-loop uncertainty model (Crowder & de Callafon), instead of `[model]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closed_loop: Option<super::closed_loop::ClosedLoopSection>,
    /// The weight `V` of the closed-loop model (eq. (2)), the analogue of `[r]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v: Option<RSection>,
    /// Units scaling `G_s = D_o·G·D_i` of the model, the data and a controller
    /// (`[scaling] outputs = [..], inputs = [..]`, or `scaling = "auto"` for a `[plant]`;
    /// see [`crate::model::Scaling`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scaling: Option<super::scaling::ScalingSpec>,
}

impl RawConfig {
    /// The files a config at `path` makes a run read, itself first (see
    /// [`Config::files_read`]); from the text alone, without building the model (a large
    /// `[plant] file` takes minutes to factor).
    pub fn files_read(&self, path: &Path) -> Vec<PathBuf> {
        let base = path.parent().unwrap_or(Path::new("."));
        let mut files = vec![path.to_path_buf()];
        files.extend(self.data.as_ref().map(|d| base.join(d)));
        files.extend(self.noise.std_file.as_ref().map(|f| base.join(f)));
        files.extend(self.noise.coherence.as_ref().map(|c| base.join(c)));
        files.extend(
            self.plant
                .as_ref()
                .and_then(|p| p.file.as_ref())
                .map(|f| base.join(f)),
        );
        files
    }
}

/// A loaded, validated config.
///
/// ```toml
/// name = "paper MIMO example"
/// data = "paper_mimo.csv"            # relative to this file; --data overrides it
///
/// [model]
/// factorization = "standard"         # or "special"
/// m = [[{ num = [1, 2], den = [1, 1] }, { num = [1, 3], den = [1, 2] }],
///      [0,                              { num = [1, 1], den = [1, 2] }]]
/// n = [[{ num = [1], den = [1, 1] }, { num = [2], den = [1, 1] }, 0],
///      [0, { num = [1], den = [1, 3] }, { num = [2], den = [1, 2] }]]
///
/// [r]
/// num = [1e-8, 0.3]
/// den = [1, 1]
/// ```
///
/// Unknown keys are errors (a typo must not be silently ignored).
#[derive(Debug, Clone)]
pub struct Config {
    /// The file it came from.
    pub path: PathBuf,
    /// What was written.
    pub raw: RawConfig,
    /// The nominal factorization.
    pub factorization: Factorization,
    /// The configured bound `r`, if any.
    pub r: Option<TransferFunction>,
    /// The data file, resolved relative to the config.
    pub data: Option<PathBuf>,
    /// The physical description, when the model was given as `[physical]`.
    pub physical: Option<super::physical::PhysicalModel>,
    /// The noise std file (resolved) and its factor.
    pub noise_std: Option<(PathBuf, f64)>,
    /// The closed-loop model when the config has `[closed_loop]`; then `factorization` is
    /// its open-loop equivalent and `r` holds the weight `V` of `[v]`.
    pub closed_loop: Option<super::closed_loop::ClosedLoopModel>,
    /// The units scaling of `[scaling]`: `factorization` is then that of `D_o·G·D_i`, and
    /// the pipeline scales the data and a controller alike ([`crate::model::Scaling`]).
    pub scaling: Option<super::scaling::Scaling>,
}

fn tf_rows(
    rows: &[Vec<TfEntry>],
    name: &str,
) -> std::result::Result<Vec<Vec<TransferFunction>>, String> {
    let cols = rows.first().map_or(0, |r| r.len());
    if rows.is_empty() || cols == 0 {
        return Err(format!("[model] {name} is empty"));
    }
    rows.iter()
        .enumerate()
        .map(|(i, row)| {
            if row.len() != cols {
                return Err(format!(
                    "[model] {name}: row {} has {} entries, row 1 has {cols}",
                    i + 1,
                    row.len()
                ));
            }
            row.iter()
                .enumerate()
                .map(|(j, e)| e.to_tf(&format!("[model] {name}[{}][{}]", i + 1, j + 1)))
                .collect()
        })
        .collect()
}

impl Config {
    /// The sampling time of a normalized frequency axis (`sample_time`), if the config has
    /// one: the data files' frequencies are per sample and are divided by it.
    pub fn sample_time(&self) -> Option<f64> {
        self.raw.sample_time
    }

    /// Every file this config makes a run read besides itself: the data, the noise
    /// `std_file` or `coherence`, a `[plant] file` (resolved against the config's folder).
    /// The output checks compare every output path with these, so that no figure or
    /// revised config is written over an input.
    pub fn files_read(&self) -> Vec<PathBuf> {
        self.raw.files_read(&self.path)
    }
    /// Reads and validates a config file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::util::read_text_file(path)?;
        Self::parse(&text, path)
    }

    /// Parses config text; `path` is used for messages and to resolve the data file.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let err = |msg: String| Error::Config {
            path: path.to_path_buf(),
            msg,
        };
        let raw: RawConfig = toml::from_str(text).map_err(|e| {
            let msg = e.message().to_string();
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let msg = msg.replace('\n', " ");
            match line {
                Some(l) => err(format!("line {l}: {msg}")),
                None => err(msg),
            }
        })?;
        Self::from_raw(raw, path)
    }

    /// The same config without its `[scaling]`: the model, the data and the noise in the
    /// data file's own units (what `diagnose` works in: the `[physical]` model it revises is
    /// written in them).  Built again from what was written, so a `[plant]`'s normalized
    /// factors are those of `G`, not of `D_o·G·D_i`.
    pub fn without_scaling(&self) -> Result<Self> {
        let mut raw = self.raw.clone();
        raw.scaling = None;
        Self::from_raw(raw, &self.path)
    }

    /// [`Config::parse`] after the TOML: checks and builds the model of what was written.
    fn from_raw(raw: RawConfig, path: &Path) -> Result<Self> {
        let err = |msg: String| Error::Config {
            path: path.to_path_buf(),
            msg,
        };
        let closed_loop = super::closed_loop::from_raw(&raw).map_err(err)?;
        if raw.scaling.is_some() && closed_loop.is_some() {
            return Err(err(
                "[scaling] is for a [plant], a [model] or a [physical] model, not a [closed_loop] model: remove [scaling] (a [closed_loop] model is in the units of its data)".into(),
            ));
        }
        let mut scaling = None;
        let plant_factorization = match &raw.plant {
            Some(_) if raw.model.is_some() || raw.physical.is_some() || closed_loop.is_some() => {
                return Err(err(
                    "give the model as one of [model], [physical], [plant] or [closed_loop], not several".into(),
                ))
            }
            Some(pl) => {
                let (f, used) = pl
                    .to_scaled_factorization(
                        path.parent().unwrap_or(Path::new(".")),
                        raw.scaling.as_ref(),
                    )
                    .map_err(err)?;
                scaling = used;
                Some(f)
            }
            None => None,
        };
        let (factorization, physical) = match (&raw.model, &raw.physical) {
            _ if plant_factorization.is_some() => (plant_factorization.expect("checked"), None),
            (None, None) if closed_loop.is_some() => (
                closed_loop
                    .as_ref()
                    .map(|c| c.open_loop_factorization())
                    .expect("checked")
                    .map_err(err)?,
                None,
            ),
            (Some(m), None) => {
                let f = Self::build_factorization(m).map_err(err)?;
                match &raw.scaling {
                    Some(spec) => {
                        let s = spec.resolve(f.outputs(), f.inputs(), None).map_err(err)?;
                        let scaled = s.factorization(&f).map_err(err)?;
                        scaling = Some(s);
                        (scaled, None)
                    }
                    None => (f, None),
                }
            }
            (None, Some(ph)) => {
                ph.validate().map_err(err)?;
                let f = ph.to_factorization().map_err(err)?;
                // The model stays in the data's units (diagnose and compare evaluate it
                // there); its special factorization takes the scaling in C and J, which
                // leaves the modal factors, hence the Theorem 3/4 envelope, unchanged.
                let f = match &raw.scaling {
                    Some(spec) => {
                        let s = spec.resolve(f.outputs(), f.inputs(), None).map_err(err)?;
                        let scaled = s.factorization(&f).map_err(err)?;
                        scaling = Some(s);
                        scaled
                    }
                    None => f,
                };
                (f, Some(ph.clone()))
            }
            (Some(_), Some(_)) => {
                return Err(err(
                    "give the model either as [model] (factors) or as [physical], not both".into(),
                ))
            }
            (None, None) => return Err(err(
                "no model: add a [model] table (factors), a [physical] table or a [plant] table"
                    .into(),
            )),
        };
        if let Some(ch) = &raw.channel {
            if ch.output == 0 || ch.input == 0 {
                return Err(err("[channel] output and input are 1-based".into()));
            }
        }
        let r = match if closed_loop.is_some() {
            &raw.v
        } else {
            &raw.r
        } {
            Some(r) => {
                let tf = TfEntry::Rational(RationalEntry {
                    num: r.num.clone(),
                    den: r.den.clone(),
                })
                .to_tf(if closed_loop.is_some() { "[v]" } else { "[r]" })
                .map_err(err)?;
                Some(tf)
            }
            None => None,
        };
        raw.noise.validate().map_err(err)?;
        if let Some(ts) = raw.sample_time {
            crate::data::check_sample_time(ts).map_err(err)?;
        }
        let base = path.parent().unwrap_or(Path::new("."));
        let data = raw.data.as_ref().map(|d| base.join(d));
        let noise_std = match (&raw.noise.std_file, raw.noise.std_factor) {
            (Some(f), k) => {
                let k = k.unwrap_or(3.0);
                if !(k.is_finite() && k > 0.0) {
                    return Err(err(format!("[noise] std_factor = {k}: must be positive")));
                }
                if raw.noise.radius.is_some() {
                    return Err(err("[noise]: give radius or std_file, not both".into()));
                }
                Some((base.join(f), k))
            }
            (None, Some(_)) => {
                return Err(err("[noise] std_factor needs std_file".into()));
            }
            (None, None) => None,
        };
        Ok(Self {
            path: path.to_path_buf(),
            raw,
            factorization,
            r,
            data,
            physical,
            noise_std,
            closed_loop,
            scaling,
        })
    }

    fn build_factorization(m: &ModelSection) -> std::result::Result<Factorization, String> {
        use super::FactorizationKind::*;
        let mm = match (&m.m, &m.m_diag) {
            (Some(rows), None) => crate::system::TfMatrix::from_rows(tf_rows(rows, "m")?)
                .ok_or("[model] m is not a rectangular matrix")?,
            (None, Some(diag)) => crate::system::TfMatrix::diagonal(
                diag.iter()
                    .enumerate()
                    .map(|(i, e)| e.to_tf(&format!("[model] m_diag[{}]", i + 1)))
                    .collect::<std::result::Result<_, _>>()?,
            ),
            (Some(_), Some(_)) => return Err("[model]: give either m or m_diag, not both".into()),
            (None, None) => return Err("[model]: m (or m_diag) is missing".into()),
        };
        let nn = crate::system::TfMatrix::from_rows(tf_rows(&m.n, "n")?)
            .ok_or("[model] n is not a rectangular matrix")?;
        if mm.rows() == mm.cols() && nn.rows() == mm.rows() {
            // Stable entries and left coprimeness (the theory's premises); sizes are
            // reported by the constructors below.
            let mk = if m.m_diag.is_some() { "m_diag" } else { "m" };
            super::coprime::check_left_coprime(&mm, &nn, "[model]", (mk, "n"))?;
        }
        match m.factorization {
            Standard => {
                if m.c.is_some() || m.j.is_some() {
                    return Err("[model]: c and j belong to factorization = \"special\"".into());
                }
                Factorization::standard(mm, nn).map_err(|e| format!("[model]: {e}"))
            }
            Special => {
                let c_rows =
                    m.c.as_ref()
                        .ok_or("[model]: factorization = \"special\" needs c (p×n numbers)")?;
                let cols = c_rows.first().map_or(0, |r| r.len());
                if cols == 0 || c_rows.iter().any(|r| r.len() != cols) {
                    return Err("[model] c must be a non-empty rectangular matrix".into());
                }
                if c_rows.iter().flatten().any(|x| !x.is_finite()) {
                    return Err("[model] c has a non-finite entry".into());
                }
                let c = DMatrix::from_fn(c_rows.len(), cols, |i, j| c_rows[i][j]);
                let j = match &m.j {
                    Some(j) => j
                        .iter()
                        .enumerate()
                        .map(|(i, e)| e.to_tf(&format!("[model] j[{}]", i + 1)))
                        .collect::<std::result::Result<_, _>>()?,
                    None => vec![TransferFunction::gain(1.0); nn.cols()],
                };
                let jm = crate::system::TfMatrix::diagonal(j.clone());
                super::coprime::check_stable(&jm, &|i, _| format!("[model] j[{}]", i + 1), "J")?;
                Factorization::special(c, mm, nn, j).map_err(|e| format!("[model]: {e}"))
            }
        }
    }
}

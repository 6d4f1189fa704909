//! `compare`: per-frequency misfit between data and model, failing bands, error measures.
//!
//! * misfit `c_k = |G_d − G_m|/r_k` with `r_k` the noise radius; a datum is **invalid** when
//!   `c_k > 1` (the noise disk around the model does not reach it);
//! * `misfit_rms = sqrt(mean c_k²)`, `invalid_fraction` = share of invalid data;
//! * without a noise radius the misfit is relative, `|G_d − G_m|/|G_d|`, and
//!   `invalid_fraction` is not defined;
//! * envelope `r_min` per datum, on the model's rational factorization (a physical model's
//!   Padé export), SISO models only:
//!   - **with a noise radius**: the noisy envelope of Theorem 4 (`noisy_envelope`, μ test):
//!     the smallest `|r(jω)|` that explains the datum together with the noise disk; 0 inside
//!     the noise of the nominal model, `inf` when no `|r|` below the A1 limit `σ_min(M̃)`
//!     explains it;
//!   - **without** (or when the noisy test cannot be computed, e.g. A7 at a datum; the reason
//!     is in `r_env_method`): the noise-free envelope (Theorem 2 or 3);
//! * `r_env_max` = the largest **finite** `r_min`; `n_unexplainable` = the number of data
//!   with `r_min = inf` (not counted in `r_env_max`);
//! * "fails with r" (`invalid_with_r`, `bands_with_r`): with the Theorem 4 envelope a datum
//!   fails iff `|r(jω)| ≤ r_min` (exact joint test of noise and the configured `r`; a datum
//!   with `r_min = 0` never fails). With the noise-free fallback the test is conservative:
//!   a datum fails when neither the noise disk alone (`c_k > 1`) nor `r` alone
//!   (`r_min > |r(jω)|`) explains it. `with_r_exact` says which test was used.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use crate::consistency::{noise_free_envelope, noisy_envelope, BisectionSettings};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::noise::resolve_noise_for_channel;
use crate::model::physical::PhysicalModel;
use crate::model::{Config, Factorization, Scaling};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::path::PathBuf;

mod report;

pub use report::{bands, Band, CompareReport, CompareRow, CompareVerdict};

/// A model that can be evaluated at `jω`.
#[derive(Debug, Clone)]
pub enum PlantModel {
    /// Physical description, evaluated exactly.
    Physical(PhysicalModel),
    /// A physical description (in the data file's units) seen in the units of its config's
    /// `[scaling]`: `D_o·G·D_i`, evaluated exactly.
    ScaledPhysical(PhysicalModel, Scaling),
    /// Coprime factors.
    Factored(Factorization),
}

impl PlantModel {
    /// From a config: the physical description when there is one, in the units of the
    /// config's data (scaled by its `[scaling]`, as the pipeline scales the data).
    pub fn from_config(c: &Config) -> Self {
        match (&c.physical, &c.scaling) {
            (Some(p), None) => PlantModel::Physical(p.clone()),
            (Some(p), Some(s)) => PlantModel::ScaledPhysical(p.clone(), s.clone()),
            (None, _) => PlantModel::Factored(c.factorization.clone()),
        }
    }

    /// `G(jω)`, `None` where the factors are singular.
    pub fn eval(&self, omega: f64) -> Option<DMatrix<Complex64>> {
        match self {
            PlantModel::Physical(p) => Some(p.eval(omega)),
            PlantModel::ScaledPhysical(p, s) => {
                let g = p.eval(omega);
                Some(DMatrix::from_fn(g.nrows(), g.ncols(), |i, j| {
                    g[(i, j)] * s.entry_factor((i, j))
                }))
            }
            PlantModel::Factored(f) => f.plant(omega),
        }
    }

    /// `(outputs, inputs)`.
    pub fn size(&self) -> (usize, usize) {
        match self {
            PlantModel::Physical(p) | PlantModel::ScaledPhysical(p, _) => {
                (p.n_outputs(), p.n_inputs())
            }
            PlantModel::Factored(f) => (f.outputs(), f.inputs()),
        }
    }

    /// The rational factorization the envelope is computed on: a physical model's Padé
    /// export (scaled in `C` and `J` for [`PlantModel::ScaledPhysical`], as the config's own
    /// factorization), or the factors.
    pub fn factorization(&self) -> std::result::Result<Factorization, String> {
        match self {
            PlantModel::Physical(p) => p.to_factorization(),
            PlantModel::ScaledPhysical(p, s) => s.factorization(&p.to_factorization()?),
            PlantModel::Factored(f) => Ok(f.clone()),
        }
    }
}

/// A SISO data set with its noise radii, ready to compare.
#[derive(Debug, Clone)]
pub struct Siso {
    /// The data file.
    pub path: PathBuf,
    /// Frequencies, rad/s.
    pub omega: Vec<f64>,
    /// Measured response.
    pub g: Vec<Complex64>,
    /// Noise radius per datum, when known.
    pub radius: Option<Vec<f64>>,
    /// Where the radius came from.
    pub radius_source: String,
    /// Selected (output, input), 1-based.
    pub channel: (usize, usize),
    /// Model entry used (0-based).
    pub model_entry: (usize, usize),
}

impl Siso {
    /// The model at every datum; an error names the frequency where it cannot be evaluated.
    pub fn model_response(&self, model: &PlantModel) -> Result<Vec<Complex64>> {
        self.omega
            .iter()
            .map(|w| {
                model
                    .eval(*w)
                    .map(|g| g[self.model_entry])
                    .filter(|v| v.is_finite())
                    .ok_or(Error::Assumption {
                        omega: *w,
                        msg: "the model cannot be evaluated (singular M̃ or a pole on the axis)"
                            .into(),
                    })
            })
            .collect()
    }

    /// The data as a 1×1 FRF set.
    pub fn as_frf(&self) -> FrfData {
        FrfData {
            path: self.path.clone(),
            omega: self.omega.clone(),
            response: self
                .g
                .iter()
                .map(|v| DMatrix::from_element(1, 1, *v))
                .collect(),
            noise_radius: self.radius.clone(),
            lines: vec![0; self.omega.len()],
        }
    }
}

/// Selects the SISO channel and resolves the noise radius with the precedence of
/// [`crate::model::noise::resolve_noise`]: `--noise-radius`, else the config's `[noise]`
/// (radius, output bound, std file), else the data's `noise_radius` column.
pub fn prepare(
    config: &Config,
    data: &FrfData,
    channel: Option<(usize, usize)>,
    noise_override: Option<f64>,
) -> Result<Siso> {
    let model = PlantModel::from_config(config);
    let (mp, mm) = model.size();
    let chan = channel
        .or(config.raw.channel.map(|c| (c.output, c.input)))
        .unwrap_or((1, 1));
    let (out, inp) = chan;
    if out == 0 || inp == 0 || out > data.outputs() || inp > data.inputs() {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "channel ({out},{inp}) is not in the data ({}×{} outputs×inputs)",
                data.outputs(),
                data.inputs(),
            ),
        });
    }
    let model_entry = if mp == 1 && mm == 1 {
        (0, 0)
    } else if mp == data.outputs() && mm == data.inputs() {
        (out - 1, inp - 1)
    } else {
        return Err(Error::Input {
            path: config.path.to_path_buf(),
            msg: format!(
                "the model is {mp}×{mm} but the data are {}×{}; give a SISO model or one of the data's size",
                data.outputs(),
                data.inputs(),
            ),
        });
    };
    if channel.is_none()
        && config.raw.channel.is_none()
        && (data.outputs() > 1 || data.inputs() > 1)
    {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "the data are {}×{}: choose the SISO channel to compare with [channel] output/input or --channel OUT,IN",
                data.outputs(),
                data.inputs(),
            ),
        });
    }
    let ch = data.channel(out - 1, inp - 1);
    let resolved = resolve_noise_for_channel(noise_override, Some(config), data, chan)?;
    let radius_source = resolved.as_ref().map_or_else(
        || "none (misfit relative to |G_d|)".to_string(),
        |r| r.description.clone(),
    );
    let radius = resolved.map(|r| r.radii);
    if let Some(r) = &radius {
        if let Some(k) = r.iter().position(|x| x.is_nan() || *x <= 0.0) {
            return Err(Error::Input {
                path: data.path.to_path_buf(),
                msg: format!(
                    "noise radius {} at omega = {} rad/s must be positive",
                    r[k], ch.omega[k],
                ),
            });
        }
    }
    Ok(Siso {
        path: data.path.clone(),
        omega: ch.omega.clone(),
        g: ch.response.iter().map(|m| m[(0, 0)]).collect(),
        radius,
        radius_source,
        channel: chan,
        model_entry,
    })
}

/// Data explained within the noise: at most this share invalid…
pub const MAX_INVALID_FRACTION: f64 = 0.05;
/// …and an rms misfit at most this.
pub const MAX_MISFIT_RMS: f64 = 1.0;

/// Misfit measures only (no envelope): `(misfit per datum, rms, max, invalid fraction)`.
pub fn misfit(siso: &Siso, gm: &[Complex64]) -> (Vec<f64>, f64, f64, Option<f64>) {
    let c: Vec<f64> = siso
        .g
        .iter()
        .zip(gm)
        .enumerate()
        .map(|(k, (d, m))| {
            let e = (d - m).norm();
            match &siso.radius {
                Some(r) => e / r[k],
                None => e / d.norm().max(f64::MIN_POSITIVE),
            }
        })
        .collect();
    let n = c.len().max(1) as f64;
    let rms = (c.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    let max = c.iter().cloned().fold(0.0, f64::max);
    let inv = siso
        .radius
        .as_ref()
        .map(|_| c.iter().filter(|x| **x > 1.0).count() as f64 / n);
    (c, rms, max, inv)
}

/// Compares a model with SISO data.
pub fn compare(config: &Config, model: &PlantModel, siso: &Siso) -> Result<CompareReport> {
    let gm = siso.model_response(model)?;
    let (c, rms, max, inv) = misfit(siso, &gm);
    let invalid: Vec<bool> = c
        .iter()
        .map(|x| siso.radius.is_some() && *x > 1.0)
        .collect();
    // Envelope on the rational factorization of the model: Theorem 4 (noisy) when the
    // noise radius is known, else (or when the μ test cannot run) noise-free.
    let mut exact = false;
    let (r_min, r_env_method) = if model.size() == (1, 1) {
        let f = model.factorization().map_err(Error::Invalid);
        let source = match model {
            PlantModel::Physical(_) => "Padé export of the physical model",
            PlantModel::ScaledPhysical(..) => {
                "Padé export of the physical model, [scaling] in C and J"
            }
            PlantModel::Factored(_) => "configured factors",
        };
        match f {
            Err(e) => (None, format!("not computed: {e}")),
            Ok(f) => {
                let frf = siso.as_frf();
                let noisy = siso.radius.as_ref().map(|rad| {
                    noisy_envelope(
                        &f,
                        &frf,
                        rad,
                        &BisectionSettings::default(),
                        &Default::default(),
                    )
                });
                match noisy {
                    Some(Ok(e)) => {
                        exact = true;
                        (
                            Some(e.r_min),
                            format!("noisy envelope, Theorem 4 (μ test with the noise radius; {source})"),
                        )
                    }
                    other => {
                        let why = match other {
                            Some(Err(e)) => format!("; the noisy test (Theorem 4) failed: {e}"),
                            _ => String::new(),
                        };
                        match noise_free_envelope(&f, &frf) {
                            Ok(e) => (
                                Some(e.r_min),
                                format!(
                                    "noise-free envelope, {} ({source}), noise not subtracted{why}",
                                    match f.kind {
                                        crate::model::FactorizationKind::Standard => "Theorem 2",
                                        crate::model::FactorizationKind::Special => "Theorem 3",
                                    },
                                ),
                            ),
                            Err(e) => (None, format!("not computed: {e}{why}")),
                        }
                    }
                }
            }
        }
    } else {
        (
            None,
            "not computed: a SISO channel of a MIMO model (the envelope needs the whole matrix)"
                .into(),
        )
    };
    let r_abs: Option<Vec<f64>> = config
        .r
        .as_ref()
        .map(|r| siso.omega.iter().map(|w| r.freq(*w).norm()).collect());
    let with_r: Option<Vec<bool>> = match (&r_min, &r_abs) {
        (Some(rm), Some(ra)) => Some(
            (0..c.len())
                .map(|k| {
                    if exact {
                        // Theorem 4: consistent iff μ(|r|) > 1, i.e. |r| > r_min (and
                        // always when r_min = 0: the noise alone explains the datum).
                        rm[k] > 0.0 && ra[k] <= rm[k]
                    } else {
                        (siso.radius.is_none() || invalid[k]) && rm[k] > ra[k]
                    }
                })
                .collect(),
        ),
        _ => None,
    };
    let n = c.len().max(1) as f64;
    let rows = (0..c.len())
        .map(|k| CompareRow {
            omega: siso.omega[k],
            data: [siso.g[k].re, siso.g[k].im],
            model: [gm[k].re, gm[k].im],
            misfit: c[k],
            noise_radius: siso.radius.as_ref().map(|r| r[k]),
            r_min: r_min.as_ref().map(|r| r[k]),
            invalid: invalid[k],
            invalid_with_r: with_r.as_ref().map(|w| w[k]),
        })
        .collect();
    let consistent = inv.is_some_and(|f| f <= MAX_INVALID_FRACTION) && rms <= MAX_MISFIT_RMS;
    Ok(CompareReport {
        config: config.path.display().to_string(),
        data: siso.path.display().to_string(),
        channel: [siso.channel.0, siso.channel.1],
        noise_source: siso.radius_source.clone(),
        normalized: siso.radius.is_some(),
        misfit_rms: rms,
        misfit_max: max,
        invalid_fraction: inv,
        invalid_fraction_with_r: with_r
            .as_ref()
            .map(|w| w.iter().filter(|x| **x).count() as f64 / n),
        r_env_max: r_min.as_ref().map(|r| {
            r.iter()
                .cloned()
                .filter(|x| x.is_finite())
                .fold(0.0, f64::max)
        }),
        n_unexplainable: r_min
            .as_ref()
            .map(|r| r.iter().filter(|x| x.is_infinite()).count()),
        with_r_exact: exact && with_r.is_some(),
        r_env_method,
        bands: bands(&siso.omega, &c, &invalid),
        bands_with_r: with_r.as_ref().map(|w| bands(&siso.omega, &c, w)),
        verdict: if siso.radius.is_none() {
            CompareVerdict::UnknownNoise
        } else if consistent {
            CompareVerdict::Consistent
        } else {
            CompareVerdict::Inconsistent
        },
        rows,
        figure: None,
    })
}

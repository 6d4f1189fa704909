//! The points where the pipeline meets the noise model and the μ test (Theorem 4,
//! [`crate::model::resolve_noise`], [`crate::consistency::noisy_envelope`], [`crate::mu`]) and the fit of `r`
//! ([`crate::fit`], [`crate::report::write_fit_exports`]).  Everything that depends on those modules
//! goes through the functions here.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use crate::consistency::noisy::{
    gamma_lft, noisy_envelope, BisectionSettings, DatumProgressFn, EnvelopeOptions,
};
use crate::consistency::{noise_free_envelope, Envelope};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::fit::{
    fit_auto, fit_unit, FitOptions, FitResult, FitSettings, OrderChoice, OrderRow, ProgressFn,
};
use crate::model::{Config, Factorization};
use crate::mu::{mu_full_scalar, FullPlusScalar, MuSettings};
use crate::system::TransferFunction;
use serde_json::Value;

/// Per-datum noise radii with the precedence of [`crate::model::noise::resolve_noise`]:
/// `--noise-radius` (or a manifest's per-dataset radius) > the config's `[noise]` > the data
/// file's `noise_radius` column.  `None` (noise-free) when none is given or all are zero.
/// (The raw radii, zeros kept, are [`crate::model::noise::noise_radii`].)
pub(super) fn noise_radii(
    config: &Config,
    data: &FrfData,
    cli: Option<f64>,
) -> Result<Option<Vec<f64>>> {
    // With [scaling] the data are scaled and the radii come back scaled like them
    // (resolve_noise_for_channel, the one place noise meets the units).
    let radii = crate::model::noise::noise_radii(cli, Some(config), data)?;
    Ok(radii.filter(|r| r.iter().any(|x| *x > 0.0)))
}

/// The envelope of the data: noise-free (Theorem 2 / Theorem 3) when `radii` is `None`,
/// noisy SISO (Theorem 4, bisection on `|r|` of the μ test) otherwise.  Returns the
/// envelope and any warning worth showing.
/// `progress` hears of the data done by the noisy envelope (the noise-free one is closed form).
/// Callers go through [`super::envelope::envelope`].
pub(super) fn open_loop_envelope(
    f: &Factorization,
    data: &FrfData,
    radii: Option<&[f64]>,
    progress: Option<DatumProgressFn<'_>>,
) -> Result<(Envelope, Vec<String>)> {
    match radii {
        None => Ok((noise_free_envelope(f, data)?, Vec::new())),
        Some(r) => {
            let env = noisy_envelope(
                f,
                data,
                r,
                &BisectionSettings::default(),
                &EnvelopeOptions { progress },
            )?;
            let inf = env.r_min.iter().filter(|x| x.is_infinite()).count();
            let w = if inf > 0 {
                vec![format!("{inf} datum(s) have r_min = ∞: no r explains them with this noise level and model")]
            } else {
                Vec::new()
            };
            Ok((env, w))
        }
    }
}

/// `μ_Γ{F_L[V(jω_i), φ_i⁻¹]}` per datum for the configured `r` (Theorem 4, Fig. 8), for
/// noisy SISO data; a datum is consistent iff its `μ_Γ > 1`.  `None` for MIMO data.
pub fn mu_per_datum(
    f: &Factorization,
    data: &FrfData,
    radii: &[f64],
    r: &TransferFunction,
) -> Option<Result<Vec<f64>>> {
    if data.outputs() != 1 || data.inputs() != 1 {
        return None;
    }
    let settings = MuSettings::default();
    let out = data
        .omega
        .iter()
        .zip(&data.response)
        .zip(radii)
        .map(|((w, phi), la)| {
            let at = f.at(*w);
            let m =
                gamma_lft(&at, phi[(0, 0)], r.freq(*w), *la).map_err(|e| Error::Assumption {
                    omega: *w,
                    msg: e.message().to_string(),
                })?;
            Ok(mu_full_scalar(&m, FullPlusScalar::gamma(at.m.nrows()), &settings)?.upper)
        })
        .collect();
    Some(out)
}

/// Why the pipeline's fit of `r` failed, for a caller to match on ([`RunOutcome::fit`](super::RunOutcome::fit),
/// `rshape batch`'s combined fit).
#[derive(Debug, Clone, thiserror::Error)]
pub enum FitFailure {
    /// The fit itself failed: inadmissible data, A1 against coverage, no feasible or no
    /// certified `r` (see [`crate::fit::FitError`]).
    #[error("fit: {0}")]
    Fit(#[from] crate::fit::FitError),
    /// The fit failed and the envelope shows why: A1 leaves `r` no or little room between two
    /// data ([`super::a1_conflict`]); the message says where, the fit's error, what to do.
    #[error("{message}")]
    A1Conflict {
        /// The fit's own error.
        fit: crate::fit::FitError,
        /// Where A1 and the envelope conflict, the fit's error, and what to change
        /// ([`super::a1_conflict::explain`]).
        message: String,
    },
    /// The fitted `r` could not be written as `r.json` (rshape's own document: a bug).
    #[error("r.json: {0}")]
    Json(String),
}

/// A fitted unit `r` with its certificate, ready to be written as `r.json`.
#[derive(Debug, Clone)]
pub struct FittedR {
    /// The fitted unit.
    pub r: TransferFunction,
    /// The `r.json` document (coefficients, poles, zeros, gain, certificate, order table).
    pub json: Value,
    /// The certificate (as in `r.json`).
    pub certificate: Value,
    /// The fit.
    pub result: FitResult,
    /// The order table of the automatic order choice.
    pub table: Option<Vec<OrderRow>>,
}

/// The A1 limit a fit imposes (Theorem 1's assumption A1, `|r(jω)| < σ_min(M̃(jω))`): the
/// factorization whose `σ_min(M̃)` bounds `r`, that bound as the fit's [`crate::fit::A1Fn`],
/// and the settings the certificate needs to prove it ([`FitSettings::with_a1_model`]).
/// `None` imposes no limit (closed-loop data: the model of Crowder & de Callafon's eq. (2)
/// has none).  Every fit of a config (`run`, `fit`, `stability --fit`, `synthesize --fit`)
/// takes its A1 from here.
pub struct A1Model<'a> {
    factorization: Option<&'a Factorization>,
    limit: Option<Box<dyn Fn(f64) -> f64 + 'a>>,
}

impl<'a> A1Model<'a> {
    /// The limit of `f` (none when `f` is `None`).
    pub fn new(f: Option<&'a Factorization>) -> Self {
        Self {
            factorization: f,
            limit: f.map(|f| Box::new(move |w: f64| f.a1_limit(w)) as Box<dyn Fn(f64) -> f64>),
        }
    }

    /// The limit a config's fit imposes: its factorization for open-loop data, none for
    /// closed-loop data ([`super::closed_loop::a1_factorization`]).
    pub fn of_config(config: &'a Config) -> Self {
        Self::new(super::closed_loop::a1_factorization(config))
    }

    /// The factorization, if a limit is imposed.
    pub fn factorization(&self) -> Option<&'a Factorization> {
        self.factorization
    }

    /// `ω ↦ σ_min(M̃(jω))`, if a limit is imposed.
    pub fn limit(&self) -> Option<crate::fit::A1Fn<'_>> {
        self.limit.as_deref().map(|g| g as crate::fit::A1Fn<'_>)
    }

    /// `base` with what the certificate needs to prove the limit (unchanged without one).
    pub fn settings(&self, base: FitSettings) -> FitSettings {
        match self.factorization {
            Some(f) => base.with_a1_model(f),
            None => base,
        }
    }
}

/// Fits the smallest unit `r` above the envelope with the defaults of `rshape fit`
/// (minimax objective; `order` fixed or chosen automatically), keeping `|r| < σ_min(M̃)`
/// (A1) when the factorization `a1_model` is given (the certificate proves A1 against it).
///
/// `progress` hears of each order as it starts (see [`crate::fit::FitProgress`]).
pub fn fit_r(
    env: &Envelope,
    a1_model: Option<&crate::model::Factorization>,
    order: OrderChoice,
    progress: Option<ProgressFn<'_>>,
) -> std::result::Result<FittedR, FitFailure> {
    let model = A1Model::new(a1_model);
    let a1 = model.limit();
    let base = model.settings(FitSettings::default());
    let (result, table) = match order {
        OrderChoice::Auto { max } => {
            let (r, t) = fit_auto(env, a1, &base, max, &FitOptions { progress })
                .map_err(|e| explain(e, env, a1_model))?;
            (r, Some(t))
        }
        OrderChoice::Fixed(n) => {
            let s = FitSettings { order: n, ..base };
            let r = fit_unit(env, a1, &s, &FitOptions { progress })
                .map_err(|e| explain(e, env, a1_model))?;
            (r, None)
        }
    };
    let text = crate::report::export::r_json(&result, table.as_deref(), None);
    let json: Value = serde_json::from_str(&text).map_err(|e| FitFailure::Json(e.to_string()))?;
    let certificate = json
        .get("certificate")
        .cloned()
        .unwrap_or_else(|| serde_json::to_value(&result.certificate).unwrap_or(Value::Null));
    Ok(FittedR {
        r: result.r.clone(),
        json,
        certificate,
        result,
        table,
    })
}

/// A fit failure with the reason no order can succeed, when the envelope shows one
/// ([`super::a1_conflict`]).
pub fn explain(
    fit: crate::fit::FitError,
    env: &Envelope,
    a1_model: Option<&crate::model::Factorization>,
) -> FitFailure {
    let gaps = a1_model.map(|f| super::a1_conflict::a1_conflicts(env, f));
    match gaps.and_then(|g| super::a1_conflict::explain(&fit, &g)) {
        Some(message) => FitFailure::A1Conflict { fit, message },
        None => FitFailure::Fit(fit),
    }
}

/// Writes the exports of `rshape fit`'s outcome (`r.json`, `r.m`, `r.py`, `r.jl`) into `dir`
/// and returns the files written: the fit ([`crate::fit::run_fit`]) computes, the pipeline
/// writes.  With a config's `[scaling]`, `r.json` carries its `scaling` entry
/// ([`crate::report::ScalingNote`]) and the others a first comment line saying so.
pub fn write_fit_exports(
    outcome: &crate::fit::FitOutcome,
    dir: &std::path::Path,
    scaling: Option<&crate::model::Scaling>,
) -> Result<Vec<std::path::PathBuf>> {
    exports(&outcome.result, outcome.table.as_deref(), dir, scaling)
}

/// Writes `r.json`, `r.m`, `r.py`, `r.jl` into `dir` (noting the config's `[scaling]` as
/// [`write_fit_exports`] does) and returns the files written.
pub fn export_r(
    fit: &FittedR,
    dir: &std::path::Path,
    scaling: Option<&crate::model::Scaling>,
) -> Result<Vec<std::path::PathBuf>> {
    exports(&fit.result, fit.table.as_deref(), dir, scaling)
}

/// The exports of a fit with the config's scaling noted ([`write_fit_exports`], [`export_r`]).
fn exports(
    result: &crate::fit::FitResult,
    table: Option<&[crate::fit::OrderRow]>,
    dir: &std::path::Path,
    scaling: Option<&crate::model::Scaling>,
) -> Result<Vec<std::path::PathBuf>> {
    let note = crate::report::ScalingNote::of_opt(scaling);
    crate::report::write_fit_exports(result, table, dir, note.as_ref())
}

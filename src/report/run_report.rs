//! `report.json` of `rshape run`: the verdict of the check of the configured `r`, the
//! per-datum envelope, the fitted `r` (as in `r.json`) with its certificate, and the time
//! per stage.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use crate::data::FrfData;
use crate::model::Config;
use crate::pipeline::RunOutcome;
use serde::Serialize;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One datum of `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ReportDatum {
    /// Frequency (rad/s).
    pub omega: f64,
    /// Smallest consistent `|r|` at this datum (`null` when infinite).
    pub r_min: Option<f64>,
    /// `σ_min(M̃(jω))`, the A1 limit.
    pub a1_limit: Option<f64>,
    /// Noise radius at this datum (noisy data).
    pub noise_radius: Option<f64>,
    /// `|r(jω)|` of the configured `r`.
    pub r_configured_abs: Option<f64>,
    /// True when the configured `r` explains the datum and A1 holds there.
    pub consistent: Option<bool>,
    /// True when A1 holds for the configured `r` at this datum (`|r| < σ_min(M̃)`).
    pub a1_ok: Option<bool>,
    /// `μ_Γ` for the configured `r` (noisy data, when computed).
    pub mu: Option<f64>,
}

/// The configured `r` as coefficients.
#[derive(Debug, Clone, Serialize)]
pub struct Coeffs {
    /// Numerator, descending powers of `s`.
    pub num: Vec<f64>,
    /// Denominator, descending powers of `s`.
    pub den: Vec<f64>,
}

/// The whole `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct RunReport {
    /// Version of rshape that wrote the report.
    pub rshape_version: String,
    /// Name of the model (config `name`).
    pub name: Option<String>,
    /// The config file.
    pub config: PathBuf,
    /// The data file.
    pub data: PathBuf,
    /// The config's `sample_time` (s), when its data are on a normalized axis (per sample):
    /// their frequencies were divided by it, so every frequency here is in rad/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_time: Option<f64>,
    /// The config's `[scaling]`: every `r`, `r_min` and datum here is that of the scaled
    /// plant `D_o·G·D_i`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scaling: Option<super::ScalingNote>,
    /// Number of data.
    pub n_data: usize,
    /// Outputs × inputs of the data.
    pub size: [usize; 2],
    /// How the envelope was computed (`theorem2`, `theorem3`, `theorem4_mu`).
    pub method: crate::consistency::EnvelopeMethod,
    /// True when noise radii were given.
    pub noisy: bool,
    /// Verdict on the configured `r`: `consistent`, `inconsistent` or `not_admissible` (A1
    /// fails at some datum, so the theorems give no verdict); `null` without a configured `r`.
    pub verdict: Option<crate::consistency::Verdict>,
    /// True when the verdict is `consistent` (`null` without a configured `r`).
    pub consistent: Option<bool>,
    /// Frequencies (rad/s) of the data where `|r| ≤ r_min` for the configured `r`.
    pub failing_omegas: Vec<f64>,
    /// Frequencies (rad/s) where the configured `r` violates A1.
    pub a1_violations: Vec<f64>,
    /// Frequencies (rad/s) where `r_min` reaches the A1 limit: no admissible `r` explains them.
    pub beyond_a1: Vec<f64>,
    /// Largest finite `r_min`.
    pub max_r_min: Option<f64>,
    /// The configured `r`.
    pub r_configured: Option<Coeffs>,
    /// The fitted `r`, as in `r.json` (`null` when the fit failed).
    pub r_fitted: Option<Value>,
    /// The certificate of the fitted `r`.
    pub certificate: Option<Value>,
    /// Why the fit failed.
    pub fit_error: Option<String>,
    /// Per-datum values.
    pub data_points: Vec<ReportDatum>,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Files written, relative to the output directory.
    pub files: Vec<String>,
    /// Milliseconds per stage, and their sum under `total`.
    pub timings_ms: BTreeMap<String, f64>,
    /// Closed-loop fields (configs with `[closed_loop]`): there `r_min` is the smallest
    /// `|V|` per datum and `r_configured`/`r_fitted` are the weight `V`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_loop: Option<ClosedLoopFields>,
}

/// The closed-loop part of `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ClosedLoopFields {
    /// True when the experiment used the model's controller (`C̄ = C`, `M₁₁ = 0`).
    pub same_controller: bool,
    /// True when the nominal's factors are the trivial `(P̂, I)`.
    pub trivial_plant_factors: bool,
    /// True when the controller's factors are the trivial `(C, I)`.
    pub trivial_controller_factors: bool,
    /// Frequencies (rad/s) of data the experiment's loop makes uninformative.
    pub uninformative_omegas: Vec<f64>,
    /// Per datum: `σ̄(Δ̄)` at the measured `Φ`, the experiment's sensitivity, the flag and,
    /// for noisy data, the Theorem 2 result (`v_min`, route, μ at `|V| = 0`).
    pub data: Vec<crate::consistency::closed_loop::ClosedLoopDatum>,
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

impl RunReport {
    /// Assembles the report of a run.
    pub fn new(config: &Config, data: &FrfData, out: &RunOutcome, files: &[PathBuf]) -> Self {
        let env = &out.envelope;
        let data_points = (0..env.len())
            .map(|i| {
                let row = out.check.as_ref().map(|c| &c.rows[i]);
                ReportDatum {
                    omega: env.omega[i],
                    r_min: finite(env.r_min[i]),
                    a1_limit: env.a1_limit.as_ref().map(|a| a[i]),
                    noise_radius: out.noise_radii.as_ref().map(|r| r[i]),
                    r_configured_abs: row.map(|r| r.r_abs),
                    consistent: row.map(|r| r.consistent),
                    a1_ok: row.map(|r| r.a1_ok),
                    mu: out.mu.as_ref().map(|m| m[i]),
                }
            })
            .collect();
        let max_r_min = env
            .r_min
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
        Self {
            rshape_version: env!("CARGO_PKG_VERSION").to_string(),
            name: config.raw.name.clone(),
            config: config.path.clone(),
            data: data.path.clone(),
            sample_time: config.sample_time(),
            scaling: super::ScalingNote::of_opt(config.scaling.as_ref()),
            n_data: env.len(),
            size: [data.outputs(), data.inputs()],
            method: env.method,
            noisy: out.noise_radii.is_some(),
            verdict: out.check.as_ref().map(|c| c.verdict),
            consistent: out.check.as_ref().map(|c| c.consistent),
            failing_omegas: out
                .check
                .as_ref()
                .map_or(Vec::new(), |c| c.failing_omegas.clone()),
            a1_violations: out
                .check
                .as_ref()
                .map_or(Vec::new(), |c| c.a1_violations.clone()),
            beyond_a1: env.beyond_a1(),
            max_r_min,
            r_configured: config.r.as_ref().map(|r| Coeffs {
                num: r.num.coeffs().to_vec(),
                den: r.den.coeffs().to_vec(),
            }),
            r_fitted: out.fit.as_ref().ok().map(|f| f.json.clone()),
            certificate: out.fit.as_ref().ok().map(|f| f.certificate.clone()),
            fit_error: out
                .fit
                .as_ref()
                .err()
                .map(|e| crate::report::fmt::one_line(&e.to_string())),
            data_points,
            warnings: out.warnings.clone(),
            files: files
                .iter()
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect(),
            timings_ms: {
                let mut t = out.timings.0.clone();
                let total: f64 = t.values().sum();
                t.insert("total".into(), total);
                t
            },
            closed_loop: match (&config.closed_loop, &out.closed_loop) {
                (Some(m), Some(rep)) => Some(ClosedLoopFields {
                    same_controller: m.same_controller,
                    trivial_plant_factors: m.plant.trivial,
                    trivial_controller_factors: m.controller.trivial,
                    uninformative_omegas: rep.uninformative(),
                    data: rep.data.clone(),
                }),
                _ => None,
            },
        }
    }
}

//! The `[noise]` table of the config and the checks of its keys (how they are resolved into
//! per-datum radii lives in [`crate::model::noise`]).

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The `[noise]` table (see [`crate::model::resolve_noise`] for how the keys are resolved).
///
/// ```toml
/// [noise]
/// radius = 0.06            # global disk radius L_a of eq. (5), in data units
/// # or, the time-domain L∞ model of Sec. III (not together with `radius`):
/// # output_bound = 0.05    # M: bound on the output noise, in output units
/// # input_amplitude = 1.0  # amplitude of the input sinusoid (default 1)
/// # or, per-frequency standard deviations (radius = std_factor·std):
/// # std_file = "data_std.csv"
/// # std_factor = 3.0
/// # or, the coherence of an H1 estimate (radius = coverage·ε·|H|, Bendat & Piersol):
/// # coherence = "frf_h1_coherence.csv"
/// # averages = 5
/// # coverage = 3.0
/// ```
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSection {
    /// Global noise-disk radius `L_a` (eq. (5)), in the units of the data.
    #[serde(default)]
    pub radius: Option<f64>,
    /// Bound `M` on the time-domain output noise, `‖n‖_∞ < M` (eq. (4)), in output units;
    /// the disk radius of each datum follows from Sec. III
    /// ([`crate::model::noise::linf_disk_radius`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_bound: Option<f64>,
    /// Amplitude of the input sinusoid of the experiment (default 1), used with
    /// `output_bound`: the measured output amplitude is `A_m = input_amplitude·|φ|`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input_amplitude: Option<f64>,
    /// A file of FRF standard deviations (`freq_hz` or `omega_rad_s`, then `std_i_j`
    /// columns), relative to the config; the noise radius is `std_factor·std`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_file: Option<PathBuf>,
    /// Factor from standard deviation to noise radius (default 3, i.e. 3σ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_factor: Option<f64>,
    /// A file of ordinary coherences γ² of an H1 estimate (`freq_hz` or `omega_rad_s`, then
    /// `coh_i_j` columns), relative to the config; the radius of each datum is
    /// `coverage·ε·|H|` with the random error `ε = √(1 − γ²)/(|γ|·√(2n))`
    /// ([`crate::data::h1_random_error`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coherence: Option<PathBuf>,
    /// The number of averages `n` of the H1 estimate (required with `coherence`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub averages: Option<i64>,
    /// Coverage factor from the random error to the radius (default 3, i.e. 3σ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<f64>,
}

impl NoiseSection {
    /// Checks the values and that `radius` and `output_bound` are not both given.
    pub fn validate(&self) -> std::result::Result<(), String> {
        if let Some(la) = self.radius {
            if !(la.is_finite() && la >= 0.0) {
                return Err(format!(
                    "[noise] radius = {la}: must be a finite number ≥ 0"
                ));
            }
        }
        if let Some(m) = self.output_bound {
            if !(m.is_finite() && m >= 0.0) {
                return Err(format!(
                    "[noise] output_bound = {m}: must be a finite number ≥ 0"
                ));
            }
        }
        if let Some(u) = self.input_amplitude {
            if !(u.is_finite() && u > 0.0) {
                return Err(format!(
                    "[noise] input_amplitude = {u}: must be a finite number > 0"
                ));
            }
            if self.output_bound.is_none() {
                return Err("[noise] input_amplitude is only used with output_bound; add output_bound or remove it".into());
            }
        }
        if self.radius.is_some() && self.output_bound.is_some() {
            return Err("[noise]: give either radius (L_a) or output_bound (M), not both".into());
        }
        if self.std_file.is_some() && self.output_bound.is_some() {
            return Err("[noise]: give either std_file or output_bound (M), not both".into());
        }
        self.validate_coherence()
    }

    /// The coherence keys: `averages` an integer ≥ 1 and required, `coverage` finite and
    /// positive, both only with `coherence`, which excludes the other sources.
    fn validate_coherence(&self) -> std::result::Result<(), String> {
        if self.coherence.is_none() {
            return match (self.averages, self.coverage) {
                (Some(_), _) => Err("[noise] averages is only used with coherence; add coherence = \"FILE.csv\" or remove it".into()),
                (_, Some(_)) => Err("[noise] coverage is only used with coherence; add coherence = \"FILE.csv\" or remove it".into()),
                _ => Ok(()),
            };
        }
        let others = [
            ("radius", self.radius.is_some()),
            ("output_bound", self.output_bound.is_some()),
            ("std_file", self.std_file.is_some()),
        ];
        if let Some((name, _)) = others.iter().find(|(_, given)| *given) {
            return Err(format!(
                "[noise]: give either coherence or {name}, not both"
            ));
        }
        match self.averages {
            None => {
                return Err("[noise] coherence needs averages = n, the number of averages (hits) of the H1 estimate".into())
            }
            Some(n) if !(1..=i64::from(u32::MAX)).contains(&n) => {
                return Err(format!(
                    "[noise] averages = {n}: must be an integer ≥ 1 (the number of averages of the H1 estimate)"
                ))
            }
            _ => {}
        }
        if let Some(k) = self.coverage {
            if !(k.is_finite() && k > 0.0) {
                return Err(format!(
                    "[noise] coverage = {k}: must be a finite number > 0 (e.g. 3 for 3σ)"
                ));
            }
        }
        Ok(())
    }
}

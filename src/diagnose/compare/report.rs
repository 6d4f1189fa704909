//! What `compare` reports: the failing bands, the per-datum rows and the report with its
//! verdict (see the parent module for the measures).

use serde::Serialize;

/// A frequency band of consecutive failing data.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Band {
    /// Lowest frequency, rad/s.
    pub omega_lo: f64,
    /// Highest frequency, rad/s.
    pub omega_hi: f64,
    /// Number of data in the band.
    pub count: usize,
    /// Largest misfit in the band.
    pub peak_misfit: f64,
    /// Frequency of the largest misfit.
    pub omega_peak: f64,
}

/// Clusters flagged data into bands of consecutive indices.
pub fn bands(omega: &[f64], misfit: &[f64], flag: &[bool]) -> Vec<Band> {
    let mut out: Vec<Band> = Vec::new();
    let mut prev: Option<usize> = None;
    for k in 0..omega.len() {
        if !flag[k] {
            continue;
        }
        match (prev, out.last_mut()) {
            (Some(p), Some(b)) if p + 1 == k => {
                b.omega_hi = omega[k];
                b.count += 1;
                if misfit[k] > b.peak_misfit {
                    b.peak_misfit = misfit[k];
                    b.omega_peak = omega[k];
                }
            }
            _ => out.push(Band {
                omega_lo: omega[k],
                omega_hi: omega[k],
                count: 1,
                peak_misfit: misfit[k],
                omega_peak: omega[k],
            }),
        }
        prev = Some(k);
    }
    out
}

/// One datum of the comparison.
#[derive(Debug, Clone, Serialize)]
pub struct CompareRow {
    /// Frequency, rad/s.
    pub omega: f64,
    /// Data, real and imaginary parts.
    pub data: [f64; 2],
    /// Model, real and imaginary parts.
    pub model: [f64; 2],
    /// `|G_d − G_m|/r` (or relative when the radius is unknown).
    pub misfit: f64,
    /// Noise radius.
    pub noise_radius: Option<f64>,
    /// Smallest consistent `|r|`: Theorem 4 (with the noise) when a radius is known,
    /// else noise-free (Theorem 2 or 3); see `r_env_method`.
    pub r_min: Option<f64>,
    /// Not explained by the noise.
    pub invalid: bool,
    /// Not explained by the noise nor by the configured r.
    pub invalid_with_r: Option<bool>,
}

/// The verdict of `compare` (serialized in snake_case: `consistent`, `inconsistent`,
/// `unknown_noise`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CompareVerdict {
    /// `invalid_fraction ≤ 5 %` and `misfit_rms ≤ 1`: explained within the noise.
    Consistent,
    /// The model misses the data by more than the noise.
    Inconsistent,
    /// No noise radius is known: the misfit cannot be judged.
    UnknownNoise,
}

impl CompareVerdict {
    /// The snake_case name (as in the JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Consistent => "consistent",
            Self::Inconsistent => "inconsistent",
            Self::UnknownNoise => "unknown_noise",
        }
    }
}

impl std::fmt::Display for CompareVerdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The error measures of one model against one data set.
#[derive(Debug, Clone, Serialize)]
pub struct CompareReport {
    /// The config.
    pub config: String,
    /// The data file.
    pub data: String,
    /// Selected channel (output, input), 1-based.
    pub channel: [usize; 2],
    /// Where the noise radius came from.
    pub noise_source: String,
    /// True when the misfit is normalized by the noise radius.
    pub normalized: bool,
    /// `sqrt(mean c_k²)`.
    pub misfit_rms: f64,
    /// Largest `c_k`.
    pub misfit_max: f64,
    /// Share of data not explained by the noise (`c_k > 1`).
    pub invalid_fraction: Option<f64>,
    /// Share of data explained neither by the noise nor by the configured r.
    pub invalid_fraction_with_r: Option<f64>,
    /// Largest finite envelope value (smallest consistent |r|) over the data: Theorem 4 with
    /// the noise radius when one is known, else noise-free.
    pub r_env_max: Option<f64>,
    /// Data no admissible `|r|` explains (`r_min = inf`), not counted in `r_env_max`.
    pub n_unexplainable: Option<usize>,
    /// True when "fails with r" is the exact Theorem 4 test (`|r| ≤ r_min`), false for the
    /// conservative noise-free approximation.
    pub with_r_exact: bool,
    /// How `r_env_max` was computed (or why not).
    pub r_env_method: String,
    /// Bands where the nominal model fails (noise only).
    pub bands: Vec<Band>,
    /// Bands where the model with the configured r fails.
    pub bands_with_r: Option<Vec<Band>>,
    /// Verdict: `consistent` when `invalid_fraction ≤ 5 %` and `misfit_rms ≤ 1`.
    pub verdict: CompareVerdict,
    /// Per-datum rows.
    pub rows: Vec<CompareRow>,
    /// The Bode overlay, when written.
    pub figure: Option<String>,
}

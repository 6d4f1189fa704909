//! Error measures of a model on the data channels: the cost `V`, `misfit_rms` and
//! `invalid_fraction` (docs/design/effects.md), from the noise-normalized misfits.

use crate::diagnose::compare::{MAX_INVALID_FRACTION, MAX_MISFIT_RMS};
use serde::Serialize;

/// Error measures of a model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Measures {
    /// `Σ|e|²/σ²`.
    pub v: f64,
    /// `sqrt(mean (|e|/r)²)` over every datum of every channel.
    pub misfit_rms: f64,
    /// Share of data with `|e| > r`.
    pub invalid_fraction: f64,
}

impl Measures {
    /// Explained within the noise.
    pub fn consistent(&self) -> bool {
        self.invalid_fraction <= MAX_INVALID_FRACTION && self.misfit_rms <= MAX_MISFIT_RMS
    }
}

/// Measures from the normalized misfits `[ch][k]`.
pub fn measures_of(c: &[Vec<f64>]) -> Measures {
    let mut c2 = 0.0;
    let mut bad = 0usize;
    let mut n = 0usize;
    for x in c.iter().flatten() {
        c2 += x * x;
        n += 1;
        if *x > 1.0 {
            bad += 1;
        }
    }
    let n = n.max(1) as f64;
    Measures {
        v: 2.0 * c2,
        misfit_rms: (c2 / n).sqrt(),
        invalid_fraction: bad as f64 / n,
    }
}

/// The Bayesian information criterion of a fit with cost `v` ([`Measures::v`]) and `n_params`
/// real parameters on `n_data` complex data (`2·n_data` real ones): `2v + p·ln(2N)`
/// (Schwarz 1978; docs/design/effects.md).
pub fn bic(v: f64, n_params: usize, n_data: usize) -> f64 {
    2.0 * v + n_params as f64 * (2.0 * n_data as f64).ln()
}

/// The evidence for `n_params` added real parameters that lower the cost by `dv`
/// ([`Measures::v`] before minus after) on `n_data` complex data: the fall of [`bic`],
/// `2Δv − p·ln(2N)`.
pub fn delta_bic(dv: f64, n_params: usize, n_data: usize) -> f64 {
    2.0 * dv - n_params as f64 * (2.0 * n_data as f64).ln()
}

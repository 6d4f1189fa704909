//! The lower envelope: per datum, the smallest `|r(jω_i)|` consistent with it, with the A1
//! limit `σ_min(M̃(jω_i))` beside it.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::noise_free::{r_min_special, r_min_standard};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::{Factorization, FactorizationKind};
use serde::Serialize;

/// How the envelope was computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EnvelopeMethod {
    /// Theorem 2, eq. (8): minimum-norm perturbation of the standard factorization.
    Theorem2,
    /// Theorem 3: `1/σ_p(X)` for the special factorization.
    Theorem3,
    /// Theorem 4: bisection on `|r|` of the μ test (noisy SISO data).
    Theorem4Mu,
    /// Read from a file.
    File,
    /// Closed-loop data, noise-free: `σ̄(Δ̄)` of the perturbation the datum determines
    /// (Crowder & de Callafon, Theorem 1 and Corollaries 1–2).
    ClosedLoopTheorem1,
    /// Closed-loop noisy SISO data: smallest `|V|` with `μ_Δs > 1` (Crowder & de Callafon,
    /// Theorem 2, eqs. (15)–(18)).
    ClosedLoopTheorem2,
}

/// Per-datum smallest consistent `|r|` and the A1 limit.
#[derive(Debug, Clone, Serialize)]
pub struct Envelope {
    /// Frequencies in rad/s, increasing.
    pub omega: Vec<f64>,
    /// Smallest `|r(jω_i)|` consistent with datum `i` (`inf` when no admissible `r` explains it).
    pub r_min: Vec<f64>,
    /// `σ_min(M̃(jω_i))`, the A1 upper limit on `|r(jω_i)|` (`None` when the model is unknown).
    pub a1_limit: Option<Vec<f64>>,
    /// How `r_min` was computed.
    pub method: EnvelopeMethod,
}

impl Envelope {
    /// Number of data.
    pub fn len(&self) -> usize {
        self.omega.len()
    }

    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.omega.is_empty()
    }

    /// Frequencies where `r_min` exceeds the A1 limit: no admissible `r` covers them.
    pub fn beyond_a1(&self) -> Vec<f64> {
        match &self.a1_limit {
            Some(a1) => self
                .omega
                .iter()
                .zip(&self.r_min)
                .zip(a1)
                .filter(|((_, r), a)| *r >= *a)
                .map(|((w, _), _)| *w)
                .collect(),
            None => Vec::new(),
        }
    }
}

/// Checks that the data have the sizes the model needs.
pub fn check_sizes(f: &Factorization, data: &FrfData) -> Result<()> {
    check_shape(f, &data.path, data.outputs(), data.inputs())
}

/// Checks that `p×m` data read from `path` have the sizes the model needs.
pub fn check_shape(f: &Factorization, path: &std::path::Path, p: usize, m: usize) -> Result<()> {
    if p != f.outputs() || m != f.inputs() {
        return Err(Error::Input {
            path: path.to_path_buf(),
            msg: format!(
                "the data are {}×{} (outputs×inputs) but the model is {}×{}; select a channel or fix the model",
                p,
                m,
                f.outputs(),
                f.inputs(),
            ),
        });
    }
    Ok(())
}

/// The noise-free envelope: Theorem 2 (eq. (8)) for the standard factorization, Theorem 3
/// for the special one.  An assumption failing at a datum is an error naming its frequency.
pub fn noise_free_envelope(f: &Factorization, data: &FrfData) -> Result<Envelope> {
    check_sizes(f, data)?;
    let mut r_min = Vec::with_capacity(data.len());
    let mut a1 = Vec::with_capacity(data.len());
    for (omega, phi) in data.omega.iter().zip(&data.response) {
        let at = f.at(*omega);
        let r = match f.kind {
            FactorizationKind::Standard => r_min_standard(&at, phi),
            FactorizationKind::Special => r_min_special(&at, phi),
        }
        .map_err(|e| Error::Assumption {
            omega: *omega,
            msg: format!("{} ({})", e.message(), data.path.display()),
        })?;
        if r.is_nan() {
            // Never a NaN in an output with exit 0 (an overflow that prescaling missed).
            return Err(Error::Assumption {
                omega: *omega,
                msg: format!(
                    "the smallest consistent |r| is not a number (the datum overflows the arithmetic); rescale the data ({})",
                    data.path.display()
                ),
            });
        }
        r_min.push(r);
        a1.push(at.a1_limit());
    }
    Ok(Envelope {
        omega: data.omega.clone(),
        r_min,
        a1_limit: Some(a1),
        method: match f.kind {
            FactorizationKind::Standard => EnvelopeMethod::Theorem2,
            FactorizationKind::Special => EnvelopeMethod::Theorem3,
        },
    })
}

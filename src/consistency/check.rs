//! Check of a given unit `r` against an envelope: the data are consistent iff
//! `|r(jω_i)| > r_min,i` at every datum (Theorem 2, Theorem 3 and Theorem 4 all reduce to
//! this once the envelope is known).  A1 (`|r| < σ_min(M̃)`) is reported at every datum.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::envelope::Envelope;
use crate::system::TransferFunction;
use serde::Serialize;

/// One datum of the check.
#[derive(Debug, Clone, Serialize)]
pub struct CheckRow {
    /// Frequency in rad/s.
    pub omega: f64,
    /// `|r(jω)|`.
    pub r_abs: f64,
    /// Smallest consistent `|r|` at this datum.
    pub r_min: f64,
    /// `|r(jω)| / r_min` (consistent iff > 1).
    pub ratio: f64,
    /// True when the datum is explained.
    pub consistent: bool,
    /// `σ_min(M̃(jω))`, when the model is known.
    pub a1_limit: Option<f64>,
    /// True when A1 holds at this datum (`|r| < σ_min(M̃)`).
    pub a1_ok: bool,
}

/// The whole check.
#[derive(Debug, Clone, Serialize)]
pub struct CheckReport {
    /// One row per datum.
    pub rows: Vec<CheckRow>,
    /// True when every datum is explained.
    pub consistent: bool,
    /// Frequencies (rad/s) of the data that are not explained.
    pub failing_omegas: Vec<f64>,
    /// Frequencies (rad/s) where A1 fails.
    pub a1_violations: Vec<f64>,
}

/// Checks `r` against every datum of the envelope.
pub fn check(r: &TransferFunction, env: &Envelope) -> CheckReport {
    let rows: Vec<CheckRow> = env
        .omega
        .iter()
        .enumerate()
        .map(|(i, &omega)| {
            let r_abs = r.freq(omega).norm();
            let r_min = env.r_min[i];
            let a1 = env.a1_limit.as_ref().map(|a| a[i]);
            CheckRow {
                omega,
                r_abs,
                r_min,
                ratio: if r_min > 0.0 {
                    r_abs / r_min
                } else {
                    f64::INFINITY
                },
                consistent: r_abs > r_min,
                a1_limit: a1,
                a1_ok: a1.is_none_or(|a| r_abs < a),
            }
        })
        .collect();
    let failing_omegas = rows
        .iter()
        .filter(|r| !r.consistent)
        .map(|r| r.omega)
        .collect();
    let a1_violations = rows.iter().filter(|r| !r.a1_ok).map(|r| r.omega).collect();
    CheckReport {
        consistent: rows.iter().all(|r| r.consistent),
        rows,
        failing_omegas,
        a1_violations,
    }
}

//! Check of a given unit `r` against an envelope: the data are consistent iff
//! `|r(jω_i)| > r_min,i` at every datum (Theorem 2, Theorem 3 and Theorem 4 all reduce to
//! this once the envelope is known) *and* `r` is admissible there, i.e. assumption A1
//! `σ_min(M̃(jω)) > |r(jω)|` (Boulet & Francis 1998, Sec. II) holds.  Where A1 fails the
//! perturbed family contains plants that are not stable and Theorems 2–4 conclude nothing
//! (the proofs use A1 to make `M̃ + Δ_M` invertible): the verdict is then
//! [`Verdict::NotAdmissible`], never "consistent".
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::envelope::Envelope;
use crate::system::TransferFunction;
use serde::Serialize;

/// The verdict of a check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// A1 holds and `|r| > r_min` at every datum.
    Consistent,
    /// A1 holds at every datum but `|r| ≤ r_min` at some.
    Inconsistent,
    /// A1 fails (`|r| ≥ σ_min(M̃)`) at some datum: `r` is not admissible there and the
    /// theorems give no verdict; make `r` smaller there (or change the factorization).
    NotAdmissible,
}

impl Verdict {
    /// The verdict as it reads in `report.json` (`consistent`, `inconsistent`, `not_admissible`).
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Consistent => "consistent",
            Verdict::Inconsistent => "inconsistent",
            Verdict::NotAdmissible => "not_admissible",
        }
    }
}

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
    /// True when `|r| > r_min` and A1 holds at this datum (the datum is explained by an
    /// admissible `r`).
    pub consistent: bool,
    /// True when `|r| > r_min`, whether or not A1 holds.
    pub covers: bool,
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
    /// `consistent`, `inconsistent` or `not_admissible` (A1 fails somewhere).
    pub verdict: Verdict,
    /// True when the verdict is [`Verdict::Consistent`].
    pub consistent: bool,
    /// Frequencies (rad/s) of the data with `|r| ≤ r_min`.
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
            let a1_ok = a1.is_none_or(|a| r_abs < a);
            CheckRow {
                omega,
                r_abs,
                r_min,
                ratio: if r_min > 0.0 {
                    r_abs / r_min
                } else {
                    f64::INFINITY
                },
                consistent: r_abs > r_min && a1_ok,
                covers: r_abs > r_min,
                a1_limit: a1,
                a1_ok,
            }
        })
        .collect();
    let failing_omegas = rows
        .iter()
        .filter(|r| !r.covers)
        .map(|r| r.omega)
        .collect::<Vec<_>>();
    let a1_violations = rows
        .iter()
        .filter(|r| !r.a1_ok)
        .map(|r| r.omega)
        .collect::<Vec<_>>();
    let verdict = if !a1_violations.is_empty() {
        Verdict::NotAdmissible
    } else if !failing_omegas.is_empty() {
        Verdict::Inconsistent
    } else {
        Verdict::Consistent
    };
    CheckReport {
        verdict,
        consistent: verdict == Verdict::Consistent,
        rows,
        failing_omegas,
        a1_violations,
    }
}

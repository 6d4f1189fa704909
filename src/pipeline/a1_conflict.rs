//! Why a fit of `r` fails at every order: the fit keeps `|r(jω)| ≥ min(r_min,i, r_min,i+1)`
//! between neighbouring data (no dips, see `rshape fit`) and `|r(jω)| < σ_min(M̃(jω))`
//! (assumption A1, Boulet & Francis 1998, Sec. II).  Where `σ_min(M̃)` falls below that level
//! between two data, no `r` satisfies both, whatever its order.  With normalized coprime
//! factors `M̃`'s zeros are the plant's poles, so this is the notch of a lightly damped pole of
//! the nominal model between two measured lines: the message says where, and what to change.
//!
//! Where `σ_min(M̃)` stays above the level but by less than [`TIGHT`], an `r` exists in
//! principle but must squeeze through the gap (a notch in `r` itself); the fit's candidates
//! then fail A1 there, and the hint names the gap (it does not claim impossibility).
//!
//! Each sample below the level is itself the proof (at that `ω` both bounds are explicit), so
//! the scan needs no refinement; a notch narrower than the sampling may be missed (then no
//! hint is given, never a wrong one).

use crate::consistency::Envelope;
use crate::model::Factorization;
use crate::report::fmt::fmt_g;

/// Samples per interval between neighbouring data (log-spaced, interior).
const SAMPLES: usize = 48;
/// At most this many evaluations of `σ_min(M̃)` in all (large models are dear per frequency).
const MAX_EVALUATIONS: usize = 20_000;

/// Below this ratio `σ_min(M̃)/level` between two data the hint calls the gap tight.
pub const TIGHT: f64 = 2.0;

/// A frequency between two data where A1 and the envelope's level cannot both hold.
#[derive(Debug, Clone, PartialEq)]
pub struct A1Conflict {
    /// The neighbouring data (rad/s).
    pub between: (f64, f64),
    /// Where `σ_min(M̃)` is lowest relative to the level (rad/s).
    pub omega: f64,
    /// `σ_min(M̃(jω))` there.
    pub sigma_min: f64,
    /// `min(r_min,i, r_min,i+1)`: the least `|r|` the fit must keep there.
    pub level: f64,
}

impl A1Conflict {
    /// Whether no `r` can pass (`σ_min(M̃) < level` at the sample), not merely a tight gap.
    pub fn impossible(&self) -> bool {
        self.sigma_min < self.level
    }

    /// `σ_min(M̃)/level` at the sample.
    pub fn ratio(&self) -> f64 {
        self.sigma_min / self.level
    }
}

/// What a fit failure says about the gaps of [`a1_conflicts`] (worst first, at most two
/// named): `(where, what to do)`, `None` without gaps.  The second part stays under 150
/// characters, so that it survives the CLI's cut of long messages.
pub fn hint_parts(gaps: &[A1Conflict]) -> Option<(String, String)> {
    let first = gaps.first()?;
    let named: Vec<String> = gaps
        .iter()
        .take(2)
        .map(|c| {
            format!(
                "σ_min(M̃) = {} at ω = {} rad/s (data at {} and {} rad/s), {} × the level {} that r must keep",
                fmt_g(c.sigma_min),
                fmt_g(c.omega),
                fmt_g(c.between.0),
                fmt_g(c.between.1),
                fmt_g(c.ratio()),
                fmt_g(c.level),
            )
        })
        .collect();
    let more = match gaps.len() {
        n if n > 2 => format!(" (and {} more)", n - 2),
        _ => String::new(),
    };
    let todo = "M̃ is nearly singular there (a lightly damped model pole, or a large gain: σ_min(M̃) ≈ 1/‖G‖): damp or move that mode, or rescale the plant's units";
    Some(if first.impossible() {
        (
            format!(
                "no r of any order can pass: A1 falls below the envelope between data: {}{more} (a measurement at ω = {} rad/s would split the gap)",
                named.join("; "),
                fmt_g(first.omega)
            ),
            todo.to_string(),
        )
    } else {
        (
            format!(
                "A1 leaves r little room between data: {}{more}; r must squeeze through",
                named.join("; ")
            ),
            todo.to_string(),
        )
    })
}

/// [`hint_parts`] as one sentence.
pub fn hint(gaps: &[A1Conflict]) -> Option<String> {
    hint_parts(gaps).map(|(w, todo)| format!("{w}: {todo}"))
}

/// Per interval between neighbouring data with finite positive `r_min`, its sample of
/// smallest `σ_min(M̃)/level` when that is below [`TIGHT`]; worst first.
pub fn a1_conflicts(env: &Envelope, f: &Factorization) -> Vec<A1Conflict> {
    // A datum at or beyond A1 already decides the failure (the model must change there).
    if let Some(a1) = &env.a1_limit {
        if env.r_min.iter().zip(a1).any(|(r, l)| r >= l) {
            return Vec::new();
        }
    }
    let mut budget = MAX_EVALUATIONS;
    let mut gaps: Vec<A1Conflict> = Vec::new();
    for k in 1..env.omega.len() {
        let (w0, w1) = (env.omega[k - 1], env.omega[k]);
        let level = env.r_min[k - 1].min(env.r_min[k]);
        if !(level.is_finite() && level > 0.0 && w0 > 0.0 && w1 > w0) {
            continue;
        }
        if budget < SAMPLES {
            break;
        }
        budget -= SAMPLES;
        let step = (w1 / w0).ln() / (SAMPLES + 1) as f64;
        let worst = (1..=SAMPLES)
            .map(|j| {
                let w = w0 * (step * j as f64).exp();
                A1Conflict {
                    between: (w0, w1),
                    omega: w,
                    sigma_min: f.a1_limit(w),
                    level,
                }
            })
            .filter(|c| c.ratio() < TIGHT)
            .min_by(|a, b| a.ratio().total_cmp(&b.ratio()));
        gaps.extend(worst);
    }
    gaps.sort_by(|a, b| a.ratio().total_cmp(&b.ratio()));
    gaps
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::consistency::EnvelopeMethod;
    use crate::system::{TfMatrix, TransferFunction};

    /// `M̃ = (s² + 2ζs + 1)/(s + 1)²`: a notch of depth `|2ζj|/|(1 + j)²| = ζ` at ω = 1.
    fn notch(zeta: f64) -> Factorization {
        let m = TransferFunction::new(vec![1.0, 2.0 * zeta, 1.0], vec![1.0, 2.0, 1.0]);
        let n = TransferFunction::new(vec![1.0], vec![1.0, 2.0, 1.0]);
        let one = |t| TfMatrix::from_rows(vec![vec![t]]).unwrap();
        Factorization::standard(one(m), one(n)).unwrap()
    }

    fn env(omega: Vec<f64>, r_min: Vec<f64>) -> Envelope {
        Envelope {
            omega,
            r_min,
            a1_limit: None,
            method: EnvelopeMethod::Theorem2,
        }
    }

    #[test]
    fn a_notch_between_two_data_is_found_and_proved_by_its_sample() {
        let f = notch(1e-3);
        let e = env(vec![0.99, 1.01], vec![0.05, 0.06]);
        let gaps = a1_conflicts(&e, &f);
        let c = gaps.first().expect("the notch (depth 1e-3) is below 0.05");
        assert!(c.impossible() && hint(&gaps).unwrap().starts_with("no r of any order"));
        // The sample is its own proof: σ_min there, recomputed, is below the level.
        assert!(f.a1_limit(c.omega) < 0.05 && c.level == 0.05);
        assert!(c.omega > 0.99 && c.omega < 1.01 && c.between == (0.99, 1.01));
        let (_, todo) = hint_parts(&gaps).unwrap();
        assert!(
            todo.contains("damp or move") && todo.chars().count() < 150,
            "{todo}"
        );
        // A well-damped model has no conflict; a shallow notch (depth ζ = 0.07) above the
        // level 0.05 is a tight gap, not an impossibility.
        assert_eq!(a1_conflicts(&e, &notch(0.5)), vec![]);
        let gaps = a1_conflicts(&e, &notch(0.07));
        assert!(!gaps[0].impossible() && (gaps[0].ratio() - 1.4).abs() < 0.05);
        assert!(hint(&gaps).unwrap().contains("squeeze"));
        // An infinite or zero r_min sets no level.
        let e = env(vec![0.99, 1.01], vec![f64::INFINITY, 0.0]);
        assert_eq!(a1_conflicts(&e, &f), vec![]);
    }
}

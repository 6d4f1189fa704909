//! Where a candidate came from and what a solver event was, as types: the fit decides on
//! them (whether to refit an order with the lower orders carried forward, which candidate is
//! the lower order's) by matching variants, never message text (GitHub issue 25).

use serde::Serialize;
use std::fmt;

/// The pole set of an area polish ([`Origin::AreaPolish`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PoleSet {
    /// The poles of the partial-fraction minimax fit of the same order.
    Minimax,
    /// The previous order's poles plus one real pole.
    PreviousPlusOne,
    /// The reference poles of the partial-fraction basis.
    Reference,
}

impl fmt::Display for PoleSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Minimax => "minimax poles",
            Self::PreviousPlusOne => "previous poles + one",
            Self::Reference => "reference poles",
        })
    }
}

/// Which candidate a fit is (see `fit::engine` for the candidates of one order).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Origin {
    /// The partial-fraction minimax level search, at level `t` (on `|r̂|²/U`).
    Minimax {
        /// The level reached.
        t: f64,
    },
    /// The area objective with these poles fixed.
    AreaPolish {
        /// The pole set.
        poles: PoleSet,
    },
    /// The previous order's fit, padded with a cancelling pole-zero pair.
    CarriedOver {
        /// Its order.
        from_order: usize,
    },
    /// The constant `r` at the largest lower bound (feasible at every order).
    Constant,
    /// The global minimax over the full numerator and denominator (`fit::polyfit`).
    PolynomialMinimax {
        /// The level reached.
        t: f64,
    },
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Minimax { t } => write!(f, "minimax (t = {t:.4e})"),
            Self::AreaPolish { poles } => write!(f, "area polish, {poles}"),
            Self::CarriedOver { from_order } => write!(f, "order {from_order} carried over"),
            Self::Constant => f.write_str("constant at the largest lower bound"),
            Self::PolynomialMinimax { t } => write!(f, "polynomial minimax (t = {t:.4e})"),
        }
    }
}

/// What a solver event was (the `action` text says it for people).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// A reduced-accuracy solution was used; the candidate is verified afterwards.
    ReducedAccuracyUsed,
    /// One level of a search was treated as not feasible (a doubt, not a proof).
    LevelNotFeasible,
    /// No level up to `t = 1e24` was feasible in the partial-fraction level search.
    NoFeasibleLevel,
    /// A candidate was dropped (spectral factorization failed, poles cannot meet the bounds).
    CandidateDiscarded,
    /// The budget of doubtful levels was spent; the remaining disk centres were skipped.
    DoubtBudgetSpent,
    /// The order alone was refitted with the lower orders carried forward.
    RefittedChained,
    /// No candidate of the order certified, the certificate named frequencies where a bound
    /// fails between the fit's constraint points; they were added and the order searched
    /// again (the cutting-plane round, `fit::cutting_plane`).
    CutsAdded,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `r.json`'s `origin` stays the text it was before the enum (scripts read it).
    #[test]
    fn origins_print_as_before() {
        let cases = [
            (Origin::Minimax { t: 2.5 }, "minimax (t = 2.5000e0)"),
            (
                Origin::AreaPolish {
                    poles: PoleSet::PreviousPlusOne,
                },
                "area polish, previous poles + one",
            ),
            (
                Origin::CarriedOver { from_order: 3 },
                "order 3 carried over",
            ),
            (Origin::Constant, "constant at the largest lower bound"),
            (
                Origin::PolynomialMinimax { t: 1.25 },
                "polynomial minimax (t = 1.2500e0)",
            ),
        ];
        for (o, text) in cases {
            assert_eq!(o.to_string(), text);
        }
        let j = serde_json::to_value(Origin::AreaPolish {
            poles: PoleSet::Minimax,
        })
        .unwrap();
        assert_eq!(j["kind"], "area_polish");
        assert_eq!(j["poles"], "minimax");
    }
}

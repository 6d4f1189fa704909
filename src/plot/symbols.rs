//! The symbols the figures use for the weight and the test, so that closed-loop runs say
//! `V`, `|Δ̄|` and `μ_Δs` (Crowder & de Callafon) where open-loop runs say `r`, `‖Δ‖` and
//! `μ_Γ` (Boulet & Francis).

/// Names written in legends, axis labels and titles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Symbols {
    /// The weight: `r` (open loop) or `V` (closed loop, eq. (2)).
    pub weight: &'static str,
    /// The per-datum smallest consistent weight: `r_min` or `|V|_min`.
    pub weight_min: &'static str,
    /// The structured singular value of the noisy test: `μ_Γ` (Theorem 4) or `μ_Δs`
    /// (Theorem 2 of the closed-loop paper).
    pub mu: &'static str,
}

impl Symbols {
    /// Open-loop data (Boulet & Francis).
    pub const OPEN_LOOP: Symbols = Symbols {
        weight: "r",
        weight_min: "r_min",
        mu: "μ_Γ",
    };
    /// Closed-loop data (Crowder & de Callafon).
    pub const CLOSED_LOOP: Symbols = Symbols {
        weight: "V",
        weight_min: "|V|_min",
        mu: "μ_Δs",
    };

    /// The symbols of a config: closed-loop with `[closed_loop]`.
    pub fn of(closed_loop: bool) -> Symbols {
        if closed_loop {
            Self::CLOSED_LOOP
        } else {
            Self::OPEN_LOOP
        }
    }
}

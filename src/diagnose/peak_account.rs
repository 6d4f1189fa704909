//! The per-peak account of `rshape diagnose` (JSON `peaks`): every peak of the residual
//! `|data − model|/r`, what became of it, and for a peak left unexplained one mode fitted
//! there on the final model (computed by `search::peaks`, reported through `report`).

use serde::Serialize;

/// What became of a peak of the residual (module `peaks`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PeakFate {
    /// A mode this run added lies in the peak's window.
    Added,
    /// A mode already in the model lies there (the rest of its fit).
    Modelled,
    /// The chosen set brought the residual down (to half, or below the threshold).
    Lowered,
    /// A mode candidate was fitted there and rejected (reason in `reason`).
    Rejected,
    /// No candidate of this run was fitted there.
    NotProposed,
}

impl PeakFate {
    /// The snake_case name (as in the JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Added => "added",
            Self::Modelled => "modelled",
            Self::Lowered => "lowered",
            Self::Rejected => "rejected",
            Self::NotProposed => "not_proposed",
        }
    }
}

/// One mode fitted at a peak on top of the final model (module `peaks`).
#[derive(Debug, Clone, Serialize)]
pub struct PeakProbe {
    /// Where the mode went, Hz.
    pub frequency_hz: f64,
    /// Its damping ratio.
    pub zeta: f64,
    /// `2(V_final − V) − n·ln(2F)`.
    pub delta_bic: f64,
    /// Plausibility flags (ω_n or ζ at a bound).
    pub flags: Vec<String>,
    /// No more invalid data, or a lower `misfit_rms` (`rank::improves`).
    pub improves: bool,
    /// ΔBIC above the search's `min_delta_bic` (default 10), no flag, and `improves`: it
    /// would pass the screen.
    pub would_pass: bool,
}

/// A peak of the residual `|data − model|/r` and its fate (module `peaks`).
#[derive(Debug, Clone, Serialize)]
pub struct Peak {
    /// Frequency of the peak, Hz.
    pub frequency_hz: f64,
    /// Height in noise units (`|e|/r`) on the retuned model, before this run added anything.
    pub height: f64,
    /// Height on the final model.
    pub height_after: f64,
    /// The window (half height, at least ±0.3 %), Hz.
    pub window_hz: [f64; 2],
    /// Its width, Hz.
    pub width_hz: f64,
    /// What became of it.
    pub fate: PeakFate,
    /// The effect that explains it, or the candidate fitted there (absent when none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effect: Option<String>,
    /// Why, in one sentence.
    pub reason: String,
    /// For a peak left unexplained: one mode fitted there on the final model (absent for
    /// an explained peak, or when that fit did not converge).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probe: Option<PeakProbe>,
}

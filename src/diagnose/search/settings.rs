//! The settings of the beam search ([`super::beam`]): how many effects, how many nodes a
//! level keeps, the evidence an effect must bring, and whether mains modes are written.

use crate::diagnose::search::rank::MIN_DELTA_BIC;

/// Search settings.
#[derive(Debug, Clone, Copy)]
pub struct SearchSettings {
    /// Most effects to add.
    pub max_effects: usize,
    /// Nodes kept per level.
    pub beam: usize,
    /// ΔBIC an effect must exceed to be added (`2(V_ref − V) − n ln(2F)`; default
    /// 10, "very strong" evidence on Kass & Raftery's scale).
    pub min_delta_bic: f64,
    /// Write modes at mains frequencies ([`crate::diagnose::admissible`]); refused by default.
    pub allow_mains: bool,
}

impl SearchSettings {
    /// Checks every field; the error names the first bad one ([`crate::settings`]).
    pub fn validate(&self) -> std::result::Result<(), crate::settings::InvalidSetting> {
        crate::settings::Checker::new("SearchSettings")
            .at_least("max_effects", self.max_effects, 1, "must be at least 1")
            .at_least("beam", self.beam, 1, "must be at least 1")
            .non_negative("min_delta_bic", self.min_delta_bic)
            .finish()
    }
}

impl Default for SearchSettings {
    fn default() -> Self {
        Self {
            max_effects: 3,
            beam: 3,
            min_delta_bic: MIN_DELTA_BIC,
            allow_mains: false,
        }
    }
}

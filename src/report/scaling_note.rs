//! The `scaling` entry of `r.json`, `report.json` and `batch.json` for a config with
//! `[scaling]`: the diagonals of `D_o`, `D_i` of `G_s = D_o·G·D_i` and what `r` refers to,
//! and the comment line that says the same in `r.m`, `r.py`, `r.jl`.  One definition for
//! `run`, `fit` and `batch`, serialized in its field order (no `serde_json::Value` round
//! trip, which would sort the keys of the file it is added to).

use crate::model::Scaling;
use serde::{Deserialize, Serialize};

/// What `r` refers to in a scaled config (the `r_refers_to` entry).
pub const R_REFERS_TO: &str = "the scaled plant G_s = D_o·G·D_i (D_o = diag(outputs), D_i = diag(inputs)); a controller K for G is K_s = D_i⁻¹·K·D_o⁻¹ for G_s";

/// The `scaling` entry of the JSON outputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalingNote {
    /// Diagonal of `D_o`, one per output.
    pub outputs: Vec<f64>,
    /// Diagonal of `D_i`, one per input.
    pub inputs: Vec<f64>,
    /// Computed by `scaling = "auto"`.
    pub auto: bool,
    /// What `r` refers to: the scaled plant, and how a controller of `G` maps to `G_s`.
    pub r_refers_to: String,
}

impl ScalingNote {
    /// The note of a config's scaling.
    pub fn of(s: &Scaling) -> Self {
        Self {
            outputs: s.outputs.clone(),
            inputs: s.inputs.clone(),
            auto: s.auto,
            r_refers_to: R_REFERS_TO.to_string(),
        }
    }

    /// The first comment line of `r.m`, `r.py`, `r.jl`, without its comment sign.
    pub fn comment(&self) -> String {
        let s = Scaling {
            outputs: self.outputs.clone(),
            inputs: self.inputs.clone(),
            auto: self.auto,
        };
        format!(
            "r refers to the scaled plant G_s = D_o*G*D_i, {}",
            s.describe()
        )
    }

    /// [`ScalingNote::of`] of an optional scaling.
    pub fn of_opt(s: Option<&Scaling>) -> Option<Self> {
        s.map(Self::of)
    }
}

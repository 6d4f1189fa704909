//! The additive terms of a physical model: flexible modes, rigid bodies and integrators
//! (with their input and output gains) and the feedthrough.

use serde::{Deserialize, Serialize};

/// A gain given as one number (SISO) or one number per channel.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Gains {
    /// One number.
    Scalar(f64),
    /// One number per channel.
    Vector(Vec<f64>),
}

impl Default for Gains {
    fn default() -> Self {
        Gains::Scalar(1.0)
    }
}

impl Gains {
    pub(super) fn len(&self) -> Option<usize> {
        match self {
            Gains::Scalar(_) => None,
            Gains::Vector(v) => Some(v.len()),
        }
    }

    /// The gains as a vector of length `n` (a scalar is used for a single channel only).
    pub fn to_vec(&self, n: usize) -> Vec<f64> {
        match self {
            Gains::Scalar(x) => vec![*x; n],
            Gains::Vector(v) => v.clone(),
        }
    }

    pub(super) fn all(&self) -> Vec<f64> {
        match self {
            Gains::Scalar(x) => vec![*x],
            Gains::Vector(v) => v.clone(),
        }
    }
}

fn one() -> f64 {
    1.0
}

fn is_one(x: &f64) -> bool {
    *x == 1.0
}

/// A flexible mode `c bᵀ/(m (s² + 2ζω_n s + ω_n²))`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModeSpec {
    /// Optional label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Natural frequency in rad/s.
    pub omega_n: f64,
    /// Damping ratio.
    pub zeta: f64,
    /// Modal mass `m` (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub mass: f64,
    /// Input gains `b` (one per input).
    #[serde(default)]
    pub input_gain: Gains,
    /// Output gains `c` (one per output).
    #[serde(default)]
    pub output_gain: Gains,
}

/// A rigid-body mode `c bᵀ/(m s²)` or an integrator `c bᵀ/(m s)`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PoleAtZeroSpec {
    /// Optional label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Mass (or inertia) `m` (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub mass: f64,
    /// Input gains `b`.
    #[serde(default)]
    pub input_gain: Gains,
    /// Output gains `c`.
    #[serde(default)]
    pub output_gain: Gains,
    /// Rigid bodies only: viscous-friction pole `p = c_v/m` in rad/s, making the term
    /// `c bᵀ/(m s (s + p))`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_pole: Option<f64>,
}

/// A feedthrough: a number (SISO) or a matrix.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Feedthrough {
    /// SISO.
    Scalar(f64),
    /// Rows.
    Matrix(Vec<Vec<f64>>),
}

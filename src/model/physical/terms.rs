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

/// The measured quantity of a physical model (`[physical] quantity`): the model is
/// `s^k` times the displacement model, `k` = 0, 1, 2 for a receptance (displacement/force),
/// a mobility (velocity/force) or an accelerance (acceleration/force).  The terms of the
/// model (modes, rigid bodies, feedthrough) keep their displacement meaning: on an
/// accelerance a rigid body `c b/(m s²)` is the mass line `c b/m`, a mode becomes
/// `c b s²/(m d(s))`, and the feedthrough (the upper residual, residual flexibility) `D s²`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Receptance (the default).
    #[default]
    Displacement,
    /// Mobility.
    Velocity,
    /// Accelerance (inertance).
    Acceleration,
}

impl Quantity {
    /// The power `k` of `s`.
    pub fn power(self) -> u8 {
        match self {
            Quantity::Displacement => 0,
            Quantity::Velocity => 1,
            Quantity::Acceleration => 2,
        }
    }

    /// `(jω)^k`.
    pub fn factor(self, omega: f64) -> num_complex::Complex64 {
        num_complex::Complex64::new(0.0, omega).powu(self.power() as u32)
    }

    /// The FRF's name: receptance, mobility or accelerance.
    pub fn frf_name(self) -> &'static str {
        match self {
            Quantity::Displacement => "receptance",
            Quantity::Velocity => "mobility",
            Quantity::Acceleration => "accelerance",
        }
    }

    pub(super) fn is_displacement(&self) -> bool {
        *self == Quantity::Displacement
    }
}

impl<'de> Deserialize<'de> for Quantity {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(QuantityVisitor)
    }
}

/// Reads `[physical] quantity`; any other value is an error naming the key and the choices.
struct QuantityVisitor;

const QUANTITY_CHOICES: &str =
    "\"displacement\" (receptance), \"velocity\" (mobility) or \"acceleration\" (accelerance)";

impl serde::de::Visitor<'_> for QuantityVisitor {
    type Value = Quantity;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "[physical] quantity = {QUANTITY_CHOICES}")
    }

    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Quantity, E> {
        match v {
            "displacement" => Ok(Quantity::Displacement),
            "velocity" => Ok(Quantity::Velocity),
            "acceleration" => Ok(Quantity::Acceleration),
            other => Err(E::custom(format!(
                "[physical] quantity = \"{}\" is not a measured quantity: write {QUANTITY_CHOICES}",
                other.chars().take(40).collect::<String>(),
            ))),
        }
    }
}

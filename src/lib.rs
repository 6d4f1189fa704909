//! # rshape
//!
//! Consistency of measured frequency-response data with perturbed coprime-factor plant
//! models, after B. Boulet and B. A. Francis, "Consistency of open-loop experimental
//! frequency-response data with coprime factor plant models", IEEE TAC 43(12), 1998.
//!
//! The pipeline reads like the modules:
//! model and data in ([`model`], [`data`]) → per-frequency envelope of the smallest
//! consistent `|r|` ([`consistency`]) → check of a given unit `r`.
//!
//! The plant is `G = C·M̃⁻¹·Ñ·J` with factor perturbations `Δ = [Δ_N  −Δ_M]`,
//! `‖Δ(jω)‖ < |r(jω)|`, `r` a unit of RH∞.
#![warn(missing_docs)]

pub mod batch;
pub mod cli;
pub mod consistency;
pub mod data;
pub mod diagnose;
pub mod error;
pub mod fit;
pub mod model;
pub mod mu;
pub mod pipeline;
pub mod plot;
pub mod report;
pub mod stability;
pub mod synthesis;
pub mod system;
pub mod util;

pub use error::{Error, Result};

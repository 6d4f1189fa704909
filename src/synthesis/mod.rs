//! Controller synthesis for the perturbed coprime-factor model of Theorem 1: the
//! Glover–McFarlane optimum for a constant bound `r` ([`glover_mcfarlane`]), optionally on
//! a plant shaped by loop-shaping weights ([`weights`]), and the H∞ optimum for a
//! frequency-dependent `r` ([`hinf_weighted`] on the [`generalized_plant`]). The result is
//! always re-proved by the Theorem 1 test ([`crate::stability`]) before it is reported.
pub mod generalized_plant;
pub mod glover_mcfarlane;
pub mod hinf_weighted;
pub mod merit;
pub mod weights;

pub use glover_mcfarlane::{central_controller, optimum, synthesize, GmController, GmOptimum};
pub use hinf_weighted::{synthesize_weighted, WeightedController, WeightedSettings};
pub use weights::Weights;

//! Controller synthesis for the perturbed coprime-factor model of Theorem 1: the
//! Glover–McFarlane optimum for a constant bound `r` (`glover_mcfarlane`), optionally on
//! a plant shaped by loop-shaping weights (`weights`), and the H∞ optimum for a
//! frequency-dependent `r` (`hinf_weighted`, its level test `hinf_gamma`, on the
//! `generalized_plant`). The result is always re-proved by the Theorem 1 test
//! ([`crate::stability`]) before it is reported.
pub(crate) mod generalized_plant;
pub(crate) mod glover_mcfarlane;
pub(crate) mod hinf_gamma;
pub(crate) mod hinf_weighted;
pub(crate) mod merit;
pub(crate) mod weights;

pub use generalized_plant::{normalize, GeneralizedPlant, NormalizedPlant};
pub use glover_mcfarlane::{
    central_controller, check_gamma_factor, closed_loop_matrix, optimum, synthesize, GmController,
    GmOptimum,
};
pub use hinf_gamma::{gamma_test, GammaFailure, GammaSolution, GammaStep};
pub use hinf_weighted::{
    synthesize_weighted, weighted_plant, IterationStatus, WeightedController, WeightedSettings,
};
pub use merit::Merit;
pub use weights::Weights;

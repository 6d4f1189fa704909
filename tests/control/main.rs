//! Test binary `control` (tests/README.md says which binary a new test joins).
//!
//! Robust stability (Theorem 1), H-infinity norms, controller synthesis (Glover-McFarlane,
//! H-infinity with r) and model reduction.

#[path = "../common/mod.rs"]
mod common;

/// The large-model structure of the benches (one copy for every file of this binary).
#[path = "../../benches/support/modes.rs"]
#[allow(dead_code)]
mod modes;

mod certified_norm;
mod closed_loop_stability_large;
mod hinf_large_modal;
mod hinf_near_d;
mod iss_reduction;
mod loop_poles_structure;
mod modal_cascade_rows;
mod progress_stages;
mod scaling;
mod stability;
mod stability_special;
mod synthesize;
mod synthesize_hinf;
mod synthesize_modal;

//! Test binary `consistency` (tests/README.md says which binary a new test joins).
//!
//! Models and the lower envelope: frequency evaluation, physical and plant models, coprime
//! factors, the noise-free and noisy envelopes (open and closed loop, Boulet & Francis Theorems
//! 2-4, Crowder & de Callafon), mu and the paper's MIMO example.

#[path = "../common/mod.rs"]
mod common;

mod closed_loop_noise_free;
mod closed_loop_noisy;
mod closed_loop_open_loop;
mod compare_noisy;
mod envelope_stream;
mod eq8_accuracy;
mod evaluation_accuracy;
mod mu;
mod noise_model;
mod noise_zero;
mod noisy_envelope;
mod noisy_low_rank;
mod paper_mimo;
mod physical_model;
mod physical_quantity;
mod plant_ncf;
mod theorems_agree;

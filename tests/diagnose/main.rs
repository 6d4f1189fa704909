//! Test binary `diagnose` (tests/README.md says which binary a new test joins).
//!
//! Discovery of missing physical effects (`diagnose`): hidden-effect suites, real data, search
//! rules, closed-loop and multi-channel discovery.

#[path = "../common/mod.rs"]
mod common;
mod hidden;

mod closed_loop_diagnose;
mod diagnose_acceptance_rule;
mod diagnose_apply;
mod diagnose_backward;
mod diagnose_band;
mod diagnose_close_modes;
mod diagnose_ema_reference;
mod diagnose_free_beam;
mod diagnose_give_up;
mod diagnose_group_path;
mod diagnose_hidden;
mod diagnose_hidden_accelerance;
mod diagnose_hidden_robot;
mod diagnose_holdout;
mod diagnose_honest_report;
mod diagnose_mains;
mod diagnose_mimo;
mod diagnose_output_effects;
mod diagnose_path_after_elimination;
mod diagnose_path_after_holdout;
mod diagnose_progress;
mod diagnose_pyfrf;
mod diagnose_pyfrf_invalid;
mod diagnose_realdata;
mod diagnose_residual_mode;
mod diagnose_residual_mode_below;
mod diagnose_retune_changes;
mod diagnose_scan;
mod diagnose_settings;
mod diagnose_stop_explained;
mod diagnose_ties;
mod diagnose_twomass;

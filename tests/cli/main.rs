//! Test binary `cli` (tests/README.md says which binary a new test joins).
//!
//! The command line end to end: subcommands' outputs and exit codes, bad input (one-line errors,
//! exit 2, nothing half-written), batch and merge, output folders, kill safety, help texts,
//! settings validation and the figures' legibility.

#[path = "../common/mod.rs"]
mod common;

/// The large-model structure of the benches.
#[path = "../../benches/support/modes.rs"]
#[allow(dead_code)]
mod modes;

mod a1_proof;
mod a1_verdict;
mod bad_input;
mod bad_input_batch;
mod bad_input_kinds;
mod batch_cli;
mod batch_noise_files;
mod batch_vocabulary;
mod cli_help;
mod closed_loop_cli;
mod configs_every;
mod diagnose_exclude;
mod figures_extreme;
mod figures_glance;
mod fit_a1_gap;
mod fit_cut_rounds;
mod fit_proven_bound;
mod fuzz_inputs;
mod hardening_iii;
mod hardening_iii_gaps;
mod hardening_iii_minor;
mod kill_safety;
mod load_notice;
mod output_modes;
mod output_policy;
mod progress_cli;
mod quiet_output;
mod run_cli;
mod sample_time;
mod scaling_batch;
mod scaling_cli;
mod scaling_compare;
mod scaling_diagnose;
mod settings_validate;

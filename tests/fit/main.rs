//! Test binary `fit` (tests/README.md says which binary a new test joins).
//!
//! The fit of r(s): certificates, reference fitters, random envelopes, the paper's examples,
//! work reports.

#[path = "../common/mod.rs"]
mod common;

mod certificate_arm_notch;
mod certificate_cutting_plane;
mod certificate_exact;
mod fit_a1_memo;
mod fit_chain;
mod fit_defects;
mod fit_digest;
mod fit_lower_bound;
mod fit_paper;
mod fit_parallel;
mod fit_random;
mod fit_reference;
mod fit_sweep;
mod fit_sweep_rule;
mod fit_thorough;
mod fit_work_report;

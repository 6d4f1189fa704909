//! Consistency of data with the perturbed factorization: per-datum envelopes and checks
//! (Boulet & Francis 1998, BF98; theorem numbers are BF98's, whose Theorem 1 is the robust
//! stability theorem).
//!
//! What is here (the submodules are private; everything below is re-exported here):
//! * the envelope: [`Envelope`] (per datum the smallest consistent `|r(jω_i)|` and the A1
//!   limit `σ_min(M̃(jω_i))`) and how it was computed, [`EnvelopeMethod`];
//! * noise-free data (Sec. IV-A): [`noise_free_envelope`] (held in memory) and
//!   [`noise_free_envelope_rows`] (streamed from a file); per datum [`r_min_standard`]
//!   (Theorem 2, the minimum-norm perturbation of eq. (8), [`min_norm_perturbation`]) and
//!   [`r_min_special`] (Theorem 3, `1/σ_p(X)` with [`theorem3_x`]); what can fail,
//!   [`AssumptionFailure`];
//! * noisy SISO data (Sec. IV-B, Theorem 4): [`noisy_envelope`] and
//!   [`noisy_envelope_report`] ([`NoisyReport`], [`NoisyDatum`]) by a bracketed search on
//!   `|r|` ([`BisectionSettings`]); per datum [`r_min_noisy`] on the LFT
//!   [`gamma_lft`] `= F_L(V, φ⁻¹)` (eq. (15)) of the interconnection [`v_matrix`]
//!   (eqs. (13)–(14)); what can fail, [`NoisyFailure`];
//! * the check of a given unit `r` against an envelope: [`check`] ([`CheckReport`],
//!   [`CheckRow`], [`Verdict`]), consistent only where A1 holds;
//! * closed-loop data (Crowder & de Callafon): the [`closed_loop`] folder.
//!
//! The equations of each step are in the items' docs; `cargo doc --document-private-items`
//! shows the submodules' notes as well.
pub(crate) mod check;
pub mod closed_loop;
pub(crate) mod envelope;
pub(crate) mod noise_free;
pub(crate) mod noisy;
pub(crate) mod stream;

pub use check::{check, CheckReport, CheckRow, Verdict};
pub use envelope::{noise_free_envelope, Envelope, EnvelopeMethod};
pub use noise_free::{
    min_norm_perturbation, r_min_special, r_min_standard, theorem3_x, AssumptionFailure,
};
pub use noisy::{
    gamma_lft, lower_lft, noisy_envelope, noisy_envelope_report, r_min_noisy, v_matrix,
    BisectionSettings, DatumProgressFn, EnvelopeOptions, NoisyDatum, NoisyFailure, NoisyReport,
};
pub use stream::noise_free_envelope_rows;

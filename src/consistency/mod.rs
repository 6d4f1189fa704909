//! Consistency of data with the perturbed factorization: per-datum envelopes and checks.
pub mod check;
pub mod closed_loop;
pub mod envelope;
pub mod noise_free;
pub mod noisy;
pub mod stream;

pub use check::{check, CheckReport, CheckRow, Verdict};
pub use envelope::{noise_free_envelope, Envelope, EnvelopeMethod};
pub use noisy::{
    noisy_envelope, noisy_envelope_report, BisectionSettings, NoisyDatum, NoisyReport,
};

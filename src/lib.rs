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
//!
//! Full citations of every paper the documentation cites are in `docs/references.md`
//! (BF98: Boulet & Francis 1998; CdC: Crowder & de Callafon; Theorem 1 of both Boulet &
//! Francis papers is Vidyasagar's robust stability theorem).
//!
//! # Example: from a model and data to a certified `r(s)`
//!
//! A plant `1/(s(s+1))` given as `[plant]` (rshape computes its normalized left coprime
//! factors), data measured on a plant with a 10 % gain error, the envelope of Theorem 2,
//! the check of a configured `r`, and the fit of the smallest certified unit above the
//! envelope:
//!
//! ```
//! use rshape::{check, envelope, fit_unit, Config, FitSettings, FrfData, RunOptions};
//! use nalgebra::DMatrix;
//! use num_complex::Complex64;
//! use std::path::Path;
//!
//! let config = Config::parse(
//!     "[plant]\ntf = [[{ num = [1], den = [1, 1, 0] }]]\n[r]\nnum = [0.02]\nden = [1]\n",
//!     Path::new("example.toml"),
//! )?;
//! // "Measurements": the true plant 1.1/(s(s+1)) at 20 frequencies from 0.1 to 10 rad/s.
//! let omega: Vec<f64> = (0..20).map(|k| 0.1 * 100f64.powf(k as f64 / 19.0)).collect();
//! let response = omega
//!     .iter()
//!     .map(|&w| {
//!         let s = Complex64::new(0.0, w);
//!         DMatrix::from_element(1, 1, Complex64::new(1.1, 0.0) / (s * (s + 1.0)))
//!     })
//!     .collect();
//! let data = FrfData {
//!     path: "measured.csv".into(),
//!     lines: (2..22).collect(),
//!     omega,
//!     response,
//!     noise_radius: None,
//! };
//! let env = envelope(&config, &data, &RunOptions::default())?.envelope;
//! // The smallest consistent |r| per datum (Theorem 2) is finite and positive.
//! assert!(env.r_min.iter().all(|r| r.is_finite() && *r > 0.0));
//! // A constant r = 0.02 is too small for a 10 % gain error somewhere in the band.
//! let report = check(config.r.as_ref().unwrap(), &env);
//! assert!(!report.consistent);
//! // The smallest certified biproper unit of order 2 above the envelope.
//! let a1 = |w: f64| config.factorization.a1_limit(w);
//! let fit = fit_unit(&env, Some(&a1), &FitSettings { order: 2, ..Default::default() }, &Default::default())?;
//! assert!(fit.certificate.passed);
//! assert!(env.omega.iter().zip(&env.r_min).all(|(w, r)| fit.r.freq(*w).norm() >= *r * (1.0 - 1e-9)));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]
#![warn(unnameable_types)]

pub mod batch;
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
pub mod settings;
pub mod stability;
pub mod synthesis;
pub mod system;
pub mod util;

pub use error::{Error, Result};

// The curated surface: the types and calls of the pipeline, in its order.  Everything else
// is reachable at its folder (`rshape::system::hinf_norm`): the files inside `system`,
// `consistency`, `data`, `model`, `mu`, `report`, `batch` and `stability` are private.

/// Per-frequency envelope of the smallest consistent `|r|`, chosen for the config
/// ([`pipeline::envelope::envelope`]), and the check of a given `r` against it.
pub use consistency::{check, CheckReport, Envelope};
/// Data in: frequency-response measurements and their CSV reader.
pub use data::{read_frf_csv, FrfData};
/// Fit and certificate of the smallest unit `r(s)` above the envelope.
pub use fit::{fit_auto, fit_unit, Certificate, FitError, FitOptions, FitResult, FitSettings};
/// Model in: a loaded config ([`model::Config`]) and its factorization.
pub use model::{Config, Factorization};
pub use pipeline::envelope::{envelope, EnvelopeOutcome};
/// The whole `rshape run` pipeline on loaded inputs, and the options of its entry points.
pub use pipeline::{run, RunOptions, RunOutcome};
/// A settings field out of its range.
pub use settings::InvalidSetting;
/// Robust stability of a controller with a given `r` (Theorem 1).
pub use stability::analyze as robust_stability;
/// Transfer functions (`r`, entries of the factors).
pub use system::TransferFunction;

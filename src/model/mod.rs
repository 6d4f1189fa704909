//! Nominal models: coprime factorizations, the uncertainty bound `r`, and the TOML config.
pub mod closed_loop;
pub mod config;
pub mod controller;
pub mod coprime;
pub mod factorization;
pub mod noise;
pub mod physical;
pub mod plant;

pub use config::Config;
pub use factorization::{Factorization, FactorizationKind, FactorsAt};

//! rshape: consistency of frequency-response data with coprime-factor models.
pub mod system;

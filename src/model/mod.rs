//! Nominal models: coprime factorizations, the uncertainty bound `r`, and the TOML config.
//!
//! What is here (the submodules are private, except the folders [`physical`] and
//! [`closed_loop`]; everything below is re-exported here):
//! * the config file: [`Config`] (its TOML format is in its documentation) with its raw
//!   sections [`RawConfig`], [`ModelSection`], [`RSection`], [`NoiseSection`],
//!   [`ChannelSection`], [`PlantSection`] and the entries [`TfEntry`], [`RationalEntry`];
//! * the factorization `G = C·M̃⁻¹·Ñ·J` (Boulet & Francis 1998, eq. (1)): [`Factorization`],
//!   standard (`G = M̃⁻¹Ñ`, Theorem 2) or special (flexible structures, `C` constant `p×n`,
//!   `J` diagonal, Theorem 3) as [`FactorizationKind`], evaluated at one frequency as
//!   [`FactorsAt`], with [`sigma_min`] for the A1 limit;
//! * are the factors coprime and stable at all (Vidyasagar's rank test): [`check_stable`],
//!   [`check_left_coprime`], [`check_right_coprime`], [`common_zero`] ([`CommonZero`]),
//!   tolerances [`COPRIME_TOL`] and [`MAX_COFACTOR_SIZE`];
//! * the measurement noise (BF98 Sec. III, eqs. (4)–(5)): [`resolve_noise`] (sources and
//!   precedence, [`ResolvedNoise`], [`NoiseSource`]), [`resolve_noise_for_channel`],
//!   [`noise_source`], [`is_noise_free`], [`noise_radii`], and the `L∞` output-bound model
//!   [`linf_disk_radius`], [`phase_bound`], [`radii_from_output_bound`];
//! * units: `[scaling]`, `G_s = D_o·G·D_i` applied to the model, the data and a controller
//!   ([`Scaling`], [`ScalingSpec`], [`ScalingSection`], [`auto_scaling`]);
//! * a controller `K` for the robust-stability test: [`Controller`] ([`ControllerSection`],
//!   [`Feedback`]);
//! * models described by their physics: the [`physical`] folder; the closed-loop model of
//!   Crowder & de Callafon: the [`closed_loop`] folder.
pub(crate) mod a1_inverse;
pub mod closed_loop;
pub(crate) mod config;
pub(crate) mod controller;
pub(crate) mod coprime;
pub(crate) mod factorization;
pub(crate) mod noise;
pub mod physical;
pub(crate) mod plant;
pub(crate) mod scaling;

pub use config::{
    ChannelSection, Config, ModelSection, NoiseSection, RSection, RationalEntry, RawConfig, TfEntry,
};
pub use controller::{Controller, ControllerSection, Feedback};
pub use coprime::{
    check_left_coprime, check_right_coprime, check_stable, common_zero, CommonZero, COPRIME_TOL,
    MAX_COFACTOR_SIZE,
};
pub use factorization::{sigma_min, Factorization, FactorizationKind, FactorsAt};
pub use noise::{
    is_noise_free, linf_disk_radius, noise_radii, noise_source, phase_bound,
    radii_from_output_bound, resolve_noise, resolve_noise_for_channel, NoiseSource, ResolvedNoise,
};
pub use plant::PlantSection;
pub use scaling::{auto_scaling, Scaling, ScalingSection, ScalingSpec};

//! The catalogue of physical effects (docs/design/effects.md): the bottom layer of
//! [`crate::diagnose`], using nothing of the layers above.
//! * `effect`: the [`effect::Effect`] trait each effect implements, with what every effect
//!   shares (the channel selection `Sel`, the ζ bounds, a term's residue);
//! * one file per effect (`delay`, `lag`, `nmp_zero`, `zoh`, `gain`, `sign`, `mode`,
//!   `integrator`, `feedthrough`, `friction`, `mode_shift`, `damping`, `residual_mode`,
//!   `residual_mode_below`),
//!   registered below;
//! * `path`, `configured`, `coefficient` and `factor`: the four recurring shapes, a path
//!   effect on one parameter (`delay`, `lag`, `nmp_zero`, `zoh`: `OnPath`, `on_path!`), a
//!   refit of one parameter of a configured mode (`mode_shift`, `damping`: `RefitsMode`,
//!   `refits_mode!`), an added term `c_ch/s^k` of one coefficient per channel
//!   (`feedthrough`, `integrator`: `Coefficient`, `coefficient!`) and a path factor the
//!   search does not try (`gain`, `sign`: `PathFactor`, `path_factor!`), whose files hold
//!   only what differs;
//! * `candidates`: the candidate [`Cand`] (one variant per registered effect) and what it
//!   dispatches to its effect;
//! * `explain`: what each means in the data;
//! * `lscf`: mode proposals from the residual by an LSCF stabilization diagram.
//!
//! Adding an effect is one file implementing [`effect::Effect`] and one line in the
//! registration list below (docs/design/effects.md, "Adding an effect").
pub(crate) mod candidates;
pub(crate) mod coefficient;
pub(crate) mod configured;
pub(crate) mod effect;
pub(crate) mod explain;
pub(crate) mod factor;
pub(crate) mod lscf;
pub(crate) mod path;
pub(crate) mod pseudo_mode;
mod tests;

/// The registration list: declares each effect's module, makes [`Cand`] (one variant per
/// line, carrying the effect's target), [`crate::diagnose::EFFECT_NAMES`], the candidate
/// list and `with_effect!`, which calls a body with the candidate's effect.  The order is the
/// order in which the candidates are tried (path effects per channel selection first).
macro_rules! register {
    ($d:tt $( $(#[$doc:meta])* $variant:ident $(($target:ty))? => $module:ident :: $ty:ident, )*) => {
        $( pub(crate) mod $module; )*

        /// A candidate effect: one variant per registered effect, carrying its target.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Cand {
            $( $(#[$doc])* $variant $(($target))?, )*
        }

        /// The effect names of the JSON output (`retune` is the refit of the configured
        /// parameters), in the registration order.
        pub const EFFECT_NAMES: [&str; 1 + [$( stringify!($variant) ),*].len()] = [
            "retune",
            $( <$module::$ty as effect::Effect>::NAME, )*
        ];

        /// The candidates tried on a model: the path effects on each channel selection of
        /// `sels` (in turn), then the additive terms of `base`.
        pub(crate) fn tried(base: &crate::model::physical::PhysicalModel, sels: &[effect::Sel]) -> Vec<Cand> {
            let mut v = Vec::new();
            for s in sels {
                $( v.extend(<$module::$ty as effect::Effect>::tried_on(*s).into_iter().map(IntoCand::into_cand)); )*
            }
            $( v.extend(<$module::$ty as effect::Effect>::tried(base).into_iter().map(IntoCand::into_cand)); )*
            v
        }

        $(
            impl IntoCand for $module::$ty {
                fn into_cand(self) -> Cand {
                    let e = self;
                    $crate::diagnose::effects::cand_of!($variant, e $(, $target)?)
                }
            }
        )*

        /// `with_effect!(c, e => body)`: `body` with `e` the effect of candidate `c`.
        macro_rules! with_effect {
            ($d c:expr, $d e:ident => $d body:expr) => {
                match $d c {
                    $( $crate::diagnose::effects::cand_pattern!($variant, t $(, $target)?) => {
                        let $d e = $crate::diagnose::effects::effect_of!($module::$ty, t $(, $target)?);
                        $d body
                    } )*
                }
            };
        }
        pub(crate) use with_effect;
    };
}

/// The pattern of a registered variant, binding its target to `$t` when it has one.
macro_rules! cand_pattern {
    ($variant:ident, $t:ident, $target:ty) => {
        $crate::diagnose::effects::Cand::$variant($t)
    };
    ($variant:ident, $t:ident) => {
        $crate::diagnose::effects::Cand::$variant
    };
}
pub(crate) use cand_pattern;

/// An effect value as its candidate (made by the registration list; crate-private, so the
/// effect types stay private).
pub(crate) trait IntoCand {
    /// The candidate of this effect.
    fn into_cand(self) -> Cand;
}

/// The candidate of an effect value `$e` of a registered variant (its target is `$e.0`).
macro_rules! cand_of {
    ($variant:ident, $e:ident, $target:ty) => {
        $crate::diagnose::effects::Cand::$variant($e.0)
    };
    ($variant:ident, $e:ident) => {{
        let _ = $e;
        $crate::diagnose::effects::Cand::$variant
    }};
}
pub(crate) use cand_of;

/// The effect of a registered variant, from its target `$t` when it has one.
macro_rules! effect_of {
    ($module:ident :: $ty:ident, $t:ident, $target:ty) => {
        $crate::diagnose::effects::$module::$ty(*$t)
    };
    ($module:ident :: $ty:ident, $t:ident) => {
        $crate::diagnose::effects::$module::$ty
    };
}
pub(crate) use effect_of;

register! { $
    /// Pure delay `e^{−sτ}`; θ = \[τ\] (s, |τ| used).
    Delay(effect::Sel) => delay::Delay,
    /// First-order lag; θ = [ln ω_c].
    Lag(effect::Sel) => lag::Lag,
    /// NMP zero all-pass; θ = [ln z].
    NmpZero(effect::Sel) => nmp_zero::NmpZero,
    /// Zero-order hold; θ = [ln T].
    Zoh(effect::Sel) => zoh::Zoh,
    /// Gain; θ = \[k\].
    Gain(effect::Sel) => gain::Gain,
    /// Sign flip; no parameter.
    Sign(effect::Sel) => sign::Sign,
    /// Added mode `ρ_ch/(s² + 2ζω s + ω²)`; θ = [ln ω_n, ln ζ, ρ_1 … ρ_C] (one residue per
    /// channel, shared `ω_n` and `ζ`).
    Mode => mode::Mode,
    /// Added `c_ch/s^order` (order 1: integrator, 2: rigid body); θ = [c_1 … c_C].
    Integrator(u8) => integrator::Integrator,
    /// Added feedthrough; θ = [d_1 … d_C].
    Feedthrough => feedthrough::Feedthrough,
    /// Viscous friction on rigid body `i` of the base model: `1/s²` becomes
    /// `1/(s (s + p))`; θ = [ln p].
    Friction(usize) => friction::Friction,
    /// Shifted frequency of mode `i` (0-based) of the base model; θ = [ln ω_n].
    ModeShift(usize) => mode_shift::ModeShift,
    /// Changed damping of mode `i`; θ = [ln ζ].
    Damping(usize) => damping::Damping,
    /// A pseudo-mode above the band, a residual term (tried once the upper residual is in
    /// the model); θ = [ln ω_n, ρ_1 … ρ_C].
    ResidualMode => residual_mode::ResidualMode,
    /// A pseudo-mode below the band, a residual term (tried once the lower residual, a
    /// rigid body, is in the model); θ = [ln ω_n, ρ_1 … ρ_C].
    ResidualModeBelow => residual_mode_below::ResidualModeBelow,
}

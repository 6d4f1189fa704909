//! What the path effects on one parameter share (`delay`, `lag`, `nmp_zero`, `zoh`): each
//! multiplies the path of the channels it selects ([`Sel`]) by a factor of one parameter
//! `x` (a corner, a zero, a hold time: θ = ln x; a delay: θ = τ, `|τ|` used), is written as
//! one [`EffectSpec`] field, and is negligible when its phase at the band top is below the
//! noise's phase resolution there.  An effect of this shape implements [`OnPath`] (only
//! what differs) and gets its [`Effect`] methods from `on_path!(Type)`.

use crate::diagnose::effects::effect::{sig, Band, Explain, Sel, Site};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

#[allow(unused_imports)] // for the docs
use crate::diagnose::effects::effect::Effect;

/// A path effect on one parameter: what differs between them.
pub trait OnPath: Copy {
    /// The effect's name ([`Effect::NAME`]).
    const NAME: &'static str;
    /// The kind of path effect it is written as.
    const KIND: EffectKind;
    /// The name of its SI parameter (`tau_s`, `omega_c`, `z`, `t_s`).
    const SI: &'static str;
    /// True when θ is the parameter's logarithm (typical magnitude 1); false when θ is the
    /// delay τ itself (`|τ|` used, typical magnitude `1/ω_max`, SI σ = σ_θ).
    const LOG: bool;
    /// True when it is tried on one output (a sensor) as well as on every channel and each
    /// input.
    const ON_SENSOR: bool;

    /// The effect on the channels `sel`.
    fn on(sel: Sel) -> Self;
    /// The channels it acts on.
    fn channels(&self) -> Sel;
    /// Box bounds of θ for data over `[ω_min, ω_max]`.
    fn bounds_in(w_min: f64, w_max: f64) -> (f64, f64);
    /// Multiplies `path` at `ω` by its factor with the natural parameter `x`.
    fn apply(x: f64, omega: f64, path: &mut Complex64);
    /// `∂ ln f/∂x` of that factor `f` at `ω` (closed form, for the analytic Jacobian of a
    /// fit of the effect alone, [`Effect::path_log_slope`]).
    fn log_slope(x: f64, omega: f64) -> Complex64;
    /// Sets its parameter `v` (SI) in the written spec.
    fn set(e: &mut EffectSpec, v: f64);
    /// The phase it adds at the band top `w_hi` as written in `e`, and its words in the
    /// negligible rule (`a delay of … s lags …°`); `None` when `e` lacks the parameter.
    fn top_phase(e: &EffectSpec, w_hi: f64) -> Option<(f64, String)>;
    /// Why the fitted natural parameter `x` is physically implausible in `band`, if it is
    /// (checked before the at-bound flag, which it replaces).
    fn implausible(x: f64, band: Band) -> Option<String>;
    /// [`Effect::explain`].
    fn says(&self, x: &Explain) -> String;
    /// [`Effect::prior`].
    fn rank() -> usize;
    /// [`Effect::starts`].
    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>>;
}

/// The natural parameter of θ: `exp θ` or `|τ|`.
pub(crate) fn natural_of<T: OnPath>(th: f64) -> f64 {
    if T::LOG {
        th.exp()
    } else {
        th.abs()
    }
}

/// `∂x/∂θ` of [`natural_of`]: `x` for a logarithm, the sign of `τ` for a delay (`+1` at 0,
/// the side a forward difference sees).
pub(crate) fn dnatural_of<T: OnPath>(th: f64) -> f64 {
    if T::LOG {
        th.exp()
    } else if th >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// `on_path!(Type)`: implements [`Effect`] for `Type`, which implements [`OnPath`] (a
/// macro, not a blanket impl: two blanket impls of [`Effect`] would overlap).
macro_rules! on_path {
    ($t:ty) => {
        const _: () = {
            use $crate::diagnose::effects::effect::{
                at_bound_flag, last, one, sig, Band, Effect, Explain, Param, Resolution, Sel, Si,
                Site, Stands, Writer,
            };
            use $crate::diagnose::effects::path::{dnatural_of, natural_of, OnPath};
            use $crate::model::physical::PhysicalModel;
            use num_complex::Complex64;

            type T = $t;

            impl Effect for T {
                const NAME: &'static str = <T as OnPath>::NAME;

                fn tried_on(sel: Sel) -> Vec<Self> {
                    if matches!(sel, Sel::Output(_)) && !<T as OnPath>::ON_SENSOR {
                        vec![]
                    } else {
                        vec![<T as OnPath>::on(sel)]
                    }
                }

                fn tried(_: &PhysicalModel) -> Vec<Self> {
                    vec![]
                }

                fn sel(&self) -> Option<Sel> {
                    Some(self.channels())
                }

                fn n_params(&self, _: usize) -> usize {
                    1
                }

                fn typ(&self, _: &[f64], omega_max: f64) -> Vec<f64> {
                    vec![if <T as OnPath>::LOG { 1.0 } else { 1.0 / omega_max }]
                }

                fn bounds(&self, _: usize, w_min: f64, w_max: f64, _: f64) -> Vec<(f64, f64)> {
                    vec![<T as OnPath>::bounds_in(w_min, w_max)]
                }

                fn natural(&self, th: &[f64], nat: &mut [f64]) {
                    nat[0] = natural_of::<T>(th[0]);
                }

                fn base_residue(&self, _: &PhysicalModel, _: (usize, usize)) -> f64 {
                    0.0
                }

                fn modify(
                    &self,
                    nat: &[f64],
                    _: f64,
                    _: &PhysicalModel,
                    omega: f64,
                    _: usize,
                    entry: (usize, usize),
                    _: &mut Complex64,
                    path: &mut Complex64,
                ) {
                    if self.channels().hits(entry) {
                        <T as OnPath>::apply(nat[0], omega, path);
                    }
                }

                fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
                    let x = natural_of::<T>(th[0]);
                    one(<T as OnPath>::SI, x, if <T as OnPath>::LOG { x } else { 1.0 })
                }

                fn write(&self, w: &mut Writer) {
                    let v = w.get(<T as OnPath>::SI);
                    w.path_effect(<T as OnPath>::KIND, &self.channels(), &|e| <T as OnPath>::set(e, v));
                }

                fn explain(&self, x: &Explain) -> String {
                    self.says(x)
                }

                fn prior(&self) -> usize {
                    <T as OnPath>::rank()
                }

                fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
                    self.grid(site)
                }

                fn flags(
                    &self,
                    th: &[f64],
                    at: &dyn Fn(usize) -> bool,
                    si: &Si,
                    band: Band,
                    out: &mut Vec<String>,
                ) {
                    if let Some(f) = <T as OnPath>::implausible(natural_of::<T>(th[0]), band) {
                        out.push(f);
                    } else if at(0) {
                        out.push(at_bound_flag(si));
                    }
                }

                fn stands(&self) -> Stands {
                    Stands::AddedPathEffect
                }

                fn lacks_its_term(&self, _: &PhysicalModel) -> bool {
                    false
                }

                fn its_mode(&self, _: &PhysicalModel) -> Option<usize> {
                    None
                }

                fn term_alone(&self, _: &PhysicalModel) -> Option<PhysicalModel> {
                    None
                }

                fn below_resolution(&self, m: &PhysicalModel, r: &Resolution) -> Option<String> {
                    let (phase, what) = <T as OnPath>::top_phase(m.effect.last()?, r.w_hi)?;
                    (phase < r.phase_top).then(|| {
                        format!(
                            "{what} at the band top, below the noise's phase resolution there ({}°)",
                            sig(r.phase_top.to_degrees())
                        )
                    })
                }

                fn owns(&self, m: &PhysicalModel) -> Vec<Param> {
                    last(m.effect.len()).map(Param::PathEffect).into_iter().collect()
                }

                fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
                    0.0
                }

                fn path_log_slope(&self, th: f64, omega: f64) -> Option<Complex64> {
                    Some(<T as OnPath>::log_slope(natural_of::<T>(th), omega) * dnatural_of::<T>(th))
                }
            }
        };
    };
}
pub(crate) use on_path;

/// The words of a phase shift `phase` (rad) in the negligible rule of a lag, an NMP zero or
/// a hold.
pub fn shifts_phase(phase: f64) -> Option<(f64, String)> {
    Some((
        phase,
        format!("it shifts the phase by {}°", sig(phase.to_degrees())),
    ))
}

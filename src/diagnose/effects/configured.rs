//! What the refits of one parameter of a configured mode share (`mode_shift`, `damping`):
//! the effect changes `ω_n` or `ζ` of mode `i` of the configured model (θ = [ln ω_n] or
//! [ln ζ]), replacing its term `ρ/(s² + 2ζω s + ω²)` with the refit one; it is written back
//! into that mode, stands there, and owns that one parameter.  An effect of this shape
//! implements [`RefitsMode`] (only what differs) and gets its [`Effect`] methods from
//! `refits_mode!(Type)`.

use crate::diagnose::effects::effect::{clamp_zeta, Explain, Site};

#[allow(unused_imports)] // for the docs
use crate::diagnose::effects::effect::Effect;

/// The parameter of a configured mode an effect refits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeParam {
    /// `ω_n` (SI name `omega_n`).
    Omega,
    /// `ζ` (SI name `zeta`, clamped to [`crate::diagnose::effects::effect::ZETA_BOUNDS`]).
    Zeta,
}

/// A refit of one parameter of a configured mode: what differs between them.
pub trait RefitsMode: Copy {
    /// The effect's name ([`Effect::NAME`]).
    const NAME: &'static str;
    /// The parameter it refits.
    const PARAM: ModeParam;
    /// The flag when θ sits at its bound (`None`: no flag).
    const AT_BOUND: Option<&'static str>;

    /// The configured mode it changes (0-based).
    fn mode(&self) -> usize;
    /// Box bounds of θ for data over `[ω_min, ω_max]` and the record's ζ floor `zeta_lo`.
    fn bounds_in(w_min: f64, w_max: f64, zeta_lo: f64) -> (f64, f64);
    /// [`Effect::explain`].
    fn says(&self, x: &Explain) -> String;
    /// [`Effect::prior`].
    fn rank() -> usize;
    /// [`Effect::starts`].
    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>>;
}

/// The refit parameter from θ: `exp θ`, a damping ratio clamped.
pub(crate) fn natural_of<T: RefitsMode>(th: f64) -> f64 {
    match T::PARAM {
        ModeParam::Omega => th.exp(),
        ModeParam::Zeta => clamp_zeta(th.exp()),
    }
}

pub(crate) fn si_name<T: RefitsMode>() -> &'static str {
    match T::PARAM {
        ModeParam::Omega => "omega_n",
        ModeParam::Zeta => "zeta",
    }
}

/// `refits_mode!(Type)`: implements [`Effect`] for `Type`, which implements [`RefitsMode`] (a
/// macro, not a blanket impl: two blanket impls of [`Effect`] would overlap).
macro_rules! refits_mode {
    ($t:ty) => {
        const _: () = {
            use num_complex::Complex64;
            use $crate::diagnose::effects::configured::{
                natural_of, si_name, ModeParam, RefitsMode,
            };
            use $crate::diagnose::effects::effect::{
                one, residue, Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands,
                Writer,
            };
            use $crate::diagnose::effects::mode::mode_term;
            use $crate::model::physical::PhysicalModel;

            type T = $t;

            impl Effect for T {
                const NAME: &'static str = <T as RefitsMode>::NAME;

                fn tried_on(_: Sel) -> Vec<Self> {
                    vec![]
                }

                fn tried(_: &PhysicalModel) -> Vec<Self> {
                    vec![]
                }

                fn sel(&self) -> Option<Sel> {
                    None
                }

                fn n_params(&self, _: usize) -> usize {
                    1
                }

                fn typ(&self, _: &[f64], _: f64) -> Vec<f64> {
                    vec![1.0]
                }

                fn bounds(
                    &self,
                    _: usize,
                    w_min: f64,
                    w_max: f64,
                    zeta_lo: f64,
                ) -> Vec<(f64, f64)> {
                    vec![<T as RefitsMode>::bounds_in(w_min, w_max, zeta_lo)]
                }

                fn natural(&self, th: &[f64], nat: &mut [f64]) {
                    nat[0] = natural_of::<T>(th[0]);
                }

                fn base_residue(&self, base: &PhysicalModel, entry: (usize, usize)) -> f64 {
                    let md = &base.mode[self.mode()];
                    let (p, m) = (base.n_outputs(), base.n_inputs());
                    residue(&md.output_gain, &md.input_gain, md.mass, p, m, entry)
                }

                fn modify(
                    &self,
                    nat: &[f64],
                    rho: f64,
                    base: &PhysicalModel,
                    omega: f64,
                    _: usize,
                    _: (usize, usize),
                    core: &mut Complex64,
                    _: &mut Complex64,
                ) {
                    let md = &base.mode[self.mode()];
                    let (w, z) = match <T as RefitsMode>::PARAM {
                        ModeParam::Omega => (nat[0], md.zeta),
                        ModeParam::Zeta => (md.omega_n, nat[0]),
                    };
                    *core +=
                        mode_term(omega, w, z, rho) - mode_term(omega, md.omega_n, md.zeta, rho);
                }

                fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
                    let mut v = one("mode", (self.mode() + 1) as f64, 0.0);
                    let x = natural_of::<T>(th[0]);
                    v.extend(one(si_name::<T>(), x, x));
                    v
                }

                fn write(&self, w: &mut Writer) {
                    let v = w.get(si_name::<T>());
                    let md = &mut w.m.mode[self.mode()];
                    match <T as RefitsMode>::PARAM {
                        ModeParam::Omega => md.omega_n = v,
                        ModeParam::Zeta => md.zeta = v,
                    }
                }

                fn explain(&self, x: &Explain) -> String {
                    self.says(x)
                }

                fn prior(&self) -> usize {
                    <T as RefitsMode>::rank()
                }

                fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
                    self.grid(site)
                }

                fn flags(
                    &self,
                    _: &[f64],
                    at: &dyn Fn(usize) -> bool,
                    _: &Si,
                    _: Band,
                    out: &mut Vec<String>,
                ) {
                    if let Some(flag) = <T as RefitsMode>::AT_BOUND {
                        if at(0) {
                            out.push(flag.into());
                        }
                    }
                }

                fn stands(&self) -> Stands {
                    Stands::ConfiguredMode(self.mode())
                }

                fn lacks_its_term(&self, m: &PhysicalModel) -> bool {
                    self.mode() >= m.mode.len()
                }

                fn its_mode(&self, _: &PhysicalModel) -> Option<usize> {
                    Some(self.mode())
                }

                fn term_alone(&self, _: &PhysicalModel) -> Option<PhysicalModel> {
                    None
                }

                fn below_resolution(&self, _: &PhysicalModel, _: &Resolution) -> Option<String> {
                    None
                }

                fn owns(&self, _: &PhysicalModel) -> Vec<Param> {
                    vec![match <T as RefitsMode>::PARAM {
                        ModeParam::Omega => Param::ModeOmega(self.mode()),
                        ModeParam::Zeta => Param::ModeZeta(self.mode()),
                    }]
                }

                fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
                    0.0
                }
            }
        };
    };
}
pub(crate) use refits_mode;

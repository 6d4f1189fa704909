//! What the added terms of one coefficient per channel share (`feedthrough`, `integrator`):
//! the effect adds `c_ch / s^k` to the core of each channel (k = 0: the feedthrough `D`; 1: an
//! integrator; 2: a rigid body or the lower residual), θ = [c_1 … c_C], unbounded, linear in
//! the model (typical magnitude `|c|`, natural = internal); each `c_ch` starts at the
//! noise-weighted least-squares coefficient of the residual on `path / s^k`.  It changes no
//! configured term, has no mode, no size rule of its own and no "same set" distance.  An
//! effect of this shape implements [`Coefficient`] (only what differs) and gets its
//! [`Effect`] methods from `coefficient!(Type)`.

use crate::diagnose::effects::effect::{Band, Explain, Param, Stands, Writer};
use crate::model::physical::PhysicalModel;

#[allow(unused_imports)] // for the docs
use crate::diagnose::effects::effect::Effect;

/// An added term of one coefficient per channel: what differs between them.
pub trait Coefficient: Copy {
    /// The effect's name ([`Effect::NAME`]).
    const NAME: &'static str;
    /// The SI name of the coefficients (`d`, `c`; `d_<out>_<in>` with several channels).
    const SI: &'static str;

    /// [`Effect::tried`].
    fn tried(base: &PhysicalModel) -> Vec<Self>;
    /// The power `k` of the term `c/s^k` it adds.
    fn power(&self) -> u8;
    /// Labels written before the coefficients in [`Effect::si_params`] (SI factor 0).
    fn labels(&self) -> Vec<(String, f64, f64)>;
    /// [`Effect::write`].
    fn write_into(&self, w: &mut Writer);
    /// [`Effect::explain`].
    fn says(&self, x: &Explain) -> String;
    /// [`Effect::prior`].
    fn rank() -> usize;
    /// Why the term is physically implausible on the measured quantity of `band`, if it is
    /// ([`Effect::flags`]).
    fn implausible(&self, band: Band) -> Option<String>;
    /// [`Effect::stands`].
    fn stands_as(&self) -> Stands;
    /// [`Effect::term_alone`].
    fn alone(&self, m: &PhysicalModel) -> Option<PhysicalModel>;
    /// [`Effect::owns`].
    fn owned(&self, m: &PhysicalModel) -> Vec<Param>;
}

/// `coefficient!(Type)`: implements [`Effect`] for `Type`, which implements [`Coefficient`] (a
/// macro, not a blanket impl: two blanket impls of [`Effect`] would overlap).
macro_rules! coefficient {
    ($t:ty) => {
        const _: () = {
            use num_complex::Complex64;
            use $crate::diagnose::effects::coefficient::Coefficient;
            use $crate::diagnose::effects::effect::{
                per_channel, Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands,
                Writer,
            };
            use $crate::model::physical::PhysicalModel;

            type T = $t;

            /// `s^k` at `ω`.
            fn s_power(t: &T, omega: f64) -> Complex64 {
                Complex64::new(0.0, omega).powi(t.power() as i32)
            }

            impl Effect for T {
                const NAME: &'static str = <T as Coefficient>::NAME;

                fn tried_on(_: Sel) -> Vec<Self> {
                    vec![]
                }

                fn tried(base: &PhysicalModel) -> Vec<Self> {
                    <T as Coefficient>::tried(base)
                }

                fn sel(&self) -> Option<Sel> {
                    None
                }

                fn n_params(&self, n_ch: usize) -> usize {
                    n_ch
                }

                fn typ(&self, theta: &[f64], _: f64) -> Vec<f64> {
                    theta.iter().map(|x| x.abs().max(1e-300)).collect()
                }

                fn bounds(&self, n_ch: usize, _: f64, _: f64, _: f64) -> Vec<(f64, f64)> {
                    vec![(f64::NEG_INFINITY, f64::INFINITY); n_ch]
                }

                fn natural(&self, _: &[f64], _: &mut [f64]) {}

                fn base_residue(&self, _: &PhysicalModel, _: (usize, usize)) -> f64 {
                    0.0
                }

                fn modify(
                    &self,
                    nat: &[f64],
                    _: f64,
                    _: &PhysicalModel,
                    omega: f64,
                    ch: usize,
                    _: (usize, usize),
                    core: &mut Complex64,
                    _: &mut Complex64,
                ) {
                    *core += nat[ch] / s_power(self, omega);
                }

                fn si_params(
                    &self,
                    th: &[f64],
                    entries: &[(usize, usize)],
                ) -> Vec<(String, f64, f64)> {
                    let mut v = self.labels();
                    v.extend(per_channel(<T as Coefficient>::SI, th, 0, entries));
                    v
                }

                fn write(&self, w: &mut Writer) {
                    self.write_into(w)
                }

                fn explain(&self, x: &Explain) -> String {
                    self.says(x)
                }

                fn prior(&self) -> usize {
                    <T as Coefficient>::rank()
                }

                /// Each channel's coefficient by least squares on `path/s^k`.
                fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
                    let om = site.omega();
                    vec![(0..site.n_ch())
                        .map(|ch| site.ls(&[ch], &|ch, k| site.path(ch, k) / s_power(self, om[k])))
                        .collect()]
                }

                fn flags(
                    &self,
                    _: &[f64],
                    _: &dyn Fn(usize) -> bool,
                    _: &Si,
                    band: Band,
                    out: &mut Vec<String>,
                ) {
                    out.extend(self.implausible(band));
                }

                fn stands(&self) -> Stands {
                    self.stands_as()
                }

                fn lacks_its_term(&self, _: &PhysicalModel) -> bool {
                    false
                }

                fn its_mode(&self, _: &PhysicalModel) -> Option<usize> {
                    None
                }

                fn term_alone(&self, m: &PhysicalModel) -> Option<PhysicalModel> {
                    self.alone(m)
                }

                fn below_resolution(&self, _: &PhysicalModel, _: &Resolution) -> Option<String> {
                    None
                }

                fn owns(&self, m: &PhysicalModel) -> Vec<Param> {
                    self.owned(m)
                }

                fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
                    0.0
                }
            }
        };
    };
}
pub(crate) use coefficient;

//! What the path factors the search does not try share (`gain`, `sign`): the effect
//! multiplies the path of the channels it selects ([`Sel`]) by a factor whose parameters are
//! their SI values (θ = SI, linear, typical magnitude `|θ|`, bounded to ±1000), is written as
//! one [`EffectSpec`] of its kind with the note, and has no plausibility flag, no size rule,
//! no mode and no term alone.  The search leaves them to the retune (which refits the
//! model's own gains and signs); `compare` revisions and library users name them.  An effect
//! of this shape implements [`PathFactor`] (only what differs) and gets its [`Effect`]
//! methods from `path_factor!(Type)`.

use crate::diagnose::effects::effect::{Explain, Sel, Site};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

#[allow(unused_imports)] // for the docs
use crate::diagnose::effects::effect::Effect;

/// A path factor the search does not try: what differs between them.
pub trait PathFactor: Copy {
    /// The effect's name ([`Effect::NAME`]).
    const NAME: &'static str;
    /// The kind of path effect it is written as.
    const KIND: EffectKind;
    /// The SI names of its parameters, in θ's order (none for a fixed factor).
    const PARAMS: &'static [&'static str];

    /// The channels it acts on.
    fn channels(&self) -> Sel;
    /// Multiplies `path` by its factor with the parameters `nat`.
    fn apply(nat: &[f64], path: &mut Complex64);
    /// Sets its parameters `v` (in [`PathFactor::PARAMS`] order) in the written spec.
    fn set(e: &mut EffectSpec, v: &[f64]);
    /// [`Effect::explain`].
    fn says(&self, x: &Explain) -> String;
    /// [`Effect::prior`].
    fn rank() -> usize;
    /// [`Effect::starts`].
    fn start(&self, site: &dyn Site) -> Vec<Vec<f64>>;
}

/// `path_factor!(Type)`: implements [`Effect`] for `Type`, which implements [`PathFactor`]
/// (a macro, not a blanket impl: two blanket impls of [`Effect`] would overlap).
macro_rules! path_factor {
    ($t:ty) => {
        const _: () = {
            use num_complex::Complex64;
            use $crate::diagnose::effects::effect::{
                Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands, Writer,
            };
            use $crate::diagnose::effects::factor::PathFactor;
            use $crate::model::physical::PhysicalModel;

            type T = $t;

            impl Effect for T {
                const NAME: &'static str = <T as PathFactor>::NAME;

                fn tried_on(_: Sel) -> Vec<Self> {
                    vec![]
                }

                fn tried(_: &PhysicalModel) -> Vec<Self> {
                    vec![]
                }

                fn sel(&self) -> Option<Sel> {
                    Some(self.channels())
                }

                fn n_params(&self, _: usize) -> usize {
                    <T as PathFactor>::PARAMS.len()
                }

                fn typ(&self, theta: &[f64], _: f64) -> Vec<f64> {
                    theta.iter().map(|x| x.abs().max(1e-300)).collect()
                }

                fn bounds(&self, _: usize, _: f64, _: f64, _: f64) -> Vec<(f64, f64)> {
                    vec![(-1e3, 1e3); <T as PathFactor>::PARAMS.len()]
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
                    _: f64,
                    _: usize,
                    entry: (usize, usize),
                    _: &mut Complex64,
                    path: &mut Complex64,
                ) {
                    if self.channels().hits(entry) {
                        <T as PathFactor>::apply(nat, path);
                    }
                }

                fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
                    <T as PathFactor>::PARAMS
                        .iter()
                        .zip(th)
                        .map(|(n, v)| (n.to_string(), *v, 1.0))
                        .collect()
                }

                fn write(&self, w: &mut Writer) {
                    let v: Vec<f64> = <T as PathFactor>::PARAMS.iter().map(|n| w.get(n)).collect();
                    w.path_effect(<T as PathFactor>::KIND, &self.channels(), &|e| {
                        <T as PathFactor>::set(e, &v)
                    });
                }

                fn explain(&self, x: &Explain) -> String {
                    self.says(x)
                }

                fn prior(&self) -> usize {
                    <T as PathFactor>::rank()
                }

                fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
                    self.start(site)
                }

                fn flags(
                    &self,
                    _: &[f64],
                    _: &dyn Fn(usize) -> bool,
                    _: &Si,
                    _: Band,
                    _: &mut Vec<String>,
                ) {
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

                fn below_resolution(&self, _: &PhysicalModel, _: &Resolution) -> Option<String> {
                    None
                }

                fn owns(&self, _: &PhysicalModel) -> Vec<Param> {
                    vec![]
                }

                fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
                    0.0
                }
            }
        };
    };
}
pub(crate) use path_factor;

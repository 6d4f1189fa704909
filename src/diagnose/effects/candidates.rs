//! Candidate missing effects: the candidate [`Cand`] (one variant per effect registered in
//! [`crate::diagnose::effects`]) and what it asks of its effect ([`Effect`]): how it
//! modifies the model, its parameters (internal and SI), its bounds, and how it is written
//! back into a physical model.
//!
//! The current model at datum `k` of channel `(o, i)` is held as `G = core · path` (the
//! additive dynamics times the product of the path effects).  A candidate either multiplies
//! `path` (delay, lag, gain, sign, ZOH, NMP zero: on every channel, on one output or on one
//! input, [`Sel`]) or changes `core` (added mode, shifted or re-damped mode, integrator or
//! rigid body, feedthrough).  An added mode is the modal model of docs/design/effects.md: one `ω_n`
//! and `ζ` shared by every channel and a residue per channel.  Positive parameters are fitted
//! in logarithms.

use crate::diagnose::effects::effect::{
    Band, Effect, Explain, Param, Resolution, Site, Stands, Writer,
};
use crate::diagnose::effects::with_effect;
use crate::model::physical::PhysicalModel;
use num_complex::Complex64;
use std::collections::BTreeMap;

pub use crate::diagnose::effects::{Cand, EFFECT_NAMES};

pub use crate::diagnose::effects::effect::Sel;
pub use crate::report::fmt::{fmt_w, sig};

/// Names of modes and terms `diagnose` adds start with this.
pub const ADDED_NOTE: &str = "added by rshape diagnose";

/// The name of effect `E`.
fn name_of<E: Effect>(_: &E) -> &'static str {
    E::NAME
}

impl Cand {
    /// The effect name.
    pub fn name(&self) -> &'static str {
        with_effect!(self, e => name_of(&e))
    }

    /// The name with the channel selection of a path effect (`delay (output 2)`).
    pub fn label(&self) -> String {
        with_effect!(self, e => match e.sel() {
            Some(s) => format!("{}{}", name_of(&e), s.suffix()),
            None => name_of(&e).into(),
        })
    }

    /// Number of fitted parameters with `n_ch` channels.
    pub fn n_params(&self, n_ch: usize) -> usize {
        with_effect!(self, e => e.n_params(n_ch))
    }

    /// True when the candidate can change channel `entry`: an additive term changes every
    /// channel, a path effect those its selection hits ([`Sel::hits`]; its `modify` leaves
    /// the others as they are).
    pub fn acts_on(&self, entry: (usize, usize)) -> bool {
        with_effect!(self, e => e.sel().is_none_or(|s| s.hits(entry)))
    }

    /// True for effects that multiply the model (spread over the band): the path effects.
    pub fn multiplicative(&self) -> bool {
        with_effect!(self, e => e.sel().is_some())
    }

    /// Typical magnitude of each internal parameter (for finite differences).
    pub fn typ(&self, theta: &[f64], omega_max: f64) -> Vec<f64> {
        with_effect!(self, e => e.typ(theta, omega_max))
    }

    /// Box bounds `(lo, hi)` of each internal parameter for data over `[ω_min, ω_max]`
    /// (docs/design/effects.md step 3): an added mode resonates inside the band (an out-of-band one is a
    /// compliance or mass line: the feedthrough and rigid-body candidates), `ζ ∈ [ζ_lo, 0.7]` (`ζ_lo` the
    /// record's floor, `lsq::resolution::band_floor`),
    /// corners and zeros within two decades of the band, a delay below 100/ω_min.
    pub fn bounds(&self, n_ch: usize, w_min: f64, w_max: f64, zeta_lo: f64) -> Vec<(f64, f64)> {
        with_effect!(self, e => e.bounds(n_ch, w_min, w_max, zeta_lo))
    }

    /// The parameters [`Cand::modify_natural`] uses, from the internal ones `th` (appended
    /// to `out`): `exp` of the log-parameters, `|τ|`, `ζ` clamped.  A residual computes them
    /// once per model instead of once per datum.
    pub fn natural(&self, th: &[f64], out: &mut Vec<f64>) {
        let start = out.len();
        out.extend_from_slice(th);
        with_effect!(self, e => e.natural(th, &mut out[start..]))
    }

    /// Modifies `(core, path)` of channel `ch` (model entry `entry`) at `ω` with parameters
    /// `th`; `base` gives the modes that `ModeShift`, `Damping` and `Friction` refer to.
    #[allow(clippy::too_many_arguments)]
    pub fn modify(
        &self,
        th: &[f64],
        base: &PhysicalModel,
        omega: f64,
        ch: usize,
        entry: (usize, usize),
        core: &mut Complex64,
        path: &mut Complex64,
    ) {
        let mut nat = Vec::with_capacity(th.len());
        self.natural(th, &mut nat);
        let rho = self.base_residue(base, entry);
        self.modify_natural(&nat, rho, base, omega, ch, entry, core, path);
    }

    /// The residue at model entry `entry` of the configured term a candidate changes (the
    /// mode of `ModeShift` and `Damping`, the rigid body of `Friction`); 0 for the others.
    pub fn base_residue(&self, base: &PhysicalModel, entry: (usize, usize)) -> f64 {
        with_effect!(self, e => e.base_residue(base, entry))
    }

    /// [`Cand::modify`] with the parameters of [`Cand::natural`] and the configured term's
    /// residue `rho` ([`Cand::base_residue`]: a residual computes it once per channel, not
    /// once per datum).
    #[allow(clippy::too_many_arguments)]
    pub fn modify_natural(
        &self,
        nat: &[f64],
        rho: f64,
        base: &PhysicalModel,
        omega: f64,
        ch: usize,
        entry: (usize, usize),
        core: &mut Complex64,
        path: &mut Complex64,
    ) {
        with_effect!(self, e => e.modify(nat, rho, base, omega, ch, entry, core, path))
    }

    /// [`Cand::modify_natural`] at the data `ks` of channel `ch` (frequencies `omega[k]`),
    /// `core[q]` and `path[q]` belonging to datum `ks[q]`: the effect is looked up once,
    /// not once per datum, and each datum gets the same operations as one call of
    /// [`Cand::modify_natural`] (the same values, bit for bit).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn modify_natural_many(
        &self,
        nat: &[f64],
        rho: f64,
        base: &PhysicalModel,
        omega: &[f64],
        ks: &[usize],
        ch: usize,
        entry: (usize, usize),
        core: &mut [Complex64],
        path: &mut [Complex64],
    ) {
        with_effect!(self, e => {
            for ((&k, c), p) in ks.iter().zip(core.iter_mut()).zip(path.iter_mut()) {
                e.modify(nat, rho, base, omega[k], ch, entry, c, p);
            }
        })
    }

    /// `∂ ln f/∂θ` at `ω` of a one-parameter path effect's factor (the effect's
    /// `path_log_slope`); `None` for the other effects.
    pub fn path_log_slope(&self, th: f64, omega: f64) -> Option<Complex64> {
        with_effect!(self, e => e.path_log_slope(th, omega))
    }

    /// The SI parameters `(name, value, factor)` from the internal ones; `factor` turns an
    /// internal standard deviation into an SI one (0 for labels).  Per-channel residues are
    /// named `rho`, `c`, `d` for one channel, else `rho_<out>_<in>` (1-based).
    pub fn si_params(&self, th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        with_effect!(self, e => e.si_params(th, entries))
    }

    /// Writes the effect into a physical model.  An additive term with a residue per
    /// channel is written as output gains (one input) or input gains (one output).
    pub fn apply_to(
        &self,
        th: &[f64],
        entries: &[(usize, usize)],
        m: &mut PhysicalModel,
        note: &str,
    ) {
        let si = self.si_params(th, entries);
        let mut w = Writer {
            th,
            entries,
            m,
            note,
            si,
        };
        with_effect!(self, e => e.write(&mut w))
    }

    /// The plain-language explanation of the effect's signature in the data
    /// ([`crate::diagnose::effects::explain::explain`]).
    pub(crate) fn explain_with(&self, x: &Explain) -> String {
        with_effect!(self, e => e.explain(x))
    }

    /// Prior rank among near-ties (lower first): fewer assumptions first.
    pub fn prior(&self) -> usize {
        with_effect!(self, e => e.prior())
    }

    /// Starting points of the candidate's parameters on the least-squares problem `site`.
    pub(crate) fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        with_effect!(self, e => e.starts(site))
    }

    /// Physical plausibility flags of a fit with internal parameters `th` (`at(i)`: θ_i at
    /// its bound; `si`: the SI parameters by name).
    pub(crate) fn flags(
        &self,
        th: &[f64],
        at: &dyn Fn(usize) -> bool,
        si: &BTreeMap<String, f64>,
        band: Band,
        out: &mut Vec<String>,
    ) {
        with_effect!(self, e => e.flags(th, at, si, band, out))
    }

    /// Where the candidate stands in a written model.
    pub(crate) fn stands(&self) -> Stands {
        with_effect!(self, e => e.stands())
    }

    /// True when `m` lacks the configured term the candidate acts on (friction on a rigid
    /// body, or a changed mode, that a holdout or elimination set left out).
    pub fn lacks_its_term(&self, m: &PhysicalModel) -> bool {
        with_effect!(self, e => e.lacks_its_term(m))
    }

    /// The mode the candidate adds or changes in its refit model `m` ([`Effect::its_mode`]).
    pub(crate) fn its_mode(&self, m: &PhysicalModel) -> Option<usize> {
        with_effect!(self, e => e.its_mode(m))
    }

    /// Its term alone in a bare copy of `m` ([`Effect::term_alone`]).
    pub(crate) fn term_alone(&self, m: &PhysicalModel) -> Option<PhysicalModel> {
        with_effect!(self, e => e.term_alone(m))
    }

    /// Why it is below what the noise resolves ([`Effect::below_resolution`]).
    pub(crate) fn below_resolution(&self, m: &PhysicalModel, r: &Resolution) -> Option<String> {
        with_effect!(self, e => e.below_resolution(m, r))
    }

    /// The parameters of its refit model `m` it owns ([`Effect::owns`]).
    pub(crate) fn owns(&self, m: &PhysicalModel) -> Vec<Param> {
        with_effect!(self, e => e.owns(m))
    }

    /// How far apart two fits of the candidate are ([`Effect::apart`]).
    pub(crate) fn apart(&self, a: &[f64], b: &[f64]) -> f64 {
        with_effect!(self, e => e.apart(a, b))
    }
}

//! The [`Effect`] trait: what one physical effect of the catalogue (docs/design/effects.md)
//! tells the search, each in its own file of `effects/`, registered once in
//! [`crate::diagnose::effects`] (docs/design/effects.md, "Adding an effect").
//!
//! An effect is its candidate's target (the channel selection of a path effect, the
//! configured mode or rigid body it changes, the order of an integrator) and knows its
//! parameters θ (internal: positive ones in logarithms) and their bounds, how it modifies the
//! model `G = core · path` at a datum, its SI parameters and how it is written into a
//! physical model, its starting points, its plausibility flags, its prior rank among
//! near-ties and the plain-language explanation of its signature.

use crate::model::physical::{EffectKind, EffectPath, EffectSpec, Gains, PhysicalModel, Quantity};
use num_complex::Complex64;
use std::collections::BTreeMap;

pub use crate::report::fmt::{fmt_change, fmt_w, sig};

/// The channels a multiplicative effect acts on (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sel {
    /// Every channel.
    All,
    /// The channels of one output (a sensor effect).
    Output(usize),
    /// The channels of one input (an actuator effect).
    Input(usize),
}

impl Sel {
    /// True when the effect acts on the model entry `(output, input)`.
    pub fn hits(&self, entry: (usize, usize)) -> bool {
        match self {
            Sel::All => true,
            Sel::Output(o) => entry.0 == *o,
            Sel::Input(i) => entry.1 == *i,
        }
    }

    pub(crate) fn suffix(&self) -> String {
        match self {
            Sel::All => String::new(),
            Sel::Output(o) => format!(" (output {})", o + 1),
            Sel::Input(i) => format!(" (input {})", i + 1),
        }
    }
}

/// Lower and upper bound of a damping ratio in any model (the fits' lower bound is the
/// record's floor, `lsq::resolution::band_floor`, above this; the model refuses
/// `ζ < 1e-12`).
pub const ZETA_BOUNDS: (f64, f64) = (1e-9, 0.7);

pub(crate) fn clamp_zeta(z: f64) -> f64 {
    z.clamp(ZETA_BOUNDS.0, ZETA_BOUNDS.1)
}

/// The residue `c_o b_i / m` of a term at a model entry.
pub fn residue(c: &Gains, b: &Gains, m: f64, p: usize, n_in: usize, e: (usize, usize)) -> f64 {
    c.to_vec(p)[e.0] * b.to_vec(n_in)[e.1] / m
}

/// The damping written for a pseudo-mode above or below the band (`residual_mode`,
/// `residual_mode_below`): small, not fitted (out of the band its damping does not show;
/// `ζ₀ω_n` is far below its distance to the band's edge).
pub const PSEUDO_ZETA: f64 = 0.01;

/// One physical effect of the catalogue.  Every method is required: a new effect states each
/// of them (no catch-all can give it another effect's answer).
pub trait Effect: Copy {
    /// The effect's name (JSON `effect`, [`crate::diagnose::EFFECT_NAMES`]).
    const NAME: &'static str;

    /// The candidates of this effect tried on the channels `sel` (path effects; none for
    /// the others), in the order they are tried.
    fn tried_on(sel: Sel) -> Vec<Self>
    where
        Self: Sized;

    /// The candidates of this effect tried once on `base` (additive terms; none for path
    /// effects).
    fn tried(base: &PhysicalModel) -> Vec<Self>
    where
        Self: Sized;

    /// The channels a path effect acts on; `None` for an additive term (which changes
    /// `core`, not `path`).
    fn sel(&self) -> Option<Sel>;

    /// Number of fitted parameters with `n_ch` channels.
    fn n_params(&self, n_ch: usize) -> usize;

    /// Typical magnitude of each internal parameter (for finite differences).
    fn typ(&self, theta: &[f64], omega_max: f64) -> Vec<f64>;

    /// Box bounds `(lo, hi)` of each internal parameter for data over `[ω_min, ω_max]`;
    /// a damping ratio's lower bound is `zeta_lo`, the record's floor
    /// (`lsq::resolution::band_floor`).
    fn bounds(&self, n_ch: usize, w_min: f64, w_max: f64, zeta_lo: f64) -> Vec<(f64, f64)>;

    /// The natural parameters [`Effect::modify`] uses, from the internal ones `th`: `nat`
    /// holds a copy of `th` to change in place (`exp` of the log-parameters, `|τ|`, `ζ`
    /// clamped).
    fn natural(&self, th: &[f64], nat: &mut [f64]);

    /// The residue at model entry `entry` of the configured term the effect changes; 0 when
    /// it changes none.
    fn base_residue(&self, base: &PhysicalModel, entry: (usize, usize)) -> f64;

    /// Modifies `(core, path)` of channel `ch` (model entry `entry`) at `ω` with the natural
    /// parameters `nat` and the configured term's residue `rho`.
    #[allow(clippy::too_many_arguments)]
    fn modify(
        &self,
        nat: &[f64],
        rho: f64,
        base: &PhysicalModel,
        omega: f64,
        ch: usize,
        entry: (usize, usize),
        core: &mut Complex64,
        path: &mut Complex64,
    );

    /// The SI parameters `(name, value, factor)` from the internal ones; `factor` turns an
    /// internal standard deviation into an SI one (0 for labels).
    fn si_params(&self, th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)>;

    /// Writes the effect into the physical model of `w`.
    fn write(&self, w: &mut Writer);

    /// The plain-language explanation of the effect's signature in the data.
    fn explain(&self, x: &Explain) -> String;

    /// Prior rank among near-ties (lower first): fewer assumptions first.
    fn prior(&self) -> usize;

    /// Starting points of the effect's parameters on the least-squares problem `site`.
    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>>;

    /// Physical plausibility flags of a fit (pushed on `out`): `th` its internal
    /// parameters, `at(i)` true when θ_i sits at its bound, `si` the SI parameters by name.
    fn flags(
        &self,
        th: &[f64],
        at: &dyn Fn(usize) -> bool,
        si: &Si,
        band: Band,
        out: &mut Vec<String>,
    );

    /// Where the effect stands in a written model (how `final_effects` reads its refit
    /// parameters back).
    fn stands(&self) -> Stands;

    /// True when `m` lacks the configured term the effect acts on (a holdout or elimination
    /// set left out the effect that added it): then the effect is not written.
    fn lacks_its_term(&self, m: &PhysicalModel) -> bool;

    /// The index of the mode the effect adds (the last) or changes in its jointly refit
    /// model `m`, for the mode rules of `diagnose::admissible`; `None` when it has no mode.
    fn its_mode(&self, m: &PhysicalModel) -> Option<usize>;

    /// Its rigid-body, integrator or friction term alone (in a [`bare`] copy of `m`, its
    /// refit model), whose own size `diagnose::admissible` compares with the data; `None`
    /// for an effect without such a term.
    fn term_alone(&self, m: &PhysicalModel) -> Option<PhysicalModel>;

    /// The negligible-size rule of `diagnose::admissible` for the effect as refit in `m`:
    /// why it is below what the noise resolves `r` (its phase at the band top, a pole's
    /// relative effect at the band bottom), or `None` (also for effects without a size rule).
    fn below_resolution(&self, m: &PhysicalModel, r: &Resolution) -> Option<String>;

    /// The parameters of its refit model `m` that are the effect's own (the covariance rules
    /// of `diagnose::admissible` judge these, and not their correlation with each other).
    fn owns(&self, m: &PhysicalModel) -> Vec<Param>;

    /// How far apart two fits `a`, `b` of this effect are for the hold-out's "same set"
    /// (|Δ ln ω_n| of an added mode; 0 when the target alone tells the effect).
    fn apart(&self, a: &[f64], b: &[f64]) -> f64;

    /// `∂ ln f/∂θ` at `ω` of the factor `f(jω; θ)` a one-parameter path effect multiplies
    /// the path by (its analytic Jacobian: `∂r/∂θ = −G·∂ ln f/∂θ / σ` on the rows it acts
    /// on); `None` (the default) for every other effect.
    fn path_log_slope(&self, _th: f64, _omega: f64) -> Option<Complex64> {
        None
    }
}

/// A parameter of a physical model, by the term it belongs to (0-based indices into the
/// model's lists), as [`Effect::owns`] names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Param {
    /// `ω_n` of mode `i`.
    ModeOmega(usize),
    /// `ζ` of mode `i`.
    ModeZeta(usize),
    /// The input gains of mode `i`.
    ModeInputs(usize),
    /// The output gains (residues) of mode `i`.
    ModeResidues(usize),
    /// The input gains of rigid body `i`.
    RigidInputs(usize),
    /// The output gains (residues) of rigid body `i`.
    RigidResidues(usize),
    /// The input gains of integrator `i`.
    IntegratorInputs(usize),
    /// The output gains (residues) of integrator `i`.
    IntegratorResidues(usize),
    /// The friction pole of rigid body `i`.
    FrictionPole(usize),
    /// The parameter (delay, corner, zero, hold time) of path effect `i`.
    PathEffect(usize),
    /// Any entry of the feedthrough `D`.
    Feedthrough,
}

/// What the noise resolves at the ends of the band (`diagnose::admissible`'s negligible
/// rule): the median `r/|G|` over the top or bottom `n` lines (5 % of them, at most 20),
/// divided by √n (an effect acts coherently on every line there).
#[derive(Debug, Clone, Copy)]
pub struct Resolution {
    /// Lowest data frequency (rad/s).
    pub w_lo: f64,
    /// Highest data frequency (rad/s).
    pub w_hi: f64,
    /// The phase resolution at the band top, `asin(r/|G|)` (rad).
    pub phase_top: f64,
    /// The relative resolution `r/|G|` at the band bottom.
    pub rel_bottom: f64,
}

/// A copy of `m` without terms or path effects (its inputs, outputs and quantity kept): the
/// frame in which one term is evaluated alone.
pub fn bare(m: &PhysicalModel) -> PhysicalModel {
    PhysicalModel {
        mode: vec![],
        rigid_body: vec![],
        integrator: vec![],
        feedthrough: None,
        effect: vec![],
        inputs: Some(m.n_inputs()),
        outputs: Some(m.n_outputs()),
        ..m.clone()
    }
}

/// The index of the last element of a list of `n` (the term an effect added last).
pub fn last(n: usize) -> Option<usize> {
    n.checked_sub(1)
}

/// Where an effect stands in a written model: the kind of term its refit parameters are
/// read back from.  A new effect that writes one of these needs nothing else; one that
/// writes a new kind of term adds a variant here and its reading in `final_effects`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stands {
    /// The added mode with the effect's note: `ω_n`, `ζ` and the residues `rho`.
    AddedMode,
    /// Configured mode `i` (0-based): its `ω_n` and `ζ`.
    ConfiguredMode(usize),
    /// The friction pole of configured rigid body `i`.
    FrictionPole(usize),
    /// The added `c/s^order` with the effect's note: the residues `c`.
    AddedPoleAtZero(u8),
    /// The feedthrough `D` at each channel.
    Feedthrough,
    /// The added path effect with the effect's note.
    AddedPathEffect,
}

/// SI parameters by name.
pub type Si = BTreeMap<String, f64>;

/// The measured band and quantity a plausibility flag is judged against.
#[derive(Debug, Clone, Copy)]
pub struct Band {
    /// Lowest and highest measured frequency (rad/s).
    pub w_min: f64,
    /// Highest measured frequency (rad/s).
    pub w_max: f64,
    /// The record's lower bound on a damping ratio (`lsq::resolution::band_floor`).
    pub zeta_lo: f64,
    /// The measured quantity (receptance, mobility, accelerance).
    pub quantity: Quantity,
}

/// What an effect's [`Effect::starts`] sees of the least-squares problem: the data, the
/// current model's response and path, a noise-weighted linear least squares of the
/// residual, and the cost of the effect with given parameters.
pub trait Site {
    /// Data frequencies (rad/s).
    fn omega(&self) -> &[f64];
    /// Lowest and highest data frequency.
    fn band(&self) -> (f64, f64);
    /// Number of channels.
    fn n_ch(&self) -> usize;
    /// The configured model.
    fn base(&self) -> &PhysicalModel;
    /// The channels `sel` hits.
    fn channels(&self, sel: Sel) -> Vec<usize>;
    /// The current model's response at datum `k` of channel `ch`.
    fn response(&self, ch: usize, k: usize) -> Complex64;
    /// The current model's path at datum `k` of channel `ch` (for additive bases).
    fn path(&self, ch: usize, k: usize) -> Complex64;
    /// Noise-weighted least-squares coefficient of the residual on the basis `psi(ch, k)`
    /// over the channels `chs`.
    fn ls(&self, chs: &[usize], psi: &dyn Fn(usize, usize) -> Complex64) -> f64;
    /// The cost `V` with the effect's parameters `th` added to the current model.
    fn cost(&self, th: &[f64]) -> f64;
    /// `(V, τ)` of a delay on `sel` at `n` points `τ = j·step` (a fast route for its grid).
    fn delay_costs(&self, sel: Sel, step: f64, n: usize) -> Vec<(f64, f64)>;
    /// The worst channel's `|e|/r` at each datum.
    fn worst_misfit(&self) -> Vec<f64>;
    /// `(ω_n, ζ)` of the poles of the residual an LSCF stabilization diagram proposes.
    fn mode_proposals(&self) -> Vec<(f64, f64)>;
    /// An added mode's internal parameters at `(ω_n, ζ)`, residues by least squares.
    fn mode_theta(&self, w: f64, z: f64) -> Vec<f64>;
}

/// The best `keep` points of a 1-D grid `(cost, x)`: its local minima by cost, then the rest
/// by cost.
pub fn pick(mut vs: Vec<(f64, f64)>, keep: usize) -> Vec<Vec<f64>> {
    let mut local: Vec<(f64, f64)> = (0..vs.len())
        .filter(|&i| {
            (i == 0 || vs[i].0 <= vs[i - 1].0) && (i + 1 == vs.len() || vs[i].0 <= vs[i + 1].0)
        })
        .map(|i| vs[i])
        .collect();
    local.sort_by(|a, b| a.0.total_cmp(&b.0));
    vs.sort_by(|a, b| a.0.total_cmp(&b.0));
    local
        .into_iter()
        .chain(vs)
        .take(keep)
        .map(|(_, x)| vec![x])
        .collect()
}

/// The best `keep` points of a grid of the effect's one parameter ([`pick`]).
pub fn grid_best(site: &dyn Site, grid: &[f64], keep: usize) -> Vec<Vec<f64>> {
    let vs = grid.iter().map(|x| (site.cost(&[*x]), *x)).collect();
    pick(vs, keep)
}

/// `n` logarithms evenly spaced from `ln lo` to `ln hi`.
pub fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1) as f64)
        .collect()
}

/// What an effect's [`Effect::explain`] reads: its SI parameters, the configured model and
/// the band's top.
pub struct Explain<'a> {
    /// SI parameters `(name, value, factor)`.
    pub si: Vec<(String, f64, f64)>,
    /// The configured model.
    pub base: &'a PhysicalModel,
    /// Highest data frequency (rad/s).
    pub wmax: f64,
}

impl Explain<'_> {
    /// The SI parameter `n` (NaN when absent).
    pub fn p(&self, n: &str) -> f64 {
        self.si
            .iter()
            .find(|x| x.0 == n)
            .map(|x| x.1)
            .unwrap_or(f64::NAN)
    }

    /// The SI parameters whose names start with `prefix`, to 3 digits, comma-separated.
    pub fn list(&self, prefix: &str) -> String {
        self.si
            .iter()
            .filter(|x| x.0.starts_with(prefix))
            .map(|x| crate::report::fmt::sig(x.1))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// What an effect's [`Effect::write`] writes into: the model, the fitted parameters and the
/// note that marks what `diagnose` added.
pub struct Writer<'a> {
    /// Internal parameters.
    pub th: &'a [f64],
    /// Model entries of the channels.
    pub entries: &'a [(usize, usize)],
    /// The model written into.
    pub m: &'a mut PhysicalModel,
    /// The note (name) of the written term or effect.
    pub note: &'a str,
    /// SI parameters `(name, value, factor)`.
    pub si: Vec<(String, f64, f64)>,
}

impl Writer<'_> {
    /// The SI parameter `n` (0 when absent).
    pub fn get(&self, n: &str) -> f64 {
        self.si
            .iter()
            .find(|x| x.0 == n)
            .map(|x| x.1)
            .unwrap_or(0.0)
    }

    /// `(input gains, output gains)` carrying the per-channel residues `θ[off..]`: written as
    /// output gains (one input) or input gains (one output).
    pub fn gains(&self, off: usize) -> (Gains, Gains) {
        let (p_out, m_in) = (self.m.n_outputs(), self.m.n_inputs());
        let mut v = vec![0.0; if m_in == 1 { p_out } else { m_in }];
        for (ch, (o, i)) in self.entries.iter().enumerate() {
            v[if m_in == 1 { *o } else { *i }] = self.th[off + ch];
        }
        let g = |v: Vec<f64>| {
            if v.len() == 1 {
                Gains::Scalar(v[0])
            } else {
                Gains::Vector(v)
            }
        };
        let unit = |n: usize| g(vec![1.0; n]);
        if m_in == 1 {
            (unit(1), g(v))
        } else {
            (g(v), unit(p_out))
        }
    }

    /// Appends a path effect of `kind` on the channels `sel`, its parameters set by `set`.
    pub fn path_effect(&mut self, kind: EffectKind, sel: &Sel, set: &dyn Fn(&mut EffectSpec)) {
        let mut e = EffectSpec::new(kind);
        set(&mut e);
        match sel {
            Sel::All => {}
            Sel::Output(o) => {
                e.path = EffectPath::Output;
                e.channel = Some(o + 1);
            }
            Sel::Input(i) => e.channel = Some(i + 1),
        }
        e.note = Some(self.note.to_string());
        self.m.effect.push(e);
    }
}

/// Per-channel parameters named `name` for one channel, else `name_<out>_<in>` (1-based),
/// read from `th[off..]`.
pub fn per_channel(
    name: &str,
    th: &[f64],
    off: usize,
    entries: &[(usize, usize)],
) -> Vec<(String, f64, f64)> {
    entries
        .iter()
        .enumerate()
        .map(|(ch, (o, i))| {
            let n = if entries.len() == 1 {
                name.to_string()
            } else {
                format!("{name}_{}_{}", o + 1, i + 1)
            };
            (n, th[off + ch], 1.0)
        })
        .collect()
}

/// One SI parameter.
pub fn one(n: &str, v: f64, f: f64) -> Vec<(String, f64, f64)> {
    vec![(n.to_string(), v, f)]
}

/// The flag of a parameter at its bound: the last SI name (by name order) is reported.
pub fn at_bound_flag(si: &Si) -> String {
    format!(
        "{} at its bound: not identified",
        si.keys().last().cloned().unwrap_or_default()
    )
}

//! Candidate missing effects: how each one modifies the model, its parameters (internal and
//! SI), its bounds, and how it is written back into a physical model.
//!
//! The current model at datum `k` of channel `(o, i)` is held as `G = core · path` (the
//! additive dynamics times the product of the path effects).  A candidate either multiplies
//! `path` (delay, lag, gain, sign, ZOH, NMP zero: on every channel, on one output or on one
//! input, [`Sel`]) or changes `core` (added mode, shifted or re-damped mode, integrator or
//! rigid body, feedthrough).  An added mode is the modal model of docs/design/effects.md: one `ω_n`
//! and `ζ` shared by every channel and a residue per channel.  Positive parameters are fitted
//! in logarithms.

use crate::model::physical::{
    EffectKind, EffectPath, EffectSpec, Feedthrough, Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec,
};
use num_complex::Complex64;

pub use crate::report::fmt::{fmt_change, fmt_w, sig};

/// Names of modes and terms `diagnose` adds start with this.
pub const ADDED_NOTE: &str = "added by rshape diagnose";

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

/// A candidate effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cand {
    /// Pure delay `e^{−sτ}`; θ = \[τ\] (s, |τ| used).
    Delay(Sel),
    /// First-order lag; θ = [ln ω_c].
    Lag(Sel),
    /// Gain; θ = \[k\].
    Gain(Sel),
    /// Sign flip; no parameter.
    Sign(Sel),
    /// Added mode `ρ_ch/(s² + 2ζω s + ω²)`; θ = [ln ω_n, ln ζ, ρ_1 … ρ_C] (one residue per
    /// channel, shared `ω_n` and `ζ`).
    Mode,
    /// Shifted frequency of mode `i` (0-based) of the base model; θ = [ln ω_n].
    ModeShift(usize),
    /// Changed damping of mode `i`; θ = [ln ζ].
    Damping(usize),
    /// Added `c_ch/s^order` (order 1: integrator, 2: rigid body); θ = [c_1 … c_C].
    Integrator(u8),
    /// Added feedthrough; θ = [d_1 … d_C].
    Feedthrough,
    /// NMP zero all-pass; θ = [ln z].
    NmpZero(Sel),
    /// Zero-order hold; θ = [ln T].
    Zoh(Sel),
    /// Viscous friction on rigid body `i` of the base model: `1/s²` becomes
    /// `1/(s (s + p))`; θ = [ln p].
    Friction(usize),
}

/// The effect names of the JSON output (`retune` is the refit of the configured parameters).
pub const EFFECT_NAMES: [&str; 13] = [
    "retune",
    "delay",
    "lag",
    "gain",
    "sign",
    "mode",
    "mode_shift",
    "damping",
    "integrator",
    "feedthrough",
    "nmp_zero",
    "zoh",
    "friction",
];

/// Lower and upper bound of a damping ratio in any model (the fits' lower bound is the
/// record's floor, `lsq::resolution::band_floor`, above this; the model refuses
/// `ζ < 1e-12`).
pub const ZETA_BOUNDS: (f64, f64) = (1e-9, 0.7);

fn clamp_zeta(z: f64) -> f64 {
    z.clamp(ZETA_BOUNDS.0, ZETA_BOUNDS.1)
}

/// The residue `c_o b_i / m` of a term at a model entry.
pub fn residue(c: &Gains, b: &Gains, m: f64, p: usize, n_in: usize, e: (usize, usize)) -> f64 {
    c.to_vec(p)[e.0] * b.to_vec(n_in)[e.1] / m
}

impl Cand {
    /// The effect name.
    pub fn name(&self) -> &'static str {
        match self {
            Cand::Delay(_) => "delay",
            Cand::Lag(_) => "lag",
            Cand::Gain(_) => "gain",
            Cand::Sign(_) => "sign",
            Cand::Mode => "mode",
            Cand::ModeShift(_) => "mode_shift",
            Cand::Damping(_) => "damping",
            Cand::Integrator(_) => "integrator",
            Cand::Feedthrough => "feedthrough",
            Cand::NmpZero(_) => "nmp_zero",
            Cand::Zoh(_) => "zoh",
            Cand::Friction(_) => "friction",
        }
    }

    /// The name with the channel selection (`delay (output 2)`).
    pub fn label(&self) -> String {
        match self {
            Cand::Delay(s)
            | Cand::Lag(s)
            | Cand::Gain(s)
            | Cand::Sign(s)
            | Cand::NmpZero(s)
            | Cand::Zoh(s) => format!("{}{}", self.name(), s.suffix()),
            _ => self.name().into(),
        }
    }

    /// Number of fitted parameters with `n_ch` channels.
    pub fn n_params(&self, n_ch: usize) -> usize {
        match self {
            Cand::Sign(_) => 0,
            Cand::Mode => 2 + n_ch,
            Cand::Integrator(_) | Cand::Feedthrough => n_ch,
            _ => 1,
        }
    }

    /// True for effects that multiply the model (spread over the band).
    pub fn multiplicative(&self) -> bool {
        matches!(
            self,
            Cand::Delay(_)
                | Cand::Lag(_)
                | Cand::Gain(_)
                | Cand::Sign(_)
                | Cand::NmpZero(_)
                | Cand::Zoh(_)
        )
    }

    /// Typical magnitude of each internal parameter (for finite differences).
    pub fn typ(&self, theta: &[f64], omega_max: f64) -> Vec<f64> {
        match self {
            Cand::Delay(_) => vec![1.0 / omega_max],
            Cand::Mode => {
                let mut v = vec![1.0, 1.0];
                v.extend(theta[2..].iter().map(|x| x.abs().max(1e-300)));
                v
            }
            Cand::Gain(_) | Cand::Integrator(_) | Cand::Feedthrough => {
                theta.iter().map(|x| x.abs().max(1e-300)).collect()
            }
            Cand::Sign(_) => vec![],
            _ => vec![1.0],
        }
    }

    /// Box bounds `(lo, hi)` of each internal parameter for data over `[ω_min, ω_max]`
    /// (docs/design/effects.md step 3): an added mode resonates inside the band (an out-of-band one is a
    /// compliance or mass line: the feedthrough and rigid-body candidates), `ζ ∈ [ζ_lo, 0.7]`
    /// (`ζ_lo` the record's floor, `lsq::resolution::band_floor`), corners and zeros
    /// within two decades of the band, a delay below 100/ω_min.
    pub fn bounds(&self, n_ch: usize, w_min: f64, w_max: f64, zeta_lo: f64) -> Vec<(f64, f64)> {
        let free = (f64::NEG_INFINITY, f64::INFINITY);
        let lz = (zeta_lo.max(ZETA_BOUNDS.0).ln(), ZETA_BOUNDS.1.ln());
        match self {
            Cand::Delay(_) => vec![(-100.0 / w_min, 100.0 / w_min)],
            Cand::Lag(_) | Cand::NmpZero(_) => vec![((w_min / 100.0).ln(), (w_max * 100.0).ln())],
            Cand::Zoh(_) => vec![((0.01 / w_max).ln(), (100.0 / w_min).ln())],
            Cand::Gain(_) => vec![(-1e3, 1e3)],
            Cand::Sign(_) => vec![],
            Cand::Mode => {
                let mut v = vec![(w_min.ln(), w_max.ln()), lz];
                v.extend(std::iter::repeat_n(free, n_ch));
                v
            }
            Cand::ModeShift(_) => vec![(w_min.ln(), w_max.ln())],
            Cand::Damping(_) => vec![lz],
            Cand::Integrator(_) | Cand::Feedthrough => vec![free; n_ch],
            Cand::Friction(_) => vec![((w_min / 1e3).ln(), (w_max * 10.0).ln())],
        }
    }

    /// The parameters [`Cand::modify_natural`] uses, from the internal ones `th` (appended
    /// to `out`): `exp` of the log-parameters, `|τ|`, `ζ` clamped.  A residual computes them
    /// once per model instead of once per datum.
    pub fn natural(&self, th: &[f64], out: &mut Vec<f64>) {
        let start = out.len();
        out.extend_from_slice(th);
        let nat = &mut out[start..];
        match self {
            Cand::Delay(_) => nat[0] = th[0].abs(),
            Cand::Lag(_)
            | Cand::NmpZero(_)
            | Cand::Zoh(_)
            | Cand::ModeShift(_)
            | Cand::Friction(_) => nat[0] = th[0].exp(),
            Cand::Damping(_) => nat[0] = clamp_zeta(th[0].exp()),
            Cand::Mode => {
                nat[0] = th[0].exp();
                nat[1] = clamp_zeta(th[1].exp());
            }
            _ => {}
        }
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
        let (p, m) = (base.n_outputs(), base.n_inputs());
        match self {
            Cand::ModeShift(i) | Cand::Damping(i) => {
                let md = &base.mode[*i];
                residue(&md.output_gain, &md.input_gain, md.mass, p, m, entry)
            }
            Cand::Friction(i) => {
                let r = &base.rigid_body[*i];
                residue(&r.output_gain, &r.input_gain, r.mass, p, m, entry)
            }
            _ => 0.0,
        }
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
        let s = Complex64::new(0.0, omega);
        let one = Complex64::new(1.0, 0.0);
        let mode_term = |w: f64, z: f64, rho: f64| rho / (s * s + 2.0 * z * w * s + w * w);
        match self {
            Cand::Delay(sel) if sel.hits(entry) => *path *= (-s * nat[0]).exp(),
            Cand::Lag(sel) if sel.hits(entry) => *path /= one + s / nat[0],
            Cand::Gain(sel) if sel.hits(entry) => *path *= nat[0],
            Cand::Sign(sel) if sel.hits(entry) => *path = -*path,
            Cand::NmpZero(sel) if sel.hits(entry) => {
                let z = nat[0];
                *path *= (one - s / z) / (one + s / z)
            }
            Cand::Zoh(sel) if sel.hits(entry) => {
                let t = nat[0];
                let x = omega * t / 2.0;
                let sinc = if x.abs() < 1e-8 { 1.0 } else { x.sin() / x };
                *path *= (-s * t / 2.0).exp() * sinc
            }
            Cand::Mode => *core += mode_term(nat[0], nat[1], nat[2 + ch]),
            Cand::ModeShift(i) | Cand::Damping(i) => {
                let md = &base.mode[*i];
                let (w, z) = match self {
                    Cand::ModeShift(_) => (nat[0], md.zeta),
                    _ => (md.omega_n, nat[0]),
                };
                *core += mode_term(w, z, rho) - mode_term(md.omega_n, md.zeta, rho);
            }
            Cand::Integrator(order) => *core += nat[ch] / s.powi(*order as i32),
            Cand::Friction(i) => {
                let r = &base.rigid_body[*i];
                let p0 = r.friction_pole.unwrap_or(0.0);
                *core += rho / (s * (s + nat[0])) - rho / (s * (s + p0));
            }
            Cand::Feedthrough => *core += nat[ch],
            _ => {}
        }
    }

    /// The SI parameters `(name, value, factor)` from the internal ones; `factor` turns an
    /// internal standard deviation into an SI one (0 for labels).  Per-channel residues are
    /// named `rho`, `c`, `d` for one channel, else `rho_<out>_<in>` (1-based).
    pub fn si_params(&self, th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        let e = |x: f64| x.exp();
        let per_ch = |name: &str, off: usize| -> Vec<(String, f64, f64)> {
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
        };
        let one = |n: &str, v: f64, f: f64| vec![(n.to_string(), v, f)];
        match self {
            Cand::Delay(_) => one("tau_s", th[0].abs(), 1.0),
            Cand::Lag(_) => one("omega_c", e(th[0]), e(th[0])),
            Cand::Gain(_) => one("k", th[0], 1.0),
            Cand::Sign(_) => vec![],
            Cand::Mode => {
                let mut v = one("omega_n", e(th[0]), e(th[0]));
                let z = clamp_zeta(e(th[1]));
                v.extend(one("zeta", z, z));
                v.extend(per_ch("rho", 2));
                v
            }
            Cand::ModeShift(i) => {
                let mut v = one("mode", (*i + 1) as f64, 0.0);
                v.extend(one("omega_n", e(th[0]), e(th[0])));
                v
            }
            Cand::Damping(i) => {
                let mut v = one("mode", (*i + 1) as f64, 0.0);
                let z = clamp_zeta(e(th[0]));
                v.extend(one("zeta", z, z));
                v
            }
            Cand::Integrator(o) => {
                let mut v = one("order", *o as f64, 0.0);
                v.extend(per_ch("c", 0));
                v
            }
            Cand::Feedthrough => per_ch("d", 0),
            Cand::NmpZero(_) => one("z", e(th[0]), e(th[0])),
            Cand::Zoh(_) => one("t_s", e(th[0]), e(th[0])),
            Cand::Friction(i) => {
                let mut v = one("rigid_body", (*i + 1) as f64, 0.0);
                v.extend(one("pole", e(th[0]), e(th[0])));
                v
            }
        }
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
        let (p_out, m_in) = (m.n_outputs(), m.n_inputs());
        let si = self.si_params(th, entries);
        let get = |n: &str| si.iter().find(|x| x.0 == n).map(|x| x.1).unwrap_or(0.0);
        // (input gains, output gains) carrying the per-channel residues θ[off..].
        let gains = |off: usize| -> (Gains, Gains) {
            let mut v = vec![0.0; if m_in == 1 { p_out } else { m_in }];
            for (ch, (o, i)) in entries.iter().enumerate() {
                v[if m_in == 1 { *o } else { *i }] = th[off + ch];
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
        };
        let mut effect = |kind: EffectKind, sel: &Sel, set: &dyn Fn(&mut EffectSpec)| {
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
            e.note = Some(note.to_string());
            m.effect.push(e);
        };
        match self {
            Cand::Delay(s) => effect(EffectKind::Delay, s, &|e| e.tau_s = Some(get("tau_s"))),
            Cand::Lag(s) => effect(EffectKind::Lag, s, &|e| e.omega_c = Some(get("omega_c"))),
            Cand::Gain(s) => effect(EffectKind::Gain, s, &|e| e.k = Some(get("k"))),
            Cand::Sign(s) => effect(EffectKind::Sign, s, &|_| {}),
            Cand::NmpZero(s) => effect(EffectKind::NmpZero, s, &|e| e.z = Some(get("z"))),
            Cand::Zoh(s) => effect(EffectKind::Zoh, s, &|e| e.t_s = Some(get("t_s"))),
            Cand::Mode => {
                let (b, c) = gains(2);
                m.mode.push(ModeSpec {
                    name: Some(note.to_string()),
                    omega_n: get("omega_n"),
                    zeta: get("zeta"),
                    mass: 1.0,
                    input_gain: b,
                    output_gain: c,
                })
            }
            Cand::ModeShift(i) => m.mode[*i].omega_n = get("omega_n"),
            Cand::Friction(i) => m.rigid_body[*i].friction_pole = Some(get("pole")),
            Cand::Damping(i) => m.mode[*i].zeta = get("zeta"),
            Cand::Integrator(o) => {
                let (b, c) = gains(0);
                let spec = PoleAtZeroSpec {
                    friction_pole: None,
                    name: Some(note.to_string()),
                    mass: 1.0,
                    input_gain: b,
                    output_gain: c,
                };
                if *o == 2 {
                    m.rigid_body.push(spec)
                } else {
                    m.integrator.push(spec)
                }
            }
            Cand::Feedthrough => {
                let mut d = match &m.feedthrough {
                    Some(Feedthrough::Scalar(d)) => vec![vec![*d]],
                    Some(Feedthrough::Matrix(r)) => r.clone(),
                    None => vec![vec![0.0; m_in]; p_out],
                };
                for (ch, (o, i)) in entries.iter().enumerate() {
                    d[*o][*i] += th[ch];
                }
                m.feedthrough = Some(if p_out * m_in == 1 {
                    Feedthrough::Scalar(d[0][0])
                } else {
                    Feedthrough::Matrix(d)
                });
            }
        }
    }
}

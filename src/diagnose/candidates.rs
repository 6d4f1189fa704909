//! Candidate missing effects: how each one modifies the model, its parameters (internal and
//! SI), and how it is written back into a physical model.
//!
//! The current SISO model at datum `k` is held as `G_k = core_k · path_k` (the additive
//! dynamics times the product of the path effects).  A candidate either multiplies `path`
//! (delay, lag, gain, sign, ZOH, NMP zero) or changes `core` (added mode, shifted or
//! re-damped mode, integrator or rigid body, feedthrough).  Positive parameters are fitted
//! in logarithms.

use crate::model::physical::{
    EffectKind, EffectSpec, Feedthrough, ModeSpec, PhysicalModel, PoleAtZeroSpec,
};
use num_complex::Complex64;

/// A candidate effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cand {
    /// Pure delay `e^{−sτ}`; θ = [τ] (s, |τ| used).
    Delay,
    /// First-order lag; θ = [ln ω_c].
    Lag,
    /// Gain; θ = [k].
    Gain,
    /// Sign flip; no parameter.
    Sign,
    /// Added mode `ρ/(s² + 2ζω s + ω²)`; θ = [ln ω_n, ln ζ, ρ].
    Mode,
    /// Shifted frequency of mode `i` (0-based) of the base model; θ = [ln ω_n].
    ModeShift(usize),
    /// Changed damping of mode `i`; θ = [ln ζ].
    Damping(usize),
    /// Added `c/s^order` (order 1: integrator, 2: rigid body); θ = [c].
    Integrator(u8),
    /// Added feedthrough; θ = [d].
    Feedthrough,
    /// NMP zero all-pass; θ = [ln z].
    NmpZero,
    /// Zero-order hold; θ = [ln T].
    Zoh,
    /// Viscous friction on rigid body `i` of the base model: `1/s²` becomes
    /// `1/(s (s + p))`; θ = [ln p].  (An extension beyond the list.)
    Friction(usize),
}

/// The effect names of the JSON output.
pub const EFFECT_NAMES: [&str; 12] = [
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

fn clamp_zeta(z: f64) -> f64 {
    z.clamp(1e-4, 0.7)
}

impl Cand {
    /// The effect name.
    pub fn name(&self) -> &'static str {
        match self {
            Cand::Delay => "delay",
            Cand::Lag => "lag",
            Cand::Gain => "gain",
            Cand::Sign => "sign",
            Cand::Mode => "mode",
            Cand::ModeShift(_) => "mode_shift",
            Cand::Damping(_) => "damping",
            Cand::Integrator(_) => "integrator",
            Cand::Feedthrough => "feedthrough",
            Cand::NmpZero => "nmp_zero",
            Cand::Zoh => "zoh",
            Cand::Friction(_) => "friction",
        }
    }

    /// Number of fitted parameters.
    pub fn n_params(&self) -> usize {
        match self {
            Cand::Sign => 0,
            Cand::Mode => 3,
            _ => 1,
        }
    }

    /// True for effects that multiply the model (spread over the band).
    pub fn multiplicative(&self) -> bool {
        matches!(
            self,
            Cand::Delay | Cand::Lag | Cand::Gain | Cand::Sign | Cand::NmpZero | Cand::Zoh
        )
    }

    /// Typical magnitude of each internal parameter (for finite differences).
    pub fn typ(&self, theta: &[f64], omega_max: f64) -> Vec<f64> {
        match self {
            Cand::Delay => vec![1.0 / omega_max],
            Cand::Mode => vec![1.0, 1.0, theta[2].abs().max(1e-300)],
            Cand::Gain | Cand::Integrator(_) | Cand::Feedthrough => {
                vec![theta[0].abs().max(1e-300)]
            }
            Cand::Sign => vec![],
            _ => vec![1.0],
        }
    }

    /// Modifies `(core, path)` at `ω` with parameters `th`; `base` gives the modes that
    /// `ModeShift` and `Damping` refer to.
    pub fn modify(
        &self,
        th: &[f64],
        base: &PhysicalModel,
        omega: f64,
        core: &mut Complex64,
        path: &mut Complex64,
    ) {
        let s = Complex64::new(0.0, omega);
        let one = Complex64::new(1.0, 0.0);
        let mode_term = |w: f64, z: f64, rho: f64| rho / (s * s + 2.0 * z * w * s + w * w);
        match self {
            Cand::Delay => *path *= (-s * th[0].abs()).exp(),
            Cand::Lag => *path /= one + s / th[0].exp(),
            Cand::Gain => *path *= th[0],
            Cand::Sign => *path = -*path,
            Cand::NmpZero => {
                let z = th[0].exp();
                *path *= (one - s / z) / (one + s / z)
            }
            Cand::Zoh => {
                let t = th[0].exp();
                let x = omega * t / 2.0;
                let sinc = if x.abs() < 1e-8 { 1.0 } else { x.sin() / x };
                *path *= (-s * t / 2.0).exp() * sinc
            }
            Cand::Mode => *core += mode_term(th[0].exp(), clamp_zeta(th[1].exp()), th[2]),
            Cand::ModeShift(i) | Cand::Damping(i) => {
                let m = &base.mode[*i];
                let rho = m.output_gain.to_vec(1)[0] * m.input_gain.to_vec(1)[0] / m.mass;
                let (w, z) = match self {
                    Cand::ModeShift(_) => (th[0].exp(), m.zeta),
                    _ => (m.omega_n, clamp_zeta(th[0].exp())),
                };
                *core += mode_term(w, z, rho) - mode_term(m.omega_n, m.zeta, rho);
            }
            Cand::Integrator(order) => *core += th[0] / s.powi(*order as i32),
            Cand::Friction(i) => {
                let r = &base.rigid_body[*i];
                let rho = r.output_gain.to_vec(1)[0] * r.input_gain.to_vec(1)[0] / r.mass;
                let p0 = r.friction_pole.unwrap_or(0.0);
                *core += rho / (s * (s + th[0].exp())) - rho / (s * (s + p0));
            }
            Cand::Feedthrough => *core += th[0],
        }
    }

    /// The SI parameters `(name, value)` from the internal ones, and the factor that turns
    /// an internal standard deviation into an SI one.
    pub fn si_params(&self, th: &[f64]) -> Vec<(&'static str, f64, f64)> {
        let e = |x: f64| x.exp();
        match self {
            Cand::Delay => vec![("tau_s", th[0].abs(), 1.0)],
            Cand::Lag => vec![("omega_c", e(th[0]), e(th[0]))],
            Cand::Gain => vec![("k", th[0], 1.0)],
            Cand::Sign => vec![],
            Cand::Mode => vec![
                ("omega_n", e(th[0]), e(th[0])),
                ("zeta", clamp_zeta(e(th[1])), clamp_zeta(e(th[1]))),
                ("rho", th[2], 1.0),
            ],
            Cand::ModeShift(i) => vec![
                ("mode", (*i + 1) as f64, 0.0),
                ("omega_n", e(th[0]), e(th[0])),
            ],
            Cand::Damping(i) => vec![
                ("mode", (*i + 1) as f64, 0.0),
                ("zeta", clamp_zeta(e(th[0])), clamp_zeta(e(th[0]))),
            ],
            Cand::Integrator(o) => vec![("order", *o as f64, 0.0), ("c", th[0], 1.0)],
            Cand::Feedthrough => vec![("d", th[0], 1.0)],
            Cand::NmpZero => vec![("z", e(th[0]), e(th[0]))],
            Cand::Zoh => vec![("t_s", e(th[0]), e(th[0]))],
            Cand::Friction(i) => vec![
                ("rigid_body", (*i + 1) as f64, 0.0),
                ("pole", e(th[0]), e(th[0])),
            ],
        }
    }

    /// Writes the effect into a physical model (SISO).
    pub fn apply_to(&self, th: &[f64], m: &mut PhysicalModel, note: &str) {
        let p: std::collections::HashMap<&str, f64> = self
            .si_params(th)
            .iter()
            .map(|(n, v, _)| (*n, *v))
            .collect();
        let mut effect = |kind: EffectKind, set: &dyn Fn(&mut EffectSpec)| {
            let mut e = EffectSpec::new(kind);
            set(&mut e);
            e.note = Some(note.to_string());
            m.effect.push(e);
        };
        match self {
            Cand::Delay => effect(EffectKind::Delay, &|e| e.tau_s = Some(p["tau_s"])),
            Cand::Lag => effect(EffectKind::Lag, &|e| e.omega_c = Some(p["omega_c"])),
            Cand::Gain => effect(EffectKind::Gain, &|e| e.k = Some(p["k"])),
            Cand::Sign => effect(EffectKind::Sign, &|_| {}),
            Cand::NmpZero => effect(EffectKind::NmpZero, &|e| e.z = Some(p["z"])),
            Cand::Zoh => effect(EffectKind::Zoh, &|e| e.t_s = Some(p["t_s"])),
            Cand::Mode => m.mode.push(ModeSpec {
                name: Some(note.to_string()),
                omega_n: p["omega_n"],
                zeta: p["zeta"],
                mass: 1.0,
                input_gain: crate::model::physical::Gains::Scalar(1.0),
                output_gain: crate::model::physical::Gains::Scalar(p["rho"]),
            }),
            Cand::ModeShift(i) => m.mode[*i].omega_n = p["omega_n"],
            Cand::Friction(i) => m.rigid_body[*i].friction_pole = Some(p["pole"]),
            Cand::Damping(i) => m.mode[*i].zeta = p["zeta"],
            Cand::Integrator(o) => {
                let spec = PoleAtZeroSpec {
                    friction_pole: None,
                    name: Some(note.to_string()),
                    mass: 1.0,
                    input_gain: crate::model::physical::Gains::Scalar(1.0),
                    output_gain: crate::model::physical::Gains::Scalar(p["c"]),
                };
                if *o == 2 {
                    m.rigid_body.push(spec)
                } else {
                    m.integrator.push(spec)
                }
            }
            Cand::Feedthrough => {
                let old = match &m.feedthrough {
                    Some(Feedthrough::Scalar(d)) => *d,
                    Some(Feedthrough::Matrix(r)) => r[0][0],
                    None => 0.0,
                };
                m.feedthrough = Some(Feedthrough::Scalar(old + p["d"]));
            }
        }
    }
}

/// Formats a frequency in rad/s with Hz beside it.
pub fn fmt_w(w: f64) -> String {
    format!("{} rad/s ({} Hz)", sig(w), sig(w / std::f64::consts::TAU))
}

/// 4 significant digits.
pub fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let d = (3 - x.abs().log10().floor() as i32).max(0) as usize;
    if x.abs() >= 1e-3 && x.abs() < 1e6 {
        format!("{x:.d$}")
    } else {
        format!("{x:.3e}")
    }
}

/// A plain-language explanation of the candidate's signature in the data.
pub fn explain(c: &Cand, th: &[f64], base: &PhysicalModel, omega: &[f64]) -> String {
    let p: std::collections::HashMap<&str, f64> =
        c.si_params(th).iter().map(|(n, v, _)| (*n, *v)).collect();
    let wmax = omega.last().copied().unwrap_or(1.0);
    match c {
        Cand::Delay => format!(
            "phase falls linearly with frequency while magnitude matches: a pure delay of {} ms ({}° of extra lag at {})",
            sig(p["tau_s"] * 1e3),
            sig((wmax * p["tau_s"]).to_degrees()),
            fmt_w(wmax)
        ),
        Cand::Lag => format!(
            "magnitude droops and phase lags towards −90° above the corner, with no linear phase: a first-order lag (actuator or sensor) at ω_c = {}",
            fmt_w(p["omega_c"])
        ),
        Cand::Gain => format!(
            "the ratio data/model is flat in magnitude with zero phase: a gain error, k = {} ({:+.1} %)",
            sig(p["k"]),
            100.0 * (p["k"] - 1.0)
        ),
        Cand::Sign => "the data are the model rotated by 180° at every frequency with matching magnitude: a sign flip".into(),
        Cand::Mode => format!(
            "the misfit peaks at {} with a half-power width 2ζω_n = {} rad/s, and data/model shows a peak–notch pair: an unmodelled mode, ω_n = {}, ζ = {}, residue {}",
            fmt_w(p["omega_n"]),
            sig(2.0 * p["zeta"] * p["omega_n"]),
            fmt_w(p["omega_n"]),
            sig(p["zeta"]),
            sig(p["rho"])
        ),
        Cand::ModeShift(i) => {
            let old = base.mode[*i].omega_n;
            format!(
                "the data resonate at {} where mode {} of the model resonates at {}: the error is antisymmetric about the mode (peak at the true frequency, notch at the model's): mode {} shifted by {:+.1} %",
                fmt_w(p["omega_n"]),
                i + 1,
                fmt_w(old),
                i + 1,
                100.0 * (p["omega_n"] / old - 1.0)
            )
        }
        Cand::Damping(i) => {
            let old = base.mode[*i].zeta;
            format!(
                "the error is symmetric about mode {} at {} and the peak height is off by about ζ_model/ζ_true = {}: its damping is ζ = {} instead of {}",
                i + 1,
                fmt_w(base.mode[*i].omega_n),
                sig(old / p["zeta"]),
                sig(p["zeta"]),
                sig(old)
            )
        }
        Cand::Integrator(2) => format!(
            "the error grows as 1/ω² towards low frequency (−40 dB/dec, phase of a double integrator): a missing rigid-body mode c/s², c = {}",
            sig(p["c"])
        ),
        Cand::Integrator(_) => format!(
            "the error grows as 1/ω towards low frequency (−20 dB/dec, −90°): a missing integrator c/s, c = {}",
            sig(p["c"])
        ),
        Cand::Feedthrough => format!(
            "the error is a constant real term, flat in frequency, that dominates where the model rolls off and moves the anti-resonances: a feedthrough (residual compliance) D = {}",
            sig(p["d"])
        ),
        Cand::NmpZero => format!(
            "magnitude matches but phase falls and saturates towards −180° (−90° at {}): a non-minimum-phase zero at z = {}",
            fmt_w(p["z"]),
            fmt_w(p["z"])
        ),
        Cand::Friction(i) => format!(
            "the phase leads −180° at low frequency by atan(p/ω) and the lead fades with frequency, while the magnitude follows the rigid body: viscous friction on rigid body {}, pole p = c_v/J = {}",
            i + 1,
            fmt_w(p["pole"])
        ),
        Cand::Zoh => format!(
            "phase falls linearly (mean delay T/2 = {} ms) and magnitude droops like sinc(ωT/2) ({} dB at {}): a zero-order hold with T = {} ms (fs = {} Hz)",
            sig(p["t_s"] * 5e2),
            sig(20.0 * {
                let x = wmax * p["t_s"] / 2.0;
                (x.sin() / x).abs().log10()
            }),
            fmt_w(wmax),
            sig(p["t_s"] * 1e3),
            sig(1.0 / p["t_s"])
        ),
    }
}

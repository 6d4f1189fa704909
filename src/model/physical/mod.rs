//! A model described by its physics: flexible modes, rigid-body modes and integrators, a
//! feedthrough, and effects on the input or output path (delay, lag, gain, sign, zero-order
//! hold, non-minimum-phase zero).
//!
//! ```toml
//! [physical]
//! factor_den = [1, 41.2, 40.2]   # optional common q(s) of the special factorization
//!
//! [[physical.mode]]
//! omega_n = 5.1234         # rad/s
//! zeta = 0.1
//! mass = 4.0               # optional modal mass m (default 1)
//! input_gain = 1800.0      # b: a number (SISO) or a list, one per input
//! output_gain = -3.30e-3   # c: a number (SISO) or a list, one per output
//!
//! [[physical.rigid_body]]  # c·b/(m·s²), or c·b/(m·s·(s + p)) with friction_pole = p
//! input_gain = 1.0
//! output_gain = 100.0
//!
//! [[physical.effect]]
//! kind = "delay"           # delay | lag | gain | sign | zoh | nmp_zero
//! tau_s = 0.012            # delay: tau_s; lag: omega_c (rad/s) and order; gain: k;
//! path = "input"           # zoh: t_s (sample period, s); nmp_zero: z (rad/s)
//! ```
//!
//! **Measured quantity.** `quantity = "displacement" | "velocity" | "acceleration"`
//! (receptance, mobility, accelerance; default displacement): the model is `s^k` times the
//! displacement model below, `k` = 0, 1, 2, so the terms keep their physical meaning (on an
//! accelerance a rigid body is the mass line `c b/m`).
//!
//! **Exact evaluation.** [`PhysicalModel::eval`] returns
//! `G(jω) = (jω)^k·O(jω)·[Σ_k c_k b_kᵀ/(m_k d_k(jω)) + Σ c b/(m s²) + Σ c b/(m s) + D]·I(jω)` with
//! `d_k(s) = s² + 2ζ_kω_k s + ω_k²` and `I`, `O` the diagonal input- and output-path effects,
//! evaluated exactly (a delay is `e^{−jωτ}`, a ZOH `e^{−jωT/2}·sin(ωT/2)/(ωT/2)`). `compare`
//! and `diagnose` use this.
//!
//! **Rational export.** [`PhysicalModel::to_factorization`] builds the special (modal)
//! factorization `C·M̃⁻¹·Ñ·J` of Sec. IV-A: mode `k` becomes row `k` of `M̃` and `Ñ` and
//! column `k` of `C`, with `M̃_kk = m_k d_k(s)/q_k(s)`, `Ñ_k = b_kᵀ/q_k(s)`, `C_k = c_k`, where
//! `q_k` is `factor_den` when given, else `(s + ω_k)²` (so `M̃_kk` is a biproper unit of RH∞).
//! A rigid body `c b/(m s²)` is not in RH∞; it becomes the coprime pair
//! `M̃ = m s²/q(s)`, `Ñ = b/q(s)` with `q = factor_den` or `(s + a)²`, `a = factor_pole`
//! (default 1 rad/s). That `M̃` is in RH∞ but is not a unit (it vanishes at `s = 0`): the
//! factorization is still coprime and `G = C M̃⁻¹ Ñ J` holds, but A1 then limits `|r|` near
//! `ω = 0`. An integrator uses `M̃ = m s/(s + a)`, `Ñ = b/(s + a)`. A feedthrough `D` adds one
//! row per output with `M̃ = 1`, `Ñ = D_i`, `C = e_i`. Input-path effects go into `J`.
//! Output-path effects that every output shares commute with the plant and go into `J` too
//! (always so for one output); effects on some outputs only (a sensor lag or delay on one
//! encoder) split each modal row into one row per group of outputs with the same effects,
//! `Ñ_k` multiplied by the group's effects and `C` restricted to the group (`C` stays
//! constant; see `output_path.rs`). Irrational effects enter `J` through a Padé approximation of order
//! `pade_order` (default 6): a delay `τ` as the `[n/n]` Padé of `e^{−sτ}`, a ZOH as the Padé of
//! its mean delay `T/2` (its sinc droop, `−0.9 dB` at a quarter of the sample rate, is
//! dropped in the export and kept in the exact evaluation).

mod effect;
mod export;
mod output_path;
mod terms;
mod validate;

pub use effect::{pade, EffectKind, EffectPath, EffectSpec};
pub use terms::{Feedthrough, Gains, ModeSpec, PoleAtZeroSpec, Quantity};

use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// The `[physical]` table.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicalModel {
    /// Number of inputs (default: from the gains, else 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<usize>,
    /// The measured quantity: `"displacement"` (default), `"velocity"` or `"acceleration"`;
    /// the model is `s^k` times the displacement model ([`Quantity`]).
    #[serde(default, skip_serializing_if = "Quantity::is_displacement")]
    pub quantity: Quantity,
    /// Number of outputs (default: from the gains, else 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outputs: Option<usize>,
    /// Common denominator `q(s)` of the special factorization (degree 2), optional.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_den: Option<Vec<f64>>,
    /// Pole `a` of the factors of rigid bodies and integrators (default 1 rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_pole: Option<f64>,
    /// Order of the Padé approximations in the rational export (default 6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pade_order: Option<usize>,
    /// Rigid-body modes `c b/(m s²)`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rigid_body: Vec<PoleAtZeroSpec>,
    /// Integrators `c b/(m s)`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub integrator: Vec<PoleAtZeroSpec>,
    /// Flexible modes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mode: Vec<ModeSpec>,
    /// Feedthrough (residual compliance) `D`: a number (SISO) or rows (p×m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feedthrough: Option<Feedthrough>,
    /// Effects on the input or output path, applied in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effect: Vec<EffectSpec>,
}

impl PhysicalModel {
    /// Number of inputs.
    pub fn n_inputs(&self) -> usize {
        self.inputs.unwrap_or_else(|| {
            self.gain_lists()
                .filter_map(|(g, input)| if input { g.len() } else { None })
                .max()
                .unwrap_or(1)
        })
    }

    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        self.outputs.unwrap_or_else(|| {
            self.gain_lists()
                .filter_map(|(g, input)| if input { None } else { g.len() })
                .max()
                .unwrap_or(1)
        })
    }

    pub(super) fn gain_lists(&self) -> impl Iterator<Item = (&Gains, bool)> {
        self.mode
            .iter()
            .flat_map(|m| [(&m.input_gain, true), (&m.output_gain, false)])
            .chain(
                self.rigid_body
                    .iter()
                    .chain(&self.integrator)
                    .flat_map(|m| [(&m.input_gain, true), (&m.output_gain, false)]),
            )
    }

    pub(super) fn d_matrix(&self) -> Option<DMatrix<f64>> {
        let (p, m) = (self.n_outputs(), self.n_inputs());
        match &self.feedthrough {
            None => None,
            Some(Feedthrough::Scalar(d)) => Some(DMatrix::from_element(1, 1, *d)),
            Some(Feedthrough::Matrix(rows)) => Some(DMatrix::from_fn(p, m, |i, j| rows[i][j])),
        }
    }

    /// The dynamics without path effects, `Σ c bᵀ/(m·den(jω)) + D`, at `jω`: the
    /// displacement model, without the `(jω)^k` of the measured quantity.
    pub fn eval_core(&self, omega: f64) -> DMatrix<Complex64> {
        let (p, m) = (self.n_outputs(), self.n_inputs());
        let s = Complex64::new(0.0, omega);
        let mut g = DMatrix::<Complex64>::zeros(p, m);
        let mut add = |c: &Gains, b: &Gains, scale: Complex64| {
            let (c, b) = (c.to_vec(p), b.to_vec(m));
            for i in 0..p {
                for j in 0..m {
                    g[(i, j)] += scale * c[i] * b[j];
                }
            }
        };
        for md in &self.mode {
            let d = s * s + 2.0 * md.zeta * md.omega_n * s + md.omega_n * md.omega_n;
            add(&md.output_gain, &md.input_gain, (d * md.mass).inv());
        }
        for md in &self.rigid_body {
            let p = md.friction_pole.unwrap_or(0.0);
            add(
                &md.output_gain,
                &md.input_gain,
                (s * (s + p) * md.mass).inv(),
            );
        }
        for md in &self.integrator {
            add(&md.output_gain, &md.input_gain, (s * md.mass).inv());
        }
        if let Some(d) = self.d_matrix() {
            g += d.map(|x| Complex64::new(x, 0.0));
        }
        g
    }

    /// The exact plant `G(jω)` (`p×m`): `(jω)^k` (the measured quantity) times the
    /// displacement model, delays and ZOH included exactly.
    pub fn eval(&self, omega: f64) -> DMatrix<Complex64> {
        let mut g = self.eval_core(omega) * self.quantity.factor(omega);
        let (p, m) = (g.nrows(), g.ncols());
        for e in &self.effect {
            let v = e.eval(omega);
            match e.path {
                EffectPath::Input => {
                    for j in 0..m {
                        if e.channel.is_none_or(|c| c == j + 1) {
                            let mut col = g.column_mut(j);
                            col *= v;
                        }
                    }
                }
                EffectPath::Output => {
                    for i in 0..p {
                        if e.channel.is_none_or(|c| c == i + 1) {
                            let mut row = g.row_mut(i);
                            row *= v;
                        }
                    }
                }
            }
        }
        g
    }

    /// SISO value `G(jω)[0,0]`.
    pub fn eval_siso(&self, omega: f64) -> Complex64 {
        self.eval(omega)[(0, 0)]
    }
}

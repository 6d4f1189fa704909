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
//! **Exact evaluation.** [`PhysicalModel::eval`] returns
//! `G(jω) = O(jω)·[Σ_k c_k b_kᵀ/(m_k d_k(jω)) + Σ c b/(m s²) + Σ c b/(m s) + D]·I(jω)` with
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
//! row per output with `M̃ = 1`, `Ñ = D_i`, `C = e_i`. Input-path effects go into `J`; for a
//! SISO model, output-path effects commute and go into `J` too; for a MIMO model a dynamic
//! output-path effect has no place in the constant `C` and the export fails (the exact
//! evaluation still works). Irrational effects enter `J` through a Padé approximation of order
//! `pade_order` (default 6): a delay `τ` as the `[n/n]` Padé of `e^{−sτ}`, a ZOH as the Padé of
//! its mean delay `T/2` (its sinc droop, `−0.9 dB` at a quarter of the sample rate, is
//! dropped in the export and kept in the exact evaluation).

use super::factorization::Factorization;
use crate::system::{Polynomial, TfMatrix, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// A gain given as one number (SISO) or one number per channel.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Gains {
    /// One number.
    Scalar(f64),
    /// One number per channel.
    Vector(Vec<f64>),
}

impl Default for Gains {
    fn default() -> Self {
        Gains::Scalar(1.0)
    }
}

impl Gains {
    fn len(&self) -> Option<usize> {
        match self {
            Gains::Scalar(_) => None,
            Gains::Vector(v) => Some(v.len()),
        }
    }

    /// The gains as a vector of length `n` (a scalar is used for a single channel only).
    pub fn to_vec(&self, n: usize) -> Vec<f64> {
        match self {
            Gains::Scalar(x) => vec![*x; n],
            Gains::Vector(v) => v.clone(),
        }
    }

    fn all(&self) -> Vec<f64> {
        match self {
            Gains::Scalar(x) => vec![*x],
            Gains::Vector(v) => v.clone(),
        }
    }
}

fn one() -> f64 {
    1.0
}

fn is_one(x: &f64) -> bool {
    *x == 1.0
}

/// A flexible mode `c bᵀ/(m (s² + 2ζω_n s + ω_n²))`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModeSpec {
    /// Optional label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Natural frequency in rad/s.
    pub omega_n: f64,
    /// Damping ratio.
    pub zeta: f64,
    /// Modal mass `m` (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub mass: f64,
    /// Input gains `b` (one per input).
    #[serde(default)]
    pub input_gain: Gains,
    /// Output gains `c` (one per output).
    #[serde(default)]
    pub output_gain: Gains,
}

/// A rigid-body mode `c bᵀ/(m s²)` or an integrator `c bᵀ/(m s)`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PoleAtZeroSpec {
    /// Optional label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Mass (or inertia) `m` (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub mass: f64,
    /// Input gains `b`.
    #[serde(default)]
    pub input_gain: Gains,
    /// Output gains `c`.
    #[serde(default)]
    pub output_gain: Gains,
    /// Rigid bodies only: viscous-friction pole `p = c_v/m` in rad/s, making the term
    /// `c bᵀ/(m s (s + p))`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_pole: Option<f64>,
}

/// The kind of a path effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectKind {
    /// Pure delay `e^{−sτ}` (`tau_s`).
    Delay,
    /// First-order lag `1/(1 + s/ω_c)^order` (`omega_c`, `order`).
    Lag,
    /// A gain `k`.
    Gain,
    /// A sign flip `−1`.
    Sign,
    /// Zero-order hold `e^{−sT/2}·sinc(ωT/2)` (`t_s`).
    Zoh,
    /// Real non-minimum-phase zero as an all-pass `(1 − s/z)/(1 + s/z)` (`z`).
    NmpZero,
}

/// Which path an effect is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectPath {
    /// The input (actuator) path: it goes into `J`.
    #[default]
    Input,
    /// The output (sensor) path.
    Output,
}

/// An effect on the input or output path.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct EffectSpec {
    /// What it is.
    pub kind: EffectKind,
    /// Input or output path (default input).
    #[serde(default)]
    pub path: EffectPath,
    /// 1-based channel on that path; all channels when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<usize>,
    /// Delay in seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tau_s: Option<f64>,
    /// Lag corner in rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub omega_c: Option<f64>,
    /// Lag order (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<u32>,
    /// Gain.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k: Option<f64>,
    /// Sample period of a ZOH in seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_s: Option<f64>,
    /// NMP zero in rad/s (positive).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
    /// Free-text note (written by `diagnose --apply`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl EffectSpec {
    /// An effect of this kind with no parameters set, on the input path.
    pub fn new(kind: EffectKind) -> Self {
        Self {
            kind,
            path: EffectPath::Input,
            channel: None,
            tau_s: None,
            omega_c: None,
            order: None,
            k: None,
            t_s: None,
            z: None,
            note: None,
        }
    }

    /// Exact frequency response at `jω`.
    pub fn eval(&self, omega: f64) -> Complex64 {
        let j = Complex64::new(0.0, 1.0);
        match self.kind {
            EffectKind::Delay => (-j * omega * self.tau_s.unwrap_or(0.0)).exp(),
            EffectKind::Lag => {
                let wc = self.omega_c.unwrap_or(f64::INFINITY);
                (Complex64::new(1.0, 0.0) + j * omega / wc)
                    .powi(self.order.unwrap_or(1) as i32)
                    .inv()
            }
            EffectKind::Gain => Complex64::new(self.k.unwrap_or(1.0), 0.0),
            EffectKind::Sign => Complex64::new(-1.0, 0.0),
            EffectKind::Zoh => {
                let t = self.t_s.unwrap_or(0.0);
                let x = omega * t / 2.0;
                let sinc = if x.abs() < 1e-8 { 1.0 } else { x.sin() / x };
                (-j * x).exp() * sinc
            }
            EffectKind::NmpZero => {
                let z = self.z.unwrap_or(f64::INFINITY);
                (Complex64::new(1.0, 0.0) - j * omega / z)
                    / (Complex64::new(1.0, 0.0) + j * omega / z)
            }
        }
    }

    /// Rational approximation (exact for lag, gain, sign and NMP zero; Padé for delay and ZOH).
    pub fn to_tf(&self, pade_order: usize) -> TransferFunction {
        match self.kind {
            EffectKind::Delay => pade(self.tau_s.unwrap_or(0.0), pade_order),
            EffectKind::Zoh => pade(self.t_s.unwrap_or(0.0) / 2.0, pade_order),
            EffectKind::Lag => {
                let wc = self.omega_c.unwrap_or(1.0);
                let mut den = Polynomial::constant(1.0);
                for _ in 0..self.order.unwrap_or(1) {
                    den = den.mul(&Polynomial::new(vec![1.0 / wc, 1.0]));
                }
                TransferFunction {
                    num: Polynomial::constant(1.0),
                    den,
                }
            }
            EffectKind::Gain => TransferFunction::gain(self.k.unwrap_or(1.0)),
            EffectKind::Sign => TransferFunction::gain(-1.0),
            EffectKind::NmpZero => {
                let z = self.z.unwrap_or(1.0);
                TransferFunction::new(vec![-1.0 / z, 1.0], vec![1.0 / z, 1.0])
            }
        }
    }

    fn validate(&self, at: &str) -> Result<(), String> {
        let need = |v: Option<f64>, key: &str, positive: bool| -> Result<(), String> {
            match v {
                None => Err(format!("{at}: kind = \"{}\" needs {key}", self.kind_name())),
                Some(x) if !x.is_finite() => Err(format!("{at}: {key} = {x} is not finite")),
                Some(x) if positive && x <= 0.0 => {
                    Err(format!("{at}: {key} = {x} must be positive"))
                }
                Some(x) if x < 0.0 => Err(format!("{at}: {key} = {x} must be ≥ 0")),
                _ => Ok(()),
            }
        };
        match self.kind {
            EffectKind::Delay => need(self.tau_s, "tau_s", false),
            EffectKind::Lag => need(self.omega_c, "omega_c", true),
            EffectKind::Gain => match self.k {
                Some(k) if k.is_finite() && k != 0.0 => Ok(()),
                _ => Err(format!("{at}: kind = \"gain\" needs a finite nonzero k")),
            },
            EffectKind::Sign => Ok(()),
            EffectKind::Zoh => need(self.t_s, "t_s", true),
            EffectKind::NmpZero => need(self.z, "z", true),
        }
    }

    /// The snake-case name of the kind.
    pub fn kind_name(&self) -> &'static str {
        match self.kind {
            EffectKind::Delay => "delay",
            EffectKind::Lag => "lag",
            EffectKind::Gain => "gain",
            EffectKind::Sign => "sign",
            EffectKind::Zoh => "zoh",
            EffectKind::NmpZero => "nmp_zero",
        }
    }
}

/// The `[physical]` table.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicalModel {
    /// Number of inputs (default: from the gains, else 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<usize>,
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

/// A feedthrough: a number (SISO) or a matrix.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Feedthrough {
    /// SISO.
    Scalar(f64),
    /// Rows.
    Matrix(Vec<Vec<f64>>),
}

/// Padé `[n/n]` approximation of `e^{−sτ}`.
pub fn pade(tau: f64, n: usize) -> TransferFunction {
    if tau == 0.0 || n == 0 {
        return TransferFunction::gain(1.0);
    }
    // c_k = (2n−k)! n! / ((2n)! k! (n−k)!)
    let mut c = vec![1.0; n + 1];
    for k in 1..=n {
        c[k] = c[k - 1] * ((n - k + 1) as f64) / (((2 * n - k + 1) * k) as f64);
    }
    // ascending powers: num_k = c_k (−τ)^k, den_k = c_k τ^k; Polynomial wants descending.
    let num: Vec<f64> = (0..=n)
        .rev()
        .map(|k| c[k] * (-tau).powi(k as i32))
        .collect();
    let den: Vec<f64> = (0..=n).rev().map(|k| c[k] * tau.powi(k as i32)).collect();
    TransferFunction::new(num, den)
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

    fn gain_lists(&self) -> impl Iterator<Item = (&Gains, bool)> {
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

    /// Checks every parameter; the message names the table and the key.
    pub fn validate(&self) -> Result<(), String> {
        let (p, m) = (self.n_outputs(), self.n_inputs());
        if self.mode.is_empty()
            && self.rigid_body.is_empty()
            && self.integrator.is_empty()
            && self.feedthrough.is_none()
        {
            return Err("[physical]: no dynamics: add a [[physical.mode]], [[physical.rigid_body]], [[physical.integrator]] or a feedthrough".into());
        }
        let gains_ok = |g: &Gains, n: usize, at: &str, what: &str| -> Result<(), String> {
            if let Some(l) = g.len() {
                if l != n {
                    return Err(format!("{at}: {what} has {l} entries, the model has {n}"));
                }
            } else if n != 1 {
                return Err(format!(
                    "{at}: {what} is one number but the model has {n} channels: give a list"
                ));
            }
            if g.all().iter().any(|x| !x.is_finite()) {
                return Err(format!("{at}: {what} has a non-finite entry"));
            }
            Ok(())
        };
        for (k, md) in self.mode.iter().enumerate() {
            let at = format!("[[physical.mode]] #{}", k + 1);
            if !(md.omega_n.is_finite() && md.omega_n > 0.0) {
                return Err(format!(
                    "{at}: omega_n = {} must be positive (rad/s)",
                    md.omega_n
                ));
            }
            if !(md.zeta.is_finite() && md.zeta > 0.0) {
                return Err(format!(
                    "{at}: zeta = {} must be positive (an undamped mode has no stable factorization)",
                    md.zeta
                ));
            }
            if !(md.mass.is_finite() && md.mass > 0.0) {
                return Err(format!("{at}: mass = {} must be positive", md.mass));
            }
            gains_ok(&md.input_gain, m, &at, "input_gain")?;
            gains_ok(&md.output_gain, p, &at, "output_gain")?;
        }
        for (name, list) in [
            ("rigid_body", &self.rigid_body),
            ("integrator", &self.integrator),
        ] {
            for (k, md) in list.iter().enumerate() {
                let at = format!("[[physical.{name}]] #{}", k + 1);
                if !(md.mass.is_finite() && md.mass > 0.0) {
                    return Err(format!("{at}: mass = {} must be positive", md.mass));
                }
                match md.friction_pole {
                    Some(_) if name == "integrator" => {
                        return Err(format!("{at}: friction_pole belongs to a rigid_body"))
                    }
                    Some(p) if !(p.is_finite() && p >= 0.0) => {
                        return Err(format!("{at}: friction_pole = {p} must be ≥ 0 (rad/s)"))
                    }
                    _ => {}
                }
                gains_ok(&md.input_gain, m, &at, "input_gain")?;
                gains_ok(&md.output_gain, p, &at, "output_gain")?;
            }
        }
        match &self.feedthrough {
            Some(Feedthrough::Scalar(d)) if p * m != 1 || !d.is_finite() => {
                return Err(
                    "[physical] feedthrough: one finite number only for a SISO model; give p rows of m numbers".into(),
                )
            }
            Some(Feedthrough::Matrix(rows))
                if rows.len() != p
                    || rows.iter().any(|r| r.len() != m || r.iter().any(|x| !x.is_finite())) =>
            {
                return Err(format!(
                    "[physical] feedthrough: must be {p} rows of {m} finite numbers"
                ))
            }
            _ => {}
        }
        for (k, e) in self.effect.iter().enumerate() {
            let at = format!("[[physical.effect]] #{}", k + 1);
            e.validate(&at)?;
            let n = match e.path {
                EffectPath::Input => m,
                EffectPath::Output => p,
            };
            if let Some(c) = e.channel {
                if c == 0 || c > n {
                    return Err(format!("{at}: channel = {c} is not in 1..={n}"));
                }
            }
        }
        if let Some(q) = &self.factor_den {
            let poly = Polynomial::new(q.clone());
            if poly.degree() != 2
                || q.iter().any(|x| !x.is_finite())
                || poly.roots().roots.iter().any(|r| r.re >= 0.0)
            {
                return Err("[physical] factor_den: must be a stable degree-2 polynomial (descending powers of s)".into());
            }
        }
        if let Some(a) = self.factor_pole {
            if !(a.is_finite() && a > 0.0) {
                return Err(format!("[physical] factor_pole = {a}: must be positive"));
            }
        }
        Ok(())
    }

    fn d_matrix(&self) -> Option<DMatrix<f64>> {
        let (p, m) = (self.n_outputs(), self.n_inputs());
        match &self.feedthrough {
            None => None,
            Some(Feedthrough::Scalar(d)) => Some(DMatrix::from_element(1, 1, *d)),
            Some(Feedthrough::Matrix(rows)) => Some(DMatrix::from_fn(p, m, |i, j| rows[i][j])),
        }
    }

    /// The dynamics without path effects, `Σ c bᵀ/(m·den(jω)) + D`, at `jω`.
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

    /// The exact plant `G(jω)` (`p×m`), delays and ZOH included exactly.
    pub fn eval(&self, omega: f64) -> DMatrix<Complex64> {
        let mut g = self.eval_core(omega);
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

    /// The special factorization `C·M̃⁻¹·Ñ·J` (rational; see the module docs).
    pub fn to_factorization(&self) -> Result<Factorization, String> {
        self.validate()?;
        let (p, m) = (self.n_outputs(), self.n_inputs());
        let a = self.factor_pole.unwrap_or(1.0);
        let q_default = |w: f64| Polynomial::new(vec![1.0, 2.0 * w, w * w]);
        let q = |w: f64| match &self.factor_den {
            Some(c) => Polynomial::new(c.clone()),
            None => q_default(w),
        };
        let mut m_diag = Vec::new();
        let mut n_rows: Vec<Vec<TransferFunction>> = Vec::new();
        let mut c_cols: Vec<Vec<f64>> = Vec::new();
        for md in &self.mode {
            let qk = q(md.omega_n);
            let d = Polynomial::new(vec![
                md.mass,
                md.mass * 2.0 * md.zeta * md.omega_n,
                md.mass * md.omega_n * md.omega_n,
            ]);
            m_diag.push(TransferFunction {
                num: d,
                den: qk.clone(),
            });
            n_rows.push(over(&md.input_gain.to_vec(m), &qk));
            c_cols.push(md.output_gain.to_vec(p));
        }
        for (list, order) in [(&self.rigid_body, 2usize), (&self.integrator, 1)] {
            for md in list {
                let qk = if order == 2 {
                    q(a)
                } else {
                    Polynomial::new(vec![1.0, a])
                };
                let mut num = vec![md.mass];
                num.extend(std::iter::repeat_n(0.0, order));
                if let Some(p) = md.friction_pole {
                    num = vec![md.mass, md.mass * p, 0.0];
                }
                m_diag.push(TransferFunction {
                    num: Polynomial::new(num),
                    den: qk.clone(),
                });
                n_rows.push(over(&md.input_gain.to_vec(m), &qk));
                c_cols.push(md.output_gain.to_vec(p));
            }
        }
        if let Some(d) = self.d_matrix() {
            for i in 0..p {
                m_diag.push(TransferFunction::gain(1.0));
                n_rows.push((0..m).map(|j| TransferFunction::gain(d[(i, j)])).collect());
                let mut col = vec![0.0; p];
                col[i] = 1.0;
                c_cols.push(col);
            }
        }
        let n = m_diag.len();
        let c = DMatrix::from_fn(p, n, |i, k| c_cols[k][i]);
        let order = self.pade_order.unwrap_or(6);
        let mut j = vec![TransferFunction::gain(1.0); m];
        for e in &self.effect {
            if e.path == EffectPath::Output && p * m != 1 {
                if e.kind == EffectKind::Gain || e.kind == EffectKind::Sign {
                    return Err(format!(
                        "[physical] effect \"{}\" on the output path of a MIMO model: fold it into the output gains for the factorization",
                        e.kind_name()
                    ));
                }
                return Err(format!(
                    "[physical] effect \"{}\" on the output path of a MIMO model has no place in the constant C of the special factorization; move it to the input path",
                    e.kind_name()
                ));
            }
            let tf = e.to_tf(order);
            let n_ch = if e.path == EffectPath::Input { m } else { p };
            for (k, jk) in j.iter_mut().enumerate().take(n_ch) {
                if e.channel.is_none_or(|c| c == k + 1) {
                    *jk = jk.mul(&tf);
                }
            }
        }
        let mm = TfMatrix::diagonal(m_diag);
        let nn = TfMatrix::from_rows(n_rows).ok_or("[physical]: inconsistent input gains")?;
        Factorization::special(c, mm, nn, j).map_err(|e| format!("[physical]: {e}"))
    }
}

/// The row of `Ñ` for one modal coordinate: constant input gains over the common
/// denominator `q(s)` of its row of `M̃`.
fn over(gains: &[f64], q: &Polynomial) -> Vec<TransferFunction> {
    gains
        .iter()
        .map(|b| TransferFunction {
            num: Polynomial::constant(*b),
            den: q.clone(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pade_matches_delay_at_low_frequency() {
        let p = pade(0.01, 6);
        for w in [1.0, 10.0, 100.0] {
            let exact = Complex64::new(0.0, -w * 0.01).exp();
            assert!((p.freq(w) - exact).norm() < 1e-9, "w = {w}");
        }
    }
}

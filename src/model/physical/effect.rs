//! Effects on the input or output path: delay, lag, gain, sign, zero-order hold and
//! non-minimum-phase zero, evaluated exactly or as a rational (Padé) approximation.

use crate::system::{Polynomial, TransferFunction};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

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
    /// The name of the positive parameter a refit moves in logarithms (`omega_c` of a lag,
    /// `z` of an NMP zero, `t_s` of a hold); `None` for a delay (refit as τ itself), a gain and
    /// a sign.
    pub fn log_param_name(&self) -> Option<&'static str> {
        match self.kind {
            EffectKind::Lag => Some("omega_c"),
            EffectKind::NmpZero => Some("z"),
            EffectKind::Zoh => Some("t_s"),
            EffectKind::Delay | EffectKind::Gain | EffectKind::Sign => None,
        }
    }

    /// The field of that parameter ([`EffectSpec::log_param_name`]).
    pub fn log_param_mut(&mut self) -> Option<&mut Option<f64>> {
        match self.kind {
            EffectKind::Lag => Some(&mut self.omega_c),
            EffectKind::NmpZero => Some(&mut self.z),
            EffectKind::Zoh => Some(&mut self.t_s),
            EffectKind::Delay | EffectKind::Gain | EffectKind::Sign => None,
        }
    }

    /// The value of that parameter, when the effect has one and it is set.
    pub fn log_param(&self) -> Option<f64> {
        match self.kind {
            EffectKind::Lag => self.omega_c,
            EffectKind::NmpZero => self.z,
            EffectKind::Zoh => self.t_s,
            EffectKind::Delay | EffectKind::Gain | EffectKind::Sign => None,
        }
    }

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

    pub(super) fn validate(&self, at: &str) -> Result<(), String> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The refit's log-parameter is the field its name says (read back through serde's own
    /// field names, not through the same match).
    #[test]
    fn log_param_names_its_field() {
        use EffectKind::*;
        for kind in [Delay, Lag, Gain, Sign, Zoh, NmpZero] {
            let mut e = EffectSpec::new(kind);
            match e.log_param_mut() {
                Some(v) => *v = Some(3.5),
                None => {
                    assert!(matches!(kind, Delay | Gain | Sign), "{kind:?}");
                    assert_eq!(e.log_param_name(), None);
                    continue;
                }
            }
            assert_eq!(e.log_param(), Some(3.5), "{kind:?}");
            let json = serde_json::to_value(&e).expect("serializes");
            let name = e.log_param_name().expect("named");
            assert_eq!(json[name], 3.5, "{kind:?}: {json}");
        }
    }

    #[test]
    fn pade_matches_delay_at_low_frequency() {
        let p = pade(0.01, 6);
        for w in [1.0, 10.0, 100.0] {
            let exact = Complex64::new(0.0, -w * 0.01).exp();
            assert!((p.freq(w) - exact).norm() < 1e-9, "w = {w}");
        }
    }
}

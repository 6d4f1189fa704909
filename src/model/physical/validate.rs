//! Checks of a `[physical]` table: every message names the table, the entry and the key.

use super::{EffectPath, Feedthrough, Gains, PhysicalModel};
use crate::system::Polynomial;

/// Natural frequencies accepted (rad/s): `ω_n²` and the products of the mode's
/// polynomials stay far from overflow and underflow, and the data's frequency grid can reach
/// the mode (an `ω_n` of 1e300 made the envelope's iterations spin).
pub const OMEGA_N_RANGE: std::ops::RangeInclusive<f64> = 1e-8..=1e10;

/// Largest damping ratio accepted.
pub const MAX_ZETA: f64 = 1e4;

/// Smallest damping ratio accepted: below it the mode's real part `ζω_n` is lost in the
/// rounding of `s² + 2ζω_n s + ω_n²` near `ω_n` (relative `ε ≈ 1e-16`), so the factors and
/// the A1 limit at the resonance are noise (`ζ = 5e-324` was accepted).
pub const MIN_ZETA: f64 = 1e-12;

impl PhysicalModel {
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
            if !md.omega_n.is_finite() {
                return Err(format!(
                    "{at}: omega_n = {} is not a finite number: give the natural frequency in rad/s",
                    md.omega_n
                ));
            }
            if md.omega_n <= 0.0 {
                return Err(format!(
                    "{at}: omega_n = {} must be positive (rad/s)",
                    md.omega_n
                ));
            }
            if !OMEGA_N_RANGE.contains(&md.omega_n) {
                return Err(format!(
                    "{at}: omega_n = {:e} rad/s is outside {:e}…{:e} rad/s, where ω_n² and the mode's coefficients stay representable: check the units",
                    md.omega_n,
                    OMEGA_N_RANGE.start(),
                    OMEGA_N_RANGE.end()
                ));
            }
            if md.zeta.is_finite() && md.zeta > MAX_ZETA {
                return Err(format!(
                    "{at}: zeta = {:e} is above {MAX_ZETA:e}: a damping ratio is of order 1e-4…10",
                    md.zeta
                ));
            }
            if !(md.zeta.is_finite() && md.zeta > 0.0) {
                return Err(format!(
                    "{at}: zeta = {} must be positive (an undamped mode has no stable factorization)",
                    md.zeta
                ));
            }
            if md.zeta < MIN_ZETA {
                return Err(format!(
                    "{at}: zeta = {:e} is below {MIN_ZETA:e}: the mode's damping is lost in double-precision rounding; a damping ratio is of order 1e-4…10",
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
}

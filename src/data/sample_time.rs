//! Normalized frequency axes: data whose first column counts cycles (`freq_hz`) or radians
//! (`omega_rad_s`) **per sample** rather than per second, as FRFs estimated from sampled
//! records with an unknown or separate sampling time are written (the DaISy sets).  The
//! config's `sample_time = Ts` says so; each frequency is then divided by `Ts`:
//! `f = f_norm / Ts` Hz, `ω = ω_norm / Ts` rad/s.
//!
//! A normalized frequency lies in `(0, 0.5]` cycles/sample (`(0, π]` rad/sample): the DFT of a
//! sampled record has no line above the Nyquist frequency.  A frequency beyond it means the
//! column is not normalized (a file in Hz given a `sample_time`) and is refused with its line.

use super::{FrfData, StdData};
use crate::error::{Error, Result};
use std::f64::consts::PI;
use std::path::Path;

/// Checks a `sample_time` value: finite and positive.
pub fn check_sample_time(ts: f64) -> std::result::Result<(), String> {
    if ts.is_finite() && ts > 0.0 {
        Ok(())
    } else {
        Err(format!(
            "sample_time = {ts}: must be the sampling time in seconds, a finite number > 0 (write 1 when it is unknown: frequencies are then per sample)"
        ))
    }
}

/// `ω_norm / Ts` for a normalized angular frequency read at `line` of `path` (rad/sample,
/// `2π·f_norm` when the column was `freq_hz`); beyond Nyquist (`π` rad/sample) is an error.
pub fn denormalize(omega_norm: f64, ts: f64, path: &Path, line: usize) -> Result<f64> {
    // A relative 1e-12 above π still counts as the Nyquist line (0.5 written in decimal).
    if omega_norm > PI * (1.0 + 1e-12) {
        return Err(Error::Data {
            path: path.to_path_buf(),
            line,
            msg: format!(
                "frequency {} cycles/sample is above the Nyquist frequency 0.5 cycles/sample: with `sample_time` in the config the first column must be a normalized frequency (cycles/sample as `freq_hz`, rad/sample as `omega_rad_s`); if the column is in Hz or rad/s, remove `sample_time`",
                crate::report::fmt::fmt_g(omega_norm / (2.0 * PI))
            ),
        });
    }
    let omega = omega_norm / ts;
    if !omega.is_finite() {
        return Err(Error::Data {
            path: path.to_path_buf(),
            line,
            msg: format!("frequency / sample_time = {omega_norm} / {ts:e} overflows: is sample_time in seconds?"),
        });
    }
    Ok(omega)
}

/// The data with their normalized frequencies divided by `Ts` (see the module doc).
pub fn denormalize_frf(mut data: FrfData, ts: f64) -> Result<FrfData> {
    for (w, &line) in data.omega.iter_mut().zip(&data.lines) {
        *w = denormalize(*w, ts, &data.path, line)?;
    }
    Ok(data)
}

/// A std or coherence file with its normalized frequencies divided by `Ts`.
pub fn denormalize_std(mut data: StdData, ts: f64, path: &Path) -> Result<StdData> {
    for (w, &line) in data.omega.iter_mut().zip(&data.lines) {
        *w = denormalize(*w, ts, path, line)?;
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nyquist_is_the_limit_and_ts_divides() {
        let p = Path::new("x.csv");
        // 0.25 cycles/sample at Ts = 1 ms is 250 Hz.
        let w = denormalize(2.0 * PI * 0.25, 1e-3, p, 3).unwrap();
        assert!((w / (2.0 * PI) - 250.0).abs() < 1e-9);
        assert!(denormalize(2.0 * PI * 0.5, 1.0, p, 3).is_ok());
        let e = denormalize(2.0 * PI * 0.6, 1.0, p, 7)
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.csv:7:") && e.contains("Nyquist"), "{e}");
        assert!(check_sample_time(0.0).is_err() && check_sample_time(f64::NAN).is_err());
    }
}

//! A zero-order hold `e^{−sT/2}·sinc(ωT/2)` on a path: θ = [ln T].  Tried on every channel
//! and on each input (an actuator-side effect), not on a sensor.

use crate::diagnose::effects::effect::{fmt_w, grid_best, log_grid, sig, Band, Explain, Sel, Site};
use crate::diagnose::effects::path::{on_path, shifts_phase, OnPath};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

/// A zero-order hold on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Zoh(pub Sel);

impl OnPath for Zoh {
    const NAME: &'static str = "zoh";
    const KIND: EffectKind = EffectKind::Zoh;
    const SI: &'static str = "t_s";
    const LOG: bool = true;
    const ON_SENSOR: bool = false;

    fn on(sel: Sel) -> Self {
        Zoh(sel)
    }

    fn channels(&self) -> Sel {
        self.0
    }

    /// `T` from `0.01/ω_max` to `100/ω_min`.
    fn bounds_in(w_min: f64, w_max: f64) -> (f64, f64) {
        ((0.01 / w_max).ln(), (100.0 / w_min).ln())
    }

    fn apply(t: f64, omega: f64, path: &mut Complex64) {
        let s = Complex64::new(0.0, omega);
        let x = omega * t / 2.0;
        let sinc = if x.abs() < 1e-8 { 1.0 } else { x.sin() / x };
        *path *= (-s * t / 2.0).exp() * sinc
    }

    /// `f = e^{−sT/2} sin(u)/u`, `u = ωT/2`: `−s/2 + (u cot u − 1)/T` (`−u²/3` for the
    /// bracket near 0, where the factor uses `sinc = 1`).
    fn log_slope(t: f64, omega: f64) -> Complex64 {
        let u = omega * t / 2.0;
        let bracket = if u.abs() < 1e-4 {
            -u * u / 3.0
        } else {
            u / u.tan() - 1.0
        };
        -Complex64::new(0.0, omega) / 2.0 + bracket / t
    }

    fn set(e: &mut EffectSpec, v: f64) {
        e.t_s = Some(v);
    }

    /// The mean delay's `ω_max T/2`.
    fn top_phase(e: &EffectSpec, w_hi: f64) -> Option<(f64, String)> {
        shifts_phase(0.5 * w_hi * e.t_s?)
    }

    /// A hold whose Nyquist frequency π/T lies inside the band: the data above it would be
    /// aliases, not a hold's roll-off.
    fn implausible(t: f64, band: Band) -> Option<String> {
        (std::f64::consts::PI / t < band.w_max).then(|| {
            format!(
                "implausible: a zero-order hold with T = {} s has its Nyquist frequency {} inside the measured band (up to {})",
                sig(t),
                fmt_w(std::f64::consts::PI / t),
                fmt_w(band.w_max)
            )
        })
    }

    fn says(&self, x: &Explain) -> String {
        format!(
            "phase falls linearly (mean delay T/2 = {} ms) and magnitude droops like sinc(ωT/2) ({} dB at {}): a zero-order hold{} with T = {} ms (fs = {} Hz)",
            sig(x.p("t_s") * 5e2),
            sig(20.0 * {
                let y = x.wmax * x.p("t_s") / 2.0;
                (y.sin() / y).abs().log10()
            }),
            fmt_w(x.wmax),
            self.0.suffix(),
            sig(x.p("t_s") * 1e3),
            sig(1.0 / x.p("t_s"))
        )
    }

    fn rank() -> usize {
        4
    }

    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let wmax = site.band().1;
        grid_best(site, &log_grid(0.01 / wmax, 3.0 / wmax, 40), 3)
    }
}

on_path!(Zoh);

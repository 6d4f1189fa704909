//! A real non-minimum-phase zero as an all-pass `(1 − s/z)/(1 + s/z)` on a path: θ = [ln z].
//! Tried on every channel and on each input (an actuator-side effect), not on a sensor.

use crate::diagnose::effects::effect::{fmt_w, grid_best, log_grid, Band, Explain, Sel, Site};
use crate::diagnose::effects::path::{on_path, shifts_phase, OnPath};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

/// An NMP zero on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct NmpZero(pub Sel);

impl OnPath for NmpZero {
    const NAME: &'static str = "nmp_zero";
    const KIND: EffectKind = EffectKind::NmpZero;
    const SI: &'static str = "z";
    const LOG: bool = true;
    const ON_SENSOR: bool = false;

    fn on(sel: Sel) -> Self {
        NmpZero(sel)
    }

    fn channels(&self) -> Sel {
        self.0
    }

    /// A zero within two decades of the band.
    fn bounds_in(w_min: f64, w_max: f64) -> (f64, f64) {
        ((w_min / 100.0).ln(), (w_max * 100.0).ln())
    }

    fn apply(z: f64, omega: f64, path: &mut Complex64) {
        let s = Complex64::new(0.0, omega);
        let one = Complex64::new(1.0, 0.0);
        *path *= (one - s / z) / (one + s / z)
    }

    /// `f = (1 − s/z)/(1 + s/z)`: `(2s/z²)/(1 − (s/z)²)`.
    fn log_slope(z: f64, omega: f64) -> Complex64 {
        let u = Complex64::new(0.0, omega) / z;
        2.0 * u / ((Complex64::new(1.0, 0.0) - u * u) * z)
    }

    fn set(e: &mut EffectSpec, v: f64) {
        e.z = Some(v);
    }

    /// `2 atan(ω_max/z)`.
    fn top_phase(e: &EffectSpec, w_hi: f64) -> Option<(f64, String)> {
        shifts_phase(2.0 * (w_hi / e.z?).atan())
    }

    fn implausible(_: f64, _: Band) -> Option<String> {
        None
    }

    fn says(&self, x: &Explain) -> String {
        format!(
            "magnitude matches but phase falls and saturates towards −180° (−90° at {}): a non-minimum-phase zero{} at z = {}",
            fmt_w(x.p("z")),
            self.0.suffix(),
            fmt_w(x.p("z"))
        )
    }

    fn rank() -> usize {
        9
    }

    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let (wmin, wmax) = site.band();
        grid_best(site, &log_grid(wmin / 3.0, wmax * 30.0, 40), 3)
    }
}

on_path!(NmpZero);

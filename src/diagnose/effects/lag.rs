//! A first-order lag `1/(1 + s/ω_c)` on a path (an actuator or a sensor): θ = [ln ω_c].

use crate::diagnose::effects::effect::{fmt_w, grid_best, log_grid, Band, Explain, Sel, Site};
use crate::diagnose::effects::path::{on_path, shifts_phase, OnPath};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

/// A lag on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Lag(pub Sel);

impl OnPath for Lag {
    const NAME: &'static str = "lag";
    const KIND: EffectKind = EffectKind::Lag;
    const SI: &'static str = "omega_c";
    const LOG: bool = true;
    const ON_SENSOR: bool = true;

    fn on(sel: Sel) -> Self {
        Lag(sel)
    }

    fn channels(&self) -> Sel {
        self.0
    }

    /// A corner within two decades of the band.
    fn bounds_in(w_min: f64, w_max: f64) -> (f64, f64) {
        ((w_min / 100.0).ln(), (w_max * 100.0).ln())
    }

    fn apply(omega_c: f64, omega: f64, path: &mut Complex64) {
        let s = Complex64::new(0.0, omega);
        *path /= Complex64::new(1.0, 0.0) + s / omega_c;
    }

    /// `f = 1/(1 + s/ω_c)`: `(s/ω_c²)/(1 + s/ω_c)`.
    fn log_slope(omega_c: f64, omega: f64) -> Complex64 {
        let u = Complex64::new(0.0, omega) / omega_c;
        u / ((Complex64::new(1.0, 0.0) + u) * omega_c)
    }

    fn set(e: &mut EffectSpec, v: f64) {
        e.omega_c = Some(v);
    }

    /// `order · atan(ω_max/ω_c)`.
    fn top_phase(e: &EffectSpec, w_hi: f64) -> Option<(f64, String)> {
        shifts_phase((w_hi / e.omega_c?).atan() * e.order.unwrap_or(1) as f64)
    }

    fn implausible(_: f64, _: Band) -> Option<String> {
        None
    }

    fn says(&self, x: &Explain) -> String {
        format!(
            "magnitude droops and phase lags towards −90° above the corner, with no linear phase: a first-order lag{} ({}) at ω_c = {}",
            self.0.suffix(),
            match self.0 {
                Sel::Output(_) => "a sensor",
                Sel::Input(_) => "an actuator",
                Sel::All => "actuator or sensor",
            },
            fmt_w(x.p("omega_c"))
        )
    }

    fn rank() -> usize {
        3
    }

    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let (wmin, wmax) = site.band();
        grid_best(site, &log_grid(wmin / 3.0, wmax * 30.0, 40), 3)
    }
}

on_path!(Lag);

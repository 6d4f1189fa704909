//! A pure delay `e^{−sτ}` on a path (transport or computation delay): θ = \[τ\] (s, `|τ|`
//! used).

use crate::diagnose::effects::effect::{fmt_w, pick, sig, Band, Explain, Sel, Site};
use crate::diagnose::effects::path::{on_path, OnPath};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

/// A delay of more than this phase (rad) at the band top is implausible: more than half a
/// cycle of lag is not a transport or computation delay a servo loop works with.
pub const MAX_DELAY_PHASE: f64 = std::f64::consts::PI;

/// A delay on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Delay(pub Sel);

impl OnPath for Delay {
    const NAME: &'static str = "delay";
    const KIND: EffectKind = EffectKind::Delay;
    const SI: &'static str = "tau_s";
    const LOG: bool = false;
    const ON_SENSOR: bool = true;

    fn on(sel: Sel) -> Self {
        Delay(sel)
    }

    fn channels(&self) -> Sel {
        self.0
    }

    /// A delay below 100/ω_min.
    fn bounds_in(w_min: f64, _: f64) -> (f64, f64) {
        (-100.0 / w_min, 100.0 / w_min)
    }

    fn apply(tau: f64, omega: f64, path: &mut Complex64) {
        *path *= (-Complex64::new(0.0, omega) * tau).exp();
    }

    /// `f = e^{−jωτ}`: `−jω`.
    fn log_slope(_: f64, omega: f64) -> Complex64 {
        -Complex64::new(0.0, omega)
    }

    fn set(e: &mut EffectSpec, v: f64) {
        e.tau_s = Some(v);
    }

    /// `ω_max |τ|`.
    fn top_phase(e: &EffectSpec, w_hi: f64) -> Option<(f64, String)> {
        let tau = e.tau_s?.abs();
        let phase = w_hi * tau;
        Some((
            phase,
            format!(
                "a delay of {} s lags {}°",
                sig(tau),
                sig(phase.to_degrees())
            ),
        ))
    }

    /// More than half a cycle of lag at the band top is not a transport or computation
    /// delay a servo loop works with; it fits the slope of dynamics the model lacks.
    fn implausible(tau: f64, band: Band) -> Option<String> {
        (tau * band.w_max > MAX_DELAY_PHASE).then(|| {
            format!(
                "implausible: a delay of {} s lags {:.0}° at the band top {} (more than {:.0}°): the phase slope is unmodelled dynamics, not a delay",
                sig(tau),
                (tau * band.w_max).to_degrees(),
                fmt_w(band.w_max),
                MAX_DELAY_PHASE.to_degrees()
            )
        })
    }

    fn says(&self, x: &Explain) -> String {
        format!(
            "phase falls linearly with frequency while magnitude matches: a pure delay{} of {} ms ({}° of extra lag at {})",
            self.0.suffix(),
            sig(x.p("tau_s") * 1e3),
            sig((x.wmax * x.p("tau_s")).to_degrees()),
            fmt_w(x.wmax)
        )
    }

    fn rank() -> usize {
        2
    }

    /// The best points of a grid of `τ` in steps of 0.05 rad of phase at the band top, over
    /// six half cycles.
    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let step = 0.05 / site.band().1;
        let n = (6.0 * std::f64::consts::PI / 0.05) as usize + 1;
        pick(site.delay_costs(self.0, step, n), 3)
    }
}

on_path!(Delay);

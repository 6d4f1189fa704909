//! A pure delay `e^{−sτ}` on a path (transport or computation delay): θ = \[τ\] (s, `|τ|`
//! used).

use crate::diagnose::effects::effect::{at_bound_flag, fmt_w, one, pick, sig, Band, Effect, Explain, Sel, Si, Site, Stands, Writer};
use crate::model::physical::{EffectKind, PhysicalModel};
use num_complex::Complex64;

/// A delay of more than this phase (rad) at the band top is implausible: more than half a
/// cycle of lag is not a transport or computation delay a servo loop works with.
pub const MAX_DELAY_PHASE: f64 = std::f64::consts::PI;

/// A delay on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Delay(pub Sel);

impl Effect for Delay {
    const NAME: &'static str = "delay";

    fn tried_on(sel: Sel) -> Vec<Self> {
        vec![Delay(sel)]
    }

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![]
    }

    fn sel(&self) -> Option<Sel> {
        Some(self.0)
    }

    fn n_params(&self, _: usize) -> usize {
        1
    }

    fn typ(&self, _: &[f64], omega_max: f64) -> Vec<f64> {
        vec![1.0 / omega_max]
    }

    /// A delay below 100/ω_min.
    fn bounds(&self, _: usize, w_min: f64, _: f64, _: f64) -> Vec<(f64, f64)> {
        vec![(-100.0 / w_min, 100.0 / w_min)]
    }

    fn natural(&self, th: &[f64], nat: &mut [f64]) {
        nat[0] = th[0].abs();
    }

    fn base_residue(&self, _: &PhysicalModel, _: (usize, usize)) -> f64 {
        0.0
    }

    fn modify(
        &self,
        nat: &[f64],
        _: f64,
        _: &PhysicalModel,
        omega: f64,
        _: usize,
        entry: (usize, usize),
        _: &mut Complex64,
        path: &mut Complex64,
    ) {
        if self.0.hits(entry) {
            *path *= (-Complex64::new(0.0, omega) * nat[0]).exp();
        }
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        one("tau_s", th[0].abs(), 1.0)
    }

    fn write(&self, w: &mut Writer) {
        let v = w.get("tau_s");
        w.path_effect(EffectKind::Delay, &self.0, &|e| e.tau_s = Some(v));
    }

    fn explain(&self, x: &Explain) -> String {
        format!(
            "phase falls linearly with frequency while magnitude matches: a pure delay{} of {} ms ({}° of extra lag at {})",
            self.0.suffix(),
            sig(x.p("tau_s") * 1e3),
            sig((x.wmax * x.p("tau_s")).to_degrees()),
            fmt_w(x.wmax)
        )
    }

    fn prior(&self) -> usize {
        2
    }

    /// The best points of a grid of `τ` in steps of 0.05 rad of phase at the band top, over
    /// six half cycles.
    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let step = 0.05 / site.band().1;
        let n = (6.0 * std::f64::consts::PI / 0.05) as usize + 1;
        pick(site.delay_costs(self.0, step, n), 3)
    }

    fn flags(&self, th: &[f64], at: &dyn Fn(usize) -> bool, si: &Si, band: Band, out: &mut Vec<String>) {
        // More than half a cycle of lag at the band top is not a transport or computation
        // delay a servo loop works with; it fits the slope of dynamics the model lacks.
        if th[0].abs() * band.w_max > MAX_DELAY_PHASE {
            out.push(format!(
                "implausible: a delay of {} s lags {:.0}° at the band top {} (more than {:.0}°): the phase slope is unmodelled dynamics, not a delay",
                sig(th[0].abs()),
                (th[0].abs() * band.w_max).to_degrees(),
                fmt_w(band.w_max),
                MAX_DELAY_PHASE.to_degrees()
            ));
        } else if at(0) {
            out.push(at_bound_flag(si));
        }
    }

    fn stands(&self) -> Stands {
        Stands::AddedPathEffect
    }

    fn lacks_its_term(&self, _: &PhysicalModel) -> bool {
        false
    }
}

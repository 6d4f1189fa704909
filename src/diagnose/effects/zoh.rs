//! A zero-order hold `e^{−sT/2}·sinc(ωT/2)` on a path: θ = [ln T].  Tried on every channel
//! and on each input (an actuator-side effect), not on a sensor.

use crate::diagnose::effects::effect::{at_bound_flag, fmt_w, grid_best, log_grid, one, sig, Band, Effect, Explain, Sel, Si, Site, Stands, Writer};
use crate::model::physical::{EffectKind, PhysicalModel};
use num_complex::Complex64;

/// zoh on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Zoh(pub Sel);

impl Effect for Zoh {
    const NAME: &'static str = "zoh";

    fn tried_on(sel: Sel) -> Vec<Self> {
        if matches!(sel, Sel::Output(_)) {
            vec![]
        } else {
            vec![Zoh(sel)]
        }
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

    fn typ(&self, _: &[f64], _: f64) -> Vec<f64> {
        vec![1.0]
    }

    fn bounds(&self, _: usize, w_min: f64, w_max: f64, _: f64) -> Vec<(f64, f64)> {
        vec![((0.01 / w_max).ln(), (100.0 / w_min).ln())]
    }

    fn natural(&self, th: &[f64], nat: &mut [f64]) {
        nat[0] = th[0].exp();
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
            let s = Complex64::new(0.0, omega);
            let t = nat[0];
            let x = omega * t / 2.0;
            let sinc = if x.abs() < 1e-8 { 1.0 } else { x.sin() / x };
            *path *= (-s * t / 2.0).exp() * sinc
        }
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        one("t_s", th[0].exp(), th[0].exp())
    }

    fn write(&self, w: &mut Writer) {
        let v = w.get("t_s");
        w.path_effect(EffectKind::Zoh, &self.0, &|e| e.t_s = Some(v));
    }

    fn explain(&self, x: &Explain) -> String {
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

    fn prior(&self) -> usize {
        4
    }

    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let wmax = site.band().1;
        grid_best(site, &log_grid(0.01 / wmax, 3.0 / wmax, 40), 3)
    }

    fn flags(&self, th: &[f64], at: &dyn Fn(usize) -> bool, si: &Si, band: Band, out: &mut Vec<String>) {
        // A zero-order hold whose Nyquist frequency π/T lies inside the band: the data above
        // it would be aliases, not a hold's roll-off.
        if std::f64::consts::PI / th[0].exp() < band.w_max {
            out.push(format!(
                "implausible: a zero-order hold with T = {} s has its Nyquist frequency {} inside the measured band (up to {})",
                sig(th[0].exp()),
                fmt_w(std::f64::consts::PI / th[0].exp()),
                fmt_w(band.w_max)
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

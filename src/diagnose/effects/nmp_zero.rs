//! A real non-minimum-phase zero as an all-pass `(1 − s/z)/(1 + s/z)` on a path: θ = [ln z].
//! Tried on every channel and on each input (an actuator-side effect), not on a sensor.

use crate::diagnose::effects::effect::{at_bound_flag, fmt_w, grid_best, log_grid, one, Band, Effect, Explain, Sel, Si, Site, Stands, Writer};
use crate::model::physical::{EffectKind, PhysicalModel};
use num_complex::Complex64;

/// nmp_zero on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct NmpZero(pub Sel);

impl Effect for NmpZero {
    const NAME: &'static str = "nmp_zero";

    fn tried_on(sel: Sel) -> Vec<Self> {
        if matches!(sel, Sel::Output(_)) {
            vec![]
        } else {
            vec![NmpZero(sel)]
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
        vec![((w_min / 100.0).ln(), (w_max * 100.0).ln())]
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
            let (one, z) = (Complex64::new(1.0, 0.0), nat[0]);
            *path *= (one - s / z) / (one + s / z)
        }
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        one("z", th[0].exp(), th[0].exp())
    }

    fn write(&self, w: &mut Writer) {
        let v = w.get("z");
        w.path_effect(EffectKind::NmpZero, &self.0, &|e| e.z = Some(v));
    }

    fn explain(&self, x: &Explain) -> String {
        format!(
            "magnitude matches but phase falls and saturates towards −180° (−90° at {}): a non-minimum-phase zero{} at z = {}",
            fmt_w(x.p("z")),
            self.0.suffix(),
            fmt_w(x.p("z"))
        )
    }

    fn prior(&self) -> usize {
        9
    }

    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let (wmin, wmax) = site.band();
        grid_best(site, &log_grid(wmin / 3.0, wmax * 30.0, 40), 3)
    }

    fn flags(&self, th: &[f64], at: &dyn Fn(usize) -> bool, si: &Si, band: Band, out: &mut Vec<String>) {
        let _ = (th, band);
        if at(0) {
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

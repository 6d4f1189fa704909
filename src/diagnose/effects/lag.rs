//! A first-order lag `1/(1 + s/ω_c)` on a path (an actuator or a sensor): θ = [ln ω_c].

use crate::diagnose::effects::effect::{at_bound_flag, fmt_w, grid_best, log_grid, one, Band, Effect, Explain, Sel, Si, Site, Stands, Writer};
use crate::model::physical::{EffectKind, PhysicalModel};
use num_complex::Complex64;

/// lag on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Lag(pub Sel);

impl Effect for Lag {
    const NAME: &'static str = "lag";

    fn tried_on(sel: Sel) -> Vec<Self> {
        vec![Lag(sel)]
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
            *path /= Complex64::new(1.0, 0.0) + s / nat[0];
        }
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        one("omega_c", th[0].exp(), th[0].exp())
    }

    fn write(&self, w: &mut Writer) {
        let v = w.get("omega_c");
        w.path_effect(EffectKind::Lag, &self.0, &|e| e.omega_c = Some(v));
    }

    fn explain(&self, x: &Explain) -> String {
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

    fn prior(&self) -> usize {
        3
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

//! Viscous friction on rigid body `i` of the configured model: `1/s²` becomes
//! `1/(s (s + p))`; θ = [ln p].  Tried on each rigid body without a friction pole.

use crate::diagnose::effects::effect::{
    at_bound_flag, bare, fmt_w, grid_best, log_grid, one, residue, sig, Band, Effect, Explain,
    Param, Resolution, Sel, Si, Site, Stands, Writer,
};
use crate::model::physical::PhysicalModel;
use num_complex::Complex64;

/// Friction on rigid body `i` (0-based).
#[derive(Debug, Clone, Copy)]
pub struct Friction(pub usize);

impl Effect for Friction {
    const NAME: &'static str = "friction";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    fn tried(base: &PhysicalModel) -> Vec<Self> {
        base.rigid_body
            .iter()
            .enumerate()
            .filter(|(_, r)| r.friction_pole.is_none())
            .map(|(i, _)| Friction(i))
            .collect()
    }

    fn sel(&self) -> Option<Sel> {
        None
    }

    fn n_params(&self, _: usize) -> usize {
        1
    }

    fn typ(&self, _: &[f64], _: f64) -> Vec<f64> {
        vec![1.0]
    }

    fn bounds(&self, _: usize, w_min: f64, w_max: f64, _: f64) -> Vec<(f64, f64)> {
        vec![((w_min / 1e3).ln(), (w_max * 10.0).ln())]
    }

    fn natural(&self, th: &[f64], nat: &mut [f64]) {
        nat[0] = th[0].exp();
    }

    fn base_residue(&self, base: &PhysicalModel, entry: (usize, usize)) -> f64 {
        let r = &base.rigid_body[self.0];
        let (p, m) = (base.n_outputs(), base.n_inputs());
        residue(&r.output_gain, &r.input_gain, r.mass, p, m, entry)
    }

    fn modify(
        &self,
        nat: &[f64],
        rho: f64,
        base: &PhysicalModel,
        omega: f64,
        _: usize,
        _: (usize, usize),
        core: &mut Complex64,
        _: &mut Complex64,
    ) {
        let s = Complex64::new(0.0, omega);
        let p0 = base.rigid_body[self.0].friction_pole.unwrap_or(0.0);
        *core += rho / (s * (s + nat[0])) - rho / (s * (s + p0));
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        let mut v = one("rigid_body", (self.0 + 1) as f64, 0.0);
        v.extend(one("pole", th[0].exp(), th[0].exp()));
        v
    }

    fn write(&self, w: &mut Writer) {
        w.m.rigid_body[self.0].friction_pole = Some(w.get("pole"));
    }

    fn explain(&self, x: &Explain) -> String {
        format!(
            "the phase leads −180° at low frequency by atan(p/ω) and the lead fades with frequency, while the magnitude follows the rigid body: viscous friction on rigid body {}, pole p = c_v/J = {}",
            self.0 + 1,
            fmt_w(x.p("pole"))
        )
    }

    fn prior(&self) -> usize {
        6
    }

    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let (wmin, wmax) = site.band();
        grid_best(site, &log_grid(wmin / 1000.0, wmax, 40), 3)
    }

    fn flags(
        &self,
        _: &[f64],
        at: &dyn Fn(usize) -> bool,
        si: &Si,
        _: Band,
        out: &mut Vec<String>,
    ) {
        if at(0) {
            out.push(at_bound_flag(si));
        }
    }

    fn stands(&self) -> Stands {
        Stands::FrictionPole(self.0)
    }

    fn lacks_its_term(&self, m: &PhysicalModel) -> bool {
        self.0 >= m.rigid_body.len()
    }

    fn its_mode(&self, _: &PhysicalModel) -> Option<usize> {
        None
    }

    /// The rigid body with its friction pole.
    fn term_alone(&self, m: &PhysicalModel) -> Option<PhysicalModel> {
        let mut alone = bare(m);
        alone.rigid_body.push(m.rigid_body.get(self.0)?.clone());
        Some(alone)
    }

    /// A pole whose relative effect at the band bottom, `p/ω_min`, is below the noise's
    /// relative resolution there.
    fn below_resolution(&self, m: &PhysicalModel, r: &Resolution) -> Option<String> {
        let p = m.rigid_body.get(self.0)?.friction_pole?;
        (p / r.w_lo < r.rel_bottom).then(|| {
            format!(
                "a friction pole at {} rad/s changes the response at the band bottom ({} rad/s) by {}, below the noise's relative resolution there ({})",
                sig(p),
                sig(r.w_lo),
                sig(p / r.w_lo),
                sig(r.rel_bottom)
            )
        })
    }

    fn owns(&self, _: &PhysicalModel) -> Vec<Param> {
        vec![Param::FrictionPole(self.0)]
    }

    fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
        0.0
    }
}

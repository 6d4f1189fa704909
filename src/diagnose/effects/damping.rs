//! A changed damping of a configured mode: θ = [ln ζ].  Not tried by the search (the retune
//! refits the model's own dampings); `compare` revisions and library users name it.

use crate::diagnose::effects::effect::{clamp_zeta, fmt_w, grid_best, log_grid, one, residue, sig, Band, Effect, Explain, Sel, Si, Site, Stands, Writer, ZETA_BOUNDS};
use crate::diagnose::effects::mode::mode_term;
use crate::model::physical::PhysicalModel;
use num_complex::Complex64;

/// Damping of mode `i` (0-based) of the configured model.
#[derive(Debug, Clone, Copy)]
pub struct Damping(pub usize);

impl Effect for Damping {
    const NAME: &'static str = "damping";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![]
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

    fn bounds(&self, _: usize, _: f64, _: f64, zeta_lo: f64) -> Vec<(f64, f64)> {
        vec![(zeta_lo.max(ZETA_BOUNDS.0).ln(), ZETA_BOUNDS.1.ln())]
    }

    fn natural(&self, th: &[f64], nat: &mut [f64]) {
        nat[0] = clamp_zeta(th[0].exp());
    }

    fn base_residue(&self, base: &PhysicalModel, entry: (usize, usize)) -> f64 {
        let md = &base.mode[self.0];
        let (p, m) = (base.n_outputs(), base.n_inputs());
        residue(&md.output_gain, &md.input_gain, md.mass, p, m, entry)
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
        let md = &base.mode[self.0];
        let (w, z) = (md.omega_n, nat[0]);
        *core += mode_term(omega, w, z, rho) - mode_term(omega, md.omega_n, md.zeta, rho);
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        let mut v = one("mode", (self.0 + 1) as f64, 0.0);
        let z = clamp_zeta(th[0].exp());
        v.extend(one("zeta", z, z));
        v
    }

    fn write(&self, w: &mut Writer) {
        w.m.mode[self.0].zeta = w.get("zeta");
    }

    fn explain(&self, x: &Explain) -> String {
        let i = self.0;
        let old = x.base.mode[i].zeta;
        format!(
            "the error is symmetric about mode {} at {}: its damping is ζ = {} instead of {}",
            i + 1,
            fmt_w(x.base.mode[i].omega_n),
            sig(x.p("zeta")),
            sig(old)
        )
    }

    fn prior(&self) -> usize {
        7
    }

    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        grid_best(site, &log_grid(1e-3, 0.7, 30), 3)
    }

    fn flags(&self, _: &[f64], at: &dyn Fn(usize) -> bool, _: &Si, _: Band, out: &mut Vec<String>) {
        if at(0) {
            out.push("ζ at its bound: not identified".into());
        }
    }

    fn stands(&self) -> Stands {
        Stands::ConfiguredMode(self.0)
    }

    fn lacks_its_term(&self, m: &PhysicalModel) -> bool {
        self.0 >= m.mode.len()
    }
}

//! A shifted frequency of a configured mode: θ = [ln ω_n].  Not tried by the search (the
//! retune refits the model's own frequencies); `compare` revisions and library users name it.

use crate::diagnose::effects::effect::{fmt_change, fmt_w, grid_best, one, residue, Band, Effect, Explain, Sel, Si, Site, Stands, Writer};
use crate::diagnose::effects::mode::mode_term;
use crate::model::physical::PhysicalModel;
use num_complex::Complex64;

/// A shifted frequency of mode `i` (0-based) of the configured model.
#[derive(Debug, Clone, Copy)]
pub struct ModeShift(pub usize);

impl Effect for ModeShift {
    const NAME: &'static str = "mode_shift";

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

    fn bounds(&self, _: usize, w_min: f64, w_max: f64, _: f64) -> Vec<(f64, f64)> {
        vec![(w_min.ln(), w_max.ln())]
    }

    fn natural(&self, th: &[f64], nat: &mut [f64]) {
        nat[0] = th[0].exp();
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
        let (w, z) = (nat[0], md.zeta);
        *core += mode_term(omega, w, z, rho) - mode_term(omega, md.omega_n, md.zeta, rho);
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        let mut v = one("mode", (self.0 + 1) as f64, 0.0);
        v.extend(one("omega_n", th[0].exp(), th[0].exp()));
        v
    }

    fn write(&self, w: &mut Writer) {
        w.m.mode[self.0].omega_n = w.get("omega_n");
    }

    fn explain(&self, x: &Explain) -> String {
        let i = self.0;
        let old = x.base.mode[i].omega_n;
        format!(
            "the data resonate at {} where mode {} of the model resonates at {}: mode {} shifted by {}",
            fmt_w(x.p("omega_n")),
            i + 1,
            fmt_w(old),
            i + 1,
            fmt_change(x.p("omega_n") / old)
        )
    }

    fn prior(&self) -> usize {
        8
    }

    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let w0 = site.base().mode[self.0].omega_n;
        let grid: Vec<f64> = (0..61)
            .map(|j| w0.ln() + (j as f64 - 30.0) / 60.0)
            .collect();
        grid_best(site, &grid, 3)
    }

    fn flags(&self, _: &[f64], at: &dyn Fn(usize) -> bool, _: &Si, _: Band, out: &mut Vec<String>) {
        let _ = (at, out);
    }

    fn stands(&self) -> Stands {
        Stands::ConfiguredMode(self.0)
    }

    fn lacks_its_term(&self, m: &PhysicalModel) -> bool {
        self.0 >= m.mode.len()
    }
}

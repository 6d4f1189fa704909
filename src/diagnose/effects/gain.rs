//! A gain error `k` on a path: θ = \[k\].  Not tried by the search (the retune refits the
//! model's own gains); `compare` revisions and library users name it.

use crate::diagnose::effects::effect::{
    fmt_change, one, sig, Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands, Writer,
};
use crate::model::physical::{EffectKind, PhysicalModel};
use num_complex::Complex64;

/// gain on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Gain(pub Sel);

impl Effect for Gain {
    const NAME: &'static str = "gain";

    fn tried_on(sel: Sel) -> Vec<Self> {
        let _ = sel;
        vec![]
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

    fn typ(&self, theta: &[f64], _: f64) -> Vec<f64> {
        theta.iter().map(|x| x.abs().max(1e-300)).collect()
    }

    fn bounds(&self, _: usize, w_min: f64, w_max: f64, _: f64) -> Vec<(f64, f64)> {
        let _ = (w_min, w_max);
        vec![(-1e3, 1e3)]
    }

    fn natural(&self, _: &[f64], _: &mut [f64]) {}

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
            let _ = s;
            *path *= nat[0];
        }
    }

    fn si_params(&self, th: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        one("k", th[0], 1.0)
    }

    fn write(&self, w: &mut Writer) {
        let v = w.get("k");
        w.path_effect(EffectKind::Gain, &self.0, &|e| e.k = Some(v));
    }

    fn explain(&self, x: &Explain) -> String {
        format!(
            "the ratio data/model is flat in magnitude with zero phase: a gain error{}, k = {} ({})",
            self.0.suffix(),
            sig(x.p("k")),
            fmt_change(x.p("k"))
        )
    }

    fn prior(&self) -> usize {
        1
    }

    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        vec![vec![
            1.0 + site.ls(&site.channels(self.0), &|ch, k| site.response(ch, k)),
        ]]
    }

    fn flags(
        &self,
        th: &[f64],
        at: &dyn Fn(usize) -> bool,
        si: &Si,
        band: Band,
        out: &mut Vec<String>,
    ) {
        let _ = (th, at, si, band, out);
    }

    fn stands(&self) -> Stands {
        Stands::AddedPathEffect
    }

    fn lacks_its_term(&self, _: &PhysicalModel) -> bool {
        false
    }

    fn its_mode(&self, _: &PhysicalModel) -> Option<usize> {
        None
    }

    fn term_alone(&self, _: &PhysicalModel) -> Option<PhysicalModel> {
        None
    }

    fn below_resolution(&self, _: &PhysicalModel, _: &Resolution) -> Option<String> {
        None
    }

    fn owns(&self, _: &PhysicalModel) -> Vec<Param> {
        vec![]
    }

    fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
        0.0
    }
}

//! A sign flip `−1` on a path: no parameter.  Not tried by the search (the retune refits the
//! model's own gains, signs included); `compare` revisions and library users name it.

use crate::diagnose::effects::effect::{
    Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands, Writer,
};
use crate::model::physical::{EffectKind, PhysicalModel};
use num_complex::Complex64;

/// A sign flip on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Sign(pub Sel);

impl Effect for Sign {
    const NAME: &'static str = "sign";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![]
    }

    fn sel(&self) -> Option<Sel> {
        Some(self.0)
    }

    fn n_params(&self, _: usize) -> usize {
        0
    }

    fn typ(&self, _: &[f64], _: f64) -> Vec<f64> {
        vec![]
    }

    fn bounds(&self, _: usize, _: f64, _: f64, _: f64) -> Vec<(f64, f64)> {
        vec![]
    }

    fn natural(&self, _: &[f64], _: &mut [f64]) {}

    fn base_residue(&self, _: &PhysicalModel, _: (usize, usize)) -> f64 {
        0.0
    }

    fn modify(
        &self,
        _: &[f64],
        _: f64,
        _: &PhysicalModel,
        _: f64,
        _: usize,
        entry: (usize, usize),
        _: &mut Complex64,
        path: &mut Complex64,
    ) {
        if self.0.hits(entry) {
            *path = -*path;
        }
    }

    fn si_params(&self, _: &[f64], _: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        vec![]
    }

    fn write(&self, w: &mut Writer) {
        w.path_effect(EffectKind::Sign, &self.0, &|_| {});
    }

    fn explain(&self, _: &Explain) -> String {
        "the data are the model rotated by 180° at every frequency with matching magnitude: a sign flip".into()
    }

    fn prior(&self) -> usize {
        0
    }

    fn starts(&self, _: &dyn Site) -> Vec<Vec<f64>> {
        vec![vec![]]
    }

    fn flags(&self, _: &[f64], _: &dyn Fn(usize) -> bool, _: &Si, _: Band, _: &mut Vec<String>) {}

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

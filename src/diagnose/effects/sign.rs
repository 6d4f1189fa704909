//! A sign flip `−1` on a path: no parameter.  Not tried by the search (the retune refits the
//! model's own gains, signs included); `compare` revisions and library users name it.

use crate::diagnose::effects::effect::{Explain, Sel, Site};
use crate::diagnose::effects::factor::{path_factor, PathFactor};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

/// A sign flip on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Sign(pub Sel);

impl PathFactor for Sign {
    const NAME: &'static str = "sign";
    const KIND: EffectKind = EffectKind::Sign;
    const PARAMS: &'static [&'static str] = &[];

    fn channels(&self) -> Sel {
        self.0
    }

    fn apply(_: &[f64], path: &mut Complex64) {
        *path = -*path;
    }

    fn set(_: &mut EffectSpec, _: &[f64]) {}

    fn says(&self, _: &Explain) -> String {
        "the data are the model rotated by 180° at every frequency with matching magnitude: a sign flip".into()
    }

    fn rank() -> usize {
        0
    }

    /// No parameter: one empty start.
    fn start(&self, _: &dyn Site) -> Vec<Vec<f64>> {
        vec![vec![]]
    }
}

path_factor!(Sign);

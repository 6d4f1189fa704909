//! A gain error `k` on a path: θ = \[k\].  Not tried by the search (the retune refits the
//! model's own gains); `compare` revisions and library users name it.

use crate::diagnose::effects::effect::{fmt_change, sig, Explain, Sel, Site};
use crate::diagnose::effects::factor::{path_factor, PathFactor};
use crate::model::physical::{EffectKind, EffectSpec};
use num_complex::Complex64;

/// gain on the channels it selects.
#[derive(Debug, Clone, Copy)]
pub struct Gain(pub Sel);

impl PathFactor for Gain {
    const NAME: &'static str = "gain";
    const KIND: EffectKind = EffectKind::Gain;
    const PARAMS: &'static [&'static str] = &["k"];

    fn channels(&self) -> Sel {
        self.0
    }

    fn apply(nat: &[f64], path: &mut Complex64) {
        *path *= nat[0];
    }

    fn set(e: &mut EffectSpec, v: &[f64]) {
        e.k = Some(v[0]);
    }

    fn says(&self, x: &Explain) -> String {
        format!(
            "the ratio data/model is flat in magnitude with zero phase: a gain error{}, k = {} ({})",
            self.0.suffix(),
            sig(x.p("k")),
            fmt_change(x.p("k"))
        )
    }

    fn rank() -> usize {
        1
    }

    /// `1 +` the least-squares coefficient of the residual on the response.
    fn start(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        vec![vec![
            1.0 + site.ls(&site.channels(self.0), &|ch, k| site.response(ch, k)),
        ]]
    }
}

path_factor!(Gain);

//! An added feedthrough `D` (the upper residual of modes above the band); θ = [d_1 … d_C].

use crate::diagnose::effects::effect::{
    per_channel, Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands, Writer,
};
use crate::model::physical::{Feedthrough as Spec, PhysicalModel, Quantity};
use num_complex::Complex64;

/// An added feedthrough.
#[derive(Debug, Clone, Copy)]
pub struct Feedthrough;

impl Effect for Feedthrough {
    const NAME: &'static str = "feedthrough";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![Feedthrough]
    }

    fn sel(&self) -> Option<Sel> {
        None
    }

    fn n_params(&self, n_ch: usize) -> usize {
        n_ch
    }

    fn typ(&self, theta: &[f64], _: f64) -> Vec<f64> {
        theta.iter().map(|x| x.abs().max(1e-300)).collect()
    }

    fn bounds(&self, n_ch: usize, _: f64, _: f64, _: f64) -> Vec<(f64, f64)> {
        vec![(f64::NEG_INFINITY, f64::INFINITY); n_ch]
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
        _: f64,
        ch: usize,
        _: (usize, usize),
        core: &mut Complex64,
        _: &mut Complex64,
    ) {
        *core += nat[ch];
    }

    fn si_params(&self, th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        per_channel("d", th, 0, entries)
    }

    fn write(&self, w: &mut Writer) {
        let m = &mut *w.m;
        let (p_out, m_in) = (m.n_outputs(), m.n_inputs());
        let mut d = match &m.feedthrough {
            Some(Spec::Scalar(d)) => vec![vec![*d]],
            Some(Spec::Matrix(r)) => r.clone(),
            None => vec![vec![0.0; m_in]; p_out],
        };
        for (ch, (o, i)) in w.entries.iter().enumerate() {
            d[*o][*i] += w.th[ch];
        }
        m.feedthrough = Some(if p_out * m_in == 1 {
            Spec::Scalar(d[0][0])
        } else {
            Spec::Matrix(d)
        });
    }

    fn explain(&self, x: &Explain) -> String {
        match x.base.quantity {
            Quantity::Displacement => format!(
                "the error is a constant real term, flat in frequency, that dominates where the model rolls off and moves the anti-resonances: the upper residual (residual flexibility of modes above the band) D = {}",
                x.list("d")
            ),
            q => format!(
                "the error rises as ω{} towards the band top and moves the anti-resonances: the upper residual of the {} (residual flexibility of modes above the band, D s{} with D = {})",
                if q == Quantity::Acceleration { "²" } else { "" },
                q.frf_name(),
                if q == Quantity::Acceleration { "²" } else { "" },
                x.list("d")
            ),
        }
    }

    fn prior(&self) -> usize {
        5
    }

    /// Each channel's `d` by least squares on the path.
    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        vec![(0..site.n_ch())
            .map(|ch| site.ls(&[ch], &|ch, k| site.path(ch, k)))
            .collect()]
    }

    fn flags(&self, _: &[f64], _: &dyn Fn(usize) -> bool, _: &Si, _: Band, _: &mut Vec<String>) {}

    fn stands(&self) -> Stands {
        Stands::Feedthrough
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
        vec![Param::Feedthrough]
    }

    fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
        0.0
    }
}

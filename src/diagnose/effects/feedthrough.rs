//! An added feedthrough `D` (the upper residual of modes above the band); θ = [d_1 … d_C].

use crate::diagnose::effects::coefficient::{coefficient, Coefficient};
use crate::diagnose::effects::effect::{Band, Explain, Param, Stands, Writer};
use crate::model::physical::{Feedthrough as Spec, PhysicalModel, Quantity};

/// An added feedthrough.
#[derive(Debug, Clone, Copy)]
pub struct Feedthrough;

impl Coefficient for Feedthrough {
    const NAME: &'static str = "feedthrough";
    const SI: &'static str = "d";

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![Feedthrough]
    }

    /// `D s⁰`.
    fn power(&self) -> u8 {
        0
    }

    fn labels(&self) -> Vec<(String, f64, f64)> {
        vec![]
    }

    /// Added to the configured `D` entry by entry.
    fn write_into(&self, w: &mut Writer) {
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

    fn says(&self, x: &Explain) -> String {
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

    fn rank() -> usize {
        5
    }

    /// A feedthrough is plausible on every quantity (the upper residual).
    fn implausible(&self, _: Band) -> Option<String> {
        None
    }

    fn stands_as(&self) -> Stands {
        Stands::Feedthrough
    }

    /// None: the feedthrough's size is not judged alone.
    fn alone(&self, _: &PhysicalModel) -> Option<PhysicalModel> {
        None
    }

    fn owned(&self, _: &PhysicalModel) -> Vec<Param> {
        vec![Param::Feedthrough]
    }
}

coefficient!(Feedthrough);

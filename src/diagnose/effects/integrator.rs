//! An added `c_ch/s^order`: order 1 an integrator, order 2 a rigid body (or the lower
//! residual of modes below the band); θ = [c_1 … c_C].

use crate::diagnose::effects::coefficient::{coefficient, Coefficient};
use crate::diagnose::effects::effect::{bare, last, one, Band, Explain, Param, Stands, Writer};
use crate::model::physical::{PhysicalModel, PoleAtZeroSpec, Quantity};

/// An added integrator (order 1) or rigid body (order 2).
#[derive(Debug, Clone, Copy)]
pub struct Integrator(pub u8);

impl Coefficient for Integrator {
    const NAME: &'static str = "integrator";
    const SI: &'static str = "c";

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![Integrator(1), Integrator(2)]
    }

    fn power(&self) -> u8 {
        self.0
    }

    fn labels(&self) -> Vec<(String, f64, f64)> {
        one("order", self.0 as f64, 0.0)
    }

    fn write_into(&self, w: &mut Writer) {
        let (b, c) = w.gains(0);
        let spec = PoleAtZeroSpec {
            friction_pole: None,
            name: Some(w.note.to_string()),
            mass: 1.0,
            input_gain: b,
            output_gain: c,
        };
        if self.0 == 2 {
            w.m.rigid_body.push(spec)
        } else {
            w.m.integrator.push(spec)
        }
    }

    fn says(&self, x: &Explain) -> String {
        if self.0 != 2 {
            return format!(
                "the error grows as 1/ω towards low frequency in displacement (−20 dB/dec, −90°): a missing integrator c/s, c = {}",
                x.list("c")
            );
        }
        match x.base.quantity {
            Quantity::Displacement => format!(
                "the error grows as 1/ω² towards low frequency (−40 dB/dec, phase of a double integrator): a missing rigid-body mode, or the lower residual (residual mass of modes below the band) c/s², c = {}",
                x.list("c")
            ),
            Quantity::Velocity => format!(
                "the error grows as 1/ω towards low frequency (−20 dB/dec, −90°: the mobility of a mass): a missing rigid-body mode, or the lower residual (modes below the band) c/s² in displacement, c = {}",
                x.list("c")
            ),
            Quantity::Acceleration => format!(
                "the error is a constant real term at low frequency (the mass line of an accelerance): a missing rigid-body mode (1/m = c), or the lower residual of modes below the band, c/s² in displacement, c = {}",
                x.list("c")
            ),
        }
    }

    fn rank() -> usize {
        6
    }

    /// On a mobility or an accelerance, c/s (displacement) is a constant mobility or an
    /// accelerance rising as ω: no structural term (a rigid body or the lower residual is
    /// c/s², the upper residual a constant D).
    fn implausible(&self, band: Band) -> Option<String> {
        let q = band.quantity;
        (self.0 == 1 && q != Quantity::Displacement).then(|| {
            format!(
                "implausible on a {}: c/s in displacement is {} here, which no structural term gives (a rigid-body mode or the lower residual is c/s², the upper residual D)",
                q.frf_name(),
                if q == Quantity::Acceleration { "c·s" } else { "a constant c" }
            )
        })
    }

    fn stands_as(&self) -> Stands {
        Stands::AddedPoleAtZero(self.0)
    }

    /// The rigid body or integrator it added (the last).
    fn alone(&self, m: &PhysicalModel) -> Option<PhysicalModel> {
        let mut alone = bare(m);
        if self.0 == 2 {
            alone.rigid_body.push(m.rigid_body.last()?.clone());
        } else {
            alone.integrator.push(m.integrator.last()?.clone());
        }
        Some(alone)
    }

    /// The residues of the term it added.
    fn owned(&self, m: &PhysicalModel) -> Vec<Param> {
        if self.0 == 2 {
            last(m.rigid_body.len()).map(Param::RigidResidues)
        } else {
            last(m.integrator.len()).map(Param::IntegratorResidues)
        }
        .into_iter()
        .collect()
    }
}

coefficient!(Integrator);

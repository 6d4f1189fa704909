//! An added `c_ch/s^order`: order 1 an integrator, order 2 a rigid body (or the lower
//! residual of modes below the band); θ = [c_1 … c_C].

use crate::diagnose::effects::effect::{
    bare, last, one, per_channel, Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands,
    Writer,
};
use crate::model::physical::{PhysicalModel, PoleAtZeroSpec, Quantity};
use num_complex::Complex64;

/// An added integrator (order 1) or rigid body (order 2).
#[derive(Debug, Clone, Copy)]
pub struct Integrator(pub u8);

impl Effect for Integrator {
    const NAME: &'static str = "integrator";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![Integrator(1), Integrator(2)]
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
        omega: f64,
        ch: usize,
        _: (usize, usize),
        core: &mut Complex64,
        _: &mut Complex64,
    ) {
        *core += nat[ch] / Complex64::new(0.0, omega).powi(self.0 as i32);
    }

    fn si_params(&self, th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        let mut v = one("order", self.0 as f64, 0.0);
        v.extend(per_channel("c", th, 0, entries));
        v
    }

    fn write(&self, w: &mut Writer) {
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

    fn explain(&self, x: &Explain) -> String {
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

    fn prior(&self) -> usize {
        6
    }

    /// Each channel's residue by least squares on `path/s^order`.
    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let om = site.omega();
        vec![(0..site.n_ch())
            .map(|ch| {
                site.ls(&[ch], &|ch, k| {
                    site.path(ch, k) / Complex64::new(0.0, om[k]).powi(self.0 as i32)
                })
            })
            .collect()]
    }

    fn flags(
        &self,
        _: &[f64],
        _: &dyn Fn(usize) -> bool,
        _: &Si,
        band: Band,
        out: &mut Vec<String>,
    ) {
        // On a mobility or an accelerance, c/s (displacement) is a constant mobility or an
        // accelerance rising as ω: no structural term (a rigid body or the lower residual is
        // c/s², the upper residual a constant D).
        let q = band.quantity;
        if self.0 == 1 && q != Quantity::Displacement {
            out.push(format!(
                "implausible on a {}: c/s in displacement is {} here, which no structural term gives (a rigid-body mode or the lower residual is c/s², the upper residual D)",
                q.frf_name(),
                if q == Quantity::Acceleration { "c·s" } else { "a constant c" }
            ));
        }
    }

    fn stands(&self) -> Stands {
        Stands::AddedPoleAtZero(self.0)
    }

    fn lacks_its_term(&self, _: &PhysicalModel) -> bool {
        false
    }

    fn its_mode(&self, _: &PhysicalModel) -> Option<usize> {
        None
    }

    /// The rigid body or integrator it added (the last).
    fn term_alone(&self, m: &PhysicalModel) -> Option<PhysicalModel> {
        let mut alone = bare(m);
        if self.0 == 2 {
            alone.rigid_body.push(m.rigid_body.last()?.clone());
        } else {
            alone.integrator.push(m.integrator.last()?.clone());
        }
        Some(alone)
    }

    fn below_resolution(&self, _: &PhysicalModel, _: &Resolution) -> Option<String> {
        None
    }

    /// The residues of the term it added.
    fn owns(&self, m: &PhysicalModel) -> Vec<Param> {
        if self.0 == 2 {
            last(m.rigid_body.len()).map(Param::RigidResidues)
        } else {
            last(m.integrator.len()).map(Param::IntegratorResidues)
        }
        .into_iter()
        .collect()
    }

    fn apart(&self, _: &[f64], _: &[f64]) -> f64 {
        0.0
    }
}

//! A pseudo-mode below the band: the lower residual's curvature (issue 33, "out-of-band
//! modes"), the counterpart of [`super::residual_mode`].  The lower residual `c/s²` (a
//! rigid body in the model: the residual mass of the modes below the band) is the first term
//! of a mode below the band, `ρ/(ω_n² − ω²) = −ρ/ω² (1 + ω_n²/ω² + …)` for `ω > ω_n`; a mode
//! not far below the band bottom bends the in-band error by its second term, `ω_n²/ω⁴`,
//! which no `c/s²` follows, and the residual left by the lower residual is structured
//! towards the bottom.  This term is that mode, `ρ_ch/(s² + 2ζ₀ω_n s + ω_n²)` with `ω_n`
//! below the band and the small damping `ζ₀` of either pseudo-mode (held in the screen,
//! free in the joint refits, never reported); θ = [ln ω_n, ρ_1 … ρ_C].  It is a **residual
//! term**, not an identified mode (the mode rules of `diagnose::admissible` do not apply;
//! ΔBIC, the holdout and the negligible rule do).  Tried only on a model that has the lower
//! residual (a rigid body) already, which it leaves in place: where the data show a rigid
//! body and no curvature, `ω_n` runs to the bottom of its box (flagged "not placed") or its
//! ΔBIC does not pay for its parameters.

use crate::diagnose::effects::effect::{
    fmt_w, Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands, Writer,
};
use crate::diagnose::effects::pseudo_mode;
use crate::model::physical::PhysicalModel;
use num_complex::Complex64;

/// A pseudo-mode below the band.
#[derive(Debug, Clone, Copy)]
pub struct ResidualModeBelow;

/// Its `ω_n` lies between these multiples of the band bottom.
pub const BELOW: (f64, f64) = (0.1, 0.95);

/// True when a mode's name marks it as this pseudo-mode (written by `diagnose`).
pub fn is_pseudo_mode_below(name: Option<&str>) -> bool {
    name.is_some_and(|n| n.ends_with(<ResidualModeBelow as Effect>::NAME))
}

impl Effect for ResidualModeBelow {
    const NAME: &'static str = "residual term: mode below the band";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    /// On a model with the lower residual (a rigid body) and no pseudo-mode below yet.
    fn tried(base: &PhysicalModel) -> Vec<Self> {
        let has = base
            .mode
            .iter()
            .any(|m| is_pseudo_mode_below(m.name.as_deref()));
        if !base.rigid_body.is_empty() && !has {
            vec![ResidualModeBelow]
        } else {
            vec![]
        }
    }

    fn sel(&self) -> Option<Sel> {
        None
    }

    fn n_params(&self, n_ch: usize) -> usize {
        1 + n_ch
    }

    fn typ(&self, theta: &[f64], _: f64) -> Vec<f64> {
        pseudo_mode::typ(theta)
    }

    /// `ω_n` in `[0.1, 0.95] ω_min`, residues free.
    fn bounds(&self, n_ch: usize, w_min: f64, _: f64, _: f64) -> Vec<(f64, f64)> {
        pseudo_mode::bounds(n_ch, (BELOW.0 * w_min, BELOW.1 * w_min))
    }

    fn natural(&self, th: &[f64], nat: &mut [f64]) {
        nat[0] = th[0].exp();
    }

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
        *core += pseudo_mode::term(nat, omega, ch);
    }

    fn si_params(&self, th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        pseudo_mode::si_params(th, entries)
    }

    fn write(&self, w: &mut Writer) {
        pseudo_mode::write(w)
    }

    fn explain(&self, x: &Explain) -> String {
        format!(
            "the error the lower residual (the rigid body's c/s²) leaves bends towards the band bottom more than c/s² follows: the nearest modes below the band, written as one pseudo-mode at {} (residues {}) beside the rigid body — a residual term, not an identified mode",
            fmt_w(x.p("omega_n")),
            x.list("rho")
        )
    }

    fn prior(&self) -> usize {
        11
    }

    /// `ω_n` on a log grid below the band, the residues by least squares.
    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let (wmin, _) = site.band();
        pseudo_mode::starts(site, (BELOW.0 * wmin, BELOW.1 * wmin))
    }

    fn flags(
        &self,
        th: &[f64],
        at: &dyn Fn(usize) -> bool,
        _: &Si,
        _: Band,
        out: &mut Vec<String>,
    ) {
        pseudo_mode::not_placed(
            th,
            at,
            "the lower residual alone, or modes further down",
            out,
        )
    }

    fn stands(&self) -> Stands {
        Stands::AddedMode
    }

    fn lacks_its_term(&self, _: &PhysicalModel) -> bool {
        false
    }

    /// None: a residual term, not a mode the mode rules judge.
    fn its_mode(&self, _: &PhysicalModel) -> Option<usize> {
        None
    }

    fn term_alone(&self, _: &PhysicalModel) -> Option<PhysicalModel> {
        None
    }

    fn below_resolution(&self, _: &PhysicalModel, _: &Resolution) -> Option<String> {
        None
    }

    /// None: its frequency stands for the modes below the band and its residues go with
    /// the lower residual's by construction; the covariance rules would refuse what it is.
    fn owns(&self, _: &PhysicalModel) -> Vec<Param> {
        vec![]
    }

    fn apart(&self, a: &[f64], b: &[f64]) -> f64 {
        (a[0] - b[0]).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::effects::effect::PSEUDO_ZETA;
    use crate::model::physical::ModeSpec;
    use crate::model::physical::PoleAtZeroSpec;

    #[test]
    fn its_term_is_a_lightly_damped_mode_below_the_band() {
        // Above its ω_n the term is ρ/(ω_n² − ω²) = −ρ/ω² (1 + ω_n²/ω² + …): the lower
        // residual c/s² with c = −ρ, plus a curvature ω_n²/ω² that c/s² lacks.
        let (w, rho) = (50.0, 3.0e5);
        for om in [100.0, 300.0, 1000.0] {
            let mut core = Complex64::new(0.0, 0.0);
            let mut path = Complex64::new(1.0, 0.0);
            ResidualModeBelow.modify(
                &[w, rho],
                0.0,
                &PhysicalModel::default(),
                om,
                0,
                (0, 0),
                &mut core,
                &mut path,
            );
            let exact = rho / Complex64::new(w * w - om * om, 2.0 * PSEUDO_ZETA * w * om);
            assert!(
                (core - exact).norm() < 1e-12 * exact.norm(),
                "{om}: {core} vs {exact}"
            );
            // Nearly real, and its series above ω_n to second order.
            let x = (w / om).powi(2);
            let series = -rho / (om * om) * (1.0 + x + x * x);
            assert!(
                (core.re / series - 1.0).abs() < x.powi(3) / (1.0 - x) + 1e-3,
                "{om}"
            );
            assert!(core.im.abs() < 0.03 * core.re.abs(), "{om}");
        }
        let b = ResidualModeBelow.bounds(2, 100.0, 1000.0, 1e-6);
        assert!((b[0].0.exp() - 10.0).abs() < 1e-9 && (b[0].1.exp() - 95.0).abs() < 1e-9);
        assert_eq!(b.len(), 3);
    }

    #[test]
    fn tried_only_on_a_model_with_a_rigid_body_and_no_pseudo_mode_below() {
        let mut m = PhysicalModel::default();
        assert!(ResidualModeBelow::tried(&m).is_empty());
        m.rigid_body.push(PoleAtZeroSpec {
            friction_pole: None,
            name: None,
            mass: 1.0,
            input_gain: Default::default(),
            output_gain: Default::default(),
        });
        assert_eq!(ResidualModeBelow::tried(&m).len(), 1);
        // The pseudo-mode above does not stand in for it.
        m.mode.push(ModeSpec {
            name: Some(format!(
                "added by rshape diagnose: {}",
                crate::diagnose::effects::residual_mode::ResidualMode::NAME
            )),
            omega_n: 2000.0,
            zeta: PSEUDO_ZETA,
            mass: 1.0,
            input_gain: Default::default(),
            output_gain: Default::default(),
        });
        assert_eq!(ResidualModeBelow::tried(&m).len(), 1);
        m.mode.push(ModeSpec {
            name: Some(format!(
                "added by rshape diagnose: {}",
                ResidualModeBelow::NAME
            )),
            omega_n: 20.0,
            zeta: PSEUDO_ZETA,
            mass: 1.0,
            input_gain: Default::default(),
            output_gain: Default::default(),
        });
        assert!(ResidualModeBelow::tried(&m).is_empty());
        assert!(is_pseudo_mode_below(m.mode[1].name.as_deref()));
        assert!(!is_pseudo_mode_below(m.mode[0].name.as_deref()));
    }
}

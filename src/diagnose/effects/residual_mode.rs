//! A pseudo-mode above the band: the upper residual's curvature (issue 33, "out-of-band
//! modes").  The upper residual `D` (the feedthrough, `D s^k` on a mobility or accelerance)
//! is the first term of the modes above the band, `ρ/(ω_n² − ω²) ≈ ρ/ω_n² (1 + ω²/ω_n² + …)`;
//! a mode not far above the band top bends the in-band error more than a constant follows,
//! and the residual left by `D` is structured towards the top.  This term is that mode,
//! `ρ_ch/(s² + 2ζ₀ω_n s + ω_n²)` with `ω_n` above the band and a small damping `ζ₀` (the
//! band does not see it: held in the screen, free in the joint refits, never reported);
//! θ = [ln ω_n, ρ_1 … ρ_C].  It is a **residual term**: its
//! frequency stands for the modes above the band, it is not an identified mode (the mode
//! rules of `diagnose::admissible` do not apply; ΔBIC, the holdout and the negligible rule
//! do).  Tried only on a model that has the upper residual already.

use crate::diagnose::effects::effect::{
    fmt_w, Band, Effect, Explain, Param, Resolution, Sel, Si, Site, Stands, Writer,
};
use crate::diagnose::effects::pseudo_mode;
use crate::model::physical::PhysicalModel;
use num_complex::Complex64;

/// A pseudo-mode above the band.
#[derive(Debug, Clone, Copy)]
pub struct ResidualMode;

/// Its `ω_n` lies between these multiples of the band top.
pub const ABOVE: (f64, f64) = (1.05, 10.0);

/// True when a mode's name marks it as a pseudo-mode (a residual term written by
/// `diagnose`), this one above the band or its counterpart below it
/// ([`super::residual_mode_below`]).
pub fn is_pseudo_mode(name: Option<&str>) -> bool {
    name.is_some_and(|n| n.ends_with(<ResidualMode as Effect>::NAME))
        || super::residual_mode_below::is_pseudo_mode_below(name)
}

/// True when a mode's name marks it as this pseudo-mode, the one above the band.
pub fn is_pseudo_mode_above(name: Option<&str>) -> bool {
    name.is_some_and(|n| n.ends_with(<ResidualMode as Effect>::NAME))
}

impl Effect for ResidualMode {
    const NAME: &'static str = "residual term: mode above the band";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    /// On a model with the upper residual and no pseudo-mode yet.
    fn tried(base: &PhysicalModel) -> Vec<Self> {
        let has = base
            .mode
            .iter()
            .any(|m| is_pseudo_mode_above(m.name.as_deref()));
        if base.feedthrough.is_some() && !has {
            vec![ResidualMode]
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

    /// `ω_n` in `[1.05, 10] ω_max`, residues free.
    fn bounds(&self, n_ch: usize, _: f64, w_max: f64, _: f64) -> Vec<(f64, f64)> {
        pseudo_mode::bounds(n_ch, (ABOVE.0 * w_max, ABOVE.1 * w_max))
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
            "the error the upper residual leaves bends towards the band top ({}) more than a constant term follows: the nearest modes above the band, written as one pseudo-mode at {} (residues {}) — a residual term, not an identified mode",
            fmt_w(x.wmax),
            fmt_w(x.p("omega_n")),
            x.list("rho")
        )
    }

    fn prior(&self) -> usize {
        11
    }

    /// `ω_n` on a log grid above the band, the residues by least squares.
    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let (_, wmax) = site.band();
        pseudo_mode::starts(site, (ABOVE.0 * wmax, ABOVE.1 * wmax))
    }

    fn flags(
        &self,
        th: &[f64],
        at: &dyn Fn(usize) -> bool,
        _: &Si,
        _: Band,
        out: &mut Vec<String>,
    ) {
        pseudo_mode::not_placed(th, at, "the upper residual alone, or modes further up", out)
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

    /// None: its frequency stands for the modes above the band and its residues go with the
    /// upper residual's by construction; the covariance rules would refuse what it is.
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

    #[test]
    fn its_term_is_an_undamped_mode_above_the_band() {
        // Below its ω_n the term is ρ/(ω_n² − ω²) within the small damping's share.
        let (w, rho) = (1500.0, 3.0e5);
        for om in [100.0, 600.0, 1000.0] {
            let mut core = Complex64::new(0.0, 0.0);
            let mut path = Complex64::new(1.0, 0.0);
            ResidualMode.modify(
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
            // Nearly real: the band sees its frequency, not its damping.
            let undamped = rho / (w * w - om * om);
            assert!((core.re / undamped - 1.0).abs() < 1e-3, "{om}");
            assert!(core.im.abs() < 0.03 * undamped.abs(), "{om}");
        }
        let b = ResidualMode.bounds(2, 10.0, 1000.0, 1e-6);
        assert!((b[0].0.exp() - 1050.0).abs() < 1e-9 && (b[0].1.exp() - 10_000.0).abs() < 1e-6);
        assert_eq!(b.len(), 3);
    }

    #[test]
    fn tried_only_on_a_model_with_the_upper_residual_and_no_pseudo_mode() {
        let mut m = PhysicalModel::default();
        assert!(ResidualMode::tried(&m).is_empty());
        m.feedthrough = Some(crate::model::physical::Feedthrough::Scalar(1e-3));
        assert_eq!(ResidualMode::tried(&m).len(), 1);
        m.mode.push(ModeSpec {
            name: Some(format!("added by rshape diagnose: {}", ResidualMode::NAME)),
            omega_n: 2000.0,
            zeta: PSEUDO_ZETA,
            mass: 1.0,
            input_gain: Default::default(),
            output_gain: Default::default(),
        });
        assert!(ResidualMode::tried(&m).is_empty());
    }
}

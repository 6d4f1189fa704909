//! A changed damping of a configured mode: θ = [ln ζ].  Not tried by the search (the retune
//! refits the model's own dampings); `compare` revisions and library users name it.

use crate::diagnose::effects::configured::{refits_mode, ModeParam, RefitsMode};
use crate::diagnose::effects::effect::{
    fmt_w, grid_best, log_grid, sig, Explain, Site, ZETA_BOUNDS,
};

/// Damping of mode `i` (0-based) of the configured model.
#[derive(Debug, Clone, Copy)]
pub struct Damping(pub usize);

impl RefitsMode for Damping {
    const NAME: &'static str = "damping";
    const PARAM: ModeParam = ModeParam::Zeta;
    const AT_BOUND: Option<&'static str> = Some("ζ at its bound: not identified");

    fn mode(&self) -> usize {
        self.0
    }

    /// `ζ` from the record's floor to 0.7.
    fn bounds_in(_: f64, _: f64, zeta_lo: f64) -> (f64, f64) {
        (zeta_lo.max(ZETA_BOUNDS.0).ln(), ZETA_BOUNDS.1.ln())
    }

    fn says(&self, x: &Explain) -> String {
        let i = self.0;
        let old = x.base.mode[i].zeta;
        format!(
            "the error is symmetric about mode {} at {}: its damping is ζ = {} instead of {}",
            i + 1,
            fmt_w(x.base.mode[i].omega_n),
            sig(x.p("zeta")),
            sig(old)
        )
    }

    fn rank() -> usize {
        7
    }

    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        grid_best(site, &log_grid(1e-3, 0.7, 30), 3)
    }
}

refits_mode!(Damping);

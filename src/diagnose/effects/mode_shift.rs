//! A shifted frequency of a configured mode: θ = [ln ω_n].  Not tried by the search (the
//! retune refits the model's own frequencies); `compare` revisions and library users name it.

use crate::diagnose::effects::configured::{refits_mode, ModeParam, RefitsMode};
use crate::diagnose::effects::effect::{fmt_change, fmt_w, grid_best, Explain, Site};

/// A shifted frequency of mode `i` (0-based) of the configured model.
#[derive(Debug, Clone, Copy)]
pub struct ModeShift(pub usize);

impl RefitsMode for ModeShift {
    const NAME: &'static str = "mode_shift";
    const PARAM: ModeParam = ModeParam::Omega;
    const AT_BOUND: Option<&'static str> = None;

    fn mode(&self) -> usize {
        self.0
    }

    /// Inside the band.
    fn bounds_in(w_min: f64, w_max: f64, _: f64) -> (f64, f64) {
        (w_min.ln(), w_max.ln())
    }

    fn says(&self, x: &Explain) -> String {
        let i = self.0;
        let old = x.base.mode[i].omega_n;
        format!(
            "the data resonate at {} where mode {} of the model resonates at {}: mode {} shifted by {}",
            fmt_w(x.p("omega_n")),
            i + 1,
            fmt_w(old),
            i + 1,
            fmt_change(x.p("omega_n") / old)
        )
    }

    fn rank() -> usize {
        8
    }

    /// ±½ in `ln ω_n` around the configured frequency, 61 points.
    fn grid(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let w0 = site.base().mode[self.0].omega_n;
        let grid: Vec<f64> = (0..61)
            .map(|j| w0.ln() + (j as f64 - 30.0) / 60.0)
            .collect();
        grid_best(site, &grid, 3)
    }
}

refits_mode!(ModeShift);

//! `rshape fit` as a library call: fit (fixed order or automatic), certificate, and the text
//! to print.  The fit writes nothing: [`crate::pipeline::write_fit_exports`] writes the
//! exports of a [`FitOutcome`].  The CLI subcommand is a thin wrapper around both.

use super::order::{fit_auto, format_table, OrderRow};
use super::{fit_unit, A1Fn, FitError, FitOptions, FitResult, FitSettings, ProgressFn};
use crate::consistency::Envelope;

/// `--order N` or `--order auto` (sweep `0..=max`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrderChoice {
    /// A fixed order.
    Fixed(usize),
    /// Sweep orders `0..=max` and choose.
    Auto {
        /// Highest order tried.
        max: usize,
    },
}

impl std::str::FromStr for OrderChoice {
    type Err = String;
    /// `"auto"` (orders 0 to 8) or a number.
    fn from_str(s: &str) -> Result<Self, String> {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(Self::Auto { max: 8 });
        }
        s.parse::<usize>()
            .ok()
            .filter(|n| *n <= super::MAX_ORDER)
            .map(Self::Fixed)
            .ok_or_else(|| format!("--order `{s}`: expected `auto` or an integer 0..=20"))
    }
}

/// What `rshape fit` produced.
#[derive(Debug, Clone)]
pub struct FitOutcome {
    /// The certified fit.
    pub result: FitResult,
    /// The order table (auto only).
    pub table: Option<Vec<OrderRow>>,
    /// Human-readable report: order table (auto), r, certificate (the solver events are in
    /// [`events_text`], for `--verbose`).
    pub text: String,
    /// Wall-clock seconds of the fit and certificate.
    pub seconds: f64,
}

/// Fits and certifies, and returns the printable report; `progress` hears of each order as
/// it starts.  An uncertified fit is an error, so a caller that writes the exports of the
/// outcome ([`crate::pipeline::write_fit_exports`]) writes only certified ones.
pub fn run_fit(
    env: &Envelope,
    a1: Option<A1Fn<'_>>,
    settings: &FitSettings,
    order: OrderChoice,
    progress: Option<ProgressFn<'_>>,
) -> Result<FitOutcome, FitError> {
    let start = std::time::Instant::now();
    let (result, table) = match order {
        OrderChoice::Fixed(n) => {
            let s = FitSettings {
                order: n,
                ..settings.clone()
            };
            (fit_unit(env, a1, &s, &FitOptions { progress })?, None)
        }
        OrderChoice::Auto { max } => {
            let (r, t) = fit_auto(env, a1, settings, max, &FitOptions { progress })?;
            (r, Some(t))
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let mut text = String::new();
    if let Some(t) = &table {
        text.push_str(&format_table(t, result.order, settings.auto_tolerance));
    }
    text.push_str(&summary(&result));
    Ok(FitOutcome {
        result,
        table,
        text,
        seconds,
    })
}

/// A short text summary of a certified fit.
pub fn summary(r: &FitResult) -> String {
    let c = &r.certificate;
    let mut s = String::new();
    let cx = |v: &[num_complex::Complex64]| {
        v.iter()
            .map(|z| {
                if z.im == 0.0 {
                    format!("{:.6e}", z.re)
                } else {
                    format!("{:.6e}{:+.6e}j", z.re, z.im)
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    s.push_str(&format!(
        "r(s): order {}, gain {:.6e} ({})\n  zeros: [{}]\n  poles: [{}]\n",
        r.order,
        r.gain,
        r.origin,
        cx(&r.zeros),
        cx(&r.poles)
    ));
    s.push_str(&format!(
        "certificate: {} ({} frequencies)\n  worst |r|/r_min over the data = {:.6} at {:.6e} rad/s\n  conservatism log10(|r|/r_min): mean {:.5}, max {:.5}\n",
        if c.passed { "passed" } else { "FAILED" },
        c.grid_points,
        c.worst_ratio,
        c.worst_ratio_omega,
        c.mean_log10_ratio,
        c.max_log10_ratio
    ));
    if c.worst_between_ratio.is_finite() {
        s.push_str(&format!(
            "  between data: min |r|/min(neighbouring r_min) = {:.6} at {:.6e} rad/s\n",
            c.worst_between_ratio, c.worst_between_omega
        ));
    }
    match (c.worst_a1_margin, c.worst_a1_omega) {
        (Some(m), Some(w)) => s.push_str(&format!(
            "  A1 ({}): min σ_min(M̃)/|r| = {:.6} at {:.6e} rad/s\n",
            c.a1_checked_on, m, w
        )),
        _ => s.push_str("  A1: not checked (no model and no a1_limit)\n"),
    }
    s.push_str(&format!(
        "  min |r| = {:.4e} (floor {:.4e}); |r(∞)| = {:.4e}\n  distance to the jω-axis: poles {:.4e}, zeros {:.4e} rad/s; min damping {:.4e}\n",
        c.min_abs_r, r.floor, c.r_at_infinity, c.min_axis_distance_pole, c.min_axis_distance_zero, c.min_damping
    ));
    if c.repair_factor != 1.0 {
        s.push_str(&format!(
            "  repaired: gain scaled by {:.9} (ucover-style) and re-verified\n",
            c.repair_factor
        ));
    }
    s
}

/// The one line `rshape fit` prints by default about the work done: `N LPs in T s`.
pub fn work_line(r: &FitResult, seconds: f64) -> String {
    format!(
        "{} LPs in {seconds:.2} s ({} solver events; --verbose lists them)\n",
        r.lp_solves,
        r.solver_events.len()
    )
}

/// The solver events of a fit, one line each (internal bookkeeping: `--verbose` only).
pub fn events_text(r: &FitResult) -> String {
    let mut s = format!(
        "solver events ({} events over {} LPs):\n",
        r.solver_events.len(),
        r.lp_solves
    );
    for e in &r.solver_events {
        s.push_str(&format!(
            "  order {}: {}: {:?}; {}\n",
            e.order, e.stage, e.status, e.action
        ));
    }
    s
}

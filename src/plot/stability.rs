//! `stability.svg`: the pointwise Theorem 1 limit `1/σ_max(T(jω))` against `|r(jω)|` for
//! each bound (configured and fitted). Where `|r|` stays below the limit curve the
//! controller is proven robust; the smallest ratio is the margin `α*`.

use super::style::*;
use crate::error::Result;
use plotters::prelude::*;

/// What the figure shows.
pub struct StabilityInput<'a> {
    /// Title.
    pub title: &'a str,
    /// Frequencies (rad/s).
    pub omega: &'a [f64],
    /// `1/σ_max(T(jω))`.
    pub inv_t: &'a [f64],
    /// `(label, |r(jω)|)` per bound.
    pub r: &'a [(String, Vec<f64>)],
}

/// Renders the figure on log-log axes.
pub fn stability_svg(inp: &StabilityInput) -> Result<String> {
    let (xlo, xhi) = omega_range(inp.omega);
    let all = inp
        .inv_t
        .iter()
        .chain(inp.r.iter().flat_map(|(_, v)| v.iter()))
        .filter(|v| v.is_finite() && **v > 0.0);
    let (ylo, yhi) = log_range(all, 2.0).unwrap_or((0.01, 100.0));
    let rows = inp.r.len() + 1;
    loglog_figure(inp.title, (xlo, xhi), (ylo, yhi), "magnitude", rows, |p| {
        // Limits are purple and dashed, as the A1 limit of r_vs_delta.svg; the configured r
        // is blue and the fitted r orange in every figure.
        let s = C_PURPLE.stroke_width(3);
        p.chart
            .draw_series(DashedLineSeries::new(
                inp.omega
                    .iter()
                    .zip(inp.inv_t)
                    .filter(|(_, v)| v.is_finite() && **v > 0.0)
                    .map(|(w, v)| (*w, clamp(*v, ylo, yhi))),
                8,
                5,
                s,
            ))
            .map_err(plot_err)?;
        p.legend.add(
            "1/σ_max(T(jω)): largest |r| proven robust (Theorem 1)",
            move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], s),
        );
        let others = [C_GREEN, C_RED, C_GREY];
        for (k, (label, r)) in inp.r.iter().enumerate() {
            let c = if label.starts_with("configured") {
                C_BLUE
            } else if label.starts_with("fitted") {
                C_ORANGE
            } else {
                others[k % others.len()]
            }
            .stroke_width(3);
            p.chart
                .draw_series(LineSeries::new(
                    inp.omega
                        .iter()
                        .zip(r)
                        .map(|(w, v)| (*w, clamp(*v, ylo, yhi))),
                    c,
                ))
                .map_err(plot_err)?;
            p.legend.add(format!("|r(jω)|, {label}"), move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], c)
            });
        }
        Ok(())
    })
}

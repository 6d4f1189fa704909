//! `batch.svg`: every dataset's lower envelope (the per-datum smallest consistent `|r|`),
//! the combined envelope (their pointwise maximum, which one `r` must cover), and the
//! configured and fitted `r`, on log-log axes.

use super::style::{self, *};
use super::symbols::Symbols;
use crate::error::Result;
use crate::system::TransferFunction;
use plotters::prelude::*;

/// What the figure shows.
pub struct BatchFigureInput<'a> {
    /// Title of the figure.
    pub title: &'a str,
    /// Per dataset: frequencies (rad/s) and `r_min` (empty when only the combined envelope
    /// is known, as after `merge`).
    pub datasets: &'a [(&'a [f64], &'a [f64])],
    /// The combined envelope: frequencies and `r_min`.
    pub combined: (&'a [f64], &'a [f64]),
    /// The configured `r`, when there is one.
    pub r_configured: Option<&'a TransferFunction>,
    /// The fitted `r`, when the fit succeeded.
    pub r_fitted: Option<&'a TransferFunction>,
    /// Dense frequency grid for the `r` curves (rad/s).
    pub grid: &'a [f64],
}

/// Renders `batch.svg`, naming the weight by `sym` (`r`, or `V` in closed loop).
pub fn batch_svg(inp: &BatchFigureInput, sym: &Symbols) -> Result<String> {
    let (w, wmin) = (sym.weight, sym.weight_min);
    let pos = |v: &f64| v.is_finite() && *v > 0.0;
    let mag =
        |r: &TransferFunction| -> Vec<f64> { inp.grid.iter().map(|x| r.freq(*x).norm()).collect() };
    let conf = inp.r_configured.map(mag);
    let fit = inp.r_fitted.map(mag);
    let (xlo, xhi) = omega_range(inp.combined.0);
    let ys = inp
        .combined
        .1
        .iter()
        .chain(inp.datasets.iter().flat_map(|d| d.1.iter()))
        .chain(conf.iter().flatten())
        .chain(fit.iter().flatten())
        .filter(|v| pos(v));
    let (ylo, yhi) = log_range(ys, 2.5).unwrap_or((1e-3, 1e3));
    let rows = 1
        + usize::from(!inp.datasets.is_empty())
        + usize::from(conf.is_some())
        + usize::from(fit.is_some());
    let y_desc = "magnitude (absolute, unitless)";
    loglog_figure(inp.title, (xlo, xhi), (ylo, yhi), y_desc, rows, |p| {
        let pts = |om: &[f64], v: &[f64]| -> Vec<(f64, f64)> {
            om.iter()
                .zip(v)
                .filter(|(_, y)| pos(y))
                .map(|(x, y)| (*x, style::clamp(*y, ylo, yhi)))
                .collect()
        };
        // Each dataset thin and light, so that the combined envelope stands out on top; the
        // colours skip blue and orange, which mean the configured and the fitted r.
        let shade = |k: usize| PALETTE[2 + k % (PALETTE.len() - 2)].mix(0.55);
        for (k, (om, v)) in inp.datasets.iter().enumerate() {
            let col = shade(k);
            p.chart
                .draw_series(LineSeries::new(pts(om, v), col.stroke_width(1)))
                .map_err(plot_err)?;
        }
        if !inp.datasets.is_empty() {
            let col = shade(0);
            p.legend.add(
                format!(
                    "{wmin} per datum of each of the {} datasets (one colour each)",
                    inp.datasets.len()
                ),
                move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], col.stroke_width(1)),
            );
        }
        let s = ShapeStyle::from(&BLACK).stroke_width(2);
        p.chart
            .draw_series(LineSeries::new(pts(inp.combined.0, inp.combined.1), s))
            .map_err(plot_err)?;
        p.legend.add(
            format!("combined envelope: the largest {wmin} over the datasets"),
            move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], s),
        );
        if let (Some(r), Some(c)) = (inp.r_configured, &conf) {
            let label = format!("|{w}(jω)|, configured {w} = {}", tf_label(r));
            p.weight(pts(inp.grid, c), WeightCurve::Configured, label)?;
        }
        if let (Some(r), Some(f)) = (inp.r_fitted, &fit) {
            let label = format!(
                "|{w}(jω)|, fitted {w} = {} (one {w} for all datasets)",
                tf_label(r)
            );
            p.weight(pts(inp.grid, f), WeightCurve::Fitted, label)?;
        }
        Ok(())
    })
}

//! `batch.svg`: every dataset's lower envelope (the per-datum smallest consistent `|r|`),
//! the combined envelope (their pointwise maximum, which one `r` must cover), the
//! configured and fitted `r`, and the A1 limit where the configured `r` crosses it, on
//! log-log axes.

use super::fine::Look;
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
    /// Dense frequency grid for the `r` curves (rad/s), over every dataset's frequencies.
    pub grid: &'a [f64],
    /// `σ_min(M̃(jω))` on `grid` (the A1 limit), when the model is known: drawn where the
    /// configured `r` reaches it.
    pub a1_on_grid: Option<&'a [f64]>,
}

/// Renders `batch.svg`, naming the weight by `sym` (`r`, or `V` in closed loop).
pub fn batch_svg(inp: &BatchFigureInput, sym: &Symbols) -> Result<String> {
    let (w, wmin) = (sym.weight, sym.weight_min);
    let pos = |v: &f64| v.is_finite() && *v > 0.0;
    let mag =
        |r: &TransferFunction| -> Vec<f64> { inp.grid.iter().map(|x| r.freq(*x).norm()).collect() };
    let conf = inp.r_configured.map(mag);
    let fit = inp.r_fitted.map(mag);
    // A1 matters where the configured r reaches it (then r is not admissible there).
    let a1 = match (inp.a1_on_grid, &conf) {
        (Some(a), Some(c)) if a.iter().zip(c).any(|(a, c)| c >= a) => Some(a),
        _ => None,
    };
    let xs: Vec<f64> = inp
        .combined
        .0
        .iter()
        .chain(inp.datasets.iter().flat_map(|d| d.0.iter()))
        .copied()
        .collect();
    let (xlo, xhi) = omega_range(&xs);
    let ys = inp
        .combined
        .1
        .iter()
        .chain(inp.datasets.iter().flat_map(|d| d.1.iter()))
        .chain(conf.iter().flatten())
        .chain(fit.iter().flatten())
        .filter(|v| pos(v));
    let (ylo, yhi) = log_range(ys, 2.5).unwrap_or((1e-3, 1e3));
    let n_zero = inp.combined.1.iter().filter(|v| **v == 0.0).count();
    let rows = 1
        + usize::from(!inp.datasets.is_empty())
        + usize::from(conf.is_some())
        + usize::from(fit.is_some())
        + usize::from(a1.is_some())
        + usize::from(n_zero > 0);
    let y_desc = "magnitude (absolute, unitless)";
    loglog_figure(inp.title, (xlo, xhi), (ylo, yhi), y_desc, rows, |p| {
        let (ylo, yhi) = p.y_axis().ends();
        // Non-positive or infinite values break the line (no segment across a gap where
        // r_min = 0: the noise alone explains those data).
        let pts = |om: &[f64], v: &[f64]| -> Vec<(f64, f64)> {
            om.iter()
                .zip(v)
                .map(|(x, y)| {
                    if pos(y) {
                        (*x, style::clamp(*y, ylo, yhi))
                    } else {
                        (*x, f64::NAN)
                    }
                })
                .collect()
        };
        // The combined envelope first, as a wide translucent grey band, so that each
        // dataset's envelope (thin, one colour each) stays visible on top of it; colours
        // skip blue and orange, which mean the configured and the fitted r.
        let band = Look::solid(C_GREY, 7.0).alpha(0.3);
        p.line_with_legend(
            pts(inp.combined.0, inp.combined.1),
            band,
            format!("combined envelope: the largest {wmin} over the datasets (grey band)"),
        );
        let shade = |k: usize| PALETTE[2 + k % (PALETTE.len() - 2)];
        for (k, (om, v)) in inp.datasets.iter().enumerate() {
            let look = Look::solid(shade(k), 1.5).alpha(0.9);
            p.line(pts(om, v), look);
            let col = shade(k).mix(0.9);
            p.chart
                .draw_series(
                    om.iter()
                        .zip(v.iter())
                        .filter(|(_, y)| pos(y))
                        .map(|(x, y)| {
                            Circle::new((*x, style::clamp(*y, ylo, yhi)), 2, col.filled())
                        }),
                )
                .map_err(plot_err)?;
        }
        if !inp.datasets.is_empty() {
            let look = Look::solid(shade(0), 1.5).alpha(0.9);
            p.legend.add_line(
                format!(
                    "{wmin} per datum of each of the {} datasets (one colour each)",
                    inp.datasets.len()
                ),
                look,
                &p.overlay,
            );
        }
        if n_zero > 0 {
            let col = C_GREEN.mix(0.55);
            let tri = |(x, y): (i32, i32)| vec![(x - 4, y - 7), (x + 4, y - 7), (x, y)];
            p.chart
                .draw_series(
                    inp.combined
                        .0
                        .iter()
                        .zip(inp.combined.1)
                        .filter(|(_, r)| **r == 0.0)
                        .map(|(x, _)| {
                            EmptyElement::at((*x, ylo)) + Polygon::new(tri((0, 0)), col.filled())
                        }),
                )
                .map_err(plot_err)?;
            p.legend.add(
                format!(
                    "combined {wmin} = 0 at {n_zero} frequencies: explained by the noise alone (drawn at the bottom; the envelope breaks there)"
                ),
                move |(x, y)| Polygon::new(tri((x + 12, y + 4)), col.filled()),
            );
        }
        if let Some(a) = a1 {
            p.line_with_legend(
                pts(inp.grid, a),
                LIMIT,
                format!("A1 limit σ_min(M̃(jω)): the configured |{w}| reaches it, so it is not admissible there"),
            );
        }
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

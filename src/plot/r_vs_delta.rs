//! `r_vs_delta.svg`: the analogue of Fig. 3 (noise-free: `|r(jω)|` against the norms of the
//! minimum-norm perturbations `‖Δᵢ‖` of eq. (8)) and of Fig. 8 (noisy: against the
//! Theorem 4 bisection values), on log-log axes, with the A1 limit `σ_min(M̃(jω))`.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::style::{self, *};
use super::symbols::Symbols;
use crate::error::Result;
use crate::system::TransferFunction;
use plotters::prelude::*;

/// What the figure shows.  Slices indexed by datum have the length of `omega`.
pub struct RVsDeltaInput<'a> {
    /// Title of the figure.
    pub title: &'a str,
    /// Data frequencies (rad/s).
    pub omega: &'a [f64],
    /// Smallest consistent `|r|` per datum (`inf` when no admissible `r` explains it).
    pub r_min: &'a [f64],
    /// Legend label of the per-datum values, e.g. `‖Δᵢ‖ (Theorem 2, eq. 8)`.
    pub r_min_label: &'a str,
    /// Per datum: true when the configured `r` fails to explain it (`|r| ≤ r_min`).
    pub failing: &'a [bool],
    /// Per datum: true when the configured `r` breaks A1 there (`|r| ≥ σ_min(M̃)`: not
    /// admissible); empty when unknown.
    pub a1_failing: &'a [bool],
    /// The configured `r`, when there is one.
    pub r_configured: Option<&'a TransferFunction>,
    /// The fitted `r`, when there is one.
    pub r_fitted: Option<&'a TransferFunction>,
    /// Dense frequency grid for the curves (rad/s).
    pub grid: &'a [f64],
    /// `σ_min(M̃(jω))` on `grid` (the A1 limit), when the model is known.
    pub a1_on_grid: Option<&'a [f64]>,
}

/// Renders `r_vs_delta.svg` with the open-loop symbols (`r`).
pub fn r_vs_delta_svg(inp: &RVsDeltaInput) -> Result<String> {
    r_vs_delta_svg_with(inp, &Symbols::OPEN_LOOP)
}

/// Renders `r_vs_delta.svg`, naming the weight and its per-datum minimum by `sym`.
pub fn r_vs_delta_svg_with(inp: &RVsDeltaInput, sym: &Symbols) -> Result<String> {
    let (w, wmin) = (sym.weight, sym.weight_min);
    let mag =
        |r: &TransferFunction| -> Vec<f64> { inp.grid.iter().map(|w| r.freq(*w).norm()).collect() };
    let conf = inp.r_configured.map(mag);
    let fit = inp.r_fitted.map(mag);
    let (xlo, xhi) = omega_range(inp.omega);
    // The y range is set by the data and the r curves; the A1 curve may leave it.
    let ys = inp
        .r_min
        .iter()
        .chain(conf.iter().flatten())
        .chain(fit.iter().flatten())
        .chain(inp.a1_on_grid.into_iter().flatten());
    let (ylo, yhi) = log_range(ys, 2.5).unwrap_or((1e-3, 1e3));
    let (ylo, yhi) = (ylo.max(yhi * 1e-12), yhi);
    // the explained data, then each curve and marker kind present
    let rows = 1
        + usize::from(conf.is_some())
        + usize::from(fit.is_some())
        + usize::from(inp.a1_on_grid.is_some())
        + usize::from(inp.a1_failing.iter().any(|f| *f))
        + usize::from(inp.failing.iter().any(|f| *f))
        + usize::from(inp.r_min.iter().any(|r| r.is_infinite()))
        + usize::from(inp.r_min.contains(&0.0));

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size_with_legend(rows)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (plot, below) = root.split_vertically(SIZE.1);
        let mut leg = Legend::default();
        let mut chart = loglog_chart(
            &plot,
            inp.title,
            (xlo, xhi),
            (ylo, yhi),
            "magnitude (absolute, unitless)",
        )?;

        let grid = inp.grid;
        let curve = |v: &[f64]| -> Vec<(f64, f64)> {
            grid.iter()
                .zip(v)
                .filter(|(_, y)| y.is_finite() && **y > 0.0)
                .map(|(w, y)| (*w, style::clamp(*y, ylo, yhi)))
                .collect()
        };
        if let Some(a1) = inp.a1_on_grid {
            let s = ShapeStyle::from(&C_PURPLE).stroke_width(2);
            chart
                .draw_series(DashedLineSeries::new(curve(a1), 8, 5, s))
                .map_err(plot_err)?;
            leg.add(
                "A1 limit σ_min(M̃(jω)): |r| must stay below",
                move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], s),
            );
        }
        if let Some(c) = &conf {
            let s = ShapeStyle::from(&C_BLUE).stroke_width(3);
            chart
                .draw_series(LineSeries::new(curve(c), s))
                .map_err(plot_err)?;
            leg.add(
                format!(
                    "|{w}(jω)|, configured {w} = {}",
                    tf_label(inp.r_configured.expect("set"))
                ),
                move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], s),
            );
        }
        if let Some(f) = &fit {
            let s = ShapeStyle::from(&C_ORANGE).stroke_width(3);
            chart
                .draw_series(DashedLineSeries::new(curve(f), 12, 4, s))
                .map_err(plot_err)?;
            leg.add(
                format!(
                    "|{w}(jω)|, fitted {w} = {}",
                    tf_label(inp.r_fitted.expect("set"))
                ),
                move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], s),
            );
        }
        // 0: explained, 1: |r| ≤ r_min, 2: |r| > r_min but A1 fails (not admissible).
        let class = |i: usize| -> u8 {
            if inp.failing[i] {
                1
            } else if inp.a1_failing.get(i).copied().unwrap_or(false) {
                2
            } else {
                0
            }
        };
        let pts = |want: u8| -> Vec<(f64, f64)> {
            (0..inp.omega.len())
                .filter(|&i| class(i) == want && inp.r_min[i].is_finite() && inp.r_min[i] > 0.0)
                .map(|i| (inp.omega[i], style::clamp(inp.r_min[i], ylo, yhi)))
                .collect()
        };
        let ok = pts(0);
        if !ok.is_empty() {
            chart
                .draw_series(ok.iter().map(|p| Circle::new(*p, 5, C_GREEN.filled())))
                .map_err(plot_err)?;
            leg.add(
                if inp.r_configured.is_some() {
                    format!("{}: explained by the configured {w}", inp.r_min_label)
                } else {
                    inp.r_min_label.to_string()
                },
                |(x, y)| Circle::new((x + 12, y), 5, C_GREEN.filled()),
            );
        }
        let inadmissible = pts(2);
        if !inadmissible.is_empty() {
            let sq = |(x, y): (i32, i32)| [(x - 6, y - 6), (x + 6, y + 6)];
            chart
                .draw_series(inadmissible.iter().map(|p| {
                    EmptyElement::at(*p)
                        + Rectangle::new(sq((0, 0)), C_PURPLE.stroke_width(2))
                        + Cross::new((0, 0), 4, C_PURPLE.stroke_width(2))
                }))
                .map_err(plot_err)?;
            leg.add(
                format!(
                    "{}: NOT ADMISSIBLE, configured |{w}(jω)| ≥ σ_min(M̃) (A1 fails)",
                    inp.r_min_label
                ),
                move |(x, y)| {
                    EmptyElement::at((x + 12, y))
                        + Rectangle::new(sq((0, 0)), C_PURPLE.stroke_width(2))
                        + Cross::new((0, 0), 4, C_PURPLE.stroke_width(2))
                },
            );
        }
        let bad = pts(1);
        if !bad.is_empty() {
            chart
                .draw_series(bad.iter().map(|p| {
                    EmptyElement::at(*p)
                        + Circle::new((0, 0), 8, C_RED.stroke_width(3))
                        + Cross::new((0, 0), 5, C_RED.stroke_width(2))
                }))
                .map_err(plot_err)?;
            leg.add(
                format!(
                    "{}: FAILING, configured |{w}(jω)| ≤ {wmin}",
                    inp.r_min_label
                ),
                |(x, y)| {
                    EmptyElement::at((x + 12, y))
                        + Circle::new((0, 0), 7, C_RED.stroke_width(3))
                        + Cross::new((0, 0), 4, C_RED.stroke_width(2))
                },
            );
        }
        let infinite: Vec<(f64, f64)> = inp
            .omega
            .iter()
            .zip(inp.r_min)
            .filter(|(_, r)| r.is_infinite())
            .map(|(w, _)| (*w, yhi))
            .collect();
        if !infinite.is_empty() {
            let tri = |(x, y): (i32, i32)| vec![(x - 7, y + 12), (x + 7, y + 12), (x, y)];
            chart
                .draw_series(
                    infinite
                        .iter()
                        .map(|p| EmptyElement::at(*p) + Polygon::new(tri((0, 0)), C_RED.filled())),
                )
                .map_err(plot_err)?;
            leg.add(
                format!("{wmin} = ∞: no admissible {w} explains the datum (drawn at the top)"),
                move |(x, y)| Polygon::new(tri((x + 12, y - 6)), C_RED.filled()),
            );
        }
        let zeros: Vec<(f64, f64)> = inp
            .omega
            .iter()
            .zip(inp.r_min)
            .filter(|(_, r)| **r == 0.0)
            .map(|(w, _)| (*w, ylo))
            .collect();
        if !zeros.is_empty() {
            let tri = |(x, y): (i32, i32)| vec![(x - 4, y - 7), (x + 4, y - 7), (x, y)];
            let col = C_GREEN.mix(0.55);
            chart
                .draw_series(
                    zeros
                        .iter()
                        .map(|p| EmptyElement::at(*p) + Polygon::new(tri((0, 0)), col.filled())),
                )
                .map_err(plot_err)?;
            leg.add(
                format!(
                    "{wmin} = 0 at {} data: explained by the noise alone (drawn at the bottom)",
                    zeros.len()
                ),
                move |(x, y)| Polygon::new(tri((x + 12, y + 4)), col.filled()),
            );
        }
        leg.draw(&below)?;
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}

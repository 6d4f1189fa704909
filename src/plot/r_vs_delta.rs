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

/// Renders `r_vs_delta.svg`, naming the weight and its per-datum minimum by `sym`: the A1
/// limit, the configured and fitted weights, the data by verdict, and the data with
/// `r_min = ∞` or `0` at the edges of the axis.
pub fn r_vs_delta_svg_with(inp: &RVsDeltaInput, sym: &Symbols) -> Result<String> {
    let mag =
        |r: &TransferFunction| -> Vec<f64> { inp.grid.iter().map(|w| r.freq(*w).norm()).collect() };
    let conf = inp.r_configured.map(mag);
    let fit = inp.r_fitted.map(mag);
    let x = omega_range(inp.omega);
    let y = y_range(inp, conf.as_deref(), fit.as_deref());
    let rows = legend_rows(inp);
    let y_desc = "magnitude (absolute, unitless)";
    loglog_figure(inp.title, x, y, y_desc, rows, |p| {
        let fig = Figure { inp, sym, y };
        fig.a1_limit(p)?;
        let w = sym.weight;
        if let (Some(r), Some(c)) = (inp.r_configured, &conf) {
            let label = format!("|{w}(jω)|, configured {w} = {}", tf_label(r));
            p.weight(fig.curve(c), WeightCurve::Configured, label)?;
        }
        if let (Some(r), Some(f)) = (inp.r_fitted, &fit) {
            let label = format!("|{w}(jω)|, fitted {w} = {}", tf_label(r));
            p.weight(fig.curve(f), WeightCurve::Fitted, label)?;
        }
        fig.explained(p)?;
        fig.inadmissible(p)?;
        fig.failing(p)?;
        fig.infinite(p)?;
        fig.zeros(p)
    })
}

/// The y range: set by the data and the weight curves (the A1 curve may leave it), at most
/// twelve decades.
fn y_range(inp: &RVsDeltaInput, conf: Option<&[f64]>, fit: Option<&[f64]>) -> (f64, f64) {
    let ys = inp
        .r_min
        .iter()
        .chain(conf.into_iter().flatten())
        .chain(fit.into_iter().flatten())
        .chain(inp.a1_on_grid.into_iter().flatten());
    let (ylo, yhi) = log_range(ys, 2.5).unwrap_or((1e-3, 1e3));
    (ylo.max(yhi * 1e-12), yhi)
}

/// Legend entries: the explained data, then each curve and marker kind present.
fn legend_rows(inp: &RVsDeltaInput) -> usize {
    1 + usize::from(inp.r_configured.is_some())
        + usize::from(inp.r_fitted.is_some())
        + usize::from(inp.a1_on_grid.is_some())
        + usize::from(inp.a1_failing.iter().any(|f| *f))
        + usize::from(inp.failing.iter().any(|f| *f))
        + usize::from(inp.r_min.iter().any(|r| r.is_infinite()))
        + usize::from(inp.r_min.contains(&0.0))
}

/// What a datum's marker says.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Class {
    /// The configured `r` explains it (or there is none).
    Explained,
    /// `|r| ≤ r_min`: the configured `r` does not explain it.
    Failing,
    /// `|r| > r_min` but A1 fails there: `r` is not admissible.
    Inadmissible,
}

/// The input, the symbols and the y range, shared by the drawing steps.
struct Figure<'i, 'd> {
    inp: &'i RVsDeltaInput<'d>,
    sym: &'i Symbols,
    y: (f64, f64),
}

impl Figure<'_, '_> {
    /// The positive finite values of `v` on the dense grid, clamped into the axis.
    fn curve(&self, v: &[f64]) -> Vec<(f64, f64)> {
        let (ylo, yhi) = self.y;
        self.inp
            .grid
            .iter()
            .zip(v)
            .filter(|(_, y)| y.is_finite() && **y > 0.0)
            .map(|(w, y)| (*w, style::clamp(*y, ylo, yhi)))
            .collect()
    }

    fn class(&self, i: usize) -> Class {
        if self.inp.failing[i] {
            Class::Failing
        } else if self.inp.a1_failing.get(i).copied().unwrap_or(false) {
            Class::Inadmissible
        } else {
            Class::Explained
        }
    }

    /// The data of class `want` with a positive finite `r_min`, clamped into the axis.
    fn points(&self, want: Class) -> Vec<(f64, f64)> {
        let (inp, (ylo, yhi)) = (self.inp, self.y);
        (0..inp.omega.len())
            .filter(|&i| self.class(i) == want && inp.r_min[i].is_finite() && inp.r_min[i] > 0.0)
            .map(|i| (inp.omega[i], style::clamp(inp.r_min[i], ylo, yhi)))
            .collect()
    }

    /// The A1 limit `σ_min(M̃(jω))`, dashed purple, when the model is known.
    fn a1_limit(&self, p: &mut LogLogPlot) -> Result<()> {
        let Some(a1) = self.inp.a1_on_grid else {
            return Ok(());
        };
        p.line_with_legend(
            self.curve(a1),
            LIMIT,
            "A1 limit σ_min(M̃(jω)): |r| must stay below",
        );
        Ok(())
    }

    /// Green dots, small and translucent (the curves are drawn over them, so none hides the
    /// fitted weight): the data the configured weight explains.
    fn explained(&self, p: &mut LogLogPlot) -> Result<()> {
        let ok = self.points(Class::Explained);
        if ok.is_empty() {
            return Ok(());
        }
        p.chart
            .draw_series(
                ok.iter()
                    .map(|p| Circle::new(*p, 4, C_GREEN.mix(0.55).filled())),
            )
            .map_err(plot_err)?;
        let label = if self.inp.r_configured.is_some() {
            let w = self.sym.weight;
            format!("{}: explained by the configured {w}", self.inp.r_min_label)
        } else {
            self.inp.r_min_label.to_string()
        };
        p.legend.add(label, |(x, y)| {
            Circle::new((x + 12, y), 4, C_GREEN.mix(0.55).filled())
        });
        Ok(())
    }

    /// Purple crossed squares: `|r| > r_min` but A1 fails (not admissible).
    fn inadmissible(&self, p: &mut LogLogPlot) -> Result<()> {
        let pts = self.points(Class::Inadmissible);
        if pts.is_empty() {
            return Ok(());
        }
        let mark = |at: (i32, i32)| {
            EmptyElement::at(at)
                + Rectangle::new([(-6, -6), (6, 6)], C_PURPLE.stroke_width(2))
                + Cross::new((0, 0), 4, C_PURPLE.stroke_width(2))
        };
        p.chart
            .draw_series(pts.iter().map(|p| {
                EmptyElement::at(*p)
                    + Rectangle::new([(-6, -6), (6, 6)], C_PURPLE.stroke_width(2))
                    + Cross::new((0, 0), 4, C_PURPLE.stroke_width(2))
            }))
            .map_err(plot_err)?;
        let w = self.sym.weight;
        p.legend.add(
            format!(
                "{}: NOT ADMISSIBLE, configured |{w}(jω)| ≥ σ_min(M̃) (A1 fails)",
                self.inp.r_min_label
            ),
            move |(x, y)| mark((x + 12, y)),
        );
        Ok(())
    }

    /// Red crossed circles: `|r| ≤ r_min`, the configured weight does not explain them.
    fn failing(&self, p: &mut LogLogPlot) -> Result<()> {
        let bad = self.points(Class::Failing);
        if bad.is_empty() {
            return Ok(());
        }
        p.chart
            .draw_series(bad.iter().map(|p| {
                EmptyElement::at(*p)
                    + Circle::new((0, 0), 6, C_RED.stroke_width(2))
                    + Cross::new((0, 0), 5, C_RED.stroke_width(2))
            }))
            .map_err(plot_err)?;
        let (w, wmin) = (self.sym.weight, self.sym.weight_min);
        p.legend.add(
            format!(
                "{}: FAILING, configured |{w}(jω)| ≤ {wmin}",
                self.inp.r_min_label
            ),
            |(x, y)| {
                EmptyElement::at((x + 12, y))
                    + Circle::new((0, 0), 6, C_RED.stroke_width(2))
                    + Cross::new((0, 0), 4, C_RED.stroke_width(2))
            },
        );
        Ok(())
    }

    /// Red triangles at the top: `r_min = ∞`, no admissible weight explains the datum.
    fn infinite(&self, p: &mut LogLogPlot) -> Result<()> {
        let inp = self.inp;
        let infinite: Vec<(f64, f64)> = inp
            .omega
            .iter()
            .zip(inp.r_min)
            .filter(|(_, r)| r.is_infinite())
            .map(|(w, _)| (*w, self.y.1))
            .collect();
        if infinite.is_empty() {
            return Ok(());
        }
        let tri = |(x, y): (i32, i32)| vec![(x - 7, y + 12), (x + 7, y + 12), (x, y)];
        p.chart
            .draw_series(
                infinite
                    .iter()
                    .map(|p| EmptyElement::at(*p) + Polygon::new(tri((0, 0)), C_RED.filled())),
            )
            .map_err(plot_err)?;
        let (w, wmin) = (self.sym.weight, self.sym.weight_min);
        p.legend.add(
            format!("{wmin} = ∞: no admissible {w} explains the datum (drawn at the top)"),
            move |(x, y)| Polygon::new(tri((x + 12, y - 6)), C_RED.filled()),
        );
        Ok(())
    }

    /// Pale green triangles at the bottom: `r_min = 0`, explained by the noise alone.
    fn zeros(&self, p: &mut LogLogPlot) -> Result<()> {
        let inp = self.inp;
        let zeros: Vec<(f64, f64)> = inp
            .omega
            .iter()
            .zip(inp.r_min)
            .filter(|(_, r)| **r == 0.0)
            .map(|(w, _)| (*w, self.y.0))
            .collect();
        if zeros.is_empty() {
            return Ok(());
        }
        let tri = |(x, y): (i32, i32)| vec![(x - 4, y - 7), (x + 4, y - 7), (x, y)];
        let col = C_GREEN.mix(0.55);
        p.chart
            .draw_series(
                zeros
                    .iter()
                    .map(|p| EmptyElement::at(*p) + Polygon::new(tri((0, 0)), col.filled())),
            )
            .map_err(plot_err)?;
        let wmin = self.sym.weight_min;
        p.legend.add(
            format!(
                "{wmin} = 0 at {} data: explained by the noise alone (drawn at the bottom)",
                zeros.len()
            ),
            move |(x, y)| Polygon::new(tri((x + 12, y + 4)), col.filled()),
        );
        Ok(())
    }
}

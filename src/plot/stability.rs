//! `stability.svg`: the pointwise Theorem 1 limit `1/σ_max(T(jω))` against `|r(jω)|` for
//! each bound (configured and fitted). Where `|r|` stays below the limit curve the
//! controller is proven robust; the smallest ratio is the margin `α*`, written on the
//! figure with the verdict and (for `synthesize`) the method and its `γ`.

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
    /// Per bound: the frequency where `|r|·σ_max(T)` peaks (where `α*` binds; 0 for the
    /// steady state, `inf` at high frequency), in the order of `r`.
    pub binding: &'a [f64],
    /// Lines written in the plot's upper left corner: the method and `γ`, then `α*` and the
    /// verdict per bound.
    pub notes: &'a [String],
}

/// Renders the figure on log-log axes.
pub fn stability_svg(inp: &StabilityInput) -> Result<String> {
    // The axis holds the binding frequencies too (a finite positive one outside the grid
    // widens it).
    let xs: Vec<f64> = inp
        .omega
        .iter()
        .chain(inp.binding.iter())
        .copied()
        .filter(|w| w.is_finite() && *w > 0.0)
        .collect();
    let (xlo, xhi) = omega_range(&xs);
    let all = inp
        .inv_t
        .iter()
        .chain(inp.r.iter().flat_map(|(_, v)| v.iter()))
        .filter(|v| v.is_finite() && **v > 0.0);
    let (ylo, yhi) = log_range(all, 2.0).unwrap_or((0.01, 100.0));
    let rows = inp.r.len() + 1 + usize::from(!inp.binding.is_empty());
    let y_desc = "|r(jω)| and the limit 1/σ_max(T(jω))";
    loglog_figure(inp.title, (xlo, xhi), (ylo, yhi), y_desc, rows, |p| {
        let (ylo, yhi) = (p.y_axis().ends().0, p.y_axis().ends().1);
        // Limits are purple and dashed, as the A1 limit of r_vs_delta.svg; the configured r
        // is blue and solid, the fitted r orange and dashed, in every figure.
        p.line_with_legend(
            inp.omega
                .iter()
                .zip(inp.inv_t)
                .filter(|(_, v)| v.is_finite() && **v > 0.0)
                .map(|(w, v)| (*w, clamp(*v, ylo, yhi))),
            LIMIT,
            "1/σ_max(T(jω)): largest |r| proven robust (Theorem 1)",
        );
        let others = [C_GREEN, C_RED, C_GREY];
        for (k, (label, r)) in inp.r.iter().enumerate() {
            let look = if label.starts_with("configured") {
                WeightCurve::Configured.look()
            } else if label.starts_with("fitted") {
                WeightCurve::Fitted.look()
            } else {
                super::fine::Look::solid(others[k % others.len()], 3.0)
            };
            p.line_with_legend(
                inp.omega
                    .iter()
                    .zip(r)
                    .map(|(w, v)| (*w, clamp(*v, ylo, yhi))),
                look,
                format!("|r(jω)|, {label}"),
            );
        }
        binding_marks(p, inp)?;
        notes(p, inp.notes)
    })
}

/// Grey dotted verticals where `α*` binds (at the axis' left edge for ω = 0, right edge for
/// ω = ∞).
fn binding_marks(p: &mut LogLogPlot, inp: &StabilityInput) -> Result<()> {
    if inp.binding.is_empty() {
        return Ok(());
    }
    let (xlo, xhi) = p.x_axis().ends();
    let (ylo, yhi) = p.y_axis().ends();
    let look = super::fine::Look::dashed(C_GREY, 1.5, 2.0, 4.0);
    for w in inp.binding {
        let x = if w.is_nan() {
            continue;
        } else {
            w.clamp(xlo, xhi)
        };
        p.line([(x, ylo), (x, yhi)], look);
    }
    let where_: Vec<String> = inp
        .binding
        .iter()
        .map(|w| {
            if *w == 0.0 {
                "ω = 0 (steady state, at the left edge)".to_string()
            } else if w.is_infinite() {
                "ω → ∞ (at the right edge)".to_string()
            } else {
                format!("ω = {} rad/s", crate::report::fmt::fmt_g(*w))
            }
        })
        .collect();
    p.legend.add_line(
        format!("where α* binds: {}", where_.join("; ")),
        look,
        &p.overlay,
    );
    Ok(())
}

/// The notes, one per line, in a white box in the plot's upper left corner.
fn notes(p: &mut LogLogPlot, lines: &[String]) -> Result<()> {
    if lines.is_empty() {
        return Ok(());
    }
    let area = p.chart.plotting_area();
    let ((x0, _), (y0, _)) = {
        let (xr, yr) = area.get_pixel_range();
        ((xr.start, xr.end), (yr.start, yr.end))
    };
    let root = area.strip_coord_spec();
    let width = lines
        .iter()
        .map(|l| l.chars().count() as f64 * 0.6 * LEGEND as f64)
        .fold(0.0, f64::max) as i32
        + 16;
    let h = lines.len() as i32 * 18 + 10;
    let (ox, oy) = (x0 - root.get_base_pixel().0, y0 - root.get_base_pixel().1);
    root.draw(&Rectangle::new(
        [(ox + 8, oy + 8), (ox + 8 + width, oy + 8 + h)],
        WHITE.mix(0.9).filled(),
    ))
    .map_err(plot_err)?;
    root.draw(&Rectangle::new(
        [(ox + 8, oy + 8), (ox + 8 + width, oy + 8 + h)],
        C_GREY.stroke_width(1),
    ))
    .map_err(plot_err)?;
    for (k, l) in lines.iter().enumerate() {
        let col = if l.contains("NOT") || l.contains("withheld") {
            C_RED
        } else {
            BLACK
        };
        root.draw(&Text::new(
            l.clone(),
            (ox + 16, oy + 14 + 18 * k as i32),
            TextStyle::from((FONT, LEGEND).into_font()).color(&col),
        ))
        .map_err(plot_err)?;
    }
    Ok(())
}

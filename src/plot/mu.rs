//! `mu.svg`: the structured singular value `μ_Γ{F_L[V(jω_i), φ_i⁻¹]}` per datum for the
//! configured `r`, with the line `μ = 1` (the analogue of Fig. 8).  By Lemma 5 / Theorem 4
//! a datum is consistent with the model, `r` and the noise level iff `μ_Γ > 1` there.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::style::*;
use super::symbols::Symbols;
use crate::error::Result;
use plotters::prelude::*;

/// What the figure shows.
pub struct MuInput<'a> {
    /// Title of the figure.
    pub title: &'a str,
    /// Data frequencies (rad/s).
    pub omega: &'a [f64],
    /// `μ_Γ` per datum (`inf` allowed, drawn at the top).
    pub mu: &'a [f64],
    /// Per datum: true when the configured `r` breaks A1 there (Theorem 4 then gives no
    /// verdict, whatever `μ`); empty when unknown.
    pub a1_failing: &'a [bool],
}

/// Renders `mu.svg` on log-log axes with the open-loop symbols (`μ_Γ`, `r`); data with
/// `μ ≤ 1` are highlighted.
pub fn mu_svg(inp: &MuInput) -> Result<String> {
    mu_svg_with(inp, &Symbols::OPEN_LOOP)
}

/// Renders `mu.svg`, naming `μ` and the weight by `sym`.
pub fn mu_svg_with(inp: &MuInput, sym: &Symbols) -> Result<String> {
    let (mu_name, w) = (sym.mu, sym.weight);
    let (xlo, xhi) = omega_range(inp.omega);
    let (ylo, yhi) =
        log_range(inp.mu.iter().chain(std::iter::once(&1.0)), 2.5).unwrap_or((0.1, 10.0));
    let rows =
        1 + usize::from(
            inp.mu
                .iter()
                .enumerate()
                .any(|(i, m)| *m > 1.0 && !inp.a1_failing.get(i).copied().unwrap_or(false)),
        ) + usize::from(inp.a1_failing.iter().any(|f| *f))
            + usize::from(inp.mu.iter().any(|m| *m <= 1.0));
    let y_desc = format!("{mu_name} (dimensionless)");
    loglog_figure(inp.title, (xlo, xhi), (ylo, yhi), &y_desc, rows, |p| {
        let (xlo, xhi) = p.x_axis().ends();
        p.line_with_legend(
            [(xlo, 1.0), (xhi, 1.0)],
            super::fine::Look::dashed(C_GREY, 2.0, 10.0, 6.0),
            "μ = 1: consistent above, inconsistent at or below",
        );
        let a1_fails = |i: usize| inp.a1_failing.get(i).copied().unwrap_or(false);
        // (ω, μ clamped, μ > 1, A1 holds)
        let pts: Vec<(f64, f64, bool, bool)> = (0..inp.omega.len())
            .filter(|&i| !inp.mu[i].is_nan())
            .map(|i| {
                let m = inp.mu[i];
                (inp.omega[i], clamp(m, ylo, yhi), m > 1.0, !a1_fails(i))
            })
            .collect();
        // A thin line through the data guides the eye; the markers carry the verdict.
        p.line(
            pts.iter().map(|p| (p.0, p.1)),
            super::fine::Look::solid(C_BLUE, 1.0).alpha(0.35),
        );
        if pts.iter().any(|p| p.2 && p.3) {
            p.chart
                .draw_series(
                    pts.iter()
                        .filter(|p| p.2 && p.3)
                        .map(|p| Circle::new((p.0, p.1), 3, C_BLUE.filled())),
                )
                .map_err(plot_err)?;
            p.legend.add(
                format!("{mu_name} per datum, configured {w} (consistent)"),
                |(x, y)| Circle::new((x + 12, y), 4, C_BLUE.filled()),
            );
        }
        let n_inadmissible = pts.iter().filter(|p| p.2 && !p.3).count();
        if n_inadmissible > 0 {
            let sq = |(x, y): (i32, i32)| [(x - 4, y - 4), (x + 4, y + 4)];
            p.chart
                .draw_series(pts.iter().filter(|p| p.2 && !p.3).map(|p| {
                    EmptyElement::at((p.0, p.1))
                        + Rectangle::new(sq((0, 0)), C_PURPLE.stroke_width(2))
                }))
                .map_err(plot_err)?;
            p.legend.add(
format!(
                    "{mu_name} > 1 but A1 fails ({n_inadmissible} data): configured {w} NOT ADMISSIBLE, no verdict"
                ),
move |(x, y)| {
                    EmptyElement::at((x + 12, y)) + Rectangle::new(sq((0, 0)), C_PURPLE.stroke_width(2))
                });
        }
        if pts.iter().any(|p| !p.2) {
            p.chart
                .draw_series(pts.iter().filter(|p| !p.2).map(|p| {
                    EmptyElement::at((p.0, p.1))
                        + Circle::new((0, 0), 6, C_RED.stroke_width(2))
                        + Cross::new((0, 0), 4, C_RED.stroke_width(2))
                }))
                .map_err(plot_err)?;
            p.legend
                .add(format!("{mu_name} ≤ 1: FAILING datum"), |(x, y)| {
                    EmptyElement::at((x + 12, y))
                        + Circle::new((0, 0), 6, C_RED.stroke_width(2))
                        + Cross::new((0, 0), 4, C_RED.stroke_width(2))
                });
        }
        Ok(())
    })
}

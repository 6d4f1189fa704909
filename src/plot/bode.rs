//! `bode.svg`: magnitude and phase of the data, with the noise disk of eq. (5) drawn as
//! error bars, against the nominal model `G = C·M̃⁻¹·Ñ·J` (as in the paper's Fig. 7).

use super::axis::{log_label, phase_tick, LogAxis};
use super::fine::{Look, Overlay, PixelMap};
use super::style::*;
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;
use plotters::prelude::*;

/// What the figure shows.
pub struct BodeInput<'a> {
    /// Title of the figure.
    pub title: &'a str,
    /// Data frequencies (rad/s).
    pub omega: &'a [f64],
    /// The measured `p×m` responses.
    pub data: &'a [DMatrix<Complex64>],
    /// Per-datum noise-disk radius, when the data are noisy.
    pub noise_radius: Option<&'a [f64]>,
    /// Dense frequency grid for the model (rad/s).
    pub grid: &'a [f64],
    /// The nominal model on `grid` (`None` where `M̃(jω)` is singular).
    pub model: &'a [Option<DMatrix<Complex64>>],
    /// Name of the response in labels: `G` (open loop) or `Φ` (closed loop).
    pub symbol: &'a str,
}

/// The model's phase of channel `ch` on the grid, unwrapped along it (NaN where the model is
/// unknown or zero).
fn model_phase(inp: &BodeInput, ch: (usize, usize)) -> Vec<f64> {
    super::bode_common::model_phase(inp.model.iter().map(|g| match g {
        Some(g) => g[ch],
        None => Complex64::new(f64::NAN, f64::NAN),
    }))
}

/// Phase (degrees) of each datum of channel `ch` on the branch of the model's unwrapped
/// phase `model` at its frequency ([`super::bode_common::data_phase`]).
fn data_phases(inp: &BodeInput, ch: (usize, usize), model: &[f64]) -> Vec<f64> {
    let reference: Vec<f64> = inp
        .omega
        .iter()
        .map(|w| super::bode_common::interp(inp.grid, model, *w))
        .collect();
    let g: Vec<Complex64> = inp.data.iter().map(|d| d[ch]).collect();
    super::bode_common::data_phase(&g, Some(&reference), inp.noise_radius)
}

/// Pixel size of one channel's panel (magnitude over phase) in a MIMO grid, and of the
/// single panel of a SISO figure.
const PANEL_MIMO: (u32, u32) = (430, 430);

/// Renders `bode.svg`: one panel per channel `G_ij` (a grid of `p` rows by `m` columns for
/// MIMO data, so that no channel hides under another), each with the magnitude (log-log) over
/// the phase (degrees); data as markers with their noise error bars, the model as a line;
/// one legend below the grid.
pub fn bode_svg(inp: &BodeInput) -> Result<String> {
    let (p, m) = inp.data.first().map_or((1, 1), |d| (d.nrows(), d.ncols()));
    let noisy = inp.noise_radius.is_some();
    let rows = 2 + usize::from(noisy);
    let (pw, ph) = if p * m == 1 {
        (SIZE.0, SIZE.1 + 200)
    } else {
        (PANEL_MIMO.0, PANEL_MIMO.1)
    };
    let width = (pw * m as u32).max(SIZE.0);
    let height = 44 + ph * p as u32 + legend_height(rows);
    let mut svg = String::new();
    let overlay = Overlay::default();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let title = fit_title(inp.title, width as f64 - 28.0, CAPTION);
        let root = root.titled(&title, (FONT, CAPTION)).map_err(plot_err)?;
        let (grid, below) = root.split_vertically(ph * p as u32);
        let panels = grid.split_evenly((p, m));
        for (k, area) in panels.iter().enumerate() {
            let ch = (k / m, k % m);
            panel(area, inp, ch, p * m == 1, &overlay)?;
        }
        let mut leg = Legend::default();
        let col = C_BLUE;
        let sym = inp.symbol;
        leg.add_line(
            format!("nominal model {sym}(jω) (line; phase unwrapped along ω)"),
            MODEL,
            &overlay,
        );
        leg.add("measured data (markers)", move |(x, y)| {
            Circle::new((x + 12, y), 3, col.mix(0.7).filled())
        });
        if noisy {
            let s = C_BLUE.mix(0.6).stroke_width(1);
            leg.add(
                "error bar: noise disk |Φ − G_p| ≤ L (eq. 5); down to the axis if it holds 0",
                move |(x, y)| PathElement::new(vec![(x + 12, y - 7), (x + 12, y + 7)], s),
            );
        }
        leg.draw(&below)?;
        root.present().map_err(plot_err)?;
    }
    overlay.inject(&mut svg);
    Ok(svg)
}

/// The model's line: solid orange.
const MODEL: Look = Look::solid(C_ORANGE, 2.0);

/// Draws channel `ch` (magnitude over phase) in `area`; the model's lines go to `overlay`.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    inp: &BodeInput,
    (i, j): (usize, usize),
    siso: bool,
    overlay: &Overlay,
) -> Result<()> {
    let radius = |k: usize| inp.noise_radius.map_or(0.0, |r| r[k]);
    let (xlo, xhi) = omega_range(inp.omega);
    let sym = inp.symbol;
    let name = if siso {
        sym.to_string()
    } else {
        format!("{sym}{}{}", i + 1, j + 1)
    };
    let mags: Vec<f64> = (0..inp.data.len())
        .map(|k| inp.data[k][(i, j)].norm() + radius(k))
        .chain(inp.model.iter().flatten().map(|g| g[(i, j)].norm()))
        .collect();
    let (ylo, yhi) = log_range(&mags, 2.0).unwrap_or((1e-3, 1e3));
    let ylo = ylo.max(yhi * 1e-10);
    let (top, bottom) = area.split_vertically(area.dim_in_pixel().1 * 55 / 100);
    let (xl, yl, font) = if siso {
        (44, 78, TICKS)
    } else {
        (34, 60, TICKS - 2)
    };
    let mut builder = ChartBuilder::on(&top);
    builder
        .margin(10)
        .x_label_area_size(xl)
        .y_label_area_size(yl);
    let zero_model = inp.model.iter().flatten().all(|g| g[(i, j)].norm() == 0.0);
    if !siso {
        let note = if zero_model { " (model ≡ 0)" } else { "" };
        builder.caption(
            format!("{name}: output {}, input {}{note}", i + 1, j + 1),
            (FONT, AXIS),
        );
    }
    let mut mag = builder
        .build_cartesian_2d(LogAxis::new(xlo, xhi), LogAxis::new(ylo, yhi))
        .map_err(plot_err)?;
    let (ylo, yhi) = mag.as_coord_spec().y_spec().ends();
    mag.configure_mesh()
        .y_desc(format!("|{name}(jω)|"))
        .axis_desc_style((FONT, if siso { AXIS } else { TICKS }))
        .label_style((FONT, font))
        .x_label_formatter(&log_label)
        .y_label_formatter(&log_label)
        .light_line_style(RGBColor(235, 235, 235))
        .max_light_lines(9)
        .x_labels(if siso { 12 } else { 6 })
        .y_labels(if siso { 10 } else { 6 })
        .draw()
        .map_err(plot_err)?;
    let col = C_BLUE;
    let dot = col.mix(0.7).filled();
    for (k, (w, d)) in inp.omega.iter().zip(inp.data).enumerate() {
        let a = d[(i, j)].norm();
        let r = radius(k);
        if r > 0.0 {
            // Down to the axis when the disk holds 0: the bar is drawn where it really ends.
            let lo = clamp((a - r).max(ylo), ylo, yhi);
            let hi = clamp(a + r, ylo, yhi);
            mag.draw_series(std::iter::once(PathElement::new(
                vec![(*w, lo), (*w, hi)],
                col.mix(0.6).stroke_width(1),
            )))
            .map_err(plot_err)?;
        }
        if a > 0.0 && a.is_finite() {
            mag.draw_series(std::iter::once(Circle::new(
                (*w, clamp(a, ylo, yhi)),
                3,
                dot,
            )))
            .map_err(plot_err)?;
        }
    }
    let line: Vec<(f64, f64)> = inp
        .grid
        .iter()
        .zip(inp.model)
        .map(|(w, g)| match g {
            Some(g) if g[(i, j)].norm() > 0.0 => (*w, clamp(g[(i, j)].norm(), ylo, yhi)),
            _ => (*w, f64::NAN),
        })
        .collect();
    overlay.curve(&PixelMap::of(&mag), line, MODEL);

    // Phase: unwrapped along the grid (as compare's overlay), the data on the model's
    // branch; the axis spans multiples of 90° just around them, ticked every 90°.
    let model = model_phase(inp, (i, j));
    let data = data_phases(inp, (i, j), &model);
    let in_band = |w: &f64| *w >= xlo && *w <= xhi;
    let axis = super::bode_common::phase_axis(
        &data,
        inp.grid
            .iter()
            .zip(&model)
            .filter(|(w, _)| in_band(w))
            .map(|(_, p)| *p),
    );
    let mut ph = ChartBuilder::on(&bottom)
        .margin(10)
        .x_label_area_size(if siso { 52 } else { 40 })
        .y_label_area_size(yl)
        .build_cartesian_2d(LogAxis::new(xlo, xhi), axis.clone())
        .map_err(plot_err)?;
    ph.configure_mesh()
        .x_desc("frequency ω (rad/s)")
        .y_desc(format!("∠{name}(jω) (degrees)"))
        .axis_desc_style((FONT, if siso { AXIS } else { TICKS }))
        .label_style((FONT, font))
        .x_label_formatter(&log_label)
        .y_label_formatter(&phase_tick)
        .light_line_style(RGBColor(235, 235, 235))
        .max_light_lines(9)
        .x_labels(if siso { 12 } else { 6 })
        .draw()
        .map_err(plot_err)?;
    for (k, (w, d)) in inp.omega.iter().zip(inp.data).enumerate() {
        let z = d[(i, j)];
        let ang = data[k];
        if !ang.is_finite() {
            continue;
        }
        let r = radius(k);
        if r > 0.0 {
            // The disk of radius r around z subtends ±asin(r/|z|) (all angles if it holds 0).
            let (lo, hi) = super::bode_common::disk_phase_bar(ang, r, z.norm(), &axis);
            ph.draw_series(std::iter::once(PathElement::new(
                vec![(*w, lo), (*w, hi)],
                col.mix(0.6).stroke_width(1),
            )))
            .map_err(plot_err)?;
        }
        ph.draw_series(std::iter::once(Circle::new((*w, axis.clamp(ang)), 3, dot)))
            .map_err(plot_err)?;
    }
    overlay.curve(
        &PixelMap::of(&ph),
        inp.grid.iter().copied().zip(model.iter().copied()),
        MODEL,
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model's phase is continuous (no jump at ±180°) and each datum sits on its branch.
    #[test]
    fn phase_is_unwrapped_along_the_model() {
        let grid: Vec<f64> = (0..200).map(|k| 0.1 * 1.05f64.powi(k)).collect();
        // G = 1/(s+1)^3: the phase runs from 0 to −270°.
        let g = |w: f64| Complex64::new(1.0, w).powi(3).inv();
        let model: Vec<Option<DMatrix<Complex64>>> = grid
            .iter()
            .map(|w| Some(DMatrix::from_element(1, 1, g(*w))))
            .collect();
        let omega = [0.5, 3.0, 20.0];
        let data: Vec<DMatrix<Complex64>> = omega
            .iter()
            .map(|w| DMatrix::from_element(1, 1, g(*w)))
            .collect();
        let inp = BodeInput {
            title: "t",
            omega: &omega,
            data: &data,
            noise_radius: None,
            grid: &grid,
            model: &model,
            symbol: "G",
        };
        let m = model_phase(&inp, (0, 0));
        assert!(m.windows(2).all(|w| (w[1] - w[0]).abs() < 20.0));
        assert!(m.last().unwrap() < &-200.0);
        let d = data_phases(&inp, (0, 0), &m);
        let exact = |w: f64| -3.0 * w.atan().to_degrees();
        for (p, w) in d.iter().zip(omega) {
            assert!((p - exact(w)).abs() < 1e-6, "{p} vs {}", exact(w));
        }
    }
}

//! `bode.svg`: magnitude and phase of the data, with the noise disk of eq. (5) drawn as
//! error bars, against the nominal model `G = C·M̃⁻¹·Ñ·J` (as in the paper's Fig. 7).

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

fn phase_deg(z: Complex64) -> f64 {
    z.arg().to_degrees()
}

/// An angle in degrees wrapped into `(-180, 180]`.
fn wrap180(a: f64) -> f64 {
    let r = a.rem_euclid(360.0);
    if r > 180.0 {
        r - 360.0
    } else {
        r
    }
}

/// The model's (wrapped) phase of channel `ch` at the grid point nearest to `w`.
fn model_phase_near(inp: &BodeInput, w: f64, ch: (usize, usize)) -> Option<f64> {
    let k = inp.grid.partition_point(|g| *g < w);
    let cand = [k.saturating_sub(1), k.min(inp.grid.len().saturating_sub(1))];
    let best = cand
        .into_iter()
        .filter(|&c| c < inp.grid.len())
        .min_by(|&a, &b| {
            (inp.grid[a] / w)
                .ln()
                .abs()
                .total_cmp(&(inp.grid[b] / w).ln().abs())
        })?;
    let g = inp.model.get(best)?.as_ref()?[ch];
    (g.norm() > 0.0).then(|| phase_deg(g))
}

/// Phase (degrees) of datum `k`, channel `ch`, on the branch of the model's phase nearby, so
/// that data and model do not sit on opposite sides of the ±180° wrap.
fn data_phase(inp: &BodeInput, k: usize, ch: (usize, usize)) -> f64 {
    let z = inp.data[k][ch];
    match model_phase_near(inp, inp.omega[k], ch) {
        Some(pm) => pm + wrap180(phase_deg(z) - pm),
        None => phase_deg(z),
    }
}

/// Splits a wrapped phase curve where it jumps by more than 180°, so no vertical line is
/// drawn across the ±180° wrap.
fn wrap_segments(points: Vec<(f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for p in points {
        let cur = out.last_mut().expect("non-empty");
        if let Some(last) = cur.last() {
            if (p.1 - last.1).abs() > 180.0 {
                out.push(Vec::new());
            }
        }
        out.last_mut().expect("non-empty").push(p);
    }
    out.into_iter().filter(|s| s.len() > 1).collect()
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
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let root = root.titled(inp.title, (FONT, CAPTION)).map_err(plot_err)?;
        let (grid, below) = root.split_vertically(ph * p as u32);
        let panels = grid.split_evenly((p, m));
        for (k, area) in panels.iter().enumerate() {
            let ch = (k / m, k % m);
            panel(area, inp, ch, p * m == 1)?;
        }
        let mut leg = Legend::default();
        let col = C_BLUE;
        let s = ShapeStyle::from(&C_ORANGE).stroke_width(2);
        let sym = inp.symbol;
        leg.add(format!("nominal model {sym}(jω) (line)"), move |(x, y)| {
            PathElement::new(vec![(x, y), (x + 24, y)], s)
        });
        leg.add("measured data (markers)", move |(x, y)| {
            Circle::new((x + 12, y), 4, col.filled())
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
    Ok(svg)
}

/// Draws channel `ch` (magnitude over phase) in `area`.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    inp: &BodeInput,
    (i, j): (usize, usize),
    siso: bool,
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
        .build_cartesian_2d((xlo..xhi).log_scale(), (ylo..yhi).log_scale())
        .map_err(plot_err)?;
    mag.configure_mesh()
        .y_desc(format!("|{name}(jω)|"))
        .axis_desc_style((FONT, if siso { AXIS } else { TICKS }))
        .label_style((FONT, font))
        .x_label_formatter(&log_tick)
        .y_label_formatter(&log_tick)
        .light_line_style(RGBColor(235, 235, 235))
        .max_light_lines(4)
        .x_labels(if siso { 12 } else { 6 })
        .draw()
        .map_err(plot_err)?;
    let col = C_BLUE;
    let s = ShapeStyle::from(&C_ORANGE).stroke_width(2);
    let line: Vec<(f64, f64)> = inp
        .grid
        .iter()
        .zip(inp.model)
        .filter_map(|(w, g)| g.as_ref().map(|g| (*w, g[(i, j)].norm())))
        .filter(|(_, y)| *y > 0.0 && y.is_finite())
        .map(|(w, y)| (w, clamp(y, ylo, yhi)))
        .collect();
    mag.draw_series(LineSeries::new(line, s))
        .map_err(plot_err)?;
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
        if a > 0.0 {
            mag.draw_series(std::iter::once(Circle::new(
                (*w, clamp(a, ylo, yhi)),
                3,
                col.filled(),
            )))
            .map_err(plot_err)?;
        }
    }

    // Phase: ±180° plus whatever the data on the model's branch need (at most ±360°).
    let (mut plo, mut phi) = (-180.0f64, 180.0f64);
    for k in 0..inp.omega.len() {
        let a = data_phase(inp, k, (i, j));
        plo = plo.min(a);
        phi = phi.max(a);
    }
    let (plo, phi) = (plo.max(-360.0) - 22.5, phi.min(360.0) + 22.5);
    let mut ph = ChartBuilder::on(&bottom)
        .margin(10)
        .x_label_area_size(if siso { 52 } else { 40 })
        .y_label_area_size(yl)
        .build_cartesian_2d((xlo..xhi).log_scale(), plo..phi)
        .map_err(plot_err)?;
    ph.configure_mesh()
        .x_desc("frequency ω (rad/s)")
        .y_desc(format!("∠{name}(jω) (degrees)"))
        .axis_desc_style((FONT, if siso { AXIS } else { TICKS }))
        .label_style((FONT, font))
        .x_label_formatter(&log_tick)
        .y_labels(if siso { 9 } else { 5 })
        .y_label_formatter(&|v| format!("{v:.0}°"))
        .light_line_style(RGBColor(235, 235, 235))
        .max_light_lines(4)
        .x_labels(if siso { 12 } else { 6 })
        .draw()
        .map_err(plot_err)?;
    let line: Vec<(f64, f64)> = inp
        .grid
        .iter()
        .zip(inp.model)
        .filter_map(|(w, g)| g.as_ref().map(|g| (*w, g[(i, j)])))
        .filter(|(_, z)| z.norm() > 0.0)
        .map(|(w, z)| (w, phase_deg(z)))
        .collect();
    for seg in wrap_segments(line) {
        ph.draw_series(LineSeries::new(seg, s)).map_err(plot_err)?;
    }
    for (k, (w, d)) in inp.omega.iter().zip(inp.data).enumerate() {
        let z = d[(i, j)];
        let ang = data_phase(inp, k, (i, j));
        let r = radius(k);
        if r > 0.0 {
            // The disk of radius r around z subtends ±asin(r/|z|) (all angles if it holds 0).
            let half = if r >= z.norm() {
                180.0
            } else {
                (r / z.norm()).asin().to_degrees()
            };
            let (lo, hi) = (clamp(ang - half, plo, phi), clamp(ang + half, plo, phi));
            ph.draw_series(std::iter::once(PathElement::new(
                vec![(*w, lo), (*w, hi)],
                col.mix(0.6).stroke_width(1),
            )))
            .map_err(plot_err)?;
        }
        ph.draw_series(std::iter::once(Circle::new((*w, ang), 3, col.filled())))
            .map_err(plot_err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::wrap_segments;

    #[test]
    fn wrap_splits_at_jumps() {
        let s = wrap_segments(vec![
            (1.0, 170.0),
            (2.0, 179.0),
            (3.0, -179.0),
            (4.0, -170.0),
        ]);
        assert_eq!(s.len(), 2);
    }

    #[test]
    fn wrap() {
        assert_eq!(super::wrap180(190.0), -170.0);
        assert_eq!(super::wrap180(-190.0), 170.0);
        assert_eq!(super::wrap180(180.0), 180.0);
    }
}

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

/// Renders `bode.svg`: magnitude (top, log-log) and phase (bottom, degrees), one colour per
/// channel `G_ij`; data as markers with error bars, the model as a line.
pub fn bode_svg(inp: &BodeInput) -> Result<String> {
    let (p, m) = inp.data.first().map_or((0, 0), |d| (d.nrows(), d.ncols()));
    let channels: Vec<(usize, usize)> = (0..p).flat_map(|i| (0..m).map(move |j| (i, j))).collect();
    let radius = |k: usize| inp.noise_radius.map_or(0.0, |r| r[k]);
    let (xlo, xhi) = omega_range(inp.omega);
    let mags = inp
        .data
        .iter()
        .enumerate()
        .flat_map(|(k, d)| {
            d.iter()
                .map(move |z| (z.norm() + radius(k)).max(0.0))
                .collect::<Vec<_>>()
        })
        .chain(
            inp.model
                .iter()
                .flatten()
                .flat_map(|g| g.iter().map(|z| z.norm()).collect::<Vec<_>>()),
        )
        .collect::<Vec<f64>>();
    let (ylo, yhi) = log_range(&mags, 2.0).unwrap_or((1e-3, 1e3));
    let ylo = ylo.max(yhi * 1e-10);
    let bar_floor = ylo;
    let rows = channels.len() + usize::from(inp.noise_radius.is_some());
    let (ylo, yhi) = reserve_bottom(
        ylo,
        yhi,
        legend_fraction(rows, (SIZE.1 + 260) * 55 / 100 - 100),
    );
    let noisy = inp.noise_radius.is_some();

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, SIZE.1 + 260)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let root = root.titled(inp.title, (FONT, CAPTION)).map_err(plot_err)?;
        let (top, bottom) = root.split_vertically((SIZE.1 + 260 - 40) * 55 / 100);

        // Magnitude.
        let mut mag = ChartBuilder::on(&top)
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(78)
            .build_cartesian_2d((xlo..xhi).log_scale(), (ylo..yhi).log_scale())
            .map_err(plot_err)?;
        loglog_mesh(&mut mag, "magnitude |G(jω)| (absolute)")?;
        for (c, &(i, j)) in channels.iter().enumerate() {
            let col = PALETTE[c % PALETTE.len()];
            let line: Vec<(f64, f64)> = inp
                .grid
                .iter()
                .zip(inp.model)
                .filter_map(|(w, g)| g.as_ref().map(|g| (*w, g[(i, j)].norm())))
                .filter(|(_, y)| *y > 0.0 && y.is_finite())
                .map(|(w, y)| (w, clamp(y, ylo, yhi)))
                .collect();
            let name = if p * m == 1 {
                "G".to_string()
            } else {
                format!("G{}{}", i + 1, j + 1)
            };
            let s = ShapeStyle::from(&col).stroke_width(2);
            let label = if line.is_empty() {
                format!("{name}: data (markers); nominal model ≡ 0, not drawn")
            } else {
                format!("{name}: nominal model (line), data (markers)")
            };
            mag.draw_series(LineSeries::new(line, s))
                .map_err(plot_err)?
                .label(label)
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (24, 0)], s)
                        + Circle::new((12, 0), 4, col.filled())
                });
            for (k, (w, d)) in inp.omega.iter().zip(inp.data).enumerate() {
                let a = d[(i, j)].norm();
                let r = radius(k);
                if r > 0.0 {
                    let lo = clamp((a - r).max(bar_floor), bar_floor, yhi);
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
        }
        if noisy {
            let s = C_GREY.stroke_width(1);
            mag.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(plot_err)?
                .label(
                    "error bar: noise disk |Φ − G_p| ≤ L (eq. 5); down to the floor if it holds 0",
                )
                .legend(move |(x, y)| PathElement::new(vec![(x + 12, y - 7), (x + 12, y + 7)], s));
        }
        legend(&mut mag, SeriesLabelPosition::LowerLeft)?;

        // Phase: ±180° plus whatever the data on the model's branch need (at most ±360°).
        let (mut plo, mut phi) = (-180.0f64, 180.0f64);
        for k in 0..inp.omega.len() {
            for &ch in &channels {
                let a = data_phase(inp, k, ch);
                plo = plo.min(a);
                phi = phi.max(a);
            }
        }
        let (plo, phi) = (plo.max(-360.0) - 22.5, phi.min(360.0) + 22.5);
        let mut ph = ChartBuilder::on(&bottom)
            .margin(14)
            .x_label_area_size(52)
            .y_label_area_size(78)
            .build_cartesian_2d((xlo..xhi).log_scale(), plo..phi)
            .map_err(plot_err)?;
        ph.configure_mesh()
            .x_desc("frequency ω (rad/s)")
            .y_desc("phase ∠G(jω) (degrees)")
            .axis_desc_style((FONT, AXIS))
            .label_style((FONT, TICKS))
            .x_label_formatter(&log_tick)
            .y_labels(9)
            .y_label_formatter(&|v| format!("{v:.0}°"))
            .light_line_style(RGBColor(235, 235, 235))
            .max_light_lines(4)
            .x_labels(12)
            .draw()
            .map_err(plot_err)?;
        for (c, &(i, j)) in channels.iter().enumerate() {
            let col = PALETTE[c % PALETTE.len()];
            let line: Vec<(f64, f64)> = inp
                .grid
                .iter()
                .zip(inp.model)
                .filter_map(|(w, g)| g.as_ref().map(|g| (*w, g[(i, j)])))
                .filter(|(_, z)| z.norm() > 0.0)
                .map(|(w, z)| (w, phase_deg(z)))
                .collect();
            for seg in wrap_segments(line) {
                ph.draw_series(LineSeries::new(seg, col.stroke_width(2)))
                    .map_err(plot_err)?;
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
        }
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
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

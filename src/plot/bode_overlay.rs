//! The Bode overlay of model discovery (`rshape compare --svg`): the measured FRF with its
//! noise disks and the model evaluated on a dense grid.  Written atomically.
//!
//! Read at a glance: the model is a line (it can be evaluated at any ω, so resonances between
//! the data show), the data are dots (red where the noise does not explain them), the grey
//! band is the union of the noise disks `|G − G_data| ≤ r` in magnitude and phase, the
//! phase is unwrapped along the model and each datum is drawn on the branch nearest the model
//! (a model at +179° and a datum at −179° are 2° apart, not 358°), and the legend sits below
//! the plots where it hides no data.

use crate::error::Result;
use crate::plot::axis::{LinAxis, LogAxis};
use crate::plot::bode_common;
use crate::plot::fine::{Look, Overlay, PixelMap};
use crate::plot::style::{
    draw_x_labels, fmt_tick, log_axis_ticks, plot_err, Legend, C_GREY, C_RED, FONT, PALETTE, TICKS,
    Y_LABEL_AREA,
};
use num_complex::Complex64;
use plotters::prelude::*;
use std::f64::consts::TAU;
use std::path::Path;

/// The measured side of the overlay.
#[derive(Debug, Clone, Copy)]
pub struct BodeData<'a> {
    /// Frequencies, rad/s, increasing.
    pub omega: &'a [f64],
    /// Measured response.
    pub g: &'a [Complex64],
    /// Noise radius per datum, when known (drawn as the grey band).
    pub radius: Option<&'a [f64]>,
    /// Data the model does not explain within the noise (drawn red).
    pub invalid: &'a [bool],
}

/// A model curve on its own (dense) frequency grid; non-finite values break the line.
#[derive(Debug, Clone)]
pub struct ModelCurve {
    /// Legend label.
    pub name: String,
    /// Frequencies, rad/s, increasing.
    pub omega: Vec<f64>,
    /// Response at `omega`.
    pub g: Vec<Complex64>,
}

/// The x-axis label (Hz here, the unit modes are quoted in, while `run` plots rad/s; the
/// text report gives both).
pub const FREQ_LABEL: &str = "frequency f = ω/2π (Hz)";

/// A dense logarithmic grid (rad/s) over the plotted band (the data's range widened by 10 %
/// on each side), merged with the data frequencies themselves: at least 2000 points and 1000
/// per decade (a step of 0.23 %), so a mode with ζ ≈ 1e-3 (half-power width 0.2 %) shows its
/// peak between data.
///
/// The band goes through the figures' axis guard (`plot::axis::log_bounds`) and the
/// grid holds at most 20 000 points, so extreme frequencies (5e-324, 1e300) cannot make it
/// endless.
pub fn dense_grid(omega: &[f64]) -> Vec<f64> {
    let (lo, hi) = match (omega.first(), omega.last()) {
        (Some(&a), Some(&b)) if a > 0.0 && b >= a => {
            crate::plot::axis::log_bounds(a / 1.1, b * 1.1)
        }
        _ => return omega.to_vec(),
    };
    let decades = (hi / lo).log10();
    let n = ((1000.0 * decades).ceil() as usize).clamp(2000, 20_000);
    let mut g: Vec<f64> = (0..=n)
        .map(|k| lo * (hi / lo).powf(k as f64 / n as f64))
        .chain(omega.iter().copied())
        .collect();
    g.sort_by(f64::total_cmp);
    g.dedup();
    g
}

pub use crate::plot::axis::unwrap_deg;

fn span(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.06).max(1.0);
    (lo - pad, hi + pad)
}

/// Pixel height of the magnitude and the phase plot.
const PANEL: (u32, u32) = (380, 300);
/// Figure width.
const WIDTH: u32 = 960;

/// The Bode overlay as an SVG document: magnitude (dB) above, unwrapped phase below, legend
/// strip at the bottom.
pub fn bode_svg(title: &str, data: &BodeData, models: &[ModelCurve]) -> Result<String> {
    let hz = |w: f64| w / TAU;
    let db = |z: &Complex64| 20.0 * z.norm().max(1e-300).log10();
    let (f0, f1) = match (data.omega.first(), data.omega.last()) {
        (Some(&a), Some(&b)) if a > 0.0 => (hz(a) / 1.1, hz(b) * 1.1),
        _ => (0.1, 1.0),
    };
    let model_phase: Vec<Vec<f64>> = models
        .iter()
        .map(|m| bode_common::model_phase(m.g.iter().copied()))
        .collect();
    let reference: Option<Vec<f64>> = models.first().map(|m| {
        data.omega
            .iter()
            .map(|w| bode_common::interp(&m.omega, &model_phase[0], *w))
            .collect()
    });
    let dph = bode_common::data_phase(data.g, reference.as_deref(), data.radius);
    let in_band = |w: &f64| hz(*w) >= f0 && hz(*w) <= f1;
    let (m0, m1) = span(data.g.iter().map(db).chain(models.iter().flat_map(|m| {
        m.omega
            .iter()
            .zip(&m.g)
            .filter(move |(w, _)| in_band(w))
            .map(|(_, z)| db(z))
    })));
    // Guarded axes: the phase spans multiples of 90° and is ticked (labels and grid lines
    // alike) at multiples of 90°.
    let phase_axis = bode_common::phase_axis(
        &dph,
        models.iter().zip(&model_phase).flat_map(|(m, p)| {
            m.omega
                .iter()
                .zip(p)
                .filter(move |(w, _)| in_band(w))
                .map(|(_, v)| *v)
        }),
    );
    let (p0, p1) = phase_axis.ends();
    let (m0, m1) = crate::plot::axis::lin_bounds(m0, m1);
    let (f0, f1) = crate::plot::axis::log_bounds(f0, f1);
    // Noise band: the magnitude and phase covered by each disk |G − G_data| ≤ r.
    let band = data.radius.map(|r| {
        let mut upper_db = Vec::new();
        let mut lower_db = Vec::new();
        let mut upper_ph = Vec::new();
        let mut lower_ph = Vec::new();
        for ((z, r), p) in data.g.iter().zip(r).zip(&dph) {
            let a = z.norm();
            upper_db.push(20.0 * (a + r).log10());
            lower_db.push(if *r < a {
                (20.0 * (a - r).log10()).max(m0)
            } else {
                m0
            });
            let (lo, hi) = bode_common::disk_phase_bar(*p, *r, a, &phase_axis);
            upper_ph.push(hi);
            lower_ph.push(lo);
        }
        (upper_db, lower_db, upper_ph, lower_ph)
    });
    let invalid_any = data.invalid.iter().any(|b| *b);
    let legend_rows = models.len() + 1 + usize::from(invalid_any) + usize::from(band.is_some());
    let legend_h = crate::plot::style::legend_height(legend_rows);
    let caption_h = 40;
    let x_area = 56;
    let height = caption_h + PANEL.0 + PANEL.1 + x_area + legend_h;
    let mut svg = String::new();
    let overlay = Overlay::default();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (head, rest) = root.split_vertically(caption_h);
        head.draw(&Text::new(
            crate::plot::style::fit_title(title, WIDTH as f64 - 28.0, 20),
            (WIDTH as i32 / 2, 12),
            TextStyle::from((FONT, 20).into_font()).pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Top,
            )),
        ))
        .map_err(plot_err)?;
        let (top, rest) = rest.split_vertically(PANEL.0);
        let (bottom, below) = rest.split_vertically(PANEL.1 + x_area);
        let mut legend: Legend<'_, SVGBackend<'_>> = Legend::default();
        let xs = LogAxis::new(f0, f1);
        let mut mag = ChartBuilder::on(&top)
            .margin_left(14)
            .margin_right(24)
            .margin_top(4)
            .x_label_area_size(6)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(xs.clone(), LinAxis::new(m0, m1))
            .map_err(plot_err)?;
        let mut ph = ChartBuilder::on(&bottom)
            .margin_left(14)
            .margin_right(24)
            .margin_top(10)
            .x_label_area_size(x_area)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(xs, phase_axis.clone())
            .map_err(plot_err)?;
        let plot_w = mag.plotting_area().get_pixel_range().0;
        let ticks = log_axis_ticks(f0, f1, (plot_w.end - plot_w.start) as f64, TICKS);
        let grid = RGBColor(225, 225, 225);
        mag.configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .x_label_formatter(&|_| String::new())
            .y_labels(8)
            .y_label_formatter(&|v| fmt_tick(*v))
            .max_light_lines(1)
            .y_desc("|G| (dB)")
            .axis_desc_style((FONT, 17))
            .label_style((FONT, TICKS))
            .light_line_style(RGBColor(240, 240, 240))
            .bold_line_style(grid)
            .draw()
            .map_err(plot_err)?;
        // The phase grid lines are the mesh's own, at the labelled multiples of 90°.
        ph.configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .x_label_formatter(&|_| String::new())
            .y_label_formatter(&crate::plot::axis::phase_tick)
            .max_light_lines(0)
            .y_desc("phase (degrees, unwrapped)")
            .axis_desc_style((FONT, 17))
            .label_style((FONT, TICKS))
            .bold_line_style(RGBColor(200, 200, 200))
            .draw()
            .map_err(plot_err)?;
        for t in &ticks {
            mag.draw_series(LineSeries::new(vec![(*t, m0), (*t, m1)], grid))
                .map_err(plot_err)?;
            ph.draw_series(LineSeries::new(vec![(*t, p0), (*t, p1)], grid))
                .map_err(plot_err)?;
        }
        if let Some((udb, ldb, uph, lph)) = &band {
            let f: Vec<f64> = data.omega.iter().map(|w| hz(*w)).collect();
            let fill = C_GREY.mix(0.22).filled();
            let poly = |u: &[f64], l: &[f64]| -> Vec<(f64, f64)> {
                f.iter()
                    .zip(u)
                    .map(|(x, y)| (*x, *y))
                    .chain(f.iter().zip(l).rev().map(|(x, y)| (*x, *y)))
                    .collect()
            };
            mag.draw_series(std::iter::once(Polygon::new(poly(udb, ldb), fill)))
                .map_err(plot_err)?;
            ph.draw_series(std::iter::once(Polygon::new(poly(uph, lph), fill)))
                .map_err(plot_err)?;
            legend.add("noise: every G with |G − G_data| ≤ r", move |(x, y)| {
                Rectangle::new([(x, y - 5), (x + 24, y + 5)], fill)
            });
        }
        for (k, (m, p)) in models.iter().zip(&model_phase).enumerate() {
            let look = Look::solid(PALETTE[k % PALETTE.len()], 2.0);
            // Broken where the model cannot be evaluated (the overlay skips non-finite points).
            let m_db = m.omega.iter().zip(&m.g).map(|(w, z)| (hz(*w), db(z)));
            overlay.curve(&PixelMap::of(&mag), m_db, look);
            let m_ph = m.omega.iter().zip(p).map(|(w, v)| (hz(*w), *v));
            overlay.curve(&PixelMap::of(&ph), m_ph, look);
            legend.add_line(
                format!("{} (line: evaluated between the data)", m.name),
                look,
                &overlay,
            );
        }
        let dot = |bad: bool| if bad { C_RED.filled() } else { BLACK.filled() };
        let dots = |ys: &[f64]| -> Vec<Circle<(f64, f64), i32>> {
            data.omega
                .iter()
                .zip(ys)
                .zip(data.invalid)
                .filter(|((_, y), _)| y.is_finite())
                .map(|((w, y), bad)| Circle::new((hz(*w), *y), 2, dot(*bad)))
                .collect()
        };
        let mdb: Vec<f64> = data.g.iter().map(|z| db(z).clamp(m0, m1)).collect();
        mag.draw_series(dots(&mdb)).map_err(plot_err)?;
        let pdeg: Vec<f64> = dph.iter().map(|p| phase_axis.clamp(*p)).collect();
        ph.draw_series(dots(&pdeg)).map_err(plot_err)?;
        legend.add("data explained by the noise", move |(x, y)| {
            Circle::new((x + 12, y), 3, BLACK.filled())
        });
        if invalid_any {
            legend.add(
                "data the model does not explain (|G_model − G_data| > r)",
                move |(x, y)| Circle::new((x + 12, y), 3, C_RED.filled()),
            );
        }
        let labels: Vec<(i32, String)> = ticks
            .iter()
            .map(|t| (ph.backend_coord(&(*t, p0)).0, fmt_tick(*t)))
            .collect();
        let (_, y_axis) = ph.backend_coord(&(f0, p0));
        draw_x_labels(&root, &labels, y_axis, TICKS)?;
        let x_mid = (plot_w.start + plot_w.end) / 2;
        root.draw(&Text::new(
            FREQ_LABEL,
            (x_mid, y_axis + 30),
            TextStyle::from((FONT, 16).into_font()).pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Top,
            )),
        ))
        .map_err(plot_err)?;
        legend.draw(&below)?;
        root.present().map_err(plot_err)?;
    }
    overlay.inject(&mut svg);
    Ok(svg)
}

/// Writes [`bode_svg`] to `path` (atomically).
pub fn bode_overlay(
    path: &Path,
    title: &str,
    data: &BodeData,
    models: &[ModelCurve],
) -> Result<()> {
    let svg = bode_svg(title, data, models).map_err(|e| crate::error::Error::Input {
        path: path.to_path_buf(),
        msg: format!("cannot draw the figure: {e}"),
    })?;
    crate::util::write_atomic(path, svg.as_bytes())
}

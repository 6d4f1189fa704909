//! Where a Bode figure's charts sit and how their frames look: the figure's size, its title,
//! the panels' areas, each chart's margins, mesh and frequency labels.  Two layouts:
//! [`Layout::Grid`] (`run`'s `bode.svg`: one panel per channel, each chart labelled by its
//! own mesh) and [`Layout::Overlay`] (`compare`'s figure: one wide panel, grid lines and
//! frequency labels at the non-overlapping ticks of `log_axis_ticks` under the phase chart).

use super::{BodeFigure, Layout, MagScale, Panel};
use crate::error::Result;
use crate::plot::axis::{log_label, phase_tick, Fraction, LogAxis, PhaseAxis};
use crate::plot::style::{
    draw_x_labels, fit_title, fmt_tick, legend_height, log_axis_ticks, plot_err, AXIS, CAPTION,
    FONT, SIZE, TICKS, Y_LABEL_AREA,
};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// A drawing area of the figure.
pub type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;
/// A chart of the figure: log frequency against `Y`.
pub type Chart<'a, 'b, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogAxis, Y>>;

/// Pixel size of one channel's panel (magnitude over phase) in a MIMO grid.
const PANEL_MIMO: (u32, u32) = (430, 430);
/// Pixel height of the overlay's magnitude and phase charts.
const PANEL_OVERLAY: (u32, u32) = (380, 300);
/// Width of the overlay figure.
const WIDTH_OVERLAY: u32 = 960;
/// Height of the overlay's title strip.
const CAPTION_OVERLAY: u32 = 40;
/// Height of the overlay's frequency labels below the phase chart.
const X_AREA_OVERLAY: u32 = 56;

/// Whether a grid holds a single panel (drawn larger, without caption).
fn single(rows: usize, cols: usize) -> bool {
    rows * cols == 1
}

/// Pixel size of one panel of a grid.
fn grid_panel(rows: usize, cols: usize) -> (u32, u32) {
    if single(rows, cols) {
        (SIZE.0, SIZE.1 + 200)
    } else {
        PANEL_MIMO
    }
}

/// The figure's pixel size, the legend strip included.
pub fn size(fig: &BodeFigure) -> (u32, u32) {
    let legend = legend_height(fig.legend.len());
    match fig.layout {
        Layout::Grid { rows, cols } => {
            let (pw, ph) = grid_panel(rows, cols);
            let width = (pw * cols as u32).max(SIZE.0);
            (width, 44 + ph * rows as u32 + legend)
        }
        Layout::Overlay => (
            WIDTH_OVERLAY,
            CAPTION_OVERLAY + PANEL_OVERLAY.0 + PANEL_OVERLAY.1 + X_AREA_OVERLAY + legend,
        ),
    }
}

/// Draws the title and splits the figure: each panel's (magnitude, phase) areas, row by
/// row, and the legend strip below.
#[allow(clippy::type_complexity)]
pub fn areas<'b>(
    fig: &BodeFigure,
    root: &Area<'b>,
    width: u32,
) -> Result<(Vec<(Area<'b>, Area<'b>)>, Area<'b>)> {
    match fig.layout {
        Layout::Grid { rows, cols } => {
            let title = fit_title(fig.title, width as f64 - 28.0, CAPTION);
            let root = root.titled(&title, (FONT, CAPTION)).map_err(plot_err)?;
            let (grid, below) = root.split_vertically(grid_panel(rows, cols).1 * rows as u32);
            let panels = grid
                .split_evenly((rows, cols))
                .into_iter()
                .map(|a| a.split_vertically(a.dim_in_pixel().1 * 55 / 100))
                .collect();
            Ok((panels, below))
        }
        Layout::Overlay => {
            let (head, rest) = root.split_vertically(CAPTION_OVERLAY);
            head.draw(&Text::new(
                fit_title(fig.title, width as f64 - 28.0, 20),
                (width as i32 / 2, 12),
                TextStyle::from((FONT, 20).into_font()).pos(Pos::new(HPos::Center, VPos::Top)),
            ))
            .map_err(plot_err)?;
            let (top, rest) = rest.split_vertically(PANEL_OVERLAY.0);
            let (bottom, below) = rest.split_vertically(PANEL_OVERLAY.1 + X_AREA_OVERLAY);
            Ok((vec![(top, bottom)], below))
        }
    }
}

/// The tick label of the magnitude axis.
fn mag_tick(scale: MagScale) -> fn(&f64) -> String {
    match scale {
        MagScale::Log => log_label,
        MagScale::Db => |v| fmt_tick(*v),
    }
}

/// No label.
fn blank(_: &f64) -> String {
    String::new()
}

/// Builds the magnitude chart of `panel` in `area` (the caption drawn with it).
pub fn mag_chart<'a, 'b, Y>(
    fig: &BodeFigure,
    panel: &Panel,
    area: &'a Area<'b>,
    x: LogAxis,
    y: Y,
) -> Result<Chart<'a, 'b, Y>>
where
    Y: Ranged<ValueType = f64> + Fraction,
{
    let mut builder = ChartBuilder::on(area);
    match fig.layout {
        Layout::Grid { rows, cols } => {
            let (xl, yl) = if single(rows, cols) {
                (44, 78)
            } else {
                (34, 60)
            };
            builder
                .margin(10)
                .x_label_area_size(xl)
                .y_label_area_size(yl);
            if let Some(c) = &panel.caption {
                builder.caption(c, (FONT, AXIS));
            }
        }
        Layout::Overlay => {
            builder
                .margin_left(14)
                .margin_right(24)
                .margin_top(4)
                .x_label_area_size(6)
                .y_label_area_size(Y_LABEL_AREA);
        }
    }
    builder.build_cartesian_2d(x, y).map_err(plot_err)
}

/// Builds the phase chart in `area`.
pub fn phase_chart<'a, 'b>(
    fig: &BodeFigure,
    area: &'a Area<'b>,
    x: LogAxis,
    y: PhaseAxis,
) -> Result<Chart<'a, 'b, PhaseAxis>> {
    let mut builder = ChartBuilder::on(area);
    match fig.layout {
        Layout::Grid { rows, cols } => {
            let one = single(rows, cols);
            builder
                .margin(10)
                .x_label_area_size(if one { 52 } else { 40 })
                .y_label_area_size(if one { 78 } else { 60 });
        }
        Layout::Overlay => {
            builder
                .margin_left(14)
                .margin_right(24)
                .margin_top(10)
                .x_label_area_size(X_AREA_OVERLAY)
                .y_label_area_size(Y_LABEL_AREA);
        }
    }
    builder.build_cartesian_2d(x, y).map_err(plot_err)
}

/// The frequencies labelled under the phase chart and drawn as grid lines (the overlay's,
/// fitted to the magnitude chart's width); none in a grid (its meshes label themselves).
pub fn x_ticks<Y>(fig: &BodeFigure, mag: &Chart<'_, '_, Y>) -> Vec<f64>
where
    Y: Ranged<ValueType = f64>,
{
    match fig.layout {
        Layout::Grid { .. } => Vec::new(),
        Layout::Overlay => {
            let r = mag.x_range();
            let (f0, f1) = (r.start, r.end);
            let w = mag.plotting_area().get_pixel_range().0;
            log_axis_ticks(f0, f1, (w.end - w.start) as f64, TICKS)
        }
    }
}

/// Draws the magnitude chart's mesh (and the overlay's grid lines at `ticks`).
pub fn mag_frame<Y>(
    fig: &BodeFigure,
    panel: &Panel,
    mag: &mut Chart<'_, '_, Y>,
    ticks: &[f64],
) -> Result<()>
where
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let label = mag_tick(fig.scale);
    match fig.layout {
        Layout::Grid { rows, cols } => {
            let one = single(rows, cols);
            mag.configure_mesh()
                .y_desc(&panel.mag_label)
                .axis_desc_style((FONT, if one { AXIS } else { TICKS }))
                .label_style((FONT, if one { TICKS } else { TICKS - 2 }))
                .x_label_formatter(&log_label)
                .y_label_formatter(&label)
                .light_line_style(RGBColor(235, 235, 235))
                .max_light_lines(9)
                .x_labels(if one { 12 } else { 6 })
                .y_labels(if one { 10 } else { 6 })
                .draw()
                .map_err(plot_err)
        }
        Layout::Overlay => {
            mag.configure_mesh()
                .disable_x_mesh()
                .x_labels(0)
                .x_label_formatter(&blank)
                .y_labels(8)
                .y_label_formatter(&label)
                .max_light_lines(1)
                .y_desc(&panel.mag_label)
                .axis_desc_style((FONT, 17))
                .label_style((FONT, TICKS))
                .light_line_style(RGBColor(240, 240, 240))
                .bold_line_style(GRID)
                .draw()
                .map_err(plot_err)?;
            let (y0, y1) = (mag.y_range().start, mag.y_range().end);
            for t in ticks {
                mag.draw_series(LineSeries::new(vec![(*t, y0), (*t, y1)], GRID))
                    .map_err(plot_err)?;
            }
            Ok(())
        }
    }
}

/// The overlay's grid lines at the labelled frequencies.
const GRID: RGBColor = RGBColor(225, 225, 225);

/// Draws the phase chart's mesh (and the overlay's grid lines at `ticks`); the phase is
/// labelled at multiples of 90°.
pub fn phase_frame(
    fig: &BodeFigure,
    panel: &Panel,
    ph: &mut Chart<'_, '_, PhaseAxis>,
    ticks: &[f64],
) -> Result<()> {
    match fig.layout {
        Layout::Grid { rows, cols } => {
            let one = single(rows, cols);
            ph.configure_mesh()
                .x_desc(&fig.freq.label)
                .y_desc(&panel.phase_label)
                .axis_desc_style((FONT, if one { AXIS } else { TICKS }))
                .label_style((FONT, if one { TICKS } else { TICKS - 2 }))
                .x_label_formatter(&log_label)
                .y_label_formatter(&phase_tick)
                .light_line_style(RGBColor(235, 235, 235))
                .max_light_lines(9)
                .x_labels(if one { 12 } else { 6 })
                .draw()
                .map_err(plot_err)
        }
        Layout::Overlay => {
            // The phase grid lines are the mesh's own, at the labelled multiples of 90°.
            ph.configure_mesh()
                .disable_x_mesh()
                .x_labels(0)
                .x_label_formatter(&blank)
                .y_label_formatter(&phase_tick)
                .max_light_lines(0)
                .y_desc(&panel.phase_label)
                .axis_desc_style((FONT, 17))
                .label_style((FONT, TICKS))
                .bold_line_style(RGBColor(200, 200, 200))
                .draw()
                .map_err(plot_err)?;
            let (p0, p1) = ph.as_coord_spec().y_spec().ends();
            for t in ticks {
                ph.draw_series(LineSeries::new(vec![(*t, p0), (*t, p1)], GRID))
                    .map_err(plot_err)?;
            }
            Ok(())
        }
    }
}

/// After the phase chart: the overlay's frequency labels at `ticks` (a second row where
/// two would touch) and the axis label under them, on `root`.
pub fn finish(
    fig: &BodeFigure,
    root: &Area<'_>,
    ph: &Chart<'_, '_, PhaseAxis>,
    ticks: &[f64],
) -> Result<()> {
    if let Layout::Grid { .. } = fig.layout {
        return Ok(());
    }
    let (f0, p0) = (ph.x_range().start, ph.as_coord_spec().y_spec().ends().0);
    let labels: Vec<(i32, String)> = ticks
        .iter()
        .map(|t| (ph.backend_coord(&(*t, p0)).0, fmt_tick(*t)))
        .collect();
    let (_, y_axis) = ph.backend_coord(&(f0, p0));
    draw_x_labels(root, &labels, y_axis, TICKS)?;
    let w = ph.plotting_area().get_pixel_range().0;
    root.draw(&Text::new(
        fig.freq.label.as_str(),
        ((w.start + w.end) / 2, y_axis + 30),
        TextStyle::from((FONT, 16).into_font()).pos(Pos::new(HPos::Center, VPos::Top)),
    ))
    .map_err(plot_err)
}

//! The log-log chart of `r_vs_delta`, `mu`, `batch` and `stability`: caption, axes and mesh,
//! the plot being drawn (chart, legend, sub-pixel curves) and the looks of its weight and
//! limit curves.

use super::legend::{size_with_legend, Legend};
use super::text::fit_title;
use super::{plot_err, AXIS, CAPTION, C_BLUE, C_ORANGE, C_PURPLE, FONT, SIZE, TICKS, Y_LABEL_AREA};
use crate::error::Result;
use crate::plot::axis::LogAxis;
use crate::plot::fine::{Look, Overlay, PixelMap};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;

/// A chart with logarithmic axes on both sides (rshape's guarded [`LogAxis`]).
pub type LogLogChart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogAxis, LogAxis>>;

/// Width available to a caption on the standard canvas.
pub const TITLE_WIDTH: f64 = SIZE.0 as f64 - 28.0;

/// A log-frequency × log-magnitude chart on `root` with the caption, margins and mesh that
/// `r_vs_delta.svg` and `mu.svg` share.
pub fn loglog_chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    title: &str,
    (xlo, xhi): (f64, f64),
    (ylo, yhi): (f64, f64),
    y_desc: &str,
) -> Result<LogLogChart<'a, 'b>> {
    let mut chart = ChartBuilder::on(root)
        .caption(fit_title(title, TITLE_WIDTH, CAPTION), (FONT, CAPTION))
        .margin(14)
        .x_label_area_size(52)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(LogAxis::new(xlo, xhi), LogAxis::new(ylo, yhi))
        .map_err(plot_err)?;
    loglog_mesh(&mut chart, y_desc)?;
    Ok(chart)
}

/// A log-log plot being drawn: the chart to put the series on, the overlay of its curves and
/// the legend that collects their entries (drawn below the plot when the figure is finished).
pub struct LogLogPlot<'a, 'b> {
    /// The chart (caption, axes and mesh of [`loglog_chart`]).
    pub chart: LogLogChart<'a, 'b>,
    /// The legend strip below the plot.
    pub legend: Legend<'a, SVGBackend<'b>>,
    /// The sub-pixel curves.
    pub overlay: Overlay,
    // The chart borrows the drawing area of a backend that lives longer ('b: 'a).
    _area: std::marker::PhantomData<&'a SVGBackend<'b>>,
}

impl LogLogPlot<'_, '_> {
    /// Draws a curve through `points` in `look` (sub-pixel, clamped into the y axis).
    pub fn line<I: IntoIterator<Item = (f64, f64)>>(&self, points: I, look: Look) {
        let map = PixelMap::of(&self.chart);
        self.overlay.curve(&map, points, look);
    }

    /// Draws a curve and adds its legend entry with the same look.
    pub fn line_with_legend<I: IntoIterator<Item = (f64, f64)>>(
        &mut self,
        points: I,
        look: Look,
        label: impl Into<String>,
    ) {
        self.line(points, look);
        self.legend.add_line(label, look, &self.overlay);
    }

    /// The x axis (guarded range).
    pub fn x_axis(&self) -> &LogAxis {
        self.chart.as_coord_spec().x_spec()
    }

    /// The y axis (guarded range).
    pub fn y_axis(&self) -> &LogAxis {
        self.chart.as_coord_spec().y_spec()
    }
}

/// A log-log figure with its legend strip below, as an SVG document: the caption, axes and
/// mesh of [`loglog_chart`] over `x` × `y`, then `draw` puts the series on the chart and their
/// entries in the legend (of `legend_rows` entries, which sets the figure's height).
pub fn loglog_figure<F>(
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
    y_desc: &str,
    legend_rows: usize,
    draw: F,
) -> Result<String>
where
    F: for<'a, 'b> FnOnce(&mut LogLogPlot<'a, 'b>) -> Result<()>,
{
    let mut svg = String::new();
    let overlay = Overlay::default();
    {
        let root =
            SVGBackend::with_string(&mut svg, size_with_legend(legend_rows)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (plot, below) = root.split_vertically(SIZE.1);
        let mut p = LogLogPlot {
            chart: loglog_chart(&plot, title, x, y, y_desc)?,
            legend: Legend::default(),
            overlay: overlay.clone(),
            _area: std::marker::PhantomData,
        };
        draw(&mut p)?;
        p.legend.draw(&below)?;
        root.present().map_err(plot_err)?;
    }
    overlay.inject(&mut svg);
    Ok(svg)
}

/// Which weight a curve shows: the configured one (solid blue) or the fitted one (dashed
/// orange), the same in every figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeightCurve {
    /// The configured `r` (or `V`).
    Configured,
    /// The fitted `r` (or `V`).
    Fitted,
}

impl WeightCurve {
    /// The look of the curve: solid blue, or dashed orange.
    pub const fn look(self) -> Look {
        match self {
            WeightCurve::Configured => Look::solid(C_BLUE, 3.0),
            WeightCurve::Fitted => Look::dashed(C_ORANGE, 3.0, 12.0, 5.0),
        }
    }
}

/// The look of a limit curve (A1, Theorem 1): dashed purple.
pub const LIMIT: Look = Look::dashed(C_PURPLE, 2.5, 8.0, 5.0);

impl LogLogPlot<'_, '_> {
    /// Draws `|w(jω)|` at `points` in the look of `kind` and adds its legend entry `label`.
    pub fn weight(
        &mut self,
        points: Vec<(f64, f64)>,
        kind: WeightCurve,
        label: String,
    ) -> Result<()> {
        self.line_with_legend(points, kind.look(), label);
        Ok(())
    }
}

/// The mesh shared by the log-log figures: frequency in rad/s on x, `y_desc` on y, ticks at
/// 1-2-5, light grid lines.
pub fn loglog_mesh<X, Y>(
    chart: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<X, Y>>,
    y_desc: &str,
) -> Result<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc("frequency ω (rad/s)")
        .y_desc(y_desc)
        .axis_desc_style((FONT, AXIS))
        .label_style((FONT, TICKS))
        .x_label_formatter(&crate::plot::axis::log_label)
        .y_label_formatter(&crate::plot::axis::log_label)
        .light_line_style(RGBColor(235, 235, 235))
        .max_light_lines(9)
        .x_labels(12)
        .y_labels(10)
        .draw()
        .map_err(plot_err)?;
    Ok(())
}

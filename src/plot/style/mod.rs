//! Shared look of the figures: size, fonts, palette, axis ranges; in its parts the legend
//! strip ([`legend`]), titles and labels as text ([`text`]), frequency tick labels
//! ([`ticks`]) and the log-log chart of `r_vs_delta`, `mu`, `batch` and `stability`
//! ([`loglog`]).

pub(crate) mod legend;
pub(crate) mod loglog;
pub(crate) mod text;
pub(crate) mod ticks;

pub use legend::{legend_height, Legend};
pub use loglog::{loglog_figure, LogLogPlot, WeightCurve, LIMIT};
pub use text::{fit_title, tf_label};
pub use ticks::{draw_x_labels, fmt_tick, log_axis_ticks};

use crate::error::Error;
use plotters::style::RGBColor;

/// Width and height of every figure in pixels.
pub const SIZE: (u32, u32) = (960, 620);
/// Font family (generic, so any SVG viewer picks a font it has).
pub const FONT: &str = "sans-serif";
/// Caption font size.
pub const CAPTION: u32 = 22;
/// Axis-label font size.
pub const AXIS: u32 = 17;
/// Tick-label font size.
pub const TICKS: u32 = 14;
/// Legend font size.
pub const LEGEND: u32 = 14;

/// Blue: the configured `r`.
pub const C_BLUE: RGBColor = RGBColor(31, 119, 180);
/// Orange: the fitted `r`.
pub const C_ORANGE: RGBColor = RGBColor(230, 120, 20);
/// Green: consistent data.
pub const C_GREEN: RGBColor = RGBColor(44, 160, 44);
/// Red: failing data.
pub const C_RED: RGBColor = RGBColor(214, 39, 40);
/// Purple: the A1 limit.
pub const C_PURPLE: RGBColor = RGBColor(148, 103, 189);
/// Grey: reference lines.
pub const C_GREY: RGBColor = RGBColor(90, 90, 90);

/// A qualitative palette for channels.
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(230, 120, 20),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// Maps a plotters error into the library error.
pub fn plot_err<E: std::fmt::Debug>(e: E) -> Error {
    Error::Invalid(format!("drawing a figure: {e:?}"))
}

/// A log-axis range covering the positive finite values, padded by a factor (at least one
/// decade in total), finite and at most [`super::axis::MAX_DECADES`] wide (the guard of
/// [`super::axis::log_bounds`]); `None` when there is no positive finite value.
pub fn log_range<'a, I: IntoIterator<Item = &'a f64>>(values: I, pad: f64) -> Option<(f64, f64)> {
    super::axis::log_data_range(values, pad)
}

/// The frequency axis: the data range extended by a quarter decade on each side.
pub fn omega_range(omega: &[f64]) -> (f64, f64) {
    log_range(omega, 10f64.powf(0.25)).unwrap_or((0.1, 10.0))
}

/// Clamps `v` into `[lo, hi]` (for drawing values that sit outside the axis).
pub fn clamp(v: f64, lo: f64, hi: f64) -> f64 {
    v.max(lo).min(hi)
}

/// Width of the y tick labels and axis description left of a plot.
pub const Y_LABEL_AREA: u32 = 78;

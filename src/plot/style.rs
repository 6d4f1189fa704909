//! Shared look of the figures: size, fonts, palette, legend placement, axis ranges.

use super::axis::LogAxis;
use super::fine::{Look, Overlay, PixelMap};
use crate::error::{Error, Result};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::RGBColor;

/// A pixel position (plotters' backend coordinate).
type BackendCoord = (i32, i32);

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

/// Shortens `title` to fit `width` pixels in font `font`: the part after the last ` — `
/// (the configuration's name) loses whole words from its middle, replaced by `…`; then,
/// if still too wide, the title is cut at a word boundary.
pub fn fit_title(title: &str, width: f64, font: u32) -> String {
    // The SVG backend writes the size as font/1.24 px; 0.55 em a character is wider than the
    // digits and lower-case letters of common sans fonts.
    let fits = |t: &str| t.chars().count() as f64 * 0.55 * font as f64 / 1.24 <= width;
    if fits(title) {
        return title.to_string();
    }
    let (head, name) = match title.rsplit_once(" — ") {
        Some((h, n)) => (format!("{h} — "), n.to_string()),
        None => (String::new(), title.to_string()),
    };
    let words: Vec<&str> = name.split(' ').collect();
    // Drop words from the middle of the name, keeping its first and last words.
    for drop in 1..words.len().saturating_sub(1) {
        let keep = words.len() - drop;
        let front = keep.div_ceil(2);
        let back = keep - front;
        let t = format!(
            "{head}{} … {}",
            words[..front].join(" "),
            words[words.len() - back..].join(" ")
        );
        if back > 0 && fits(&t) {
            return t;
        }
    }
    // Cut at a word boundary.
    let mut out = String::new();
    for w in title.split(' ') {
        let next = if out.is_empty() {
            w.to_string()
        } else {
            format!("{out} {w}")
        };
        if !fits(&format!("{next} …")) {
            break;
        }
        out = next;
    }
    if out.is_empty() {
        title
            .chars()
            .take((width / (0.5 * font as f64)) as usize)
            .collect()
    } else {
        format!("{out} …")
    }
}

/// Clamps `v` into `[lo, hi]` (for drawing values that sit outside the axis).
pub fn clamp(v: f64, lo: f64, hi: f64) -> f64 {
    v.max(lo).min(hi)
}

/// The standard legend box: white, framed, in the given corner.
pub fn legend<'a, 'b, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &'b mut ChartContext<'a, DB, CT>,
    pos: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(pos)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((FONT, LEGEND))
        .margin(8)
        .draw()
        .map_err(plot_err)
}

/// Height in pixels of a legend of `rows` entries drawn below the plot (see [`Legend`]):
/// the figure grows by this much instead of the axes giving up decades to the legend.
pub fn legend_height(rows: usize) -> u32 {
    rows as u32 * 20 + 24
}

/// The size of a figure with a legend of `rows` entries below the plot.
pub fn size_with_legend(rows: usize) -> (u32, u32) {
    (SIZE.0, SIZE.1 + legend_height(rows))
}

/// The chart of the legend strip.
type LegendChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// One entry: registers its label and sample on the legend chart.
type Entry<'a, DB> = Box<dyn FnOnce(&mut LegendChart<'a, DB>) -> Result<()> + 'a>;

/// A legend collected while the series are drawn, then drawn in its own strip below the
/// plot, where it hides no data and costs no axis range.
pub struct Legend<'a, DB: DrawingBackend> {
    entries: Vec<Entry<'a, DB>>,
    // Pixel origin of the legend's area in the document: plotters hands the samples
    // coordinates relative to it, the overlay needs absolute ones.
    origin: std::rc::Rc<std::cell::Cell<(i32, i32)>>,
}

impl<'a, DB: DrawingBackend + 'a> Default for Legend<'a, DB> {
    fn default() -> Self {
        Self {
            entries: Vec::new(),
            origin: Default::default(),
        }
    }
}

impl<'a, DB: DrawingBackend + 'a> Legend<'a, DB> {
    /// Adds an entry: its label and the function drawing its sample at a pixel position.
    pub fn add<E, F>(&mut self, label: impl Into<String>, mark: F)
    where
        E: Drawable<DB> + 'a,
        for<'b> &'b E: PointCollection<'b, BackendCoord>,
        F: Fn(BackendCoord) -> E + 'a,
    {
        let label = label.into();
        self.entries
            .push(Box::new(move |chart: &mut LegendChart<'a, DB>| {
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                    .map_err(plot_err)?
                    .label(label)
                    .legend(mark);
                Ok(())
            }));
    }

    /// Adds an entry whose sample is a line in `look`, drawn (dashes and all) by `overlay`
    /// exactly as the curve it stands for.
    pub fn add_line(&mut self, label: impl Into<String>, look: Look, overlay: &Overlay) {
        let overlay = overlay.clone();
        let origin = self.origin.clone();
        self.add(label, move |(x, y)| {
            let (ox, oy) = origin.get();
            let (ax, ay) = ((x + ox) as f64, (y + oy) as f64);
            overlay.pixels(&[(ax, ay), (ax + 24.0, ay)], look, "legend");
            EmptyElement::at((x, y))
        });
    }

    /// Draws the legend in `area` (the strip below the plot), aligned with the plot's left
    /// edge.
    pub fn draw(self, area: &'a DrawingArea<DB, plotters::coord::Shift>) -> Result<()> {
        if self.entries.is_empty() {
            return Ok(());
        }
        let mut chart = ChartBuilder::on(area)
            .margin_left(14 + Y_LABEL_AREA)
            .margin_right(14)
            .build_cartesian_2d(0f64..1f64, 0f64..1f64)
            .map_err(plot_err)?;
        self.origin.set(chart.plotting_area().get_base_pixel());
        for entry in self.entries {
            entry(&mut chart)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// Width of the y tick labels and axis description left of a plot.
pub const Y_LABEL_AREA: u32 = 78;

/// A short human form of a transfer function, e.g. `(1e-8 s + 0.3)/(s + 1)`, or
/// `order-n unit` when that would be too long for a legend.
pub fn tf_label(tf: &crate::system::TransferFunction) -> String {
    fn poly(c: &[f64]) -> String {
        let n = c.len();
        let terms: Vec<String> = c
            .iter()
            .enumerate()
            .filter(|(_, x)| **x != 0.0)
            .map(|(k, x)| {
                let p = n - 1 - k;
                let coef = if p > 0 && *x == 1.0 {
                    String::new()
                } else {
                    crate::report::fmt::fmt_g(*x)
                };
                match p {
                    0 => crate::report::fmt::fmt_g(*x),
                    1 => format!("{coef} s"),
                    _ => format!("{coef} s^{p}"),
                }
                .trim()
                .to_string()
            })
            .collect();
        if terms.is_empty() {
            "0".into()
        } else {
            terms.join(" + ").replace("+ -", "− ")
        }
    }
    let (num, den) = (poly(tf.num.coeffs()), poly(tf.den.coeffs()));
    let full = if den == "1" {
        num
    } else {
        format!("({num})/({den})")
    };
    if full.chars().count() > 48 {
        format!("order-{} unit", tf.den.degree())
    } else {
        full
    }
}

/// Estimated width in pixels of `text` in the sans-serif font of size `font`: the SVG backend
/// writes the size as `font/1.24` px, and 0.62 em per character of that is wider than the
/// digits and lower-case letters of common sans fonts.
pub fn text_width(text: &str, font: u32) -> f64 {
    text.chars().count() as f64 * 0.5 * font as f64
}

/// A tick label of an axis whose ticks were chosen by [`log_axis_ticks`]: the shortest
/// plain form from 0.01 to 99999 (`800`, `1200`, `2.5`), else `2e5`.
pub fn fmt_tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    // Six significant digits remove the last bits of the tick arithmetic.
    let v: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    if (0.01..1e5).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Tick values for a log axis over `[lo, hi]` drawn `width` pixels wide with labels of
/// `font` pixels: the densest of the usual sets (mantissas 1; 1-2-5; 1-2-3-5; 1…9; then
/// linear steps 1-2-2.5-5 × 10ᵏ for narrow ranges) whose labels, centred on their ticks,
/// keep at least 8 px apart, with at most 8 ticks (on ties the earlier set).  Labels never overlap
/// (`800.900.01000.0` was the plotters default on a narrow band).
pub fn log_axis_ticks(lo: f64, hi: f64, width: f64, font: u32) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo && lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    let px = |v: f64| (v / lo).ln() / (hi / lo).ln() * width;
    let fits = |t: &[f64]| {
        t.windows(2).all(|w| {
            let gap = px(w[1]) - px(w[0]);
            gap >= (text_width(&fmt_tick(w[0]), font) + text_width(&fmt_tick(w[1]), font)) / 2.0
                + 8.0
        })
    };
    let mut sets: Vec<Vec<f64>> = Vec::new();
    let mantissas: [&[f64]; 4] = [
        &[1.0],
        &[1.0, 2.0, 5.0],
        &[1.0, 2.0, 3.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ];
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    for m in mantissas {
        let mut t = Vec::new();
        for d in d0..=d1 {
            for &k in m {
                let v = k * 10f64.powi(d);
                if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                    t.push(v);
                }
            }
        }
        sets.push(t);
    }
    let top = 10f64.powf((hi - lo).log10().floor());
    for e in [1.0, 0.1, 0.01] {
        for m in [5.0, 2.5, 2.0, 1.0] {
            let step = m * top * e;
            let mut t = Vec::new();
            let mut k = (lo / step).ceil();
            while k * step <= hi * (1.0 + 1e-9) && t.len() < 40 {
                if k > 0.0 {
                    t.push(k * step);
                }
                k += 1.0;
            }
            sets.push(t);
        }
    }
    // The first (most log-like) of the densest sets that fit, with at most 8 ticks: more
    // makes a log axis look linear at its top end.
    let mut best: Vec<f64> = Vec::new();
    for t in sets {
        if t.len() <= 8 && t.len() > best.len() && fits(&t) {
            best = t;
        }
    }
    best
}

/// Draws `labels` centred at pixel abscissas `x` below the pixel row `y` on `area`; labels
/// that would touch their neighbour go to a second row, so none overlaps another.
pub fn draw_x_labels<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    labels: &[(i32, String)],
    y: i32,
    font: u32,
) -> Result<()> {
    let mut right_end = [f64::NEG_INFINITY; 2];
    for (x, text) in labels {
        let w = text_width(text, font);
        let left = *x as f64 - w / 2.0;
        let row = if left >= right_end[0] + 8.0 { 0 } else { 1 };
        right_end[row] = *x as f64 + w / 2.0;
        let style =
            TextStyle::from((FONT, font).into_font()).pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Top,
            ));
        let dy = 6 + row as i32 * (font as i32 + 6);
        area.draw(&Text::new(text.clone(), (*x, y + dy), style))
            .map_err(plot_err)?;
    }
    Ok(())
}

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
        .x_label_formatter(&super::axis::log_label)
        .y_label_formatter(&super::axis::log_label)
        .light_line_style(RGBColor(235, 235, 235))
        .max_light_lines(9)
        .x_labels(12)
        .y_labels(10)
        .draw()
        .map_err(plot_err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{fmt_tick, log_axis_ticks, text_width};

    /// The chosen ticks never crowd: on narrow and wide bands, neighbouring labels keep
    /// 8 px apart (the old figures printed `800.900.01000.0`).
    #[test]
    fn axis_ticks_do_not_collide() {
        for (lo, hi) in [
            (700.0, 1300.0),
            (10.0, 260.0),
            (18.0, 5500.0),
            (0.5, 2e5),
            (95.0, 105.0),
        ] {
            let width = 780.0;
            let t = log_axis_ticks(lo, hi, width, 14);
            assert!(t.len() >= 2, "{lo}-{hi}: {t:?}");
            let px = |v: f64| (v / lo).ln() / (hi / lo).ln() * width;
            for w in t.windows(2) {
                let need =
                    (text_width(&fmt_tick(w[0]), 14) + text_width(&fmt_tick(w[1]), 14)) / 2.0;
                assert!(px(w[1]) - px(w[0]) > need, "{lo}-{hi}: {t:?}");
            }
        }
        assert_eq!(fmt_tick(800.0), "800");
        assert_eq!(fmt_tick(1200.0000000001), "1200");
        assert_eq!(fmt_tick(2.5), "2.5");
    }
}

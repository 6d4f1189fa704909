//! The legend strip below a plot: entries collected while the series are drawn, then drawn
//! where they hide no data and cost no axis range.

use super::{plot_err, FONT, LEGEND, SIZE, Y_LABEL_AREA};
use crate::error::Result;
use crate::plot::fine::{Look, Overlay};
use plotters::coord::types::RangedCoordf64;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;

/// A pixel position (plotters' backend coordinate).
type BackendCoord = (i32, i32);

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

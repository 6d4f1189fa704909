//! Curves at sub-pixel precision, with real dash patterns.
//!
//! plotters hands the SVG backend whole pixels, so a slowly varying curve became a
//! staircase (one-pixel steps on flat stretches), and its dashed lines are one polyline per
//! dash, which a legend swatch cannot copy.  The figures therefore draw their curves into an
//! [`Overlay`]: `<polyline>` elements with coordinates to 1/100 px and an SVG
//! `stroke-dasharray`, mapped through the axis [`Fraction`]s, added to the document after
//! plotters has written it (on top of the markers, so no marker hides a curve).  Legend
//! swatches of curves are drawn the same way with the same look, so a dashed curve has a
//! dashed swatch (class `legend`; curves have class `curve`).

use super::axis::Fraction;
use plotters::coord::ranged1d::Ranged;
use plotters::prelude::*;
use std::cell::RefCell;
use std::fmt::Write;
use std::rc::Rc;

/// How a curve looks: colour, opacity, width (px) and dash pattern (dash, gap in px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    /// Stroke colour.
    pub color: RGBColor,
    /// Stroke opacity.
    pub opacity: f64,
    /// Stroke width in pixels.
    pub width: f64,
    /// Dash and gap lengths in pixels; `None` for a solid line.
    pub dash: Option<(f64, f64)>,
}

impl Look {
    /// A solid line.
    pub const fn solid(color: RGBColor, width: f64) -> Self {
        Self {
            color,
            opacity: 1.0,
            width,
            dash: None,
        }
    }

    /// A dashed line.
    pub const fn dashed(color: RGBColor, width: f64, dash: f64, gap: f64) -> Self {
        Self {
            color,
            opacity: 1.0,
            width,
            dash: Some((dash, gap)),
        }
    }

    /// The same look at opacity `a`.
    pub const fn alpha(mut self, a: f64) -> Self {
        self.opacity = a;
        self
    }

    fn attributes(&self) -> String {
        let RGBColor(r, g, b) = self.color;
        let mut s = format!(
            "fill=\"none\" stroke=\"#{r:02X}{g:02X}{b:02X}\" stroke-width=\"{}\" stroke-linejoin=\"round\"",
            self.width
        );
        if self.opacity < 1.0 {
            let _ = write!(s, " stroke-opacity=\"{}\"", self.opacity);
        }
        if let Some((d, g)) = self.dash {
            let _ = write!(s, " stroke-dasharray=\"{d} {g}\"");
        }
        s
    }
}

/// Maps data to pixels with sub-pixel precision: the chart's pixel ends and its axes'
/// fractions.
pub struct PixelMap<'c> {
    x: (f64, f64),
    y: (f64, f64),
    fx: &'c dyn Fraction,
    fy: &'c dyn Fraction,
}

impl<'c> PixelMap<'c> {
    /// The map of a chart whose axes are rshape's ([`super::axis`]).
    pub fn of<DB, X, Y>(chart: &'c ChartContext<'_, DB, Cartesian2d<X, Y>>) -> Self
    where
        DB: DrawingBackend,
        X: Ranged<ValueType = f64> + Fraction,
        Y: Ranged<ValueType = f64> + Fraction,
    {
        let (xr, yr) = (chart.x_range(), chart.y_range());
        let a = chart.backend_coord(&(xr.start, yr.start));
        let b = chart.backend_coord(&(xr.end, yr.end));
        let spec = chart.as_coord_spec();
        Self {
            x: (a.0 as f64, b.0 as f64),
            y: (a.1 as f64, b.1 as f64),
            fx: spec.x_spec(),
            fy: spec.y_spec(),
        }
    }

    /// The pixel position of `(x, y)`; `y` is held inside the plot, `None` when `x` is
    /// off the axis or a value is not finite.
    pub fn pixel(&self, (x, y): (f64, f64)) -> Option<(f64, f64)> {
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        let tx = self.fx.fraction(x);
        if !(-1e-9..=1.0 + 1e-9).contains(&tx) {
            return None;
        }
        let ty = self.fy.fraction(y).clamp(0.0, 1.0);
        Some((
            self.x.0 + tx * (self.x.1 - self.x.0),
            self.y.0 + ty * (self.y.1 - self.y.0),
        ))
    }
}

/// The sub-pixel curves of a figure, added to its SVG document at the end.
#[derive(Clone, Default)]
pub struct Overlay(Rc<RefCell<String>>);

impl Overlay {
    /// Draws the curve through `points` (broken where a point is not finite or off the x
    /// axis) in `look`.
    pub fn curve<I: IntoIterator<Item = (f64, f64)>>(&self, map: &PixelMap, points: I, look: Look) {
        let mut run: Vec<(f64, f64)> = Vec::new();
        for p in points {
            match map.pixel(p) {
                Some(q) => run.push(q),
                None => self.flush(&mut run, look, "curve"),
            }
        }
        self.flush(&mut run, look, "curve");
    }

    /// Draws a polyline in pixel coordinates (e.g. a legend swatch, class `legend`).
    pub fn pixels(&self, pts: &[(f64, f64)], look: Look, class: &str) {
        let mut run = pts.to_vec();
        self.flush(&mut run, look, class);
    }

    fn flush(&self, run: &mut Vec<(f64, f64)>, look: Look, class: &str) {
        if run.len() > 1 {
            let mut s = self.0.borrow_mut();
            let _ = write!(
                s,
                "<polyline class=\"{class}\" {} points=\"",
                look.attributes()
            );
            for (k, (x, y)) in run.iter().enumerate() {
                let sep = if k == 0 { "" } else { " " };
                let _ = write!(s, "{sep}{x:.2},{y:.2}");
            }
            s.push_str("\"/>\n");
        }
        run.clear();
    }

    /// Adds the curves to `svg` (before its closing tag).
    pub fn inject(&self, svg: &mut String) {
        let extra = self.0.borrow();
        if extra.is_empty() {
            return;
        }
        match svg.rfind("</svg>") {
            Some(k) => svg.insert_str(k, &extra),
            None => svg.push_str(&extra),
        }
    }
}

//! One panel of a Bode figure: its magnitude chart, then its phase chart, each framed by the
//! [`super::layout`] and then marked with the data (their noise disks as [`Spread`], then the
//! dots) and the model curves (sub-pixel lines through the [`Overlay`]).  The magnitude goes
//! through the figure's [`MagScale`].

use super::layout::{self, Area, Chart};
use super::{phase, BodeFigure, DataSeries, MagScale, Panel, Prepared, Spread};
use crate::error::Result;
use crate::plot::axis::{Fraction, PhaseAxis};
use crate::plot::fine::{Overlay, PixelMap};
use crate::plot::style::{clamp, log_range as padded_log_range, plot_err};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;

/// `20 log₁₀ a` (dB), `a` floored at 1e-300.
fn db(a: f64) -> f64 {
    20.0 * a.max(1e-300).log10()
}

impl MagScale {
    /// The ordinate of a datum's dot of magnitude `a` (before clamping into the axis), or
    /// `None` when it has no place on the axis.
    fn dot(self, a: f64) -> Option<f64> {
        match self {
            MagScale::Log => (a > 0.0 && a.is_finite()).then_some(a),
            // An unknown magnitude has no place; 0 sits at the floor (−6000 dB), clamped.
            MagScale::Db => (!a.is_nan()).then(|| db(a)),
        }
    }

    /// The ordinate of a model point of magnitude `a` on the axis `(lo, hi)`; NaN breaks the
    /// line.
    fn curve(self, a: f64, (lo, hi): (f64, f64)) -> f64 {
        match self {
            MagScale::Log if a > 0.0 => clamp(a, lo, hi),
            MagScale::Log => f64::NAN,
            // `NaN.max(1e-300)` is 1e-300: without this arm an unknown model value would
            // draw the curve down to the axis' bottom instead of breaking it.
            MagScale::Db if a.is_nan() => f64::NAN,
            MagScale::Db => db(a),
        }
    }

    /// The ordinates `(low, high)` of the noise disk of radius `r` around a datum of
    /// magnitude `a`: `|a − r|` to `a + r`, down to the axis' bottom when the disk holds 0.
    fn spread(self, a: f64, r: f64, (lo, hi): (f64, f64)) -> (f64, f64) {
        match self {
            MagScale::Log => (clamp((a - r).max(lo), lo, hi), clamp(a + r, lo, hi)),
            MagScale::Db => {
                let low = if r < a {
                    (20.0 * (a - r).log10()).max(lo)
                } else {
                    lo
                };
                (low, 20.0 * (a + r).log10())
            }
        }
    }
}

/// The log magnitude range of a panel: the data with their noise disks and every model
/// point, padded by a factor 2, at most ten decades below the top (`(1e-3, 1e3)` without a
/// positive value).
pub fn log_range(p: &Panel) -> (f64, f64) {
    let radius = |k: usize| p.data.radius.map_or(0.0, |r| r[k]);
    let mags: Vec<f64> = (p.data.g.iter().enumerate())
        .map(|(k, z)| z.norm() + radius(k))
        .chain(p.models.iter().flat_map(|m| m.g.iter().map(|z| z.norm())))
        .collect();
    let (lo, hi) = padded_log_range(&mags, 2.0).unwrap_or((1e-3, 1e3));
    (lo.max(hi * 1e-10), hi)
}

/// The dB range of a panel: the data and the model points in the band, padded by 6 % (at
/// least 1 dB), guarded.
pub fn db_range(fig: &BodeFigure, p: &Panel) -> (f64, f64) {
    let model = p.models.iter().flat_map(|m| {
        m.omega
            .iter()
            .zip(&m.g)
            .filter(|(w, _)| fig.freq.in_band(fig.freq.x(**w)))
            .map(|(_, z)| db(z.norm()))
    });
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in p
        .data
        .g
        .iter()
        .map(|z| db(z.norm()))
        .chain(model)
        .filter(|x| x.is_finite())
    {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return crate::plot::axis::lin_bounds(0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.06).max(1.0);
    crate::plot::axis::lin_bounds(lo - pad, hi + pad)
}

/// The style of datum `k`'s dot.
fn dot_style(d: &DataSeries, k: usize) -> ShapeStyle {
    match d.flagged {
        Some((flags, style)) if flags.get(k) == Some(&true) => style,
        _ => d.dot,
    }
}

/// Draws the data's marks on a chart: for datum `k`, its ordinate `y(k)` (`None`: no dot)
/// and the span `bar(k)` of its noise disk (`None`: no bar); with [`Spread::Bars`] each
/// bar before its dot, with [`Spread::Band`] one band through every span before the dots.
fn data_marks<Y>(
    chart: &mut Chart<'_, '_, Y>,
    fig: &BodeFigure,
    d: &DataSeries,
    y: impl Fn(usize) -> Option<f64>,
    bar: impl Fn(usize) -> Option<(f64, f64)>,
) -> Result<()>
where
    Y: Ranged<ValueType = f64>,
{
    let x = |k: usize| fig.freq.x(d.omega[k]);
    let dot = |k: usize, y: f64| Circle::new((x(k), y), d.dot_radius, dot_style(d, k));
    match d.spread {
        Spread::Bars(style) => {
            for k in 0..d.omega.len() {
                if let Some((lo, hi)) = bar(k) {
                    let line = PathElement::new(vec![(x(k), lo), (x(k), hi)], style);
                    chart.draw_series(std::iter::once(line)).map_err(plot_err)?;
                }
                if let Some(v) = y(k) {
                    chart
                        .draw_series(std::iter::once(dot(k, v)))
                        .map_err(plot_err)?;
                }
            }
        }
        Spread::Band(style) => {
            if d.radius.is_some() {
                let spans: Vec<(f64, f64)> = (0..d.omega.len())
                    .map(|k| bar(k).unwrap_or((f64::NAN, f64::NAN)))
                    .collect();
                let outline: Vec<(f64, f64)> = (0..spans.len())
                    .map(|k| (x(k), spans[k].1))
                    .chain((0..spans.len()).rev().map(|k| (x(k), spans[k].0)))
                    .collect();
                chart
                    .draw_series(std::iter::once(Polygon::new(outline, style)))
                    .map_err(plot_err)?;
            }
            let dots: Vec<_> = (0..d.omega.len())
                .filter_map(|k| y(k).map(|v| dot(k, v)))
                .collect();
            chart.draw_series(dots).map_err(plot_err)?;
        }
    }
    Ok(())
}

/// Draws one panel: the magnitude chart (frame, data, models) in `top` with the magnitude
/// axis `y`, then the phase chart in `bottom`, then what the layout adds under it.
pub fn pair<Y>(
    fig: &BodeFigure,
    panel: &Panel,
    prep: &Prepared,
    (top, bottom): (&Area<'_>, &Area<'_>),
    root: &Area<'_>,
    y: Y,
    overlay: &Overlay,
) -> Result<()>
where
    Y: Ranged<ValueType = f64> + ValueFormatter<f64> + Fraction + Clone,
{
    let d = &panel.data;
    let bars = matches!(d.spread, Spread::Bars(_));
    // A bar only where the radius is nonzero; the band runs through every datum.
    let radius = |k: usize| d.radius.map(|r| r[k]).filter(|r| !bars || *r > 0.0);
    let scale = fig.scale;

    let mut mag = layout::mag_chart(fig, panel, top, prep.x_axis.clone(), y)?;
    let ends = (mag.y_range().start, mag.y_range().end);
    let ticks = layout::x_ticks(fig, &mag);
    layout::mag_frame(fig, panel, &mut mag, &ticks)?;
    data_marks(
        &mut mag,
        fig,
        d,
        |k| scale.dot(d.g[k].norm()).map(|v| clamp(v, ends.0, ends.1)),
        |k| radius(k).map(|r| scale.spread(d.g[k].norm(), r, ends)),
    )?;
    for m in &panel.models {
        let line = m.omega.iter().zip(&m.g);
        let points = line.map(|(w, z)| (fig.freq.x(*w), scale.curve(z.norm(), ends)));
        overlay.curve(&PixelMap::of(&mag), points, m.look);
    }

    let axis: &PhaseAxis = &prep.phase_axis;
    let mut ph = layout::phase_chart(fig, bottom, prep.x_axis.clone(), axis.clone())?;
    layout::phase_frame(fig, panel, &mut ph, &ticks)?;
    let ang = &prep.data_phase;
    data_marks(
        &mut ph,
        fig,
        d,
        |k| ang[k].is_finite().then(|| axis.clamp(ang[k])),
        |k| {
            let finite = !bars || ang[k].is_finite();
            let r = radius(k).filter(|_| finite)?;
            Some(phase::disk_phase_bar(ang[k], r, d.g[k].norm(), axis))
        },
    )?;
    for (m, p) in panel.models.iter().zip(&prep.model_phase) {
        let points = m.omega.iter().zip(p).map(|(w, v)| (fig.freq.x(*w), *v));
        overlay.curve(&PixelMap::of(&ph), points, m.look);
    }
    layout::finish(fig, root, &ph, &ticks)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scales place a datum, its noise disk and a model point by their closed forms:
    /// `|G| = 1` with `r = 0.5` spans 0.5…1.5 (log) or −6.02…+3.52 dB; a disk holding 0 goes
    /// down to the axis; zero has no place on a log axis and is −6000 dB (floored) in dB.
    #[test]
    fn scales_place_data_disks_and_models_by_their_closed_forms() {
        let axis = (1e-3, 1e3);
        assert_eq!(MagScale::Log.spread(1.0, 0.5, axis), (0.5, 1.5));
        assert_eq!(MagScale::Log.spread(1.0, 2.0, axis), (1e-3, 3.0));
        assert_eq!(MagScale::Log.spread(1.0, 1e4, axis), (1e-3, 1e3));
        let (lo, hi) = MagScale::Db.spread(1.0, 0.5, (-60.0, 60.0));
        assert!((lo - 20.0 * 0.5f64.log10()).abs() < 1e-12 && (lo + 6.0206).abs() < 1e-4);
        assert!((hi - 20.0 * 1.5f64.log10()).abs() < 1e-12 && (hi - 3.5218).abs() < 1e-4);
        assert_eq!(MagScale::Db.spread(1.0, 2.0, (-60.0, 60.0)).0, -60.0);
        assert_eq!(MagScale::Log.dot(0.0), None);
        assert_eq!(MagScale::Log.dot(f64::NAN), None);
        assert_eq!(MagScale::Log.dot(2.0), Some(2.0));
        assert_eq!(MagScale::Db.dot(0.0), Some(-6000.0));
        assert_eq!(MagScale::Db.dot(10.0), Some(20.0));
        assert!(MagScale::Log.curve(0.0, axis).is_nan());
        assert_eq!(MagScale::Log.curve(1e6, axis), 1e3);
        assert_eq!(MagScale::Db.curve(100.0, (-1.0, 1.0)), 40.0);
        assert!(MagScale::Db.curve(f64::NAN, (-1.0, 1.0)).is_nan());
        assert_eq!(MagScale::Db.dot(f64::NAN), None);
    }
}

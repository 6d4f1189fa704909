//! Frequency tick labels that never overlap: the tick set fitted to the axis' width, the
//! labels' form, their drawing (a second row where two would touch).

use super::text::text_width;
use super::{plot_err, FONT};
use crate::error::Result;
use plotters::prelude::*;

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

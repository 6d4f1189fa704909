//! SVG figures of model discovery: the Bode overlay of data and models, and the error
//! measures across model revisions.  Written atomically.

use crate::error::{Error, Result};
use num_complex::Complex64;
use plotters::prelude::*;
use std::path::Path;

fn perr<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::Invalid(format!("{}: cannot draw the figure: {e}", path.display()))
}

const COLORS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];

fn span(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    (lo - pad, hi + pad)
}

/// Bode overlay: data (dots, red where invalid) and one curve per model, frequency in Hz.
pub fn bode_overlay(
    path: &Path,
    title: &str,
    omega: &[f64],
    data: &[Complex64],
    invalid: &[bool],
    models: &[(String, Vec<Complex64>)],
) -> Result<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 700)).into_drawing_area();
        let e = perr(path);
        root.fill(&WHITE).map_err(&e)?;
        let (top, bottom) = root.split_vertically(420);
        let hz: Vec<f64> = omega
            .iter()
            .map(|w| w / (2.0 * std::f64::consts::PI))
            .collect();
        let (f0, f1) = (
            hz.first().copied().unwrap_or(0.1) * 0.9,
            hz.last().copied().unwrap_or(1.0) * 1.1,
        );
        let db = |z: &Complex64| 20.0 * z.norm().max(1e-300).log10();
        let deg = |z: &Complex64| z.arg().to_degrees();
        let (m0, m1) = span(
            data.iter()
                .map(db)
                .chain(models.iter().flat_map(|(_, g)| g.iter().map(db))),
        );
        let mut mag = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d((f0..f1).log_scale(), m0..m1)
            .map_err(&e)?;
        mag.configure_mesh().y_desc("|G| (dB)").draw().map_err(&e)?;
        for (k, (name, g)) in models.iter().enumerate() {
            let c = COLORS[k % COLORS.len()];
            mag.draw_series(LineSeries::new(
                hz.iter().zip(g).map(|(f, z)| (*f, db(z))),
                c.stroke_width(2),
            ))
            .map_err(&e)?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
        }
        mag.draw_series(hz.iter().zip(data).zip(invalid).map(|((f, z), bad)| {
            Circle::new(
                (*f, db(z)),
                2,
                if *bad { RED.filled() } else { BLACK.filled() },
            )
        }))
        .map_err(&e)?
        .label("data (red: not explained by the noise)")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
        mag.configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(&e)?;
        let mut ph = ChartBuilder::on(&bottom)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((f0..f1).log_scale(), -180.0..180.0)
            .map_err(&e)?;
        ph.configure_mesh()
            .x_desc("frequency (Hz)")
            .y_desc("phase (deg)")
            .draw()
            .map_err(&e)?;
        for (k, (_, g)) in models.iter().enumerate() {
            let c = COLORS[k % COLORS.len()];
            ph.draw_series(
                hz.iter()
                    .zip(g)
                    .map(|(f, z)| Circle::new((*f, deg(z)), 1, c.filled())),
            )
            .map_err(&e)?;
        }
        ph.draw_series(hz.iter().zip(data).zip(invalid).map(|((f, z), bad)| {
            Circle::new(
                (*f, deg(z)),
                2,
                if *bad { RED.filled() } else { BLACK.filled() },
            )
        }))
        .map_err(&e)?;
        root.present().map_err(&e)?;
    }
    crate::util::write_atomic(path, svg.as_bytes())
}

/// Error measures across revisions: `misfit_rms` (log scale) and `invalid_fraction`.
pub fn error_history(
    path: &Path,
    labels: &[String],
    misfit_rms: &[f64],
    invalid_fraction: &[f64],
) -> Result<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        let e = perr(path);
        root.fill(&WHITE).map_err(&e)?;
        let (top, bottom) = root.split_vertically(300);
        let n = labels.len().max(1);
        let lo = misfit_rms
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min)
            .clamp(1e-6, 0.5);
        let hi = misfit_rms.iter().cloned().fold(1.0, f64::max) * 1.5;
        let lab = labels.to_vec();
        let mut a = ChartBuilder::on(&top)
            .caption("error vs revision", ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), (lo..hi).log_scale())
            .map_err(&e)?;
        let l1 = lab.clone();
        a.configure_mesh()
            .y_desc("misfit_rms")
            .x_labels(n)
            .x_label_formatter(&move |x| {
                let k = x.round();
                if (x - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < l1.len() {
                    l1[k as usize].clone()
                } else {
                    String::new()
                }
            })
            .draw()
            .map_err(&e)?;
        a.draw_series(LineSeries::new(
            misfit_rms.iter().enumerate().map(|(k, v)| (k as f64, *v)),
            COLORS[0].stroke_width(2),
        ))
        .map_err(&e)?;
        a.draw_series(
            misfit_rms
                .iter()
                .enumerate()
                .map(|(k, v)| Circle::new((k as f64, *v), 4, COLORS[0].filled())),
        )
        .map_err(&e)?;
        a.draw_series(LineSeries::new(
            vec![(-0.5, 1.0), (n as f64 - 0.5, 1.0)],
            RED.stroke_width(1),
        ))
        .map_err(&e)?;
        let mut b = ChartBuilder::on(&bottom)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), 0.0..1.0)
            .map_err(&e)?;
        let l2 = lab.clone();
        b.configure_mesh()
            .y_desc("invalid_fraction")
            .x_desc("revision")
            .x_labels(n)
            .x_label_formatter(&move |x| {
                let k = x.round();
                if (x - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < l2.len() {
                    l2[k as usize].clone()
                } else {
                    String::new()
                }
            })
            .draw()
            .map_err(&e)?;
        b.draw_series(LineSeries::new(
            invalid_fraction
                .iter()
                .enumerate()
                .map(|(k, v)| (k as f64, *v)),
            COLORS[1].stroke_width(2),
        ))
        .map_err(&e)?;
        b.draw_series(
            invalid_fraction
                .iter()
                .enumerate()
                .map(|(k, v)| Circle::new((k as f64, *v), 4, COLORS[1].filled())),
        )
        .map_err(&e)?;
        b.draw_series(LineSeries::new(
            vec![(-0.5, 0.05), (n as f64 - 0.5, 0.05)],
            RED.stroke_width(1),
        ))
        .map_err(&e)?;
        root.present().map_err(&e)?;
    }
    crate::util::write_atomic(path, svg.as_bytes())
}

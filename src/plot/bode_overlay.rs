//! The Bode overlay of model discovery (`rshape compare --svg`): the measured FRF with its
//! noise disks and the model evaluated on a dense grid.  Written atomically.
//!
//! Read at a glance: the model is a line (it can be evaluated at any ω, so resonances between
//! the data show), the data are dots (red where the noise does not explain them), the grey
//! band is the union of the noise disks `|G − G_data| ≤ r` in magnitude and phase, the
//! phase is unwrapped along the model and each datum is drawn on the branch nearest the model
//! (a model at +179° and a datum at −179° are 2° apart, not 358°), and the legend sits below
//! the plots where it hides no data.  The figure is a description drawn by the one Bode
//! drawer, [`super::bode_chart`].

use crate::error::Result;
use crate::plot::bode_chart::{
    render, BodeFigure, DataSeries, FreqAxis, Layout, LegendEntry, MagScale, ModelSeries, Panel,
    Spread,
};
use crate::plot::fine::Look;
use crate::plot::style::{C_GREY, C_RED, PALETTE};
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

/// The Bode overlay as an SVG document: magnitude (dB) above, unwrapped phase below, legend
/// strip at the bottom.
pub fn bode_svg(title: &str, data: &BodeData, models: &[ModelCurve]) -> Result<String> {
    render(&figure(title, data, models))
}

/// The description of the overlay: one panel against Hz in dB, the noise disks as a grey
/// band, the data the model does not explain in red, one line per model.
fn figure<'a>(title: &'a str, data: &BodeData<'a>, models: &'a [ModelCurve]) -> BodeFigure<'a> {
    let band = match (data.omega.first(), data.omega.last()) {
        (Some(&a), Some(&b)) if a > 0.0 => (a / TAU / 1.1, b / TAU * 1.1),
        _ => (0.1, 1.0),
    };
    let fill = C_GREY.mix(0.22).filled();
    let bad = C_RED.filled();
    let look = |k: usize| Look::solid(PALETTE[k % PALETTE.len()], 2.0);
    let mut legend = Vec::new();
    if data.radius.is_some() {
        legend.push(LegendEntry::Swatch(
            "noise: every G with |G − G_data| ≤ r".into(),
            fill,
        ));
    }
    for (k, m) in models.iter().enumerate() {
        legend.push(LegendEntry::Line(
            format!("{} (line: evaluated between the data)", m.name),
            look(k),
        ));
    }
    legend.push(LegendEntry::Dot(
        "data explained by the noise".into(),
        BLACK.filled(),
    ));
    if data.invalid.iter().any(|b| *b) {
        legend.push(LegendEntry::Dot(
            "data the model does not explain (|G_model − G_data| > r)".into(),
            bad,
        ));
    }
    BodeFigure {
        title,
        freq: FreqAxis {
            hz: true,
            label: FREQ_LABEL.into(),
            band,
        },
        scale: MagScale::Db,
        layout: Layout::Overlay,
        panels: vec![Panel {
            caption: None,
            mag_label: "|G| (dB)".into(),
            phase_label: "phase (degrees, unwrapped)".into(),
            data: DataSeries {
                omega: data.omega,
                g: data.g.to_vec(),
                radius: data.radius,
                spread: Spread::Band(fill),
                dot_radius: 2,
                dot: BLACK.filled(),
                flagged: Some((data.invalid, bad)),
            },
            models: models
                .iter()
                .enumerate()
                .map(|(k, m)| ModelSeries {
                    omega: &m.omega,
                    g: m.g.clone(),
                    look: look(k),
                })
                .collect(),
        }],
        legend,
    }
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

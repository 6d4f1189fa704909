//! The one Bode drawer: a magnitude chart over a phase chart, drawn from a figure
//! description ([`BodeFigure`]).  `bode.svg` (`run`: one panel per channel, |G| on a log
//! axis against rad/s, noise disks as error bars, as in the paper's Fig. 7) and `compare`'s
//! overlay (dB against Hz, one or more models, the noise disks as a grey band) only build a
//! description ([`super::bode`], [`super::bode_overlay`]).
//!
//! - [`phase`]: the phase conventions (the model's phase unwrapped along its grid, each datum
//!   on the model's branch), the phase axis, a noise disk's phase span;
//! - [`layout`]: where the charts sit and how their frames look ([`Layout::Grid`],
//!   [`Layout::Overlay`]);
//! - [`marks`]: the data (dots, error bars or band) and the model curves on a chart pair,
//!   through the magnitude scale ([`MagScale`]).

pub(crate) mod layout;
pub(crate) mod marks;
pub(crate) mod phase;

use super::axis::{LinAxis, LogAxis, PhaseAxis};
use super::fine::{Look, Overlay};
use super::style::{plot_err, Legend};
use crate::error::Result;
use num_complex::Complex64;
use plotters::prelude::*;

/// A Bode figure: a title, the frequency axis, the magnitude scale, the panels (one chart
/// pair each) and the legend drawn below them.
pub struct BodeFigure<'a> {
    /// Title of the figure.
    pub title: &'a str,
    /// The frequency axis (unit, label, plotted band).
    pub freq: FreqAxis,
    /// How `|G|` is plotted.
    pub scale: MagScale,
    /// How the panels are placed and framed.
    pub layout: Layout,
    /// One chart pair each, row by row.
    pub panels: Vec<Panel<'a>>,
    /// The legend's entries, in order.
    pub legend: Vec<LegendEntry>,
}

/// The frequency axis: the unit the data's ω (rad/s) is plotted in, its label and the
/// plotted band (in that unit; the model's phases inside it set the phase axis).
#[derive(Debug, Clone)]
pub struct FreqAxis {
    /// Plot `f = ω/2π` (Hz) instead of ω (rad/s).
    pub hz: bool,
    /// The axis label.
    pub label: String,
    /// The plotted band `(lo, hi)`, in the plotted unit (guarded by the axis).
    pub band: (f64, f64),
}

impl FreqAxis {
    /// The abscissa of a frequency ω (rad/s).
    pub fn x(&self, w: f64) -> f64 {
        if self.hz {
            w / std::f64::consts::TAU
        } else {
            w
        }
    }

    /// Whether the abscissa `x` lies in the band (the band as given, before the axis guard).
    pub fn in_band(&self, x: f64) -> bool {
        x >= self.band.0 && x <= self.band.1
    }
}

/// How the magnitude is plotted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MagScale {
    /// `|G|` on a log axis covering the data with their noise disks and the whole model
    /// grid, padded by a factor 2 (at most ten decades below the top); data and models
    /// that are zero are not drawn.
    Log,
    /// `20 log₁₀ |G|` (dB, `|G|` floored at 1e-300) on a linear axis covering the data and
    /// the model in the band, padded by 6 % (at least 1 dB).
    Db,
}

/// How the panels are placed and framed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// `rows × cols` panels (one per channel), each with its own tick labels, captioned
    /// when there are several; a single panel is drawn larger.
    Grid {
        /// Rows of panels (outputs).
        rows: usize,
        /// Columns of panels (inputs).
        cols: usize,
    },
    /// One wide panel (the first; its models overlaid), frequency labels chosen so none
    /// overlaps (`log_axis_ticks`) under the phase chart.
    Overlay,
}

/// One chart pair: the magnitude over the phase of one response.
pub struct Panel<'a> {
    /// Caption above the magnitude chart (the channel), if any.
    pub caption: Option<String>,
    /// The magnitude axis label.
    pub mag_label: String,
    /// The phase axis label.
    pub phase_label: String,
    /// The measured response.
    pub data: DataSeries<'a>,
    /// The model curves; the first is the phase reference of the data.
    pub models: Vec<ModelSeries<'a>>,
}

/// The measured response of a panel: dots, with the noise disks `|G − G_data| ≤ r` drawn as
/// [`Spread`].
pub struct DataSeries<'a> {
    /// Frequencies ω (rad/s), increasing.
    pub omega: &'a [f64],
    /// The response at `omega`.
    pub g: Vec<Complex64>,
    /// The noise radius per datum, when known.
    pub radius: Option<&'a [f64]>,
    /// How the noise disks are drawn.
    pub spread: Spread,
    /// Radius (pixels) of a datum's dot.
    pub dot_radius: i32,
    /// The dots' style.
    pub dot: ShapeStyle,
    /// Data drawn in another style (e.g. those the model does not explain), and that style.
    pub flagged: Option<(&'a [bool], ShapeStyle)>,
}

/// How the noise disks of the data are drawn.
#[derive(Debug, Clone, Copy)]
pub enum Spread {
    /// A bar per datum with a nonzero radius (magnitude `|G| ± r`, phase `±asin(r/|G|)`),
    /// down to the axis when the disk holds 0; each bar drawn before its dot.
    Bars(ShapeStyle),
    /// One filled band through every datum's bar, drawn before the dots.
    Band(ShapeStyle),
}

/// A model curve on its own (dense) grid; non-finite values break the line.
pub struct ModelSeries<'a> {
    /// Frequencies ω (rad/s), increasing.
    pub omega: &'a [f64],
    /// The response at `omega` (NaN where unknown).
    pub g: Vec<Complex64>,
    /// The line's look.
    pub look: Look,
}

/// An entry of the legend below the panels.
#[derive(Debug, Clone)]
pub enum LegendEntry {
    /// A line sample (a model).
    Line(String, Look),
    /// A dot sample of radius 3.
    Dot(String, ShapeStyle),
    /// A vertical bar sample (error bars).
    Bar(String, ShapeStyle),
    /// A filled swatch (a band).
    Swatch(String, ShapeStyle),
}

/// What one panel's charts show, worked out before drawing: the phases and the axes.
pub(crate) struct Prepared {
    /// Each model's phase along its grid, unwrapped (degrees).
    pub model_phase: Vec<Vec<f64>>,
    /// Each datum's phase on the first model's branch (degrees).
    pub data_phase: Vec<f64>,
    /// The phase axis.
    pub phase_axis: PhaseAxis,
    /// The frequency axis (guarded band).
    pub x_axis: LogAxis,
}

impl Prepared {
    pub(crate) fn of(fig: &BodeFigure, p: &Panel) -> Self {
        let model_phase: Vec<Vec<f64>> = p
            .models
            .iter()
            .map(|m| phase::model_phase(m.g.iter().copied()))
            .collect();
        let reference: Option<Vec<f64>> = p.models.first().map(|m| {
            p.data
                .omega
                .iter()
                .map(|w| phase::interp(m.omega, &model_phase[0], *w))
                .collect()
        });
        let data_phase = phase::data_phase(&p.data.g, reference.as_deref(), p.data.radius);
        let phase_axis = phase::phase_axis(
            &data_phase,
            p.models.iter().zip(&model_phase).flat_map(|(m, ph)| {
                m.omega
                    .iter()
                    .zip(ph)
                    .filter(|(w, _)| fig.freq.in_band(fig.freq.x(**w)))
                    .map(|(_, v)| *v)
            }),
        );
        let x_axis = LogAxis::new(fig.freq.band.0, fig.freq.band.1);
        Self {
            model_phase,
            data_phase,
            phase_axis,
            x_axis,
        }
    }
}

/// Renders the figure as an SVG document: the title, the panels (each a magnitude chart
/// over a phase chart: the data, their noise disks, the model curves), the legend below.
pub fn render(fig: &BodeFigure) -> Result<String> {
    let (width, height) = layout::size(fig);
    let mut svg = String::new();
    let overlay = Overlay::default();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (areas, below) = layout::areas(fig, &root, width)?;
        for (panel, (top, bottom)) in fig.panels.iter().zip(&areas) {
            let prep = Prepared::of(fig, panel);
            match fig.scale {
                MagScale::Log => {
                    let (lo, hi) = marks::log_range(panel);
                    let y = LogAxis::new(lo, hi);
                    marks::pair(fig, panel, &prep, (top, bottom), &root, y, &overlay)?;
                }
                MagScale::Db => {
                    let (lo, hi) = marks::db_range(fig, panel);
                    let y = LinAxis::new(lo, hi);
                    marks::pair(fig, panel, &prep, (top, bottom), &root, y, &overlay)?;
                }
            }
        }
        let mut leg = Legend::default();
        for e in &fig.legend {
            match e.clone() {
                LegendEntry::Line(label, look) => leg.add_line(label, look, &overlay),
                LegendEntry::Dot(label, s) => {
                    leg.add(label, move |(x, y)| Circle::new((x + 12, y), 3, s))
                }
                LegendEntry::Bar(label, s) => leg.add(label, move |(x, y)| {
                    PathElement::new(vec![(x + 12, y - 7), (x + 12, y + 7)], s)
                }),
                LegendEntry::Swatch(label, s) => leg.add(label, move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 24, y + 5)], s)
                }),
            }
        }
        leg.draw(&below)?;
        root.present().map_err(plot_err)?;
    }
    overlay.inject(&mut svg);
    Ok(svg)
}

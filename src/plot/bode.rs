//! `bode.svg`: magnitude and phase of the data, with the noise disk of eq. (5) drawn as
//! error bars, against the nominal model `G = C·M̃⁻¹·Ñ·J` (as in the paper's Fig. 7): the
//! description of a [`super::bode_chart`] figure (one panel per channel, |G| on a log axis
//! against rad/s).

use super::bode_chart::{
    render, BodeFigure, DataSeries, FreqAxis, Layout, LegendEntry, MagScale, ModelSeries, Panel,
    Spread,
};
use super::fine::Look;
use super::style::{omega_range, C_BLUE, C_ORANGE};
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;
use plotters::prelude::*;

/// What the figure shows.
pub struct BodeInput<'a> {
    /// Title of the figure.
    pub title: &'a str,
    /// Data frequencies (rad/s).
    pub omega: &'a [f64],
    /// The measured `p×m` responses.
    pub data: &'a [DMatrix<Complex64>],
    /// Per-datum noise-disk radius, when the data are noisy.
    pub noise_radius: Option<&'a [f64]>,
    /// Dense frequency grid for the model (rad/s).
    pub grid: &'a [f64],
    /// The nominal model on `grid` (`None` where `M̃(jω)` is singular).
    pub model: &'a [Option<DMatrix<Complex64>>],
    /// Name of the response in labels: `G` (open loop) or `Φ` (closed loop).
    pub symbol: &'a str,
}

/// Channel `ch` of the model along its grid, NaN where the model is unknown.
fn channel(
    model: &[Option<DMatrix<Complex64>>],
    ch: (usize, usize),
) -> impl Iterator<Item = Complex64> + '_ {
    model.iter().map(move |g| match g {
        Some(g) => g[ch],
        None => Complex64::new(f64::NAN, f64::NAN),
    })
}

/// The model's line: solid orange.
const MODEL: Look = Look::solid(C_ORANGE, 2.0);

/// Renders `bode.svg`: one panel per channel `G_ij` (a grid of `p` rows by `m` columns for
/// MIMO data, so that no channel hides under another), each with the magnitude (log-log) over
/// the phase (degrees); data as markers with their noise error bars, the model as a line;
/// one legend below the grid.
pub fn bode_svg(inp: &BodeInput) -> Result<String> {
    render(&figure(inp))
}

/// The description of `bode.svg`.
fn figure<'a>(inp: &BodeInput<'a>) -> BodeFigure<'a> {
    let (p, m) = inp.data.first().map_or((1, 1), |d| (d.nrows(), d.ncols()));
    let siso = p * m == 1;
    let sym = inp.symbol;
    let bar = C_BLUE.mix(0.6).stroke_width(1);
    let dot = C_BLUE.mix(0.7).filled();
    let panels = (0..p * m)
        .map(|k| {
            let (i, j) = (k / m, k % m);
            let name = if siso {
                sym.to_string()
            } else {
                format!("{sym}{}{}", i + 1, j + 1)
            };
            let zero_model = inp.model.iter().flatten().all(|g| g[(i, j)].norm() == 0.0);
            let note = if zero_model { " (model ≡ 0)" } else { "" };
            Panel {
                caption: (!siso)
                    .then(|| format!("{name}: output {}, input {}{note}", i + 1, j + 1)),
                mag_label: format!("|{name}(jω)|"),
                phase_label: format!("∠{name}(jω) (degrees)"),
                data: DataSeries {
                    omega: inp.omega,
                    g: inp.data.iter().map(|d| d[(i, j)]).collect(),
                    radius: inp.noise_radius,
                    spread: Spread::Bars(bar),
                    dot_radius: 3,
                    dot,
                    flagged: None,
                },
                models: vec![ModelSeries {
                    omega: inp.grid,
                    g: channel(inp.model, (i, j)).collect(),
                    look: MODEL,
                }],
            }
        })
        .collect();
    let mut legend = vec![
        LegendEntry::Line(
            format!("nominal model {sym}(jω) (line; phase unwrapped along ω)"),
            MODEL,
        ),
        LegendEntry::Dot("measured data (markers)".into(), dot),
    ];
    if inp.noise_radius.is_some() {
        legend.push(LegendEntry::Bar(
            "error bar: noise disk |Φ − G_p| ≤ L (eq. 5); down to the axis if it holds 0".into(),
            bar,
        ));
    }
    BodeFigure {
        title: inp.title,
        freq: FreqAxis {
            hz: false,
            label: "frequency ω (rad/s)".into(),
            band: omega_range(inp.omega),
        },
        scale: MagScale::Log,
        layout: Layout::Grid { rows: p, cols: m },
        panels,
        legend,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::bode_chart::Prepared;

    /// The model's phase is continuous (no jump at ±180°) and each datum sits on its branch.
    #[test]
    fn phase_is_unwrapped_along_the_model() {
        let grid: Vec<f64> = (0..200).map(|k| 0.1 * 1.05f64.powi(k)).collect();
        // G = 1/(s+1)^3: the phase runs from 0 to −270°.
        let g = |w: f64| Complex64::new(1.0, w).powi(3).inv();
        let model: Vec<Option<DMatrix<Complex64>>> = grid
            .iter()
            .map(|w| Some(DMatrix::from_element(1, 1, g(*w))))
            .collect();
        let omega = [0.5, 3.0, 20.0];
        let data: Vec<DMatrix<Complex64>> = omega
            .iter()
            .map(|w| DMatrix::from_element(1, 1, g(*w)))
            .collect();
        let inp = BodeInput {
            title: "t",
            omega: &omega,
            data: &data,
            noise_radius: None,
            grid: &grid,
            model: &model,
            symbol: "G",
        };
        let fig = figure(&inp);
        let prep = Prepared::of(&fig, &fig.panels[0]);
        let m = &prep.model_phase[0];
        assert!(m.windows(2).all(|w| (w[1] - w[0]).abs() < 20.0));
        assert!(m.last().unwrap() < &-200.0);
        let d = &prep.data_phase;
        let exact = |w: f64| -3.0 * w.atan().to_degrees();
        for (p, w) in d.iter().zip(omega) {
            assert!((p - exact(w)).abs() < 1e-6, "{p} vs {}", exact(w));
        }
    }
}

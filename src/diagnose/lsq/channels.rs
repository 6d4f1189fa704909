//! The data `diagnose` works on: one or several channels of an FRF set measured at the same
//! frequencies, each with its noise radius, and the model entry each channel compares with.
//! Several channels are diagnosed jointly (a mode has one `ω_n` and `ζ` across them).

use crate::data::FrfData;
use crate::diagnose::compare::{prepare, Siso};
use crate::error::{Error, Result};
use crate::model::Config;
use num_complex::Complex64;
use std::path::PathBuf;

/// Channels of one FRF set with their noise radii.
#[derive(Debug, Clone)]
pub struct Channels {
    /// The data file.
    pub path: PathBuf,
    /// Frequencies, rad/s (ascending).
    pub omega: Vec<f64>,
    /// Model entry `(output, input)` (0-based) of each channel.
    pub entries: Vec<(usize, usize)>,
    /// Measured response, `g[ch][k]`.
    pub g: Vec<Vec<Complex64>>,
    /// Noise radius, `radius[ch][k]`.
    pub radius: Vec<Vec<f64>>,
    /// Where each channel's radius came from.
    pub radius_source: Vec<String>,
}

impl Channels {
    /// Test data: the response of `truth` at `omega` on `entries` times `gain`, with noise
    /// radius `rel·|G| + floor` (no noise added).
    #[cfg(test)]
    pub(crate) fn of_model(
        truth: &crate::model::physical::PhysicalModel,
        omega: Vec<f64>,
        entries: Vec<(usize, usize)>,
        gain: f64,
        (rel, floor): (f64, f64),
    ) -> Self {
        let g: Vec<Vec<Complex64>> = entries
            .iter()
            .map(|e| omega.iter().map(|w| truth.eval(*w)[*e] * gain).collect())
            .collect();
        let radius = g
            .iter()
            .map(|c| c.iter().map(|x| rel * x.norm() + floor).collect())
            .collect();
        Self {
            path: "test".into(),
            radius_source: vec![String::new(); entries.len()],
            omega,
            entries,
            g,
            radius,
        }
    }

    /// One SISO channel (the noise radius must be known).
    pub fn from_siso(s: &Siso) -> Result<Self> {
        let radius = s.radius.clone().ok_or_else(|| {
            Error::Input {
                path: s.path.to_path_buf(),
                msg: "diagnose needs the noise radius: pass --noise-radius X, add a noise_radius column, or [noise] radius / std_file / coherence".into(),
            }
        })?;
        Ok(Self {
            path: s.path.clone(),
            omega: s.omega.clone(),
            entries: vec![s.model_entry],
            g: vec![s.g.clone()],
            radius: vec![radius],
            radius_source: vec![s.radius_source.clone()],
        })
    }

    /// Every channel of `data` (the model must have the data's size), each with the noise
    /// radius the config or `--noise-radius` gives it.
    pub fn all(config: &Config, data: &FrfData, noise_override: Option<f64>) -> Result<Self> {
        let mut out: Option<Channels> = None;
        for o in 1..=data.outputs() {
            for i in 1..=data.inputs() {
                let s = prepare(config, data, Some((o, i)), noise_override)?;
                let c = Channels::from_siso(&s)?;
                match &mut out {
                    None => out = Some(c),
                    Some(a) => {
                        a.entries.extend(c.entries);
                        a.g.extend(c.g);
                        a.radius.extend(c.radius);
                        a.radius_source.extend(c.radius_source);
                    }
                }
            }
        }
        let out = out.ok_or_else(|| Error::Input {
            path: data.path.to_path_buf(),
            msg: "no channel".into(),
        })?;
        let mut e = out.entries.clone();
        e.sort();
        e.dedup();
        if e.len() != out.entries.len() {
            return Err(Error::Input {
                path: data.path.to_path_buf(),
                msg: format!(
                    "the data have {} channels but the model {} is SISO: describe every output and input in the model, or pick one channel with --channel OUT,IN",
                    out.entries.len(),
                    config.path.display(),
                ),
            });
        }
        Ok(out)
    }

    /// The lines with `f_lo ≤ f ≤ f_hi` (Hz; `diagnose --band`), every channel with its
    /// radii.  Fewer than two lines left is an error naming the data's band.
    pub fn band(&self, f_lo: f64, f_hi: f64) -> Result<Self> {
        let tau = std::f64::consts::TAU;
        let inside = self.in_range("--band", f_lo, f_hi)?;
        let keep: Vec<usize> = (0..self.len()).filter(|k| inside(*k)).collect();
        if keep.len() < 2 {
            return Err(Error::Argument {
                arg: format!("--band {f_lo}:{f_hi}"),
                msg: format!(
                    "{} of the data's lines lie in it (the data span {} … {} Hz); at least 2 are needed",
                    keep.len(),
                    crate::report::fmt::sig(self.omega.first().copied().unwrap_or(0.0) / tau),
                    crate::report::fmt::sig(self.omega.last().copied().unwrap_or(0.0) / tau),
                ),
            });
        }
        Ok(self.keep(&keep))
    }

    /// Every line but those with `f_lo ≤ f ≤ f_hi` (Hz; `diagnose --exclude`: a spectral
    /// line or a dropout left out).  A range holding no line, or leaving fewer than two, is an
    /// error naming the range and the nearest line.
    pub fn exclude(&self, f_lo: f64, f_hi: f64) -> Result<Self> {
        let tau = std::f64::consts::TAU;
        let arg = format!("--exclude {f_lo}:{f_hi}");
        let inside = self.in_range("--exclude", f_lo, f_hi)?;
        let keep: Vec<usize> = (0..self.len()).filter(|k| !inside(*k)).collect();
        if keep.len() == self.len() {
            let mid = 0.5 * (f_lo + f_hi);
            let nearest = self
                .omega
                .iter()
                .map(|w| w / tau)
                .min_by(|a, b| (a - mid).abs().total_cmp(&(b - mid).abs()))
                .unwrap_or(f64::NAN);
            return Err(Error::Argument {
                arg,
                msg: format!(
                    "no line of the data lies in it (the nearest is at {} Hz): widen the range to hold the line to leave out",
                    crate::report::fmt::sig(nearest)
                ),
            });
        }
        if keep.len() < 2 {
            return Err(Error::Argument {
                arg,
                msg: format!(
                    "it leaves {} of the data's {} lines; at least 2 are needed",
                    keep.len(),
                    self.len()
                ),
            });
        }
        Ok(self.keep(&keep))
    }

    /// The test "line `k` lies in `f_lo ≤ f ≤ f_hi` Hz" of `--band` and `--exclude` (named by
    /// `flag` in the error for a range that is not `0 ≤ FMIN < FMAX`).
    fn in_range(&self, flag: &str, f_lo: f64, f_hi: f64) -> Result<impl Fn(usize) -> bool + '_> {
        if !(f_lo.is_finite() && f_hi.is_finite() && 0.0 <= f_lo && f_lo < f_hi) {
            return Err(Error::Argument {
                arg: format!("{flag} {f_lo}:{f_hi}"),
                msg: "give FMIN:FMAX in Hz with 0 ≤ FMIN < FMAX".into(),
            });
        }
        // Hz from rad/s carries rounding: a line at exactly FMIN or FMAX is inside.
        Ok(move |k: usize| {
            let f = self.omega[k] / std::f64::consts::TAU;
            f >= f_lo * (1.0 - 1e-12) && f <= f_hi * (1.0 + 1e-12)
        })
    }

    /// The lines `keep` (ascending), every channel with its radii.
    fn keep(&self, keep: &[usize]) -> Self {
        fn pick<T: Copy>(v: &[Vec<T>], keep: &[usize]) -> Vec<Vec<T>> {
            v.iter()
                .map(|c| keep.iter().map(|k| c[*k]).collect())
                .collect()
        }
        Self {
            path: self.path.clone(),
            omega: keep.iter().map(|k| self.omega[*k]).collect(),
            entries: self.entries.clone(),
            g: pick(&self.g, keep),
            radius: pick(&self.radius, keep),
            radius_source: self.radius_source.clone(),
        }
    }

    /// Number of channels.
    pub fn n_ch(&self) -> usize {
        self.entries.len()
    }

    /// Number of frequencies.
    pub fn len(&self) -> usize {
        self.omega.len()
    }

    /// True without data.
    pub fn is_empty(&self) -> bool {
        self.omega.is_empty()
    }

    /// Number of complex data over every channel.
    pub fn n_data(&self) -> usize {
        self.len() * self.n_ch()
    }
}

/// `(misfit_rms, invalid_fraction)` of a physical model on the channels.
pub fn misfit_channels(m: &crate::model::physical::PhysicalModel, data: &Channels) -> (f64, f64) {
    let c: Vec<Vec<f64>> = data
        .entries
        .iter()
        .enumerate()
        .map(|(ch, e)| {
            data.omega
                .iter()
                .enumerate()
                .map(|(k, w)| (data.g[ch][k] - m.eval(*w)[*e]).norm() / data.radius[ch][k])
                .collect()
        })
        .collect();
    let me = crate::diagnose::lsq::measures::measures_of(&c);
    (me.misfit_rms, me.invalid_fraction)
}

//! The diagnose fitting problem: SISO data with noise radii, the base model split as
//! `core · path`, candidate effects on top (`Mods`), the cost
//! `V = Σ|G_d − Ĝ(θ)|²/σ_k²` (`σ_k = r_k/√2`, noise uniform in the disk of radius `r_k`) and
//! the joint Levenberg–Marquardt refit of every candidate parameter.

use super::candidates::Cand;
use super::compare::{Siso, MAX_INVALID_FRACTION, MAX_MISFIT_RMS};
use super::fit::lm;
use crate::error::{Error, Result};
use crate::model::physical::PhysicalModel;
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::Serialize;

/// The fitting problem: data, noise and the base model split as `core · path`.
pub struct Problem<'a> {
    pub(super) base: &'a PhysicalModel,
    pub(super) omega: Vec<f64>,
    pub(super) g: Vec<Complex64>,
    pub(super) radius: Vec<f64>,
    pub(super) inv_sigma: Vec<f64>,
    pub(super) core0: Vec<Complex64>,
    pub(super) path0: Vec<Complex64>,
}

/// A model: the base plus effects with their internal parameters (concatenated).
#[derive(Debug, Clone, Default)]
pub struct Mods {
    /// The effects, in order.
    pub cands: Vec<Cand>,
    /// Their parameters, concatenated.
    pub theta: Vec<f64>,
}

impl Mods {
    pub(super) fn with(&self, c: Cand, th: &[f64]) -> Mods {
        let mut m = self.clone();
        m.cands.push(c);
        m.theta.extend_from_slice(th);
        m
    }
}

/// Error measures of a model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Measures {
    /// `Σ|e|²/σ²`.
    pub v: f64,
    /// `sqrt(mean (|e|/r)²)`.
    pub misfit_rms: f64,
    /// Share of data with `|e| > r`.
    pub invalid_fraction: f64,
}

impl Measures {
    /// Explained within the noise.
    pub fn consistent(&self) -> bool {
        self.invalid_fraction <= MAX_INVALID_FRACTION && self.misfit_rms <= MAX_MISFIT_RMS
    }
}

impl<'a> Problem<'a> {
    /// Sets up the problem; the model must be SISO and the noise radius known.
    pub fn new(base: &'a PhysicalModel, siso: &Siso) -> Result<Self> {
        if base.n_inputs() != 1 || base.n_outputs() != 1 {
            return Err(Error::Invalid(
                "diagnose works on a SISO [physical] model: describe the selected channel as a SISO model".into(),
            ));
        }
        let radius = siso.radius.clone().ok_or_else(|| {
            Error::Invalid(format!(
                "{}: diagnose needs the noise radius: pass --noise-radius X, add a noise_radius column, or [noise] radius / std_file",
                siso.path.display()
            ))
        })?;
        let core0: Vec<Complex64> = siso
            .omega
            .iter()
            .map(|w| base.eval_core(*w)[(0, 0)])
            .collect();
        let path0 = siso
            .omega
            .iter()
            .map(|w| {
                base.effect
                    .iter()
                    .fold(Complex64::new(1.0, 0.0), |a, e| a * e.eval(*w))
            })
            .collect();
        Ok(Self {
            base,
            omega: siso.omega.clone(),
            g: siso.g.clone(),
            inv_sigma: radius
                .iter()
                .map(|r| std::f64::consts::SQRT_2 / r)
                .collect(),
            radius,
            core0,
            path0,
        })
    }

    pub(super) fn f(&self) -> usize {
        self.omega.len()
    }

    /// Indices of the data below and above `ω_min·(ω_max/ω_min)^share`.
    pub(super) fn split_band(&self, share: f64) -> (Vec<usize>, Vec<usize>) {
        let (lo, hi) = (self.omega[0].max(1e-300), self.omega_max().max(1e-300));
        let w = (lo.ln() + share * (hi.ln() - lo.ln())).exp();
        (0..self.f()).partition(|&k| self.omega[k] < w)
    }

    pub(super) fn omega_max(&self) -> f64 {
        *self.omega.last().expect("data")
    }

    /// Model response at datum `k`, or at any `ω` with `k = None`.
    pub(super) fn eval_at(&self, mods: &Mods, k: Option<usize>, omega: f64) -> Complex64 {
        let (mut core, mut path) = match k {
            Some(k) => (self.core0[k], self.path0[k]),
            None => (
                self.base.eval_core(omega)[(0, 0)],
                self.base
                    .effect
                    .iter()
                    .fold(Complex64::new(1.0, 0.0), |a, e| a * e.eval(omega)),
            ),
        };
        let mut off = 0;
        for c in &mods.cands {
            let n = c.n_params();
            c.modify(
                &mods.theta[off..off + n],
                self.base,
                omega,
                &mut core,
                &mut path,
            );
            off += n;
        }
        core * path
    }

    /// Model response at the data.
    pub fn response(&self, mods: &Mods) -> Vec<Complex64> {
        (0..self.f())
            .map(|k| self.eval_at(mods, Some(k), self.omega[k]))
            .collect()
    }

    pub(super) fn residual(&self, mods: &Mods, mask: &[usize], out: &mut Vec<f64>) {
        out.clear();
        for &k in mask {
            let e = (self.g[k] - self.eval_at(mods, Some(k), self.omega[k])) * self.inv_sigma[k];
            out.push(e.re);
            out.push(e.im);
        }
    }

    pub(super) fn v(&self, mods: &Mods, mask: &[usize]) -> f64 {
        let mut r = Vec::with_capacity(2 * mask.len());
        self.residual(mods, mask, &mut r);
        let v: f64 = r.iter().map(|x| x * x).sum();
        if v.is_finite() {
            v
        } else {
            f64::INFINITY
        }
    }

    /// Error measures of a model on all data.
    pub fn measures(&self, mods: &Mods) -> Measures {
        let gm = self.response(mods);
        let mut v = 0.0;
        let mut c2 = 0.0;
        let mut bad = 0usize;
        for (k, gmk) in gm.iter().enumerate() {
            let e = (self.g[k] - gmk).norm();
            v += (e * self.inv_sigma[k]).powi(2);
            let c = e / self.radius[k];
            c2 += c * c;
            if c > 1.0 {
                bad += 1;
            }
        }
        let n = self.f() as f64;
        Measures {
            v,
            misfit_rms: (c2 / n).sqrt(),
            invalid_fraction: bad as f64 / n,
        }
    }

    pub(super) fn invalid_flags(&self, mods: &Mods) -> (Vec<f64>, Vec<bool>) {
        let gm = self.response(mods);
        let c: Vec<f64> = (0..self.f())
            .map(|k| (self.g[k] - gm[k]).norm() / self.radius[k])
            .collect();
        let flags = c.iter().map(|x| *x > 1.0).collect();
        (c, flags)
    }

    /// Joint LM fit of `mods` (all parameters free) on the data in `mask`.
    pub(super) fn refit(&self, mods: &Mods, mask: &[usize]) -> (Mods, f64, DMatrix<f64>) {
        if mods.theta.is_empty() {
            return (mods.clone(), self.v(mods, mask), DMatrix::zeros(0, 0));
        }
        let mut typ = Vec::new();
        let mut off = 0;
        for c in &mods.cands {
            let n = c.n_params();
            typ.extend(c.typ(&mods.theta[off..off + n], self.omega_max()));
            off += n;
        }
        let cands = mods.cands.clone();
        let res = lm(
            |th: &[f64], out: &mut Vec<f64>| {
                let m = Mods {
                    cands: cands.clone(),
                    theta: th.to_vec(),
                };
                self.residual(&m, mask, out)
            },
            &mods.theta,
            &typ,
            80,
        );
        (
            Mods {
                cands: mods.cands.clone(),
                theta: res.theta,
            },
            res.v,
            res.jtj,
        )
    }
}

//! Consistency polish: the least-squares fit moved, inside its own confidence region, towards
//! the data's noise disks.
//!
//! The noise radius `r_k` of a datum bounds its error (`|G_d − G| ≤ r_k`: the envelope of
//! Boulet & Francis is built on that bound), and a model is consistent with the data when at
//! most 5 % of the data lie outside their disks and `misfit_rms ≤ 1`.  The least-squares fit
//! `θ̂` minimizes `V = Σ|e_k|²/σ_k²` (`σ = r/√2`), not the count of data outside their disks:
//! with noise uniform in the disks, the true model has none outside while `θ̂`, having spent
//! `n_θ` degrees of freedom on the noise, may leave 5–7 % just outside (`|e|/r` of 1.0–1.1).
//! Every `θ` with `V(θ) − V(θ̂) ≤ ½ χ²_{n_θ}(0.95)` is as well supported by the data as `θ̂`
//! (the likelihood-ratio 95 % confidence region, `−2 ln L = 2V`); the polish searches that
//! region for a point with fewer data outside their disks:
//!
//! `min_θ  V(θ) + μ² Σ_k max(0, |e_k|/r_k − t)²`,  `t = 0.95`,
//!
//! over every parameter (linear and nonlinear, [`crate::diagnose::lsq::slots`]), by bounded
//! Levenberg–Marquardt from `θ̂`, for `μ = 2, 6, 20, 60` in turn (each from the last), stopping
//! when `V` leaves the region.  The point with the fewest data outside (then the lowest `V`)
//! inside the region is returned.  The information criterion of a model stays that of its
//! least-squares fit; the polish decides only whether the model is consistent.

use crate::diagnose::compare::{MAX_INVALID_FRACTION, MAX_MISFIT_RMS};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::lm::{lm_box, LmSettings};
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::lsq::slots::{
    anchor_value, bounds, design, get_lin, get_nl, set_lin, set_nl, slots, Lin, Nl,
};
use crate::model::physical::PhysicalModel;

/// Hinge threshold `t` on `|e|/r` (a margin below the disk edge, so a datum pushed onto the
/// hinge ends inside its disk).
const HINGE: f64 = 0.95;
/// Penalty weights tried in turn.
const MU: [f64; 4] = [2.0, 6.0, 20.0, 60.0];
/// LM iterations per weight.
const ITER: usize = 60;

/// Upper `p`-quantile of χ² with `nu` degrees of freedom (Wilson & Hilferty 1931: the cube
/// root of `χ²/ν` is nearly normal): at p = 0.95 it is 2.5 % low for ν = 1, 0.51 % for ν = 3
/// and below 0.1 % for ν ≥ 10, where `diagnose` uses it.
pub fn chi2_quantile(nu: f64, z_p: f64) -> f64 {
    let a = 2.0 / (9.0 * nu);
    nu * (1.0 - a + z_p * a.sqrt()).powi(3)
}

/// Standard normal quantile of 0.95.
const Z95: f64 = 1.644_853_626_951_472_2;

struct Param {
    lin: Vec<Lin>,
    nl: Vec<Nl>,
}

impl Param {
    fn model(&self, m: &PhysicalModel, th: &[f64]) -> PhysicalModel {
        let mut mm = m.clone();
        for (s, x) in self.nl.iter().zip(th) {
            set_nl(&mut mm, *s, *x);
        }
        for (s, x) in self.lin.iter().zip(&th[self.nl.len()..]) {
            set_lin(&mut mm, *s, *x);
        }
        mm
    }

    /// Weighted residual rows `(Re, Im)·√2/r` per datum (every channel).
    fn residual(&self, m: &PhysicalModel, th: &[f64], data: &Channels, all: &[usize]) -> Vec<f64> {
        let mut mm = m.clone();
        for (s, x) in self.nl.iter().zip(th) {
            set_nl(&mut mm, *s, *x);
        }
        let (a, y) = design(&mm, &self.lin, data, all);
        let x = nalgebra::DVector::from_column_slice(&th[self.nl.len()..]);
        let e = if self.lin.is_empty() { y } else { y - a * x };
        e.iter().copied().collect()
    }
}

/// `(V, data outside their disks)` from the weighted residual rows.
fn score(e: &[f64]) -> (f64, usize) {
    let v: f64 = e.iter().map(|x| x * x).sum();
    // |e|/r = |(Re, Im)·√2/r| / √2.
    let out = e
        .chunks(2)
        .filter(|c| (c[0] * c[0] + c[1] * c[1]) > 2.0)
        .count();
    (if v.is_finite() { v } else { f64::INFINITY }, out)
}

/// The polish of `m` (a least-squares fit on every datum of `data`, built from the configured
/// model `anchor`, whose boxes it keeps): a model inside the 95 % confidence region of `m`
/// with fewer data outside their disks, or `None` when there is none (see the module
/// documentation).
pub fn polish(m: &PhysicalModel, anchor: &PhysicalModel, data: &Channels) -> Option<PhysicalModel> {
    let (lin, nl) = slots(m, data);
    let par = Param { lin, nl };
    let all: Vec<usize> = (0..data.len()).collect();
    let (w_min, w_max) = (data.omega[0], *data.omega.last()?);
    let mut theta: Vec<f64> = par.nl.iter().map(|s| get_nl(m, *s)).collect();
    theta.extend(par.lin.iter().map(|s| get_lin(m, *s)));
    let n = theta.len();
    if n == 0 {
        return None;
    }
    let (mut lo, mut hi, mut typ) = (Vec::new(), Vec::new(), Vec::new());
    let zeta_lo = |w: f64| crate::diagnose::lsq::resolution::zeta_range(data, w).floor;
    for (s, x) in par.nl.iter().zip(&theta) {
        let (a, b, t) = bounds(m, *s, anchor_value(anchor, m, *s), (w_min, w_max), &zeta_lo);
        lo.push(a.min(*x));
        hi.push(b.max(*x));
        typ.push(t);
    }
    for x in &theta[par.nl.len()..] {
        lo.push(f64::NEG_INFINITY);
        hi.push(f64::INFINITY);
        typ.push(x.abs().max(1e-300));
    }
    let (v0, out0) = score(&par.residual(m, &theta, data, &all));
    if out0 == 0 || !v0.is_finite() {
        return None;
    }
    let budget = v0 + 0.5 * chi2_quantile(n as f64, Z95);
    let n_data = (data.len() * data.n_ch()) as f64;
    let mut best: Option<(usize, f64, Vec<f64>)> = None;
    for mu in MU {
        let f = |th: &[f64], out: &mut Vec<f64>| {
            let e = par.residual(m, th, data, &all);
            out.clear();
            out.extend_from_slice(&e);
            out.extend(e.chunks(2).map(|c| {
                let q = ((c[0] * c[0] + c[1] * c[1]) / 2.0).sqrt();
                mu * (q - HINGE).max(0.0)
            }));
        };
        let res = lm_box(f, &theta, &typ, &lo, &hi, &LmSettings::likelihood(ITER));
        let (v, out) = score(&par.residual(m, &res.theta, data, &all));
        if v > budget {
            break;
        }
        if out < out0 && best.as_ref().is_none_or(|b| (out, v) < (b.0, b.1)) {
            best = Some((out, v, res.theta.clone()));
        }
        // The smallest move that brings the model within the noise is enough.
        if (out as f64) <= MAX_INVALID_FRACTION * n_data
            && v <= MAX_MISFIT_RMS.powi(2) * 2.0 * n_data
        {
            break;
        }
        theta = res.theta;
    }
    best.map(|(_, _, th)| par.model(m, &th))
}

/// The model to judge consistency by: `m` itself when it is consistent or its `misfit_rms`
/// exceeds 1 (no polish can help inside the confidence region), else its polish when that
/// is consistent.  Returns the model and its measures.
pub fn settle(
    m: PhysicalModel,
    anchor: &PhysicalModel,
    data: &Channels,
) -> crate::error::Result<(PhysicalModel, Measures)> {
    let m0 = Problem::new(&m, data)?.measures(&Default::default());
    if m0.consistent() || m0.misfit_rms > MAX_MISFIT_RMS {
        return Ok((m, m0));
    }
    if let Some(p) = polish(&m, anchor, data) {
        let m1 = Problem::new(&p, data)?.measures(&Default::default());
        if m1.consistent() {
            return Ok((p, m1));
        }
    }
    Ok((m, m0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_quantiles_match_the_tables() {
        // χ²_ν(0.95) from scipy.stats.chi2.ppf(0.95, ν): 7.814728 (3), 24.995790 (15),
        // 43.772972 (30), 124.342113 (100).
        for (nu, q) in [
            (3.0, 7.814728),
            (15.0, 24.995790),
            (30.0, 43.772972),
            (100.0, 124.342113),
        ] {
            let got = chi2_quantile(nu, Z95);
            let tol = if nu < 10.0 { 6e-3 } else { 1e-3 };
            assert!(((got - q) / q).abs() < tol, "ν = {nu}: {got} vs {q}");
        }
    }
}

//! The points where the pipeline meets the noise model and the μ test (Theorem 4,
//! [`crate::model::noise`], [`crate::consistency::noisy`], [`crate::mu`]) and the fit of `r`
//! (branch `fit`).  Everything that depends on those modules goes through the functions here.
//!
//! Status: noise and μ are integrated.  Until the fit lands (`INTEGRATION(fit)` markers),
//! the "fit" is a constant unit `r = 1.05·max r_min` (a valid unit of RH∞ that covers every
//! finite datum), clearly labelled as a placeholder in every output.

use crate::consistency::noisy::{gamma_lft, noisy_envelope, BisectionSettings};
use crate::consistency::{noise_free_envelope, Envelope};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::{Config, Factorization};
use crate::mu::{mu_full_scalar, FullPlusScalar, MuSettings};
use crate::system::TransferFunction;
use serde::Serialize;
use serde_json::{json, Value};

/// Per-datum noise radii with the precedence of [`crate::model::noise::resolve_noise`]:
/// `--noise-radius` (or a manifest's per-dataset radius) > the config's `[noise]` > the data
/// file's `noise_radius` column.  `None` (noise-free) when none is given or all are zero.
pub fn noise_radii(config: &Config, data: &FrfData, cli: Option<f64>) -> Result<Option<Vec<f64>>> {
    let radii = crate::model::noise::noise_radii(cli, Some(config), data)?;
    Ok(radii.filter(|r| r.iter().any(|x| *x > 0.0)))
}

/// The envelope of the data: noise-free (Theorem 2 / Theorem 3) when `radii` is `None`,
/// noisy SISO (Theorem 4, bisection on `|r|` of the μ test) otherwise.  Returns the
/// envelope and any warning worth showing.
pub fn envelope(
    f: &Factorization,
    data: &FrfData,
    radii: Option<&[f64]>,
) -> Result<(Envelope, Vec<String>)> {
    match radii {
        None => Ok((noise_free_envelope(f, data)?, Vec::new())),
        Some(r) => {
            let env = noisy_envelope(f, data, r, &BisectionSettings::default())?;
            let inf = env.r_min.iter().filter(|x| x.is_infinite()).count();
            let w = if inf > 0 {
                vec![format!("{inf} datum(s) have r_min = ∞: no r explains them with this noise level and model")]
            } else {
                Vec::new()
            };
            Ok((env, w))
        }
    }
}

/// `μ_Γ{F_L[V(jω_i), φ_i⁻¹]}` per datum for the configured `r` (Theorem 4, Fig. 8), for
/// noisy SISO data; a datum is consistent iff its `μ_Γ > 1`.  `None` for MIMO data.
pub fn mu_per_datum(
    f: &Factorization,
    data: &FrfData,
    radii: &[f64],
    r: &TransferFunction,
) -> Option<Result<Vec<f64>>> {
    if data.outputs() != 1 || data.inputs() != 1 {
        return None;
    }
    let settings = MuSettings::default();
    let out = data
        .omega
        .iter()
        .zip(&data.response)
        .zip(radii)
        .map(|((w, phi), la)| {
            let at = f.at(*w);
            let m =
                gamma_lft(&at, phi[(0, 0)], r.freq(*w), *la).map_err(|e| Error::Assumption {
                    omega: *w,
                    msg: e.message().to_string(),
                })?;
            Ok(mu_full_scalar(&m, FullPlusScalar::gamma(at.m.nrows()), &settings)?.upper)
        })
        .collect();
    Some(out)
}

/// A fitted unit `r` with its certificate, ready to be written as `r.json`.
#[derive(Debug, Clone)]
pub struct FittedR {
    /// The fitted unit.
    pub r: TransferFunction,
    /// The `r.json` document (coefficients, poles, zeros, gain, certificate).
    pub json: Value,
    /// The certificate part of `json`.
    pub certificate: Value,
}

/// A complex number as `[re, im]` in JSON.
#[derive(Serialize)]
struct C2([f64; 2]);

/// Fits the smallest unit `r` above the envelope.
// INTEGRATION(fit): call `fit::...` and take `r.json` from `report::export`.
pub fn fit_r(env: &Envelope, a1: Option<&dyn Fn(f64) -> f64>) -> Result<FittedR> {
    let top = env
        .r_min
        .iter()
        .copied()
        .filter(|r| r.is_finite())
        .fold(0.0f64, f64::max);
    if top <= 0.0 {
        return Err(Error::Invalid(
            "no datum with a finite, positive r_min: nothing to fit".into(),
        ));
    }
    let k = 1.05 * top;
    let r = TransferFunction::gain(k);
    let ratios: Vec<f64> = env
        .r_min
        .iter()
        .filter(|x| x.is_finite() && **x > 0.0)
        .map(|x| k / x)
        .collect();
    let min_ratio = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let a1_ok = match a1 {
        Some(f) => env.omega.iter().all(|w| k < f(*w)),
        None => env
            .a1_limit
            .as_ref()
            .is_none_or(|a| a.iter().all(|l| k < *l)),
    };
    let certificate = json!({
        "covers_all_finite_data": env.r_min.iter().filter(|x| x.is_finite()).all(|x| k > *x),
        "min_ratio_at_data": min_ratio,
        "a1_holds_at_data": a1_ok,
        "infinite_data": env.r_min.iter().filter(|x| x.is_infinite()).count(),
        "dense_grid_checked": false,
    });
    let json = json!({
        "method": "constant_cover_placeholder",
        "note": "placeholder until the fit module lands: r = 1.05 * max finite r_min",
        "num": [k],
        "den": [1.0],
        "gain": k,
        "poles": Vec::<C2>::new(),
        "zeros": Vec::<C2>::new(),
        "certificate": certificate,
    });
    Ok(FittedR {
        r,
        json,
        certificate,
    })
}

/// Writes the exports of a fitted `r` into `dir` and returns the files written.
// INTEGRATION(fit): `report::export` writes r.json, r.m, r.py, r.jl.
pub fn export_r(fit: &FittedR, dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>> {
    let path = dir.join("r.json");
    let text = serde_json::to_string_pretty(&fit.json)
        .map_err(|e| Error::Invalid(format!("r.json: {e}")))?;
    crate::util::write_atomic(&path, text.as_bytes())?;
    Ok(vec![path])
}

//! The noisy SISO envelope over a data set (Theorem 4 of Boulet & Francis 1998, Sec. IV-B):
//! [`r_min_noisy`] per datum, in parallel for large models, with per-datum diagnostics.

use super::{r_min_noisy, BisectionSettings, NoisyDatum, NoisyFailure};
use crate::consistency::envelope::{check_sizes, Envelope, EnvelopeMethod};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::Factorization;
use crate::mu::MuStatus;

/// Per-datum results with the envelope.
#[derive(Debug, Clone)]
pub struct NoisyReport {
    /// The envelope (`method = Theorem4Mu`, `a1_limit` filled).
    pub envelope: Envelope,
    /// One entry per datum.
    pub data: Vec<NoisyDatum>,
}

/// Hears how many data of how many are done (from any thread; the library never prints).
pub type DatumProgressFn<'a> = &'a (dyn Fn(usize, usize) + Sync);

/// What a noisy envelope is told besides its settings, none of it changing the result: who
/// hears of the data done.  `&EnvelopeOptions::default()` (or `&Default::default()`) for none.
#[derive(Clone, Copy, Default)]
pub struct EnvelopeOptions<'a> {
    /// Hears how many data of how many are done.
    pub progress: Option<DatumProgressFn<'a>>,
}

/// The noisy envelope with per-datum diagnostics; see [`noisy_envelope`].  The data are
/// independent, so they are processed in parallel (rayon); the first failing datum in
/// frequency order is the error, as in a sequential loop.  `options.progress` hears of the
/// data done.
pub fn noisy_envelope_report(
    f: &Factorization,
    data: &FrfData,
    radius: &[f64],
    settings: &BisectionSettings,
    options: &EnvelopeOptions<'_>,
) -> Result<NoisyReport> {
    let progress = options.progress;
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    settings.validate()?;
    check_sizes(f, data)?;
    if data.outputs() != 1 || data.inputs() != 1 {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: NoisyFailure::NotSiso.message().to_string(),
        });
    }
    if radius.len() != data.len() {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!("{} noise radii for {} data", radius.len(), data.len()),
        });
    }
    let total = data.len();
    let done = AtomicUsize::new(0);
    let one = |i: usize| -> Result<NoisyDatum> {
        let (omega, la) = (data.omega[i], radius[i]);
        if !(la.is_finite() && la >= 0.0) {
            return Err(Error::Assumption {
                omega,
                msg: format!(
                    "noise radius {la} must be finite and ≥ 0 ({})",
                    data.path.display()
                ),
            });
        }
        let at = f.at(omega);
        let row = r_min_noisy(&at, data.response[i][(0, 0)], la, settings).map_err(|e| {
            Error::Assumption {
                omega,
                msg: format!("{} ({})", e.message(), data.path.display()),
            }
        })?;
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(p) = progress {
            p(d, total);
        }
        Ok(row)
    };
    // Small models stay sequential: a datum costs microseconds there.
    let results: Vec<Result<NoisyDatum>> = if f.states() >= crate::system::linalg::DIAGONAL_FROM {
        (0..total).into_par_iter().map(one).collect()
    } else {
        (0..total).map(one).collect()
    };
    let rows = results.into_iter().collect::<Result<Vec<_>>>()?;
    let envelope = Envelope {
        omega: data.omega.clone(),
        r_min: rows.iter().map(|r| r.r_min).collect(),
        a1_limit: Some(rows.iter().map(|r| r.a1_limit).collect()),
        method: EnvelopeMethod::Theorem4Mu,
    };
    Ok(NoisyReport {
        envelope,
        data: rows,
    })
}

/// The noisy SISO envelope (Theorem 4): per datum, the smallest `|r(jω_i)|` with
/// `μ_Γ{F_L[V(jω_i), φ_i⁻¹]} > 1` for the noise radius `radius[i]` (see [`r_min_noisy`]);
/// `r_min` is 0 inside the noise of the nominal model and `inf` when no admissible `r`
/// (`|r| < σ_min(M̃)`, A1) explains the datum.  Errors: non-SISO data or model, a radius
/// count that does not match, A6/A7 or a singular `M̃` at a datum (naming its frequency), and
/// a `μ` computation that failed numerically (SVD cap or non-finite entries).
pub fn noisy_envelope(
    f: &Factorization,
    data: &FrfData,
    radius: &[f64],
    settings: &BisectionSettings,
    options: &EnvelopeOptions<'_>,
) -> Result<Envelope> {
    let rep = noisy_envelope_report(f, data, radius, settings, options)?;
    for (w, d) in rep.envelope.omega.iter().zip(&rep.data) {
        if matches!(d.mu_status, MuStatus::SvdFailed | MuStatus::NonFinite) {
            return Err(Error::Assumption {
                omega: *w,
                msg: format!(
                    "the μ computation failed ({:?}); check the model and the datum",
                    d.mu_status
                ),
            });
        }
    }
    Ok(rep.envelope)
}

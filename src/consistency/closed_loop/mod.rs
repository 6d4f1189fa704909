//! Closed-loop envelopes (Crowder & de Callafon): per datum, the smallest `|V(jω_i)|`
//! consistent with closed-loop frequency-response data `Φ_i = Y_i/R_i` — noise-free
//! (Theorem 1, Corollaries 1–2, SISO and MIMO) or noisy SISO
//! (Theorem 2).  The result is an ordinary [`Envelope`] (no A1 limit: the closed-loop model
//! has none), so the check, the certified fit and the figures of the open-loop path apply.
//!
//! What is here (the submodules are private; everything below is re-exported here):
//! * the envelope: [`closed_loop_envelope`] ([`ClosedLoopReport`], [`ClosedLoopDatum`]) and
//!   the per-datum `μ` of a given `V`, [`mu_per_datum`];
//! * noise-free data (Theorem 1, Corollaries 1–2): the perturbation [`delta_bar`]
//!   ([`DeltaBar`]) and its identities — [`recover_plant`], [`closed_loop_map`],
//!   [`perturbed_plant`], [`delta_bar_from_plant`], the printed Corollary 1
//!   [`delta_bar_corollary1_printed`], the interconnection [`lft_m`] and [`upper_lft`] of
//!   eq. (6), Theorem 1's [`theorem1_n11`]; thresholds [`UNINFORMATIVE_SENSITIVITY`] and
//!   [`SINGULAR_E`];
//! * noisy SISO data (Theorem 2): [`v_min_noisy`] ([`ClosedLoopNoisyDatum`],
//!   [`NoisyRoute`]) by the closed form [`v_min_eq18`] or a `μ` bisection
//!   [`v_min_mu_bisection`] ([`VBisectionSettings`]) on [`theorem2_g1`] and [`mu_at`].
pub(crate) mod noise_free;
pub(crate) mod noisy;

pub use noise_free::{
    closed_loop_map, delta_bar, delta_bar_corollary1_printed, delta_bar_from_plant, lft_m,
    perturbed_plant, recover_plant, theorem1_n11, upper_lft, DeltaBar, SINGULAR_E,
    UNINFORMATIVE_SENSITIVITY,
};
pub use noisy::{
    mu_at, theorem2_g1, v_min_eq18, v_min_mu_bisection, v_min_noisy, ClosedLoopNoisyDatum,
    NoisyRoute, VBisectionSettings,
};

use super::envelope::{Envelope, EnvelopeMethod};
use crate::data::FrfData;
use crate::error::{Error, Result};
use crate::model::closed_loop::ClosedLoopModel;
use crate::system::TransferFunction;
use serde::Serialize;

/// Per-datum diagnostics of the closed-loop envelope.
#[derive(Debug, Clone, Serialize)]
pub struct ClosedLoopDatum {
    /// Frequency in rad/s.
    pub omega: f64,
    /// Noise-free `σ̄(Δ̄)` at the measured `Φ` (`inf` if no finite `Δ̄`).
    pub delta_bar_norm: f64,
    /// `σ_min(I − ΦC̄)`, the experiment's sensitivity.
    pub sensitivity_sigma_min: f64,
    /// True when the experiment's loop makes the datum uninformative about the plant
    /// (`σ_min(I − ΦC̄) < 1e-8`: `Φ ≈ C̄⁻¹` whatever `P₀`); the open-loop equivalent is
    /// not formed there.
    pub uninformative: bool,
    /// The noisy result, for noisy data.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noisy: Option<ClosedLoopNoisyDatum>,
}

/// The closed-loop envelope with its per-datum diagnostics.
#[derive(Debug, Clone)]
pub struct ClosedLoopReport {
    /// `r_min` holds the smallest `|V|` per datum.
    pub envelope: Envelope,
    /// One entry per datum.
    pub data: Vec<ClosedLoopDatum>,
}

impl ClosedLoopReport {
    /// Frequencies of the uninformative data.
    pub fn uninformative(&self) -> Vec<f64> {
        self.data
            .iter()
            .filter(|d| d.uninformative)
            .map(|d| d.omega)
            .collect()
    }
}

fn check_sizes(model: &ClosedLoopModel, data: &FrfData) -> Result<()> {
    if data.outputs() != model.outputs() || data.inputs() != model.inputs() {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "the closed-loop data are {}×{} (outputs×references) but the plant is {}×{}; fix the data or the [closed_loop] table",
                data.outputs(),
                data.inputs(),
                model.outputs(),
                model.inputs(),
            ),
        });
    }
    Ok(())
}

fn at_or_err(
    model: &ClosedLoopModel,
    data: &FrfData,
    omega: f64,
) -> Result<crate::model::closed_loop::ClosedLoopAt> {
    model.at(omega).ok_or_else(|| Error::Assumption {
        omega,
        msg: format!(
            "D̂, D_c or the experiment controller's denominator is singular here (a pole of P̂, C or C̄ on the axis); drop this datum ({})",
            data.path.display()
        ),
    })
}

/// The closed-loop envelope: noise-free `σ̄(Δ̄)` (Theorem 1) when `radii` is `None`, the
/// noisy SISO `v_min` (Theorem 2) otherwise.  Errors name the file or the frequency.
pub fn closed_loop_envelope(
    model: &ClosedLoopModel,
    data: &FrfData,
    radii: Option<&[f64]>,
    settings: &VBisectionSettings,
) -> Result<ClosedLoopReport> {
    settings.validate()?;
    check_sizes(model, data)?;
    if let Some(r) = radii {
        if data.outputs() != 1 || data.inputs() != 1 {
            return Err(Error::Input {
                path: data.path.to_path_buf(),
                msg: format!(
                    "the noisy closed-loop test (Theorem 2) is for SISO data, these are {}×{}; pass --noise-radius 0 for the noise-free test",
                    data.outputs(),
                    data.inputs(),
                ),
            });
        }
        if r.len() != data.len() {
            return Err(Error::Input {
                path: data.path.to_path_buf(),
                msg: format!("{} noise radii for {} data", r.len(), data.len()),
            });
        }
    }
    let mut rows = Vec::with_capacity(data.len());
    for (i, (&omega, phi)) in data.omega.iter().zip(&data.response).enumerate() {
        let at = at_or_err(model, data, omega)?;
        let nf = delta_bar(&at, phi);
        let noisy = match radii {
            Some(r) => {
                let rho = r[i];
                if !(rho.is_finite() && rho >= 0.0) {
                    return Err(Error::Assumption {
                        omega,
                        msg: format!(
                            "noise radius {rho} must be finite and ≥ 0 ({})",
                            data.path.display()
                        ),
                    });
                }
                Some(v_min_noisy(&at, phi[(0, 0)], rho, settings))
            }
            None => None,
        };
        rows.push(ClosedLoopDatum {
            omega,
            delta_bar_norm: nf.v_min,
            sensitivity_sigma_min: nf.sensitivity_sigma_min,
            uninformative: nf.uninformative,
            noisy,
        });
    }
    let envelope = Envelope {
        omega: data.omega.clone(),
        r_min: rows
            .iter()
            .map(|d| d.noisy.as_ref().map_or(d.delta_bar_norm, |n| n.v_min))
            .collect(),
        a1_limit: None,
        method: if radii.is_some() {
            EnvelopeMethod::ClosedLoopTheorem2
        } else {
            EnvelopeMethod::ClosedLoopTheorem1
        },
    };
    Ok(ClosedLoopReport {
        envelope,
        data: rows,
    })
}

/// `μ_Δs` of Theorem 2 per datum for the weight `V` (noisy SISO data): consistent iff > 1.
pub fn mu_per_datum(
    model: &ClosedLoopModel,
    data: &FrfData,
    radii: &[f64],
    v: &TransferFunction,
) -> Result<Vec<f64>> {
    check_sizes(model, data)?;
    data.omega
        .iter()
        .zip(&data.response)
        .zip(radii)
        .map(|((&w, phi), &rho)| {
            let at = at_or_err(model, data, w)?;
            Ok(match theorem2_g1(&at, phi[(0, 0)], rho) {
                Some(g1) => mu_at(&g1, v.freq(w).norm()),
                None => f64::INFINITY,
            })
        })
        .collect()
}

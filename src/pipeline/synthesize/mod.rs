//! The `rshape synthesize` pipeline: the plant's normalized coprime factors → the
//! Glover–McFarlane optimum `b_opt` and central controller ([`crate::synthesis`]) → the
//! proof by the Theorem 1 test of the stability pipeline ([`super::stability`]) for every
//! bound `r` → exports (`controller.toml` in the form `stability --controller` reads,
//! `controller.json`, `.m`/`.py`/`.jl`, `synthesis.json`, `stability.svg`/`.json`), each
//! written atomically (`exports.rs`); the printed summary is [`text()`] (`text.rs`).

use super::stability::{self as stab, StabilityOutcome};
use crate::error::{Error, Result};
use crate::model::controller::{Controller, Feedback};
use crate::model::Config;
use crate::report::fmt::fmt_g;
use crate::synthesis::{synthesize, GmController};
use crate::system::eig::{eigenvalues, spectral_abscissa};
use crate::system::ncf::NormalizedLcf;
use crate::system::TransferFunction;
use serde::Serialize;
use std::path::Path;
use std::sync::Arc;

mod exports;
mod text;

pub use exports::{controller_toml, method_label, synthesis_json, write_outputs};
pub use text::text;

/// Settings of the synthesis.
#[derive(Debug, Clone)]
pub struct SynthesisSettings {
    /// `γ = gamma_factor · γ_min` (> 1; 1.1 by default, the usual practice).
    pub gamma_factor: f64,
    /// Reduce the controller to this many states by balanced truncation (a stable
    /// controller only); the Theorem 1 proof is then of the reduced controller.
    pub reduce: Option<usize>,
    /// Loop-shaping weights: synthesize for `W₂·G·W₁`, return `W₁·K∞·W₂`.
    pub weights: Option<crate::synthesis::Weights>,
    /// The method: by default the H∞ optimum for a frequency-dependent `r`.
    pub method: Method,
}

/// Which controller to synthesize.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Glover–McFarlane (the optimum for a constant bound) whatever `r`: a closed form,
    /// well conditioned, robust to every `r` in proportion to `b(G,K)`.
    #[default]
    GloverMcfarlane,
    /// The H∞ optimum `min_K ‖r·T‖∞` for the design bound (the fitted `r` when given, else
    /// the configured one) when it is frequency dependent and no weights are given;
    /// Glover–McFarlane otherwise. It maximizes the margin for that `r` only: where `r` is
    /// tiny (a model exact at DC) the controller may give up performance and margin for any
    /// other bound there, so it is asked for explicitly.
    Hinf,
}

impl Default for SynthesisSettings {
    fn default() -> Self {
        Self {
            gamma_factor: 1.1,
            reduce: None,
            weights: None,
            method: Method::GloverMcfarlane,
        }
    }
}

/// The order reduction of the controller.
#[derive(Debug, Clone, Serialize)]
pub struct Reduction {
    /// States of the central controller.
    pub from: usize,
    /// States kept.
    pub to: usize,
    /// Hankel singular values of the central controller.
    pub hankel_singular_values: Vec<f64>,
    /// Glover's bound `2·Σ_{i>to} σᵢ` on `‖K − K_r‖∞`.
    pub error_bound: f64,
}

/// The margin of the synthesized controller for one bound `r`.
#[derive(Debug, Clone, Serialize)]
pub struct BoundResult {
    /// `configured` or `fitted`.
    pub label: String,
    /// Whether `r` is a constant (then the Glover–McFarlane controller is the optimum).
    pub constant: bool,
    /// The best margin any controller attains: `b_opt/|r|` for a constant `r`, `1/γ_opt` of
    /// the H∞ synthesis for the frequency-dependent `r` it was designed for (normalized
    /// factors only).
    pub alpha_opt: Option<f64>,
    /// The Theorem 1 margin `α*` of the synthesized controller (certified lower bound in
    /// `stability.json`).
    pub alpha: f64,
    /// The Theorem 1 verdict for this `r`.
    pub verdict: crate::stability::Verdict,
}

/// Everything the synthesis computed.
#[derive(Debug, Clone)]
pub struct SynthesisOutcome {
    /// `b_opt`, `γ`, the controller.
    pub gm: GmController,
    /// The Theorem 1 test of the controller (the proof).
    pub stability: StabilityOutcome,
    /// One row per bound.
    pub bounds: Vec<BoundResult>,
    /// Poles of the controller.
    pub controller_poles: Vec<num_complex::Complex64>,
    /// Whether the controller is proven robust for every bound given (and stabilizing).
    pub robust: bool,
    /// Notes for the reader (a frequency-dependent `r`, no controller reaching `α ≥ 1`).
    pub notes: Vec<String>,
    /// The order reduction, when asked for and done.
    pub reduction: Option<Reduction>,
    /// The closed loop's figure of merit (sensitivity bandwidth and peak).
    pub merit: crate::synthesis::merit::Merit,
    /// The H∞ synthesis with a frequency-dependent `r` and the label of that `r`, when the
    /// controller comes from it (then `gm.k` is this controller; `gm` keeps `b_opt`).
    pub hinf: Option<(String, crate::synthesis::WeightedController)>,
}

/// The normalized factors the synthesis works on: those of the config's `[plant]`, else
/// those of a minimal realization of the plant `G = C·M̃⁻¹·Ñ·J` of its factors (a `[model]`
/// or the export of a `[physical]` model). Errors (one line) when the plant has no
/// normalized coprime factors (an unstable mode the output does not see).
pub fn plant_factors(config: &Config, path: &Path) -> Result<Arc<NormalizedLcf>> {
    if let Some(ncf) = &config.factorization.realization {
        return Ok(ncf.clone());
    }
    let g = crate::stability::plant_system(&config.factorization)?.minimal(1e-10);
    NormalizedLcf::new(g)
        .map(Arc::new)
        .map_err(|e| Error::Input {
            path: path.to_path_buf(),
            msg: format!("the plant of the factors: {e}"),
        })
}

/// Synthesizes the Glover–McFarlane controller of the config's plant and proves it with the
/// Theorem 1 test for every bound in `rs` (`data` overrides the config's data file for the
/// grid of the figure).
pub fn run(
    config: &Config,
    config_path: &Path,
    rs: &[(String, TransferFunction)],
    settings: &SynthesisSettings,
    data: Option<&Path>,
    controller_path: &Path,
) -> Result<SynthesisOutcome> {
    run_with_stages(
        config,
        config_path,
        rs,
        settings,
        data,
        controller_path,
        &|_| (),
    )
}

/// [`run`], telling `stage` what it starts: the controller, then each stage of its proof
/// ([`stab::run_with_stages`], prefixed `proof: `); on a model of hundreds of modes each is
/// seconds to minutes of dense linear algebra (issue 34).
pub fn run_with_stages(
    config: &Config,
    config_path: &Path,
    rs: &[(String, TransferFunction)],
    settings: &SynthesisSettings,
    data: Option<&Path>,
    controller_path: &Path,
    stage: &dyn Fn(&str),
) -> Result<SynthesisOutcome> {
    let proof_stage = |what: &str| stage(&format!("proof: {what}"));
    let ncf = plant_factors(config, config_path)?;
    for (label, r) in rs {
        if !r.is_unit() {
            return Err(Error::Invalid(format!(
                "the {label} r is not a unit of RH∞ (stable, minimum phase, biproper): Theorem 1 needs one"
            )));
        }
    }
    stage(&format!(
        "the Glover–McFarlane controller ({} plant states: two Riccati equations)",
        ncf.plant.states()
    ));
    let mut gm = match &settings.weights {
        None => synthesize(&ncf, settings.gamma_factor)?,
        Some(w) => {
            let shaped = NormalizedLcf::new(w.shape(&ncf.plant))
                .map_err(|e| Error::Invalid(format!("the shaped plant W2·G·W1: {e}")))?;
            let mut gm = synthesize(&shaped, settings.gamma_factor)?;
            gm.k = w.controller(&gm.k);
            gm
        }
    };
    let shaped = settings.weights.is_some();
    // The design bound: the last one given (the fitted r when there is one).
    let design = rs
        .last()
        .filter(|(_, r)| !shaped && settings.method == Method::Hinf && !is_constant(r));
    let mut fallback = None;
    let hinf = match design {
        Some((label, r)) => {
            let ws = crate::synthesis::WeightedSettings {
                gamma_factor: settings.gamma_factor,
                ..Default::default()
            };
            // A failure falls back to the Glover–McFarlane controller, with a note.
            stage(&format!("the H∞ controller with the {label} r as weight"));
            match crate::synthesis::synthesize_weighted(&ncf, r, &ws) {
                Ok(h) => {
                    // The proof must be able to run on it (a controller spanning many
                    // decades can defeat the loop's eigenvalue iteration): else fall back.
                    let probe = Controller {
                        path: controller_path.to_path_buf(),
                        k: h.k.clone(),
                        feedback: Feedback::Negative,
                    };
                    let probe_stage = |what: &str| stage(&format!("trial proof: {what}"));
                    match stab::run_with_stages(config, &probe, rs, data, &probe_stage) {
                        Ok(_) => {
                            gm.k = h.k.clone();
                            Some((label.clone(), h))
                        }
                        Err(e) => {
                            fallback = Some(format!(
                                "the Theorem 1 test failed on the H∞ controller for the {label} r ({e}); the controller is the Glover–McFarlane one"
                            ));
                            None
                        }
                    }
                }
                Err(e) => {
                    fallback = Some(format!(
                        "the H∞ synthesis with the {label} r failed ({e}); the controller is the Glover–McFarlane one"
                    ));
                    None
                }
            }
        }
        None => None,
    };
    let reduction = match settings.reduce {
        Some(order) if order < gm.k.states() => {
            let from = gm.k.states();
            let abscissa = spectral_abscissa(&eigenvalues(&gm.k.a, "controller poles")?);
            if abscissa.is_nan() || abscissa >= 0.0 {
                return Err(Error::Argument {
                    arg: format!("--reduce {order}"),
                    msg: format!(
                        "the controller is unstable (pole with real part {abscissa:.3e}); balanced truncation needs a stable controller: drop --reduce",
                    ),
                });
            }
            let (kr, hsv) = gm.k.balanced_truncation(order)?;
            gm.k = kr;
            Some(Reduction {
                from,
                to: order,
                error_bound: 2.0 * hsv[order..].iter().sum::<f64>(),
                hankel_singular_values: hsv,
            })
        }
        _ => None,
    };
    let controller = Controller {
        path: controller_path.to_path_buf(),
        k: gm.k.clone(),
        feedback: Feedback::Negative,
    };
    let stability = stab::run_with_stages(config, &controller, rs, data, &proof_stage)?;
    let mut notes: Vec<String> = fallback.into_iter().collect();
    let normalized = config.factorization.realization.is_some();
    if !normalized {
        notes.push(
            "the config's factors are not the normalized ones: the controller maximizes b(G,K) of the plant they define; Theorem 1 margins are with the config's factors".to_string(),
        );
    }
    if shaped {
        notes.push(
            "loop shaping: b_opt and gamma are of the shaped plant W2*G*W1; the proof is of K = W1*Kinf*W2 on the plant".to_string(),
        );
    }
    let mut bounds = Vec::new();
    for (row, (label, r)) in stability.report.margins.iter().zip(rs) {
        let constant = is_constant(r);
        // α* = b(G,K)/|r| holds for normalized factors only.
        let alpha_opt =
            (constant && normalized && !shaped).then(|| gm.b_opt / r.at_infinity().abs());
        if let Some(a) = alpha_opt.filter(|a| *a < 1.0) {
            notes.push(format!(
                "{label} r: no controller reaches alpha >= 1: b_opt = {} < |r| = {} (best alpha {})",
                fmt_g(gm.b_opt),
                fmt_g(r.at_infinity().abs()),
                fmt_g(a)
            ));
        }
        let designed = hinf.as_ref().map(|(l, _)| l.as_str());
        if !constant && normalized && designed.is_none() {
            notes.push(format!(
                "{label} r is frequency dependent: the controller is the Glover–McFarlane optimum for a constant bound; its Theorem 1 margin with this r is {}",
                fmt_g(row.alpha)
            ));
        }
        if let Some(d) = designed.filter(|d| *d != label) {
            notes.push(format!(
                "{label} r: the controller is the H∞ optimum for the {d} r; its Theorem 1 margin with this r is {}",
                fmt_g(row.alpha)
            ));
        }
        let alpha_opt = match &hinf {
            Some((l, h)) if l == label && normalized => {
                if h.alpha_opt < 1.0 {
                    notes.push(format!(
                        "{label} r: no controller reaches alpha >= 1 (best alpha 1/gamma_opt = {})",
                        fmt_g(h.alpha_opt)
                    ));
                }
                Some(h.alpha_opt)
            }
            _ => alpha_opt,
        };
        bounds.push(BoundResult {
            label: label.clone(),
            constant,
            alpha_opt,
            alpha: row.alpha,
            verdict: row.verdict,
        });
    }
    let controller_poles = eigenvalues(&gm.k.a, "controller poles")?;
    let robust = stability.robust;
    let merit = crate::synthesis::merit::merit(&ncf.plant, &gm.k);
    // With [scaling] the controller was designed and proved for G_s = D_o·G·D_i; the outcome
    // holds K = D_i·K_s·D_o, the controller of G itself (what `stability --controller` reads
    // with the same config), for the CLI and the Python package alike.
    if let Some(s) = &config.scaling {
        gm.k = s.unscale_controller(&gm.k);
    }
    Ok(SynthesisOutcome {
        merit,
        gm,
        stability,
        bounds,
        controller_poles,
        robust,
        notes,
        reduction,
        hinf,
    })
}

/// Whether `r` is a constant.
fn is_constant(r: &TransferFunction) -> bool {
    r.num.degree() == 0 && r.den.degree() == 0
}

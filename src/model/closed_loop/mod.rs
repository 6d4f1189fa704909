//! The `[closed_loop]` config table: the controller-dependent coprime-factor uncertainty
//! model of Crowder & de Callafon, eq. (2),
//!
//! ```text
//!   P = N D⁻¹,  N = N̂ + D_c Δ̄,  D = D̂ − N_c Δ̄,  Δ̄ = V Δ,  ‖Δ‖∞ < 1,
//! ```
//!
//! with `(N̂, D̂)` a right coprime factorization (rcf) of the nominal plant `P̂` and
//! `(N_c, D_c)` one of the controller `C` that stabilizes `P̂`; the data come from an
//! experiment with the controller `C̄` (default `C̄ = C`).
//!
//! ```toml
//! [closed_loop]
//! # the nominal plant: `plant` (stable: the trivial rcf (P̂, I) is used) or n_hat + d_hat
//! n_hat = [[{ num = [1], den = [1, 2, 1] }]]
//! d_hat = [[{ num = [1, 0, 0], den = [1, 2, 1] }]]
//! # the controller C: `controller` (stable: (C, I)) or n_c + d_c
//! controller = [[{ num = [40, 20], den = [1, 20] }]]
//! # the experiment's controller C̄ (default C): experiment_controller or experiment_n_c + experiment_d_c
//! experiment_controller = [[{ num = [60, 20], den = [1, 25] }]]
//!
//! [v]                    # the weight V to check (optional, like [r])
//! num = [0.2, 0.1]
//! den = [1, 1]
//! ```
//!
//! At load time both loops `(P̂, C)` and `(P̂, C̄)` are checked for internal stability
//! ([`check_loop`]): the paper needs both (`M` of eq. (6) is stable iff `C̄`
//! stabilizes `P̂`).
//!
//! What is here (the submodules are private; everything below is re-exported here):
//! * the model: [`ClosedLoopModel`] (from the config's [`ClosedLoopSection`] by
//!   [`from_raw`]), its right factors [`RightFactors`] (of a modal nominal model by
//!   [`rcf_from_modal`]) and their values at one frequency, [`ClosedLoopAt`];
//! * internal stability of a loop: [`check_loop`] and [`check_loop_with`] (the route,
//!   [`LoopRoute`]: the scaled determinant [`scaled_determinant`] up to [`MAX_LOOP_SIZE`],
//!   the state-space eigenvalues [`check_lambda`] up to [`MAX_STATES`]), failing with
//!   [`LoopInstability`]; [`is_stable`] for a transfer-function matrix.
pub(crate) mod physical_nominal;
pub(crate) mod stability;
pub(crate) mod stability_ss;

pub use physical_nominal::rcf_from_modal;
pub use stability::{
    check_loop, check_loop_with, is_stable, scaled_determinant, LoopInstability, LoopRoute,
    MAX_LOOP_SIZE,
};
pub use stability_ss::{check_lambda, MAX_STATES};

use super::config::TfEntry;
use crate::system::{TfMatrix, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// Rows of transfer-function entries, as written in the config.
pub type TfRows = Vec<Vec<TfEntry>>;

/// The `[closed_loop]` table as written.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ClosedLoopSection {
    /// The nominal plant `P̂` (`p×m`), when it is stable (rcf `(P̂, I)`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plant: Option<TfRows>,
    /// `N̂` of an rcf of `P̂` (`p×m`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n_hat: Option<TfRows>,
    /// `D̂` of an rcf of `P̂` (`m×m`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d_hat: Option<TfRows>,
    /// The controller `C` (`m×p`) of the uncertainty model, when stable (rcf `(C, I)`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<TfRows>,
    /// `N_c` of an rcf of `C` (`m×p`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n_c: Option<TfRows>,
    /// `D_c` of an rcf of `C` (`p×p`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d_c: Option<TfRows>,
    /// The experiment's controller `C̄`, when stable and different from `C`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub experiment_controller: Option<TfRows>,
    /// `N` of an rcf of `C̄`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub experiment_n_c: Option<TfRows>,
    /// `D` of an rcf of `C̄`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub experiment_d_c: Option<TfRows>,
}

/// A right coprime factorization `K = N·D⁻¹`.
#[derive(Debug, Clone)]
pub struct RightFactors {
    /// Numerator `N`.
    pub n: TfMatrix,
    /// Denominator `D` (square).
    pub d: TfMatrix,
    /// True when this is the trivial `(K, I)` of a stable `K`.
    pub trivial: bool,
}

impl RightFactors {
    /// `N(jω)·D(jω)⁻¹`, `None` where `D(jω)` is singular.
    pub fn value(&self, omega: f64) -> Option<DMatrix<Complex64>> {
        let n = self.n.freq(omega);
        let d = self.d.freq(omega);
        // K = N D⁻¹ ⇔ Kᵀ = D⁻ᵀ Nᵀ: one LU solve.
        let kt = d.transpose().lu().solve(&n.transpose())?;
        let k = kt.transpose();
        k.iter().all(|x| x.is_finite()).then_some(k)
    }
}

/// The built closed-loop uncertainty model (eq. (2)) with the experiment controller.
#[derive(Debug, Clone)]
pub struct ClosedLoopModel {
    /// rcf `(N̂, D̂)` of the nominal plant.
    pub plant: RightFactors,
    /// rcf `(N_c, D_c)` of the controller `C` of the model.
    pub controller: RightFactors,
    /// rcf of the experiment's controller `C̄`.
    pub experiment: RightFactors,
    /// True when `C̄ = C` (no experiment controller given): `M₁₁ = 0` in eq. (6).
    pub same_controller: bool,
}

/// Every factor and the derived transfer matrices at one frequency.
#[derive(Debug, Clone)]
pub struct ClosedLoopAt {
    /// `N̂(jω)` (`p×m`).
    pub n_hat: DMatrix<Complex64>,
    /// `D̂(jω)` (`m×m`).
    pub d_hat: DMatrix<Complex64>,
    /// `N_c(jω)` (`m×p`).
    pub n_c: DMatrix<Complex64>,
    /// `D_c(jω)` (`p×p`).
    pub d_c: DMatrix<Complex64>,
    /// `C(jω) = N_c D_c⁻¹`.
    pub c: DMatrix<Complex64>,
    /// `C̄(jω)`.
    pub c_bar: DMatrix<Complex64>,
    /// `P̂(jω) = N̂ D̂⁻¹`.
    pub p_hat: DMatrix<Complex64>,
    /// True when `C̄ = C`.
    pub same_controller: bool,
}

impl ClosedLoopAt {
    /// The nominal closed-loop map `M₂₂ = (I + P̂C̄)⁻¹P̂` (eq. (6)), `None` if singular.
    pub fn nominal_closed_loop(&self) -> Option<DMatrix<Complex64>> {
        let p = self.p_hat.nrows();
        let s = DMatrix::identity(p, p) + &self.p_hat * &self.c_bar;
        s.lu().solve(&self.p_hat)
    }
}

fn rows_to_tf(rows: &TfRows, name: &str) -> Result<TfMatrix, String> {
    let cols = rows.first().map_or(0, |r| r.len());
    if rows.is_empty() || cols == 0 {
        return Err(format!("[closed_loop] {name} is empty"));
    }
    let mut out = Vec::with_capacity(rows.len());
    for (i, row) in rows.iter().enumerate() {
        if row.len() != cols {
            return Err(format!(
                "[closed_loop] {name}: row {} has {} entries, row 1 has {cols}",
                i + 1,
                row.len()
            ));
        }
        let r: Result<Vec<TransferFunction>, String> = row
            .iter()
            .enumerate()
            .map(|(j, e)| e.to_tf(&format!("[closed_loop] {name}[{}][{}]", i + 1, j + 1)))
            .collect();
        out.push(r?);
    }
    TfMatrix::from_rows(out).ok_or_else(|| format!("[closed_loop] {name} is not rectangular"))
}

/// Builds the rcf of one system from `full` (the system, trivial rcf when stable) or the
/// explicit pair; `what` names the system in messages.
fn factors(
    full: &Option<TfRows>,
    n: &Option<TfRows>,
    d: &Option<TfRows>,
    keys: (&str, &str, &str),
    what: &str,
) -> Result<Option<RightFactors>, String> {
    let (kf, kn, kd) = keys;
    match (full, n, d) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => Err(format!(
            "[closed_loop]: give {what} either as {kf} or as {kn} + {kd}, not both"
        )),
        (None, Some(_), None) => Err(format!("[closed_loop]: {kn} needs {kd}")),
        (None, None, Some(_)) => Err(format!("[closed_loop]: {kd} needs {kn}")),
        (None, None, None) => Ok(None),
        (Some(k), None, None) => {
            let k = rows_to_tf(k, kf)?;
            if k.entries().iter().any(|t| !t.is_proper()) {
                return Err(format!("[closed_loop] {kf}: every entry must be proper"));
            }
            if !stability::is_stable(&k) {
                return Err(format!(
                    "[closed_loop] {kf}: {what} is not stable, so the trivial factorization ({kf}, I) does not exist; give a right coprime factorization as {kn} and {kd} (stable, proper)"
                ));
            }
            let size = k.cols();
            Ok(Some(RightFactors {
                d: TfMatrix::diagonal(vec![TransferFunction::gain(1.0); size]),
                n: k,
                trivial: true,
            }))
        }
        (None, Some(n), Some(d)) => {
            let n = rows_to_tf(n, kn)?;
            let d = rows_to_tf(d, kd)?;
            if d.rows() != d.cols() || d.rows() != n.cols() {
                return Err(format!(
                    "[closed_loop]: {kd} must be square with as many rows as {kn} has columns ({}), got {}×{}",
                    n.cols(),
                    d.rows(),
                    d.cols()
                ));
            }
            for (m, k) in [(&n, kn), (&d, kd)] {
                if m.entries().iter().any(|t| !t.is_proper()) {
                    return Err(format!(
                        "[closed_loop] {k}: the factors must be proper (deg num ≤ deg den in every entry)"
                    ));
                }
            }
            // Stable entries (the message names the entry and its pole), then no common
            // right-half-plane zero would otherwise surface as an "unstable
            // loop" that blames the controller's stabilizing property.
            crate::model::coprime::check_right_coprime(&n, &d, "[closed_loop]", (kn, kd))?;
            Ok(Some(RightFactors {
                n,
                d,
                trivial: false,
            }))
        }
    }
}

impl ClosedLoopModel {
    /// Builds and validates the model from the table: sizes, stable factors, and internal
    /// stability of `(P̂, C)` and `(P̂, C̄)`.  Every message names the key or the loop.
    pub fn build(s: &ClosedLoopSection) -> Result<Self, String> {
        Self::build_with_plant(s, None)
    }

    /// As [`Self::build`], with the nominal's factors given from outside (`[physical]`,
    /// see [`rcf_from_modal`]) when `[closed_loop]` does not give the plant itself.
    pub fn build_with_plant(
        s: &ClosedLoopSection,
        nominal: Option<RightFactors>,
    ) -> Result<Self, String> {
        let own = factors(
            &s.plant,
            &s.n_hat,
            &s.d_hat,
            ("plant", "n_hat", "d_hat"),
            "the nominal plant",
        )?;
        let plant = match (own, nominal) {
            (Some(_), Some(_)) => return Err("[closed_loop]: the nominal plant is given twice, by [physical] and by plant/n_hat/d_hat in [closed_loop]: keep one".into()),
            (Some(f), None) | (None, Some(f)) => f,
            (None, None) => return Err("[closed_loop]: the nominal plant is missing: add plant = [[...]] (stable plant) or n_hat and d_hat (a right coprime factorization), or give it as [physical]".into()),
        };
        let controller = factors(
            &s.controller,
            &s.n_c,
            &s.d_c,
            ("controller", "n_c", "d_c"),
            "the controller C",
        )?
        .ok_or("[closed_loop]: the controller C is missing: add controller = [[...]] (stable controller) or n_c and d_c (a right coprime factorization)")?;
        let experiment = factors(
            &s.experiment_controller,
            &s.experiment_n_c,
            &s.experiment_d_c,
            ("experiment_controller", "experiment_n_c", "experiment_d_c"),
            "the experiment controller C̄",
        )?;
        let same_controller = experiment.is_none();
        let experiment = experiment.unwrap_or_else(|| controller.clone());
        let (p, m) = (plant.n.rows(), plant.n.cols());
        for (k, name) in [
            (&controller, "the controller C"),
            (&experiment, "the experiment controller C̄"),
        ] {
            if k.n.rows() != m || k.n.cols() != p {
                return Err(format!(
                    "[closed_loop]: {name} is {}×{} but the plant is {p}×{m}: a controller maps the {p} output(s) to the {m} input(s) ({m}×{p})",
                    k.n.rows(),
                    k.n.cols()
                ));
            }
        }
        stability::check_loop(&plant.n, &plant.d, &controller.n, &controller.d).map_err(|e| {
            format!("[closed_loop]: the controller C does not stabilize the nominal plant: {e}; the uncertainty model (eq. (2)) needs a stabilizing C")
        })?;
        stability::check_loop(&plant.n, &plant.d, &experiment.n, &experiment.d).map_err(|e| {
            format!("[closed_loop]: the experiment controller C̄ does not stabilize the nominal plant: {e}; M of eq. (6) is then unstable and the data cannot be validated")
        })?;
        Ok(Self {
            plant,
            controller,
            experiment,
            same_controller,
        })
    }

    /// Number of outputs `p`.
    pub fn outputs(&self) -> usize {
        self.plant.n.rows()
    }

    /// Number of inputs `m`.
    pub fn inputs(&self) -> usize {
        self.plant.n.cols()
    }

    /// Every quantity at `s = jω`; `None` where `D̂`, `D_c` or the experiment's denominator is
    /// singular (a pole of `P̂`, `C` or `C̄` on the axis at this frequency).
    pub fn at(&self, omega: f64) -> Option<ClosedLoopAt> {
        let n_hat = self.plant.n.freq(omega);
        let d_hat = self.plant.d.freq(omega);
        let p_hat = self.plant.value(omega)?;
        let c = self.controller.value(omega)?;
        let c_bar = if self.same_controller {
            c.clone()
        } else {
            self.experiment.value(omega)?
        };
        Some(ClosedLoopAt {
            n_hat,
            d_hat,
            n_c: self.controller.n.freq(omega),
            d_c: self.controller.d.freq(omega),
            c,
            c_bar,
            p_hat,
            same_controller: self.same_controller,
        })
    }

    /// The open-loop factorization used by `compare`/`diagnose` (item 6 of issue 9): for
    /// SISO, `P̂ = N̂/D̂` is also a left coprime factorization `M̃⁻¹Ñ` with `M̃ = D̂`,
    /// `Ñ = N̂`; for a stable MIMO nominal with the trivial rcf, `M̃ = I`, `Ñ = P̂`.
    pub fn open_loop_factorization(&self) -> Result<super::Factorization, String> {
        let f = if self.outputs() == 1 && self.inputs() == 1 {
            super::Factorization::standard(self.plant.d.clone(), self.plant.n.clone())
        } else if self.plant.trivial {
            let eye = TfMatrix::diagonal(vec![TransferFunction::gain(1.0); self.outputs()]);
            super::Factorization::standard(eye, self.plant.n.clone())
        } else {
            return Err("[closed_loop]: a MIMO nominal plant given by n_hat/d_hat has no left factorization here; give a stable plant = [[...]] or a SISO plant".into());
        };
        f.map_err(|e| format!("[closed_loop]: {e}"))
    }
}

/// The closed-loop model of a raw config, `None` without `[closed_loop]`.  The nominal
/// plant is given in `[closed_loop]` or, SISO, as `[physical]`.  Errors for the
/// combinations that make no sense: `[closed_loop]` with `[model]`, the nominal given both
/// in `[closed_loop]` and as `[physical]`, `[r]` in a closed-loop config (the weight is `[v]`),
/// `[v]` without `[closed_loop]`.
pub fn from_raw(raw: &super::config::RawConfig) -> Result<Option<ClosedLoopModel>, String> {
    let Some(section) = &raw.closed_loop else {
        if raw.v.is_some() {
            return Err("[v] is the weight of a closed-loop model: add a [closed_loop] table, or use [r] for open-loop data".into());
        }
        return Ok(None);
    };
    if raw.model.is_some() {
        return Err("[closed_loop] gives the nominal plant itself (plant, or n_hat and d_hat, or a SISO [physical]): remove [model]".into());
    }
    if raw.r.is_some() {
        return Err(
            "a closed-loop config is checked against the weight V: rename [r] to [v]".into(),
        );
    }
    if raw.channel.is_some() {
        return Err(
            "[channel] is not supported with [closed_loop]: give the SISO loop's data".into(),
        );
    }
    // A [physical] nominal (item 6 of issue 9: `diagnose` on closed-loop data): its
    // rational export gives the factors.
    let nominal = match &raw.physical {
        Some(ph) => {
            ph.validate()?;
            Some(physical_nominal::rcf_from_modal(&ph.to_factorization()?)?)
        }
        None => None,
    };
    ClosedLoopModel::build_with_plant(section, nominal).map(Some)
}

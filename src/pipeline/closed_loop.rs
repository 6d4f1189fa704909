//! The dispatch on the config kind: "one set of subcommands, the config decides open- or
//! closed-loop".  Every subcommand reads data, computes the envelope and fits through the
//! functions here, which pick the open-loop path (Boulet & Francis) or the closed-loop one
//! (Crowder & de Callafon, [`crate::consistency::closed_loop`]) from `[closed_loop]`.
//!
//! For closed-loop configs the envelope holds the smallest `|V|` per datum, the configured
//! weight `[v]` sits in `Config::r`, and there is no A1 limit (the model of eq. (2) has
//! none), so the check, the certified fit and the figures run unchanged.

use super::integration;
use crate::consistency::closed_loop::noisy::VBisectionSettings;
use crate::consistency::closed_loop::{closed_loop_envelope, mu_per_datum, ClosedLoopReport};
use crate::consistency::Envelope;
use crate::data::FrfData;
use crate::error::Result;
use crate::model::{Config, Factorization};
use crate::system::TransferFunction;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::path::Path;

/// Reads the data file of a config: closed-loop data (FRF or `Y`/`R` spectra) for a
/// closed-loop config, an FRF file otherwise.
pub fn read_data(config: &Config, path: &Path) -> Result<FrfData> {
    if config.closed_loop.is_some() {
        crate::data::closed_loop::read_closed_loop_csv(path)
    } else {
        crate::data::read_frf_csv(path)
    }
}

/// The factorization whose `σ_min(M̃)` bounds the fitted weight (A1), `None` for closed loop.
pub fn a1_factorization(config: &Config) -> Option<&Factorization> {
    config
        .closed_loop
        .is_none()
        .then_some(&config.factorization)
}

/// The envelope of the data for either kind of config, its warnings, and the closed-loop
/// diagnostics (closed-loop configs only).  Callers go through [`super::envelope::envelope`],
/// which resolves the noise radii first.
pub(super) fn envelope_by_kind(
    config: &Config,
    data: &FrfData,
    radii: Option<&[f64]>,
    progress: Option<crate::consistency::DatumProgressFn<'_>>,
) -> Result<(Envelope, Vec<String>, Option<ClosedLoopReport>)> {
    let Some(cl) = &config.closed_loop else {
        let (e, w) = integration::open_loop_envelope(&config.factorization, data, radii, progress)?;
        return Ok((e, w, None));
    };
    let rep = closed_loop_envelope(cl, data, radii, &VBisectionSettings::default())?;
    let mut warnings = Vec::new();
    let inf = rep
        .envelope
        .r_min
        .iter()
        .filter(|x| x.is_infinite())
        .count();
    if inf > 0 {
        warnings.push(format!(
            "{inf} datum(s) have |V|_min = ∞: I + P₀C is singular there (no plant of the set explains them)"
        ));
    }
    let un = rep.uninformative();
    if !un.is_empty() {
        warnings.push(format!(
            "{} datum(s) are uninformative (the experiment's sensitivity I − Φ·C̄ is below 1e-8: Φ ≈ C̄⁻¹ whatever the plant): omega = {}",
            un.len(),
            crate::report::fmt::fmt_omegas(&rep.envelope.omega, &un)
        ));
    }
    Ok((rep.envelope.clone(), warnings, Some(rep)))
}

/// `μ` per datum for the configured weight (noisy SISO data): Theorem 4's `μ_Γ` open-loop,
/// Theorem 2's `μ_Δs` closed-loop.  `None` when not applicable.
pub fn mu(
    config: &Config,
    data: &FrfData,
    radii: &[f64],
    r: &TransferFunction,
) -> Option<Result<Vec<f64>>> {
    match &config.closed_loop {
        None => integration::mu_per_datum(&config.factorization, data, radii, r),
        Some(cl) => {
            (data.outputs() == 1 && data.inputs() == 1).then(|| mu_per_datum(cl, data, radii, r))
        }
    }
}

/// The nominal response drawn against the data in `bode.svg`: `P̂(jω)` open-loop, the
/// nominal closed loop `(I + P̂C̄)⁻¹P̂` (`M₂₂` of eq. (6)) closed-loop.
pub fn nominal_response(config: &Config, omega: f64) -> Option<DMatrix<Complex64>> {
    match &config.closed_loop {
        None => config.factorization.plant(omega),
        Some(cl) => cl.at(omega)?.nominal_closed_loop(),
    }
}

/// Closed-loop data turned into open-loop frequency-response data of the plant (item 6 of
/// issue 9), for `compare` and `diagnose`.
#[derive(Debug, Clone)]
pub struct OpenLoopEquivalent {
    /// `P₀(jω_i) = (I − Φ_iC̄)⁻¹Φ_i`, with the propagated noise radii in `noise_radius`.
    pub data: FrfData,
    /// Frequencies (rad/s) dropped because the experiment's sensitivity `I − ΦC̄` is
    /// singular to working precision there (the plant is not recoverable).
    pub dropped: Vec<f64>,
}

/// The open-loop equivalent of closed-loop data: `P₀ = (I − ΦC̄)⁻¹Φ` per datum, and, when
/// `radii` (radii `ρ` on `Φ`) are given, a radius on `P₀`.
///
/// **First order (MIMO).**  With `S = I − ΦC̄`, `P₀ = S⁻¹Φ` and
/// `dP₀ = S⁻¹·dΦ·(I + C̄P₀)` (differentiate `S·P₀ = Φ`), so
/// `‖dP₀‖ ≤ σ̄(S⁻¹)·σ̄(I + C̄P₀)·ρ` to first order in `ρ`; for SISO, `ρ/|S|²`.
///
/// **Exact (SISO).**  `Φ ↦ Φ/(1 − ΦC̄)` is a Möbius map: it sends the noise disk
/// `|Φ' − Φ| ≤ ρ` onto a disk when `|S| > ρ|C̄|` (`1 − Φ'C̄` then stays away from 0), with
/// radius `ρ/(|S|² − ρ²|C̄|²)` and centre `ρ²|C̄|/(|S|(|S|² − ρ²|C̄|²))` away from `P₀`; the
/// smallest disk about `P₀` that holds it has radius `ρ/(|S|(|S| − ρ|C̄|))`, which is what
/// SISO data get (its first-order term is `ρ/|S|²`; the two differ by the factor
/// `1/(1 − ρ|C̄|/|S|)`).  When `|S| ≤ ρ|C̄|` the disk holds a `Φ'` with `1 = Φ'C̄`: the
/// plant is unbounded within the noise and the datum is dropped.
///
/// Data with `σ_min(S) < 1e-8` (or, SISO, `|S| ≤ ρ|C̄|`) are dropped and listed.
pub fn open_loop_equivalent(
    config: &Config,
    data: &FrfData,
    radii: Option<&[f64]>,
) -> Result<OpenLoopEquivalent> {
    use crate::consistency::closed_loop::noise_free::UNINFORMATIVE_SENSITIVITY;
    use crate::system::linalg::extreme_singular_values;
    let Some(cl) = &config.closed_loop else {
        return Ok(OpenLoopEquivalent {
            data: data.clone(),
            dropped: Vec::new(),
        });
    };
    let mut out = FrfData {
        path: data.path.clone(),
        omega: Vec::new(),
        response: Vec::new(),
        noise_radius: radii.map(|_| Vec::new()),
        lines: Vec::new(),
    };
    let mut dropped = Vec::new();
    for (i, (&w, phi)) in data.omega.iter().zip(&data.response).enumerate() {
        let at = cl.at(w).ok_or_else(|| crate::error::Error::Assumption {
            omega: w,
            msg: format!(
                "the experiment controller has a pole on the axis here; drop this datum ({})",
                data.path.display()
            ),
        })?;
        let p = phi.nrows();
        let s = DMatrix::<Complex64>::identity(p, p) - phi * &at.c_bar;
        let smin = extreme_singular_values(&s).1;
        let p0 = (smin >= UNINFORMATIVE_SENSITIVITY)
            .then(|| s.clone().lu().solve(phi))
            .flatten()
            .filter(|x| x.iter().all(|v| v.is_finite()));
        let Some(p0) = p0 else {
            dropped.push(w);
            continue;
        };
        if let (Some(r), Some(out_r)) = (radii, out.noise_radius.as_mut()) {
            let radius = if p == 1 && at.c_bar.ncols() == 1 {
                let (s_abs, k) = (s[(0, 0)].norm(), r[i] * at.c_bar[(0, 0)].norm());
                if s_abs <= k {
                    dropped.push(w);
                    continue;
                }
                r[i] / (s_abs * (s_abs - k))
            } else {
                let m = at.c_bar.nrows();
                let gain = DMatrix::<Complex64>::identity(m, m) + &at.c_bar * &p0;
                r[i] / smin * extreme_singular_values(&gain).0
            };
            out_r.push(radius);
        }
        out.omega.push(w);
        out.response.push(p0);
        out.lines.push(data.lines.get(i).copied().unwrap_or(0));
    }
    if out.is_empty() {
        return Err(crate::error::Error::Input {
            path: data.path.to_path_buf(),
            msg: "no datum has a recoverable open-loop plant (the experiment's sensitivity is singular everywhere)".into(),
        });
    }
    Ok(OpenLoopEquivalent { data: out, dropped })
}

/// What the open-loop discovery tools (`compare`, `diagnose`) work on: the config, the
/// data and the `--noise-radius` override, after [`discovery_inputs`].
#[derive(Debug, Clone)]
pub struct DiscoveryInputs {
    /// The config; for closed-loop data its noise settings are cleared (they were radii on
    /// `Φ`, now carried by `data.noise_radius`) and `r` is `None` (`[v]` weighs `Δ̄`, not the
    /// factor perturbations of `r`).
    pub config: Config,
    /// Open-loop frequency-response data of the plant, with their noise radii.
    pub data: FrfData,
    /// The `--noise-radius` override to pass on (`None` for closed-loop data: it was a
    /// radius on `Φ` and is in `data.noise_radius` now).
    pub noise_radius: Option<f64>,
    /// The config as written, unchanged (for `diagnose --apply --write`, which writes the
    /// revised model back into it).
    pub raw: crate::model::config::RawConfig,
    /// Frequencies (rad/s) dropped by [`open_loop_equivalent`].
    pub dropped: Vec<f64>,
}

/// Turns (config, data, `--noise-radius`) into what the open-loop discovery tools need:
/// unchanged for an open-loop config; for a closed-loop config, the open-loop equivalent
/// `P₀ = (I − ΦC̄)⁻¹Φ` with the noise radii on `Φ` (`--noise-radius`, `[noise]`, a
/// `noise_radius` column) propagated to `P₀` ([`open_loop_equivalent`]).  This is the one
/// hook `compare` and `diagnose` call before their own entry points (item 6 of issue 9):
/// the nominal `P̂` they compare with is `[physical]` (or the factors of `[closed_loop]`).
pub fn discovery_inputs(
    config: Config,
    data: FrfData,
    noise_radius: Option<f64>,
) -> Result<DiscoveryInputs> {
    let raw = config.raw.clone();
    if config.closed_loop.is_none() {
        return Ok(DiscoveryInputs {
            config,
            data,
            noise_radius,
            raw,
            dropped: Vec::new(),
        });
    }
    let radii = integration::noise_radii(&config, &data, noise_radius)?;
    let eq = open_loop_equivalent(&config, &data, radii.as_deref())?;
    let mut config = config;
    config.raw.noise = Default::default();
    config.noise_std = None;
    config.r = None;
    Ok(DiscoveryInputs {
        config,
        data: eq.data,
        noise_radius: None,
        raw,
        dropped: eq.dropped,
    })
}

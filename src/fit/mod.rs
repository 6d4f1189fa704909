//! Fitting the uncertainty bound: the smallest stable, minimum-phase, biproper `r(s)` (a unit
//! of RH∞) with `|r(jω_i)| ≥ (1+margin)·r_min,i` at every datum, `|r(jω)| < σ_min(M̃(jω))`
//! (A1) on a dense grid when the model is known, and `|r|` above a stated floor everywhere,
//! including `ω = ∞` (Boulet & Francis 1998, the bound of eq. (2) that makes the data
//! consistent; GitHub issue 4).
//!
//! Pipeline, one concept per file:
//! * [`basis`]: prescaling, a partial-fraction basis for `|r|² = A(ω²)/B(ω²)`, the grids;
//! * [`problem`]: the Clarabel LPs (minimax step with free poles, area step with fixed poles);
//! * [`spectral`]: spectral factorization, roots on the axis reported as errors;
//! * [`engine`]: one order — candidates, failures recorded and skipped;
//! * [`between`]: the no-dip rule between data, proved by interval branch-and-bound;
//! * [`certificate`]: dense re-evaluation of the final `r`, refinement, `ucover`-style repair;
//! * [`realization`]: a balanced cascade state-space realization of `r` for the exports;
//! * [`order`]: the order sweep and the automatic order choice;
//! * [`run`]: fit + certificate + exports, for the CLI.
//!
//! Comparisons are written `!(x > y)` on purpose throughout: a NaN must fail a check.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod basis;
pub mod between;
pub mod certificate;
pub(crate) mod chebseries;
pub(crate) mod engine;
pub mod order;
pub(crate) mod polyfit;
pub mod problem;
pub mod realization;
pub mod run;
pub mod spectral;

pub use certificate::Certificate;
pub use order::{fit_auto, OrderRow};
pub use problem::{SolverEvent, SolverStatus};
pub use run::{run_fit, FitOutcome, OrderChoice};
pub use spectral::Zpk;

use crate::consistency::Envelope;
use crate::system::TransferFunction;
use basis::{build_grid, GridSpec, Scaling};
use engine::{fit_order, Prepared, Scored};
use num_complex::Complex64;
use serde::Serialize;

/// What the fit minimizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// Log-Chebyshev: the largest `|r|/r_min` over the data (bisection over LPs, free poles
    /// and zeros), then, at that level, the smallest log-frequency-weighted area.
    #[default]
    Minimax,
    /// The log-frequency-weighted `Σ w_i |r(jω_i)|²/r_min,i²` (LP with fixed poles; the pole
    /// sets tried are the minimax poles, the previous order's and the reference poles), with
    /// `max |r|/r_min` allowed up to `area_slack` times the minimax optimum.
    Area,
}

/// Settings of a fit; [`FitSettings::default`] gives the documented defaults.
#[derive(Debug, Clone, Serialize)]
pub struct FitSettings {
    /// Order of `r` (number of poles = number of zeros).
    pub order: usize,
    /// The objective.
    pub objective: Objective,
    /// Relative margin: `|r(jω_i)| ≥ (1+margin)·r_min,i`.  Default 0.
    pub margin: f64,
    /// Positivity floor: `|r(jω)| ≥ floor_rel·min_i r_min,i` for every `ω`, including `∞`.
    /// Default 1e-3.
    pub floor_rel: f64,
    /// Dense constraint grid density (points per decade).  Default 50.
    pub grid_per_decade: usize,
    /// Decades added to each side of the data band for the positivity and A1 grid.
    /// Default 2.
    pub extend_decades: f64,
    /// Also require `|r| ≥ min(r_min,i, r_min,i+1)` between consecutive data (no dips).
    /// Default true.
    pub no_dip: bool,
    /// A1 back-off: `|r| ≤ (1 − a1_backoff)·σ_min(M̃)`.  Default 1e-6.
    pub a1_backoff: f64,
    /// Relative tolerance of the minimax bisection on `|r|`.  Default 0.002.
    pub bisection_tol: f64,
    /// For [`Objective::Area`]: allowed factor on the minimax `max |r|/r_min`.  Default 2.
    pub area_slack: f64,
    /// Smallest accepted `|Re|/|root|` of a pole or zero.  Default 1e-9.
    pub axis_tol: f64,
    /// Clarabel iteration cap per LP.  Default 200.
    pub max_solver_iter: u32,
    /// Aberth iteration cap per root computation.  Default 500.
    pub root_iter_cap: usize,
    /// Certificate grid density (points per decade).  Default 100.
    pub cert_per_decade: usize,
    /// Fit orders `0..order` first and carry each into the next, so conservatism provably
    /// never increases with the order (2–5× slower).  Default false; [`fit_auto`] always
    /// chains.
    pub chain: bool,
    /// `--order auto`: pick the smallest order whose mean and max `log10(|r|/r_min)` are
    /// within this of the best over the sweep.  Default 0.01 (2.3 %).
    pub auto_tolerance: f64,
}

impl Default for FitSettings {
    fn default() -> Self {
        Self {
            order: 2,
            objective: Objective::Minimax,
            margin: 0.0,
            floor_rel: 1e-3,
            grid_per_decade: 50,
            extend_decades: 2.0,
            no_dip: true,
            a1_backoff: 1e-6,
            bisection_tol: 0.002,
            area_slack: 2.0,
            axis_tol: 1e-9,
            max_solver_iter: 200,
            root_iter_cap: 500,
            cert_per_decade: 100,
            chain: false,
            auto_tolerance: 0.01,
        }
    }
}

/// A certified fit.
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    /// `r(s)` as a transfer function (descending powers of `s`).
    pub r: TransferFunction,
    /// Zeros (rad/s), all with negative real part.
    pub zeros: Vec<Complex64>,
    /// Poles (rad/s), all with negative real part.
    pub poles: Vec<Complex64>,
    /// Gain `r(∞)`: `r(s) = gain·Π(s − z)/Π(s − p)`.
    pub gain: f64,
    /// Order.
    pub order: usize,
    /// The objective.
    pub objective: Objective,
    /// Its value on the data: `max log10(|r|/r_min)` (minimax) or `Σ w_i |r|²/r_min²` (area).
    pub objective_value: f64,
    /// The certificate.
    pub certificate: Certificate,
    /// Which candidate won (`minimax`, `area polish, …`, `order k carried over`).
    pub origin: String,
    /// Every solver call that did not end in `Solved`, and every discarded candidate.
    pub solver_events: Vec<SolverEvent>,
    /// Number of LPs solved.
    pub lp_solves: usize,
    /// The prescaling used.
    pub scaling: Scaling,
    /// The positivity floor on `|r|` (absolute).
    pub floor: f64,
}

/// Why a fit failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum FitError {
    /// Bad input (sizes, ordering, NaN, nothing to cover).
    #[error("{0}")]
    Invalid(String),
    /// `r_min = ∞`: no admissible `r` explains these data.
    #[error("no admissible r explains the data at omega = {} rad/s (r_min = inf): the noise is too large or the model must change", fmt_list(.0))]
    Inadmissible(Vec<f64>),
    /// `r_min ≥ σ_min(M̃)`: A1 and coverage conflict.
    #[error("r_min reaches the A1 limit σ_min(M̃) at omega = {} rad/s: no r can make this nominal model consistent with the data; the model must change", fmt_list(.0))]
    BeyondA1(Vec<f64>),
    /// Every candidate failed (solver statuses and reasons listed).
    #[error("no feasible r of order {order}: {}", .reasons.join("; "))]
    NoFeasibleFit {
        /// Order attempted.
        order: usize,
        /// What went wrong.
        reasons: Vec<String>,
        /// Solver events.
        events: Vec<SolverEvent>,
    },
    /// The best fit failed its certificate even after repair.
    #[error("the fitted r of order {} failed its certificate: {}", .result.order, .reasons.join("; "))]
    Uncertified {
        /// The uncertified fit, for diagnosis only.
        result: Box<FitResult>,
        /// The failed checks.
        reasons: Vec<String>,
    },
}

fn fmt_list(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().take(20).map(|w| format!("{w:.6e}")).collect();
    if v.len() > 20 {
        format!("{} … ({} in all)", s.join(", "), v.len())
    } else {
        s.join(", ")
    }
}

/// The A1 limit `σ_min(M̃(jω))` as a function of ω in rad/s.
pub type A1Fn<'a> = &'a dyn Fn(f64) -> f64;

/// Checked, scaled inputs.
pub(crate) struct Context<'a> {
    pub env: &'a Envelope,
    pub a1: Option<A1Fn<'a>>,
    pub scaling: Scaling,
    pub floor: f64,
    pub prep: Prepared,
}

pub(crate) fn prepare<'a>(
    env: &'a Envelope,
    a1: Option<A1Fn<'a>>,
    set: &FitSettings,
) -> Result<Context<'a>, FitError> {
    let n = env.omega.len();
    if n == 0 || env.r_min.len() != n {
        return Err(FitError::Invalid(format!(
            "the envelope needs one r_min per frequency and at least one datum (got {} frequencies, {} r_min)",
            n,
            env.r_min.len()
        )));
    }
    if let Some(a) = &env.a1_limit {
        if a.len() != n {
            return Err(FitError::Invalid(
                "a1_limit must have one value per datum".into(),
            ));
        }
    }
    for i in 0..n {
        let w = env.omega[i];
        if !(w.is_finite() && w > 0.0) || (i > 0 && !(w > env.omega[i - 1])) {
            return Err(FitError::Invalid(format!(
                "frequencies must be finite, positive and strictly increasing (datum {} at {w})",
                i + 1
            )));
        }
        if env.r_min[i].is_nan() || env.r_min[i] < 0.0 {
            return Err(FitError::Invalid(format!(
                "r_min at omega = {w} is {} (must be ≥ 0 or inf)",
                env.r_min[i]
            )));
        }
    }
    let ok_margin = set.margin >= 0.0 && set.margin.is_finite();
    let ok_floor = set.floor_rel > 0.0 && set.floor_rel < 1.0;
    if !ok_margin || !ok_floor || set.grid_per_decade < 50 || set.cert_per_decade < 50 {
        return Err(FitError::Invalid(
            "settings: margin must be ≥ 0, floor_rel in (0, 1), grid densities ≥ 50 per decade"
                .into(),
        ));
    }
    let inadmissible: Vec<f64> = (0..n)
        .filter(|i| env.r_min[*i].is_infinite())
        .map(|i| env.omega[i])
        .collect();
    if !inadmissible.is_empty() {
        return Err(FitError::Inadmissible(inadmissible));
    }
    let need = 1.0 + set.margin;
    let a1_at = |i: usize| -> Option<f64> {
        match (a1, &env.a1_limit) {
            (Some(f), _) => Some(f(env.omega[i])),
            (None, Some(a)) => Some(a[i]),
            _ => None,
        }
    };
    let beyond: Vec<f64> = (0..n)
        .filter(|i| a1_at(*i).is_some_and(|a| !(env.r_min[*i] * need < a)))
        .map(|i| env.omega[i])
        .collect();
    if !beyond.is_empty() {
        return Err(FitError::BeyondA1(beyond));
    }
    let min_pos = env
        .r_min
        .iter()
        .copied()
        .filter(|r| *r > 0.0)
        .fold(f64::INFINITY, f64::min);
    if !min_pos.is_finite() {
        return Err(FitError::Invalid(
            "every r_min is 0: the data are explained within the noise and need no bound; nothing to fit"
                .into(),
        ));
    }
    let scaling = Scaling::from_data(&env.omega, &env.r_min);
    let floor = set.floor_rel * min_pos;
    let w: Vec<f64> = env.omega.iter().map(|x| x / scaling.omega0).collect();
    let rmin: Vec<f64> = env.r_min.iter().map(|r| r / scaling.rho).collect();
    let safety = 1.0 + 1e-7;
    let lower: Vec<f64> = rmin.iter().map(|r| (r * need * safety).powi(2)).collect();
    // Log-frequency trapezoid weights over the data with a bound.
    let mut weights = vec![0.0; n];
    for i in 0..n {
        if rmin[i] > 0.0 {
            let a = if i > 0 { (w[i] / w[i - 1]).ln() } else { 0.0 };
            let b = if i + 1 < n {
                (w[i + 1] / w[i]).ln()
            } else {
                0.0
            };
            weights[i] = 0.5 * (a + b);
        }
    }
    let total: f64 = weights.iter().sum();
    let cnt = rmin.iter().filter(|r| **r > 0.0).count() as f64;
    for (i, wt) in weights.iter_mut().enumerate() {
        *wt = if total > 0.0 {
            *wt / total
        } else if rmin[i] > 0.0 {
            1.0 / cnt
        } else {
            0.0
        };
    }
    let (o0, rho, back) = (scaling.omega0, scaling.rho, 1.0 - set.a1_backoff);
    let a1_scaled = a1.map(|f| move |wh: f64| (f(wh * o0) * back / rho).powi(2));
    let a1_data: Option<Vec<f64>> = env
        .a1_limit
        .as_ref()
        .map(|a| a.iter().map(|v| (v * back / rho).powi(2)).collect());
    let grid = build_grid(&GridSpec {
        w: &w,
        lower: &lower,
        a1: a1_scaled.as_ref().map(|f| f as &dyn Fn(f64) -> f64),
        a1_data: a1_data.as_deref(),
        floor: (floor / rho).powi(2),
        per_decade: set.grid_per_decade,
        extend_decades: set.extend_decades,
        no_dip: set.no_dip,
    });
    let band = (w[0], w[n - 1]);
    Ok(Context {
        env,
        a1,
        scaling,
        floor,
        prep: Prepared {
            w,
            rmin,
            weights,
            grid,
            band,
        },
    })
}

impl Context<'_> {
    pub(crate) fn cert_input(&self, set: &FitSettings) -> certificate::CertInput<'_> {
        certificate::CertInput {
            omega: &self.env.omega,
            r_min: &self.env.r_min,
            a1: self.a1,
            a1_data: self.env.a1_limit.as_deref(),
            margin: set.margin,
            floor: self.floor,
            per_decade: set.cert_per_decade,
            extend_decades: set.extend_decades,
            no_dip: set.no_dip,
            axis_tol: set.axis_tol,
        }
    }

    /// Certifies the ranked candidates of one order, best first; returns the first that
    /// passes (possibly repaired), or the reasons they all failed.
    pub(crate) fn certify_ranked(
        &self,
        order: usize,
        ranked: &[Scored],
        events: Vec<SolverEvent>,
        lp_solves: usize,
        set: &FitSettings,
    ) -> Result<(FitResult, Scored), FitError> {
        let inp = self.cert_input(set);
        let mut reasons = Vec::new();
        let mut first_failed: Option<FitResult> = None;
        let one = |cand: &Scored| -> (FitResult, Scored) {
            let unscaled = cand.zpk.unscale(self.scaling.omega0, self.scaling.rho);
            let (fixed, cert) = certificate::certify_and_repair(&unscaled, &inp);
            let objective_value = match set.objective {
                Objective::Minimax => cert.max_log10_ratio,
                Objective::Area => cand.area * cert.repair_factor.powi(2),
            };
            let res = FitResult {
                r: TransferFunction::from_zpk(&fixed.zeros, &fixed.poles, fixed.gain),
                zeros: fixed.zeros.clone(),
                poles: fixed.poles.clone(),
                gain: fixed.gain,
                order,
                objective: set.objective,
                objective_value,
                certificate: cert,
                origin: cand.origin.clone(),
                solver_events: events.clone(),
                lp_solves,
                scaling: self.scaling,
                floor: self.floor,
            };
            let mut sc = cand.clone();
            sc.zpk.gain *= res.certificate.repair_factor;
            let sc = self.prep.score(sc.zpk, &sc.origin);
            (res, sc)
        };
        for cand in ranked.iter().take(4) {
            let (res, sc) = one(cand);
            let cert = res.certificate.clone();
            if cert.passed {
                // A candidate repaired after its certificate (a dip between grid points)
                // can end a hair worse than the previous order's r: then that one is kept,
                // so conservatism never increases with the order.
                let carried = ranked
                    .iter()
                    .find(|c| c.origin.ends_with("carried over") && c.origin != cand.origin);
                if let Some(c) = carried {
                    let (cres, csc) = one(c);
                    let (a, b) = (&res.certificate, &cres.certificate);
                    if cres.certificate.passed
                        && (b.max_log10_ratio < a.max_log10_ratio
                            || b.mean_log10_ratio < a.mean_log10_ratio)
                        && b.max_log10_ratio <= a.max_log10_ratio + 1e-6
                    {
                        return Ok((cres, csc));
                    }
                }
                return Ok((res, sc));
            }
            reasons.push(format!("{}: {}", cand.origin, cert.failures.join(", ")));
            if first_failed.is_none() {
                first_failed = Some(res);
            }
        }
        match first_failed {
            Some(r) => Err(FitError::Uncertified {
                result: Box::new(r),
                reasons,
            }),
            None => Err(FitError::NoFeasibleFit {
                order,
                reasons: events
                    .iter()
                    .map(|e| format!("{}: {:?} ({})", e.stage, e.status, e.action))
                    .collect(),
                events,
            }),
        }
    }
}

/// Fits a unit `r(s)` of order `settings.order` above the envelope (see the module doc).
///
/// `a1` is `ω ↦ σ_min(M̃(jω))` when the model is known (for example
/// `|w| factorization.a1_limit(w)`); without it, A1 is taken from `env.a1_limit` at the data
/// (interpolated between them) or not enforced.  With `settings.chain`, orders `0..order` are
/// fitted first and carried forward.  The result is certified; an uncertified fit is an
/// error carrying it.
pub fn fit_unit(
    env: &Envelope,
    a1: Option<A1Fn<'_>>,
    settings: &FitSettings,
) -> Result<FitResult, FitError> {
    let ctx = prepare(env, a1, settings)?;
    match fit_with(&ctx, settings) {
        Err(e) if !settings.chain && settings.order > 0 => {
            // Every candidate of the order alone failed: fit the lower orders and carry
            // them forward (the lower-order r is always a candidate), keeping the events.
            let chained = FitSettings {
                chain: true,
                ..settings.clone()
            };
            fit_with(&ctx, &chained).map(|mut r| {
                r.solver_events.insert(
                    0,
                    SolverEvent {
                        order: settings.order,
                        stage: "order alone".into(),
                        status: SolverStatus::NoCandidate,
                        action: format!("{e}; refitted with the lower orders carried forward"),
                    },
                );
                r
            })
        }
        other => other,
    }
}

fn fit_with(ctx: &Context<'_>, settings: &FitSettings) -> Result<FitResult, FitError> {
    let start = if settings.chain { 0 } else { settings.order };
    let mut prev: Option<Scored> = None;
    let mut masks = (Vec::new(), Vec::new());
    let mut all_events = Vec::new();
    let mut solves = 0;
    let mut last = None;
    for n in start..=settings.order {
        let of = fit_order(&ctx.prep, n, prev.as_ref(), settings, &mut masks);
        all_events.extend(of.events);
        solves += of.lp_solves;
        match ctx.certify_ranked(n, &of.ranked, all_events.clone(), solves, settings) {
            Ok((res, sc)) => {
                prev = Some(sc);
                last = Some(Ok(res));
            }
            Err(e) => {
                last = Some(Err(e));
            }
        }
    }
    last.unwrap_or_else(|| Err(FitError::Invalid("no order fitted".into())))
}

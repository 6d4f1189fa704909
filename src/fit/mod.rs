//! Fitting the uncertainty bound: the smallest stable, minimum-phase, biproper `r(s)` (a unit
//! of RH∞) with `|r(jω_i)| ≥ (1+margin)·r_min,i` at every datum, `|r(jω)| < σ_min(M̃(jω))`
//! (A1) on a dense grid when the model is known, and `|r|` above a stated floor everywhere,
//! including `ω = ∞` (Boulet & Francis 1998, the bound of eq. (2) that makes the data
//! consistent; GitHub issue 4).
//!
//! Pipeline, one concept per file:
//! * `basis`: prescaling, a partial-fraction basis for `|r|² = A(ω²)/B(ω²)`, the grids;
//! * `problem`: the Clarabel LPs (minimax step with free poles, area step with fixed poles);
//! * `spectral`: spectral factorization, roots on the axis reported as errors;
//! * `engine`: one order — candidates, failures recorded and skipped;
//! * `between`: the no-dip rule between data, proved by interval branch-and-bound;
//! * `context`: input checks, prescaling, and the choice among certified candidates;
//! * `a1_proof`: assumption A1 proved on the certificate's band (an `L∞` norm of `M̃⁻¹·r`);
//! * `certificate`: dense re-evaluation of the final `r`, refinement, `ucover`-style repair;
//! * `cutting_plane`: where no candidate of an order certifies because a bound fails
//!   between grid points, those frequencies join the order's grid and it is searched again;
//! * `realization`: a balanced cascade state-space realization of `r` for the exports;
//! * `order`: the order sweep and the automatic order choice;
//! * `run`: fit + certificate + exports, for the CLI;
//! * private: `levelsearch` (the minimax level search of one order in the partial-fraction
//!   basis), `polyfit` with `polyrows` and `chebseries` (the second parametrization: the full
//!   numerator and denominator of `|r̂|²` as Chebyshev series in the disk variable, with an
//!   exact positivity test), `settings_check` ([`FitSettings::validate`]).
//!
//! Comparisons are written `!(x > y)` on purpose throughout: a NaN must fail a check.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub(crate) mod a1_memo;
pub(crate) mod a1_proof;
pub(crate) mod basis;
pub(crate) mod between;
pub(crate) mod certificate;
pub(crate) mod chebseries;
mod context;
mod cutting_plane;
pub(crate) mod engine;
#[doc(hidden)]
pub mod experiment;
mod levelsearch;
pub(crate) mod lower_bound;
mod memo;
pub(crate) mod order;
pub(crate) mod polyfit;
mod polylevel;
mod polyrows;
pub(crate) mod problem;
pub(crate) mod provenance;
pub(crate) mod realization;
pub(crate) mod run;
mod settings_check;
pub(crate) mod spectral;
mod working_set;

pub use a1_proof::A1Proof;
pub use basis::Scaling;
pub use certificate::{certify, CertInput, Certificate};
pub use lower_bound::{proven_gap_line, proven_lower_bounds, ProvenBound};
pub use order::format_table;
pub use order::{fit_auto, OrderRow};
pub use problem::{SolverEvent, SolverStatus};
pub use provenance::{EventKind, Origin, PoleSet};
pub use realization::realize;
pub use run::{events_text, run_fit, work_line, FitOutcome, OrderChoice};
pub use settings_check::MAX_ORDER;
pub use spectral::Zpk;

use crate::consistency::Envelope;
use crate::system::TransferFunction;
use context::{prepare, Context};
use engine::{fit_order, Scored};
use num_complex::Complex64;
use serde::Serialize;

/// What the fit minimizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// Log-Chebyshev: the largest `|r|/r_min` over the data (bisection over LPs, free poles
    /// and zeros; then the log-frequency-weighted area polished at that level with the poles
    /// fixed); among the candidates within the bisection tolerance `log10(1 + bisection_tol)`
    /// of the best max, the smallest mean `log10 |r|/r_min`.  Orders chained (`--order
    /// auto`, [`FitSettings::chain`]) promise: the max never rises with the order; the mean
    /// is the tie-break and may rise only where the max falls by more than that tolerance.
    #[default]
    Minimax,
    /// The log-frequency-weighted `Σ w_i |r(jω_i)|²/r_min,i²` (LP with fixed poles; the pole
    /// sets tried are the minimax poles, the previous order's and the reference poles), with
    /// `max |r|/r_min` allowed up to `area_slack` times the minimax optimum.  Orders chained
    /// promise: neither the max nor the mean rises with the order.
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
    /// Fit orders `0..order` first and carry each into the next, so the objective's promise
    /// about the orders ([`Objective`]) holds by construction (2–5× slower).  Default false; [`fit_auto`] always
    /// chains.
    pub chain: bool,
    /// `--order auto`: pick the smallest order whose max `log10(|r|/r_min)` is within this of
    /// the best over the sweep and whose mean is within this of the best mean of those orders.
    /// Default 0.01 (2.3 %).
    pub auto_tolerance: f64,
    /// The slow reference route, for cross-checks: Clarabel's iterative refinement in every
    /// LP (by default only in the second try of a solve short of `Solved`) and a plain
    /// bisection of the global polynomial candidate from `t = 1` (by default a gallop down
    /// from the best level known). On the shipped examples 0.7–1.6× the LPs, each dearer.
    /// Default false.
    pub thorough: bool,
    /// Cutting-plane rounds per order (`fit::cutting_plane`): when no candidate of an order
    /// certifies and the certificate names frequencies where a bound (A1, or `|r|` above the
    /// envelope between data) fails between the fit's constraint points, those frequencies
    /// become constraint points of that order and the order is searched again, at most this
    /// many times. 0: off. Default 3.
    pub cut_rounds: usize,
    /// Frequencies (rad/s) where `σ_min(M̃(jω))` may dip sharply: the lightly damped zeros
    /// of `M̃` ([`crate::model::Factorization::a1_dips`]). The certificate evaluates A1
    /// there and refines around each, so that a notch narrower than its grid (a mode with
    /// ζ = 1e-7) is not missed. Empty: the grid alone.
    #[serde(skip)]
    pub a1_dips: Vec<f64>,
    /// Realizations of `M̃⁻¹` with which the certificate proves A1 on its band
    /// ([`crate::model::Factorization::a1_inverse_blocks`], converted with `.into()`);
    /// [`A1Proof::Sampled`]: the grid and the dips alone.
    #[serde(skip)]
    pub a1_proof: A1Proof,
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
            thorough: false,
            cut_rounds: 3,
            a1_dips: Vec::new(),
            a1_proof: A1Proof::Sampled,
        }
    }
}

impl FitSettings {
    /// The factor `(1 + bisection_tol)²` on a level `t` (of `|r|²/r_min²`) within which the
    /// searches do not tell levels apart: a level counts as reached by a solution within it,
    /// and the best level known, times it, caps the next candidates' search.
    pub fn level_resolution(&self) -> f64 {
        (1.0 + self.bisection_tol).powi(2)
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
    /// Which candidate won.
    pub origin: Origin,
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

/// What a running fit reports: the library prints nothing, a front end (the CLI) renders it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FitProgress {
    /// The order about to be fitted.
    pub order: usize,
    /// The highest order of this fit.
    pub last_order: usize,
    /// LPs solved so far by this fit.
    pub lp_solves: usize,
}

/// Receives a [`FitProgress`] before each order is fitted.
pub type ProgressFn<'a> = &'a (dyn Fn(FitProgress) + Sync);

/// What a fit is told besides its settings, none of it changing the result: who hears its
/// progress.  `&FitOptions::default()` (or `&Default::default()`) for none.
#[derive(Clone, Copy, Default)]
pub struct FitOptions<'a> {
    /// Hears of each order before it is fitted.
    pub progress: Option<ProgressFn<'a>>,
}

/// Fits a unit `r(s)` of order `settings.order` above the envelope (see the module doc).
///
/// `a1` is `ω ↦ σ_min(M̃(jω))` when the model is known (for example
/// `|w| factorization.a1_limit(w)`); without it, A1 is taken from `env.a1_limit` at the data
/// (interpolated between them) or not enforced.  With `settings.chain`, orders `0..order` are
/// fitted first and carried forward.  The result is certified; an uncertified fit is an
/// error carrying it.  `options.progress` hears of each order before it is fitted.
pub fn fit_unit(
    env: &Envelope,
    a1: Option<A1Fn<'_>>,
    settings: &FitSettings,
    options: &FitOptions<'_>,
) -> Result<FitResult, FitError> {
    let progress = options.progress;
    // Every candidate's certificate asks for A1 on the same grid: evaluate each ω once.
    let memo = a1_memo::A1Memo::new(a1);
    let memoized = |w: f64| memo.eval(w);
    let ctx = prepare(env, memo.wrap(&memoized), settings)?;
    let fit_with =
        |set: &FitSettings, solves_before: usize| fit_with(&ctx, set, progress, solves_before);
    match fit_with(settings, 0) {
        Err(e) if !settings.chain && settings.order > 0 => {
            // Every candidate of the order alone failed: fit the lower orders and carry
            // them forward (the lower-order r is always a candidate), keeping the events.
            let chained = FitSettings {
                chain: true,
                ..settings.clone()
            };
            fit_with(&chained, 0).map(|mut r| {
                r.solver_events.insert(
                    0,
                    SolverEvent {
                        order: settings.order,
                        stage: "order alone".into(),
                        status: SolverStatus::NoCandidate,
                        kind: EventKind::RefittedChained,
                        action: format!("{e}; refitted with the lower orders carried forward"),
                    },
                );
                r
            })
        }
        Ok(alone) if !settings.chain && settings.order > 0 && doubtful(&alone) => {
            // The order alone ended on the constant fallback or after a level search that
            // failed numerically (GitHub issue 11, defect 5: a steep rise made the order-3
            // fit fall back to a constant 6 decades above the data while order 2 reached
            // 0.03 decade).  The chained fit carries the lower orders forward; the better
            // certified of the two is returned.
            let chained = FitSettings {
                chain: true,
                ..settings.clone()
            };
            match fit_with(&chained, alone.lp_solves) {
                Ok(mut c) if c.objective_value < alone.objective_value => {
                    c.solver_events.insert(
                        0,
                        SolverEvent {
                            order: settings.order,
                            stage: "order alone".into(),
                            status: SolverStatus::NoCandidate,
                            kind: EventKind::RefittedChained,
                            action: format!(
                                "level search failed numerically (best alone: {} at {:.4}); refitted with the lower orders carried forward",
                                alone.origin, alone.objective_value
                            ),
                        },
                    );
                    Ok(c)
                }
                // The LPs of the refit count too.
                Ok(c) => Ok(FitResult {
                    lp_solves: c.lp_solves,
                    ..alone
                }),
                Err(_) => Ok(alone),
            }
        }
        other => other,
    }
}

/// True when a fit of one order alone may have missed its optimum for numerical reasons:
/// it ended on the constant fallback, or its level search found no feasible level at all.
fn doubtful(r: &FitResult) -> bool {
    r.origin == Origin::Constant
        || r.solver_events
            .iter()
            .any(|e| e.order == r.order && e.kind == EventKind::NoFeasibleLevel)
}

/// Fits the orders of `settings` (one, or `0..=order` chained); `solves_before` LPs were
/// spent before (a refit) and are counted in the result.
fn fit_with(
    ctx: &Context<'_>,
    settings: &FitSettings,
    progress: Option<ProgressFn<'_>>,
    solves_before: usize,
) -> Result<FitResult, FitError> {
    let start = if settings.chain { 0 } else { settings.order };
    let mut prev: Option<Scored> = None;
    let mut masks = (Vec::new(), Vec::new());
    let mut all_events = Vec::new();
    let mut solves = solves_before;
    let mut last = None;
    for n in start..=settings.order {
        if let Some(p) = progress {
            p(FitProgress {
                order: n,
                last_order: settings.order,
                lp_solves: solves,
            });
        }
        // A failed order's working sets are dropped (see `order::fit_auto`).
        let masks_before = masks.clone();
        let of = fit_order(&ctx.prep, n, prev.as_ref(), settings, &mut masks);
        all_events.extend(of.events);
        solves += of.lp_solves;
        let (first, cuts) = ctx.certify_ranked_cuts(
            n,
            &of.ranked,
            prev.as_ref(),
            settings.objective,
            all_events.clone(),
            solves,
            settings,
        );
        let outcome = match first {
            Err(e) if settings.cut_rounds > 0 && !cuts.is_empty() => cutting_plane::search_again(
                ctx,
                n,
                prev.as_ref(),
                settings,
                cuts,
                e,
                &mut all_events,
                &mut solves,
            ),
            other => other,
        };
        match outcome {
            Ok((res, sc)) => {
                prev = Some(sc);
                last = Some(Ok(res));
            }
            Err(e) => {
                masks = masks_before;
                last = Some(Err(e));
            }
        }
    }
    last.unwrap_or_else(|| Err(FitError::Invalid("no order fitted".into())))
}

//! Checked and scaled inputs of a fit, and the choice among the certified candidates of one
//! order: [`prepare`] validates the envelope and settings and prescales them
//! ([`super::basis`]); [`Context::certify_ranked`] runs the exact certificate
//! ([`super::certificate`]) on the ranked candidates.

use super::basis::{build_grid, GridPoint, GridSpec, Scaling};
use super::engine::{admits, max_tolerance, Prepared, Scored};
use super::provenance::Origin;
use super::{certificate, A1Fn, FitError, FitResult, FitSettings, Objective, SolverEvent};
use crate::consistency::Envelope;
use crate::system::TransferFunction;

/// Checked, scaled inputs.
pub(crate) struct Context<'a> {
    pub env: &'a Envelope,
    pub a1: Option<A1Fn<'a>>,
    pub scaling: Scaling,
    pub floor: f64,
    /// Scaled lower bounds `((1 + margin)·r_min/ρ)²` per datum (with a `1e-7` safety).
    pub lower: Vec<f64>,
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
    set.validate()
        .map_err(|e| FitError::Invalid(e.to_string()))?;
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
    let min_pos = certificate::min_positive(&env.r_min);
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
    let band = (w[0], w[n - 1]);
    let mut ctx = Context {
        env,
        a1,
        scaling,
        floor,
        lower,
        prep: Prepared {
            w,
            rmin,
            weights,
            grid: Vec::new(),
            band,
        },
    };
    ctx.prep.grid = ctx.grid_with_cuts(set, &[]);
    Ok(ctx)
}

impl Context<'_> {
    /// The constraint grid of the fit ([`build_grid`]) with the frequencies `cuts` (rad/s)
    /// added as constraint points (the cutting-plane round, [`super::cutting_plane`]);
    /// `cuts` empty gives the grid of [`prepare`].
    pub(crate) fn grid_with_cuts(&self, set: &FitSettings, cuts: &[f64]) -> Vec<GridPoint> {
        let (o0, rho, back) = (self.scaling.omega0, self.scaling.rho, 1.0 - set.a1_backoff);
        let a1_scaled = self
            .a1
            .map(|f| move |wh: f64| (f(wh * o0) * back / rho).powi(2));
        let a1_data: Option<Vec<f64>> = self
            .env
            .a1_limit
            .as_ref()
            .map(|a| a.iter().map(|v| (v * back / rho).powi(2)).collect());
        let dips: Vec<f64> = set.a1_dips.iter().map(|d| d / o0).collect();
        let cuts: Vec<f64> = cuts.iter().map(|c| c / o0).collect();
        build_grid(&GridSpec {
            w: &self.prep.w,
            lower: &self.lower,
            a1: a1_scaled.as_ref().map(|f| f as &dyn Fn(f64) -> f64),
            a1_data: a1_data.as_deref(),
            floor: (self.floor / rho).powi(2),
            per_decade: set.grid_per_decade,
            extend_decades: set.extend_decades,
            no_dip: set.no_dip,
            a1_dips: &dips,
            cuts: &cuts,
        })
    }

    pub(crate) fn cert_input<'s>(&'s self, set: &'s FitSettings) -> certificate::CertInput<'s> {
        // The same floor as `self.floor` (computed alike in `prepare`).
        certificate::CertInput::of_fit(self.env, self.a1, set)
    }

    /// Certifies the ranked candidates of one order, best first; returns the first that
    /// passes (possibly repaired), or the reasons they all failed.  `prev` is the previous
    /// order's certified `r` of a chained sweep: a certified candidate that the promise of
    /// `guard` does not admit after it ([`admits`], judged on the certified, possibly
    /// repaired figures) is kept only when no admitted one passes.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn certify_ranked(
        &self,
        order: usize,
        ranked: &[Scored],
        prev: Option<&Scored>,
        guard: Objective,
        events: Vec<SolverEvent>,
        lp_solves: usize,
        set: &FitSettings,
    ) -> Result<(FitResult, Scored), FitError> {
        self.certify_ranked_cuts(order, ranked, prev, guard, events, lp_solves, set)
            .0
    }

    /// [`Self::certify_ranked`], and where the candidates that met every bound on the grid
    /// broke one between its points (rad/s, [`super::cutting_plane::cut_frequencies`]): the
    /// cuts of a cutting-plane round.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn certify_ranked_cuts(
        &self,
        order: usize,
        ranked: &[Scored],
        prev: Option<&Scored>,
        guard: Objective,
        events: Vec<SolverEvent>,
        lp_solves: usize,
        set: &FitSettings,
    ) -> (Result<(FitResult, Scored), FitError>, Vec<f64>) {
        let mut cuts = Vec::new();
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
                origin: cand.origin,
                solver_events: events.clone(),
                lp_solves,
                scaling: self.scaling,
                floor: self.floor,
            };
            let mut sc = cand.clone();
            sc.zpk.gain *= res.certificate.repair_factor;
            let sc = Scored {
                attempt: cand.attempt,
                ..self.prep.score(sc.zpk, sc.origin)
            };
            (res, sc)
        };
        // The best ranked candidate, unless its certificate had to repair it (a dip between
        // grid points, fixed by raising the gain): then the next ones and the lower order's
        // r carried over are certified too and the best certified one wins, so a repaired
        // candidate never hides a better one (an order-5 fit went from 0.40 to 0.70 decade
        // that way) and conservatism never increases with the order.
        let carried = ranked
            .iter()
            .position(|c| matches!(c.origin, Origin::CarriedOver { .. }));
        let order_of_trial: Vec<usize> = (0..ranked.len().min(4)).chain(carried).collect();
        let mut best: Option<(FitResult, Scored)> = None;
        let max_tol = max_tolerance(set);
        let admitted = |sc: &Scored| prev.is_none_or(|p| admits(guard, max_tol, p, sc));
        // Admitted first (the carried-over r always is), then the objective, then the mean.
        let better = |(a, sa): (&FitResult, &Scored), (b, sb): (&FitResult, &Scored)| {
            let (x, y) = (a.objective_value, b.objective_value);
            let (ka, kb) = (admitted(sa), admitted(sb));
            (ka && !kb)
                || (ka == kb
                    && (x < y - 1e-12
                        || (x <= y + 1e-12
                            && a.certificate.mean_log10_ratio < b.certificate.mean_log10_ratio)))
        };
        let mut seen = Vec::new();
        for i in order_of_trial {
            if seen.contains(&i) {
                continue;
            }
            seen.push(i);
            let cand = &ranked[i];
            let (res, sc) = one(cand);
            let cert = res.certificate.clone();
            if !cert.passed {
                // Only a candidate that met every bound on the grid failed between its
                // points; any other failed where the grid already holds the bound.
                if super::cutting_plane::met_grid(cand) {
                    cuts.extend(super::cutting_plane::cut_frequencies(&cert));
                }
                reasons.push(format!("{}: {}", cand.origin, cert.failures.join(", ")));
                if first_failed.is_none() {
                    first_failed = Some(res);
                }
                continue;
            }
            let repaired = cert.repair_factor > 1.0 + 1e-12;
            if best
                .as_ref()
                .is_none_or(|(b, sb)| better((&res, &sc), (b, sb)))
            {
                best = Some((res, sc));
            }
            if !repaired && carried.is_none_or(|c| seen.contains(&c)) {
                break;
            }
        }
        let result = match (best, first_failed) {
            (Some(b), _) => Ok(b),
            (None, Some(r)) => Err(FitError::Uncertified {
                result: Box::new(r),
                reasons,
            }),
            (None, None) => Err(FitError::NoFeasibleFit {
                order,
                reasons: events
                    .iter()
                    .map(|e| format!("{}: {:?} ({})", e.stage, e.status, e.action))
                    .collect(),
                events,
            }),
        };
        (result, cuts)
    }
}

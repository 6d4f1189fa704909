//! Levenberg–Marquardt on a real residual vector, with a forward-difference Jacobian and
//! Marquardt's diagonal scaling (invariant to the units of the parameters).

use nalgebra::{DMatrix, DVector};

/// Result of a fit.
#[derive(Debug, Clone)]
pub struct LmResult {
    /// The parameters at the optimum.
    pub theta: Vec<f64>,
    /// Sum of squared residuals.
    pub v: f64,
    /// `JᵀJ` at the optimum (for the covariance `(2JᵀJ)⁻¹` when `v` is a `−ln L`).
    pub jtj: DMatrix<f64>,
    /// The fit gave up (`LmSettings::give_up`): `theta` is where it stopped, not an
    /// optimum.
    pub abandoned: bool,
}

/// When a fit stops.
#[derive(Debug, Clone, Copy)]
pub struct LmSettings {
    /// Most iterations (accepted steps).
    pub max_iter: usize,
    /// Absolute tolerance on the cost: the fit stops once an accepted step, nearly undamped
    /// (damping `λ ≤ 1e-4`) or gaining at most half of the step before, lowered `V` by
    /// less than `v_tol` and the geometric series of
    /// the steps to come (their decrease falling by the ratio of the last two,
    /// `d q/(1 − q)`, an estimate: half of `v_tol` leaves room for its error) is below
    /// `v_tol / 2`.  `0` stops only on a step that gains nothing (relative `1e-12`).
    pub v_tol: f64,
    /// `(k, v)`: give up when the cost is still above `v` after `k` iterations (a fit whose
    /// result only counts below `v`, and that is not getting there).
    pub give_up: Option<(usize, f64)>,
}

impl LmSettings {
    /// `max_iter` iterations, no absolute tolerance.
    pub fn exact(max_iter: usize) -> Self {
        Self {
            max_iter,
            v_tol: 0.0,
            give_up: None,
        }
    }

    /// For a cost that is a `−ln L` (`V = Σ|e|²/σ²`): stop when what is left to gain is
    /// below [`V_TOL`] — a hundredth of a unit of `V`, a thousandth of the smallest BIC
    /// difference `diagnose` acts on (6).
    pub fn likelihood(max_iter: usize) -> Self {
        Self {
            max_iter,
            v_tol: V_TOL,
            give_up: None,
        }
    }
}

/// The absolute cost tolerance of [`LmSettings::likelihood`].
pub const V_TOL: f64 = 1e-2;

/// Damping below which a step counts as Gauss–Newton's own (the tolerance applies).
const LAMBDA_GN: f64 = 1e-4;

/// Minimizes `Σ r(θ)²`.  `typ[i]` is a typical magnitude of `θ_i` (for the finite-difference
/// step).  Deterministic.
pub fn lm<F>(f: F, theta0: &[f64], typ: &[f64], max_iter: usize) -> LmResult
where
    F: Fn(&[f64], &mut Vec<f64>),
{
    let n = theta0.len();
    lm_box(
        f,
        theta0,
        typ,
        &vec![f64::NEG_INFINITY; n],
        &vec![f64::INFINITY; n],
        &LmSettings::exact(max_iter),
    )
}

/// [`lm`] with box bounds `lo ≤ θ ≤ hi`: the start is clamped into the box, a parameter on
/// a bound that the gradient pushes outward is held there for the step (active set), and
/// every trial step is projected onto the box (a step that the projection makes worse is
/// rejected like any other, so `V` never rises).  Where Gauss–Newton converges only
/// linearly (a large residual: two accepted steps in the same direction, the second `ρ`
/// times the first), the sum of the remaining geometric series is tried as one extra point
/// (Aitken's extrapolation of the iterates), kept only when it lowers `V`.
pub fn lm_box<F>(
    f: F,
    theta0: &[f64],
    typ: &[f64],
    lo: &[f64],
    hi: &[f64],
    settings: &LmSettings,
) -> LmResult
where
    F: Fn(&[f64], &mut Vec<f64>),
{
    lm_box_jac(f, &|_, _, _| false, theta0, typ, lo, hi, settings)
}

/// A Jacobian supplied by the caller: `jac(θ, r(θ), J)` fills `J` (`∂r/∂θ`, rows of `r`,
/// one column per parameter) and returns `true`, or returns `false` to have the
/// forward-difference Jacobian used at this point instead.
pub type JacobianFn<'a> = dyn Fn(&[f64], &[f64], &mut DMatrix<f64>) -> bool + 'a;

/// The normal equations supplied by the caller: `normal(θ, r(θ))` returns `(JᵀJ, Jᵀr)` of
/// the residual's Jacobian at `θ` (from a structure the caller knows, without forming the
/// tall `J`: [`crate::diagnose::lsq::varpro::VarPro::normal`]), or `None` to have the
/// Jacobian ([`JacobianFn`], else forward differences) used at this point.
pub type NormalFn<'a> = dyn Fn(&[f64], &[f64]) -> Option<(DMatrix<f64>, DVector<f64>)> + 'a;

/// [`lm_box`] with a Jacobian supplied by the caller (an analytic or variable-projection
/// one, as the retune uses); the forward-difference one wherever `jac` declines.
#[allow(clippy::too_many_arguments)]
pub fn lm_box_jac<F>(
    f: F,
    jac_fn: &JacobianFn<'_>,
    theta0: &[f64],
    typ: &[f64],
    lo: &[f64],
    hi: &[f64],
    settings: &LmSettings,
) -> LmResult
where
    F: Fn(&[f64], &mut Vec<f64>),
{
    lm_box_normal(f, &|_, _| None, jac_fn, theta0, typ, lo, hi, settings)
}

/// [`lm_box_jac`] with the normal equations `(JᵀJ, Jᵀr)` supplied by the caller where it
/// can ([`NormalFn`]); `JᵀJ` and `Jᵀr` from the Jacobian (`jac_fn`, else forward
/// differences) wherever `normal` declines.  Only `JᵀJ` and `Jᵀr` enter a step, so the
/// iteration is the same.
#[allow(clippy::too_many_arguments)]
pub fn lm_box_normal<F>(
    f: F,
    normal: &NormalFn<'_>,
    jac_fn: &JacobianFn<'_>,
    theta0: &[f64],
    typ: &[f64],
    lo: &[f64],
    hi: &[f64],
    settings: &LmSettings,
) -> LmResult
where
    F: Fn(&[f64], &mut Vec<f64>),
{
    let n = theta0.len();
    let mut theta: Vec<f64> = (0..n).map(|i| theta0[i].clamp(lo[i], hi[i])).collect();
    let mut r = Vec::new();
    f(&theta, &mut r);
    let ss = |r: &[f64]| {
        let v: f64 = r.iter().map(|x| x * x).sum();
        if v.is_finite() {
            v
        } else {
            f64::INFINITY
        }
    };
    let mut v = ss(&r);
    let m = r.len();
    // Formed only where the caller's normal equations decline (`m × n` may be large).
    let mut jac = DMatrix::<f64>::zeros(0, n);
    let mut rp = Vec::new();
    let jacobian = |theta: &[f64], r: &[f64], jac: &mut DMatrix<f64>, rp: &mut Vec<f64>| {
        if jac.nrows() != m {
            *jac = DMatrix::zeros(m, n);
        }
        if jac_fn(theta, r, jac) {
            return;
        }
        let mut t = theta.to_vec();
        for i in 0..n {
            let h = 1e-7 * theta[i].abs().max(typ[i]).max(1e-300);
            t[i] = theta[i] + h;
            f(&t, rp);
            for k in 0..m {
                jac[(k, i)] = (rp[k] - r[k]) / h;
            }
            t[i] = theta[i];
        }
    };
    // `(JᵀJ, Jᵀr)` at θ: the caller's, else from the Jacobian (one transposed copy for both
    // products: the blocked product beats dot products).
    let normal_eq = |theta: &[f64], r: &[f64], jac: &mut DMatrix<f64>, rp: &mut Vec<f64>| {
        if let Some(ne) = normal(theta, r) {
            return ne;
        }
        jacobian(theta, r, jac, rp);
        let jt = jac.transpose();
        (&jt * &*jac, &jt * DVector::from_column_slice(r))
    };
    if n == 0 || !v.is_finite() {
        return LmResult {
            theta,
            v,
            jtj: DMatrix::zeros(n, n),
            abandoned: false,
        };
    }
    let (mut jtj, mut g) = normal_eq(&theta, &r, &mut jac, &mut rp);
    let mut lambda = 1e-3;
    let mut trial = Vec::new();
    let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut prev_step: Option<Vec<f64>> = None;
    // The decrease of the last accepted step.
    let mut prev_drop: Option<f64> = None;
    let mut abandoned = false;
    for iter in 0..settings.max_iter {
        if settings
            .give_up
            .is_some_and(|(k, above)| iter == k && v > above)
        {
            abandoned = true;
            break;
        }
        let dmax = (0..n).map(|i| jtj[(i, i)]).fold(0.0, f64::max).max(1e-300);
        // Active bounds: a parameter on a bound that the descent direction pushes outward is
        // held there (its row and column leave the step), so the projection of the step
        // cannot spoil the model's prediction and stall the iteration at growing damping.
        let active: Vec<bool> = (0..n)
            .map(|i| {
                let tol = 1e-12 * (1.0 + theta[i].abs());
                (theta[i] <= lo[i] + tol && g[i] > 0.0) || (theta[i] >= hi[i] - tol && g[i] < 0.0)
            })
            .collect();
        let mut improved = false;
        for _ in 0..12 {
            let mut a = jtj.clone();
            let mut rhs = -&g;
            for i in 0..n {
                a[(i, i)] += lambda * jtj[(i, i)].max(1e-6 * dmax);
            }
            for i in (0..n).filter(|i| active[*i]) {
                a.row_mut(i).fill(0.0);
                a.column_mut(i).fill(0.0);
                a[(i, i)] = 1.0;
                rhs[i] = 0.0;
            }
            let step = match a.cholesky() {
                Some(c) => c.solve(&rhs),
                None => {
                    lambda *= 10.0;
                    continue;
                }
            };
            let cand: Vec<f64> = (0..n)
                .map(|i| (theta[i] + step[i]).clamp(lo[i], hi[i]))
                .collect();
            f(&cand, &mut trial);
            let vt = ss(&trial);
            if vt < v {
                let v_old = v;
                let mut extrapolated = false;
                let mut rel = (v - vt) / v.max(1e-300);
                let taken: Vec<f64> = (0..n).map(|i| cand[i] - theta[i]).collect();
                theta = cand;
                std::mem::swap(&mut r, &mut trial);
                v = vt;
                lambda = (lambda / 3.0).max(1e-12);
                improved = true;
                // Linear convergence (a large-residual problem: Gauss–Newton's steps keep
                // their direction and shrink by a constant ratio ρ): the rest of the series,
                // `δ ρ/(1 − ρ)`, is tried at once and kept when it lowers the cost.
                if let Some(prev) = &prev_step {
                    let dot: f64 = (0..n).map(|i| taken[i] * prev[i]).sum();
                    let (a, b) = (norm(&taken), norm(prev));
                    let rho = a / b;
                    if dot > 0.999 * a * b && rho < 0.99 && rho > 0.3 {
                        let k = rho / (1.0 - rho);
                        let ext: Vec<f64> = (0..n)
                            .map(|i| (theta[i] + k * taken[i]).clamp(lo[i], hi[i]))
                            .collect();
                        f(&ext, &mut trial);
                        let ve = ss(&trial);
                        if ve < v {
                            rel += (v - ve) / v.max(1e-300);
                            extrapolated = true;
                            theta = ext;
                            std::mem::swap(&mut r, &mut trial);
                            v = ve;
                        }
                    }
                }
                prev_step = Some(taken);
                if rel < 1e-12 {
                    improved = false;
                }
                // What is left to gain, when the decreases keep falling by their last ratio.
                // An extrapolated jump is no term of the series: the ratio starts afresh.
                let drop = v_old - v;
                if let Some(p) = prev_drop.filter(|_| !extrapolated) {
                    let q = drop / p;
                    // Near Gauss–Newton's own step, or where the gains fall at least
                    // twofold per step (a minimum at a kink, `|τ|` at 0, approached by
                    // ever shorter damped steps): a damped step with a slowly falling gain
                    // gains little because it is short, not because little is left.
                    let undamped = lambda <= LAMBDA_GN || q <= 0.5;
                    if undamped
                        && drop < settings.v_tol
                        && q < 1.0
                        && drop * q / (1.0 - q) < 0.5 * settings.v_tol
                    {
                        improved = false;
                    }
                }
                prev_drop = (!extrapolated).then_some(drop);
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
        (jtj, g) = normal_eq(&theta, &r, &mut jac, &mut rp);
    }
    LmResult {
        theta,
        v,
        jtj,
        abandoned,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_an_exponential() {
        let xs: Vec<f64> = (0..20).map(|k| k as f64 * 0.1).collect();
        let f = |t: &[f64], r: &mut Vec<f64>| {
            r.clear();
            r.extend(
                xs.iter()
                    .map(|x| t[0] * (-t[1] * x).exp() - 2.0 * (-1.5 * x).exp()),
            );
        };
        let res = lm(f, &[1.0, 0.5], &[1.0, 1.0], 100);
        assert!((res.theta[0] - 2.0).abs() < 1e-6 && (res.theta[1] - 1.5).abs() < 1e-6);
    }

    /// A large-residual fit, where Gauss–Newton converges only linearly: `r(t) = [t,
    /// A − B t²]`, `V = t² + (A − Bt²)²`, has its only minimum at `t = 0` (`V'' = 2 − 4AB > 0`,
    /// no other stationary point for `A < 1/(2B)`), and there Gauss–Newton's steps shrink by
    /// `ρ = −Σ r r''/Σ r'² = 2AB = 0.9`: without the extrapolation the fit takes 213
    /// evaluations (residuals and forward differences) to stop at `t = 9.2e-6`; with it, 81 to
    /// `t = 3.0e-6`.
    #[test]
    fn a_linearly_converging_fit_reaches_the_minimum_in_few_evaluations() {
        let (a, b) = (1.5, 0.3);
        let evals = std::cell::Cell::new(0);
        let f = |t: &[f64], r: &mut Vec<f64>| {
            evals.set(evals.get() + 1);
            r.clear();
            r.extend([t[0], a - b * t[0] * t[0]]);
        };
        let res = lm(f, &[1.0], &[1.0], 400);
        assert!(res.theta[0].abs() < 1e-5, "t = {}", res.theta[0]);
        assert!((res.v - a * a).abs() < 1e-11, "V = {}", res.v);
        assert!(evals.get() < 120, "{} evaluations", evals.get());
    }

    /// The likelihood tolerance stops a linearly converging fit (the function above with
    /// `ρ = 2AB = 0.24`, too fast for the extrapolation) once what is left (the exact
    /// minimum is `V = A²`) is below `V_TOL`, in fewer evaluations than the exact stop.
    #[test]
    fn the_likelihood_tolerance_stops_within_it_of_the_minimum() {
        let (a, b) = (1.5, 0.08);
        let run = |settings: LmSettings| {
            let evals = std::cell::Cell::new(0);
            let f = |t: &[f64], r: &mut Vec<f64>| {
                evals.set(evals.get() + 1);
                r.clear();
                r.extend([t[0], a - b * t[0] * t[0]]);
            };
            let res = lm_box(f, &[1.0], &[1.0], &[-10.0], &[10.0], &settings);
            (res, evals.get())
        };
        let (exact, n_exact) = run(LmSettings::exact(400));
        let (tol, n_tol) = run(LmSettings::likelihood(400));
        assert!(!tol.abandoned && !exact.abandoned);
        assert!(tol.v - a * a < V_TOL, "V = {} (minimum {})", tol.v, a * a);
        assert!(
            tol.v - a * a > 1e-9,
            "it should stop before the exact minimum"
        );
        assert!(n_tol < n_exact, "{n_tol} evaluations, exact {n_exact}");
    }

    /// A minimum at a kink (`r = 100 (1 + |t|)`, as a delay's `|τ|` at 0): the damped
    /// steps shorten and the gradient never vanishes; the likelihood tolerance stops within
    /// it of the minimum, the exact stop crawls on until twelve trials fail.
    #[test]
    fn the_likelihood_tolerance_stops_at_a_kink() {
        let run = |settings: LmSettings| {
            let evals = std::cell::Cell::new(0);
            let f = |t: &[f64], r: &mut Vec<f64>| {
                evals.set(evals.get() + 1);
                r.clear();
                r.push(100.0 * (1.0 + t[0].abs()));
            };
            let res = lm_box(f, &[0.3], &[1.0], &[-1.0], &[1.0], &settings);
            (res, evals.get())
        };
        let (exact, n_exact) = run(LmSettings::exact(80));
        let (tol, n_tol) = run(LmSettings::likelihood(80));
        assert!(tol.v - 1e4 < V_TOL, "V = {}", tol.v);
        assert!(exact.v - 1e4 < tol.v - 1e4, "the exact stop goes further");
        assert!(n_tol < n_exact, "{n_tol} evaluations, exact {n_exact}");
    }

    /// A fit told to give up above a cost it cannot reach stops after the given number of
    /// iterations and says so; one whose threshold it beats runs to the minimum.
    #[test]
    fn a_fit_gives_up_only_above_its_threshold() {
        let iters = std::cell::Cell::new(0);
        let f = |t: &[f64], r: &mut Vec<f64>| {
            iters.set(iters.get() + 1);
            r.clear();
            // Rosenbrock: a curved valley, many iterations from (−1.2, 1).
            r.extend([10.0 * (t[1] - t[0] * t[0]), 1.0 - t[0]]);
        };
        let settings = |above: f64| LmSettings {
            give_up: Some((3, above)),
            ..LmSettings::exact(500)
        };
        let (lo, hi) = ([-5.0, -5.0], [5.0, 5.0]);
        let gave = lm_box(f, &[-1.2, 1.0], &[1.0, 1.0], &lo, &hi, &settings(-1.0));
        assert!(gave.abandoned);
        assert!(gave.v > 1e-3, "V = {}", gave.v);
        let n_gave = iters.replace(0);
        let full = lm_box(f, &[-1.2, 1.0], &[1.0, 1.0], &lo, &hi, &settings(1e6));
        assert!(!full.abandoned);
        assert!(full.v < 1e-20, "V = {}", full.v);
        assert!(n_gave < iters.get(), "{n_gave} vs {}", iters.get());
    }

    #[test]
    fn respects_the_box() {
        // Minimum of (t − 3)² at 3, box [0, 2]: the fit stops on the bound.
        let f = |t: &[f64], r: &mut Vec<f64>| {
            r.clear();
            r.push(t[0] - 3.0);
        };
        let res = lm_box(f, &[0.5], &[1.0], &[0.0], &[2.0], &LmSettings::exact(100));
        assert_eq!(res.theta[0], 2.0);
        assert!((res.v - 1.0).abs() < 1e-12);
    }
}

//! `retune`: the joint refit of a physical model's own parameters on one or several data
//! channels (docs/design/effects.md step 5, and the "retune first" candidate of `diagnose`).
//!
//! The model is linear in its output gains and feedthrough once the poles, the input gains
//! and the path effects are fixed: `G_{oi} = path_{oi}·(Σ_t c_{t,o} b_{t,i} shape_t + D_{oi})`
//! with `shape_t = 1/(m(s² + 2ζω_n s + ω_n²))`, `1/(m s (s + p))` or `1/(m s)`.  So the refit
//! is a variable projection (Golub–Pereyra): the linear parameters are the weighted least
//! squares solution (Householder QR on column-scaled data) for every value of the nonlinear
//! ones, and bounded Levenberg–Marquardt moves only the nonlinear ones:
//!
//! | term | nonlinear parameters | box |
//! |---|---|---|
//! | mode | `ln ω_n`, `ln ζ` | `ω_n₀/1.3 … 1.3ω_n₀` (inside the band for a mode `diagnose` added), `ζ` from the record's floor at the mode ([`super::resolution::zeta_range`]) to 0.7 |
//! | rigid body with friction | `ln p` | a decade either side |
//! | input gains (several inputs) | `b_i`, `i ≥ 2` | two decades, sign kept |
//! | delay | `τ` | `[0, 10 τ₀ + 1/ω_max]` |
//! | lag, NMP zero, ZOH | `ln ω_c`, `ln z`, `ln T` | a decade either side |
//!
//! Output gains (residues) and feedthrough are free (least squares): a gain error of any
//! size, or a sign error, is absorbed in them, so a `gain` or `sign` path effect is kept as
//! it is.  From a rough start (`rough = true`) each mode is first placed by a grid over
//! `ω_n₀/1.3 … 1.3ω_n₀` and five damping values, the residues solved at every point.  The
//! cost is `V = Σ|G_d − G(θ)|²/σ²`, `σ = r/√2`; the refit never raises it.

use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::lm::{lm_box_normal, LmSettings, V_TOL};
use crate::diagnose::lsq::slots::{
    anchor_value, block_matrix, blocks, bounds, design, get_nl, set_lin, set_nl, slots, Lin, Nl,
    MODE_BOX,
};
use crate::diagnose::lsq::varpro::VarPro;
use crate::model::physical::PhysicalModel;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use rayon::prelude::*;

/// Iterations after which [`retune_or_give_up`] gives up a refit still above its cost.
pub(crate) const GIVE_UP_AFTER: usize = 10;

/// Most accepted Levenberg–Marquardt steps of a retune.
pub(crate) const MAX_ITERATIONS: usize = 200;

/// Hears a long retune count what it does (a model of hundreds of modes refits for minutes,
/// issue 34): `(what, done, total)` with `what` one of [`PLACING`] (the rough placement,
/// mode by mode) and [`ITERATING`] (the joint refit's Levenberg–Marquardt iterations, of at
/// most [`MAX_ITERATIONS`]).
pub(crate) type RetuneTell<'a> = &'a (dyn Fn(&'static str, usize, usize) + Sync);

/// What a retune's listener hears during the rough placement (`done` of `total` modes placed;
/// [`crate::diagnose::DiagnoseProgress::Retune`]).
pub const PLACING: &str = "rough placement, mode";

/// What a retune's listener hears during the joint refit (iteration `done` of at most `total`;
/// [`crate::diagnose::DiagnoseProgress::Retune`]).
pub const ITERATING: &str = "joint refit, iteration";

/// The result of a refit.
#[derive(Debug, Clone)]
pub struct NominalRefit {
    /// The refit model.
    pub model: PhysicalModel,
    /// Number of refit parameters (linear and nonlinear).
    pub n_params: usize,
    /// Cost before (on the fitted data).
    pub v_before: f64,
    /// Cost after (≤ `v_before`).
    pub v_after: f64,
}

/// Weighted LS of the linear slots of `m` (nonlinear ones fixed) on the data at `mask`:
/// writes the solution into `m` and returns the cost.
fn solve_linear(m: &mut PhysicalModel, lin: &[Lin], data: &Channels, mask: &[usize]) -> f64 {
    let v = solve_linear_res(m, lin, data, mask).norm_squared();
    if v.is_finite() {
        v
    } else {
        f64::INFINITY
    }
}

/// [`solve_linear`], returning the weighted residual (real and imaginary parts).
pub(crate) fn solve_linear_res(
    m: &mut PhysicalModel,
    lin: &[Lin],
    data: &Channels,
    mask: &[usize],
) -> DVector<f64> {
    let (a, y) = design(m, lin, data, mask);
    let n = lin.len();
    let rows_per_ch = 2 * mask.len();
    let mut x = DVector::<f64>::zeros(n);
    for (chs, cols) in blocks(lin, data) {
        if cols.is_empty() {
            continue;
        }
        let (rows, ab) = block_matrix(&a, &chs, &cols, rows_per_ch);
        let yb = DVector::from_fn(rows.len(), |i, _| y[rows[i]]);
        for (j, xj) in cols.iter().zip(qr_solve(ab, yb).iter()) {
            x[*j] = *xj;
        }
    }
    for (j, l) in lin.iter().enumerate() {
        if !x[j].is_finite() {
            x[j] = 0.0;
        }
        set_lin(m, *l, x[j]);
    }
    &y - &a * &x
}

/// Least squares `min ‖y − A x‖`: column scaling, then Householder QR; a column with a
/// negligible pivot is dropped (its parameter set to 0), so a rank-deficient basis cannot
/// blow up.
fn qr_solve(mut a: DMatrix<f64>, y: DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let scale = crate::system::linalg::equilibrate_columns(&mut a);
    if a.nrows() < n {
        let mut x = min_norm_solve(a, y);
        for (xi, s) in x.iter_mut().zip(&scale) {
            *xi /= s;
        }
        return x;
    }
    let qr = a.qr();
    let r = qr.r();
    // Qᵀy by the Householder reflections (no explicit Q).
    let mut qty = y;
    qr.q_tr_mul(&mut qty);
    // At least as many rows as parameters here (fewer went to `min_norm_solve`).
    let k = r.nrows().min(n);
    let rmax = (0..k).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    let mut x = DVector::<f64>::zeros(n);
    for i in (0..k).rev() {
        if r[(i, i)].abs() <= 1e-12 * rmax {
            continue;
        }
        let mut acc = qty[i];
        for j in i + 1..n {
            acc -= r[(i, j)] * x[j];
        }
        x[i] = acc / r[(i, i)];
    }
    for (xi, s) in x.iter_mut().zip(&scale) {
        *xi /= s;
    }
    x
}

/// More parameters than rows (a 1000-mode model on 200 data, issue 34): the least-norm
/// solution of `A x = y` (in the equilibrated columns), `Aᵀ = Q R`, `Rᵀ z = y`, `x = Q z`,
/// which fits every row when `A` has full row rank (a row with a negligible pivot is left
/// unfitted). Every column takes part, where the basic solution of the square QR kept the
/// first `rows` columns only (the modes of the lowest frequencies, badly conditioned on the
/// whole band).
fn min_norm_solve(a: DMatrix<f64>, y: DVector<f64>) -> DVector<f64> {
    let rows = a.nrows();
    let qr = a.transpose().qr();
    let r = qr.r();
    let rmax = (0..rows).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    // Rᵀ z = y, forward substitution.
    let mut z = DVector::<f64>::zeros(rows);
    for i in 0..rows {
        // A NaN pivot counts as negligible too.
        if r[(i, i)].abs().is_nan() || r[(i, i)].abs() <= 1e-12 * rmax {
            continue;
        }
        let mut acc = y[i];
        for j in 0..i {
            acc -= r[(j, i)] * z[j];
        }
        z[i] = acc / r[(i, i)];
    }
    qr.q() * z
}

/// Cost `V` of `m` on the data at `mask`.
pub fn cost(m: &PhysicalModel, data: &Channels, mask: &[usize]) -> f64 {
    let mut v = 0.0;
    for k in mask {
        let g = m.eval(data.omega[*k]);
        for (ch, e) in data.entries.iter().enumerate() {
            v += 2.0 * ((data.g[ch][*k] - g[*e]).norm() / data.radius[ch][*k]).powi(2);
        }
    }
    if v.is_finite() {
        v
    } else {
        f64::INFINITY
    }
}

/// Refits every parameter of `m` jointly on the data at `mask` (all data when `None`); with
/// `rough`, each mode is first placed by a grid (see the module documentation).  The boxes
/// are around the values of `m` itself: [`retune_within`] with `m` as its own anchor.
pub fn retune(
    m: &PhysicalModel,
    data: &Channels,
    mask: Option<&[usize]>,
    rough: bool,
) -> NominalRefit {
    retune_within(m, m, data, mask, rough)
}

/// [`retune`] on every datum, telling `tell` its counts ([`RetuneTell`]): the root of
/// `diagnose`, the one refit a large model is silent in for minutes otherwise.
pub(crate) fn retune_telling(
    m: &PhysicalModel,
    data: &Channels,
    rough: bool,
    tell: RetuneTell<'_>,
) -> NominalRefit {
    refit_holding(m, m, data, None, rough, None, &[], Some(tell)).0
}

/// [`retune`] with the boxes of the configured parameters around their values in `anchor`,
/// the configured model `m` was built from (effects added to it keep boxes around their
/// current values).  A chain of refits (every node of the search, the holdouts) then cannot
/// walk a configured mode, box by box, away from where the user put it.
pub fn retune_within(
    m: &PhysicalModel,
    anchor: &PhysicalModel,
    data: &Channels,
    mask: Option<&[usize]>,
    rough: bool,
) -> NominalRefit {
    retune_or_give_up(m, anchor, data, mask, rough, None).0
}

/// [`retune_within`] on every datum that gives up when its cost is still above `give_up`
/// after [`GIVE_UP_AFTER`] iterations: the refit and whether it gave up (then the model is
/// where the fit stopped).  For a refit whose result counts only below a known cost (a
/// child of the search against its reference).
pub(crate) fn retune_or_give_up(
    m: &PhysicalModel,
    anchor: &PhysicalModel,
    data: &Channels,
    mask: Option<&[usize]>,
    rough: bool,
    give_up: Option<f64>,
) -> (NominalRefit, bool) {
    refit_holding(m, anchor, data, mask, rough, give_up, &[], None)
}

/// [`retune_within`] on every datum with the nonlinear slots `hold` kept at their values in
/// `m` (a profile of the likelihood in one parameter, [`super::profile`]).
pub(crate) fn retune_holding(
    m: &PhysicalModel,
    anchor: &PhysicalModel,
    data: &Channels,
    hold: &[Nl],
) -> NominalRefit {
    refit_holding(m, anchor, data, None, false, None, hold, None).0
}

#[allow(clippy::too_many_arguments)]
fn refit_holding(
    m: &PhysicalModel,
    anchor: &PhysicalModel,
    data: &Channels,
    mask: Option<&[usize]>,
    rough: bool,
    give_up: Option<f64>,
    hold: &[Nl],
    tell: Option<RetuneTell<'_>>,
) -> (NominalRefit, bool) {
    let tell = |what: &'static str, done: usize, total: usize| {
        if let Some(t) = tell {
            t(what, done, total);
        }
    };
    let all: Vec<usize> = (0..data.len()).collect();
    let mask = mask.unwrap_or(&all);
    let (lin, mut nl) = slots(m, data);
    nl.retain(|s| !hold.contains(s));
    // On part of the band (a holdout fit), a mode resonating outside that part is not
    // identified there: its ω_n and ζ keep their values.
    if mask.len() < data.len() && !mask.is_empty() {
        let lo = mask
            .iter()
            .map(|k| data.omega[*k])
            .fold(f64::INFINITY, f64::min)
            / 1.25;
        let hi = mask.iter().map(|k| data.omega[*k]).fold(0.0, f64::max) * 1.25;
        nl.retain(|s| match s {
            Nl::ModeW(i) | Nl::ModeZ(i) => (lo..=hi).contains(&m.mode[*i].omega_n),
            _ => true,
        });
    }
    let v_before = cost(m, data, mask);
    let w_min = data.omega[0];
    let w_max = *data.omega.last().expect("data");
    let mut start = m.clone();
    let mut v_start = solve_linear(&mut start, &lin, data, mask);
    // Settled: the linear slots alone already fit the data below what the Levenberg–Marquardt
    // stopping rule acts on, or they are at least as many as the real data values (1000
    // modes on 200 data, issue 34): then no ω_n, ζ or other nonlinear parameter is
    // identified by the data, and each grid point and finite-difference Jacobian column would
    // be a full rank-deficient least squares (hours at that size). The linear least-norm
    // solution is the refit.
    let settled = v_start < V_TOL || lin.len() >= 2 * mask.len() * data.n_ch();
    if rough && !settled {
        for i in 0..m.mode.len() {
            let (w0, z0) = (start.mode[i].omega_n, start.mode[i].zeta);
            let mut best = (v_start, w0, z0);
            let grid: Vec<(f64, f64)> = (0..33)
                .flat_map(|j| {
                    let w = w0 * MODE_BOX.powf(-1.0 + j as f64 / 16.0);
                    [z0, 0.003, 0.01, 0.03, 0.1].map(|z| (w, z))
                })
                .collect();
            // The other columns factored once, each grid point's cost from the mode's own
            // columns projected off them ([`crate::diagnose::lsq::mode_grid::ModeGrid`]); the full least
            // squares at every point where they are rank-deficient.  The points are
            // independent: costed in parallel, the best taken in grid order as before.
            let fast = crate::diagnose::lsq::mode_grid::ModeGrid::new(&start, i, &lin, data, mask);
            let costs: Vec<f64> = grid
                .par_iter()
                .map(|&(w, z)| match &fast {
                    Some(g) => g.cost(w, z),
                    None => {
                        let mut t = start.clone();
                        t.mode[i].omega_n = w;
                        t.mode[i].zeta = z;
                        solve_linear(&mut t, &lin, data, mask)
                    }
                })
                .collect();
            for (&(w, z), &v) in grid.iter().zip(&costs) {
                if v < best.0 {
                    best = (v, w, z);
                }
            }
            start.mode[i].omega_n = best.1;
            start.mode[i].zeta = best.2;
            v_start = solve_linear(&mut start, &lin, data, mask);
            tell(PLACING, i + 1, m.mode.len());
        }
    }
    let theta0: Vec<f64> = nl.iter().map(|s| get_nl(&start, *s)).collect();
    let (mut lo, mut hi, mut typ) = (Vec::new(), Vec::new(), Vec::new());
    let zeta_lo = |w: f64| super::resolution::zeta_range(data, w).floor;
    for s in &nl {
        // Bounds around the configured value, so a rough start may not wander further.
        let (a, b, t) = bounds(m, *s, anchor_value(anchor, m, *s), (w_min, w_max), &zeta_lo);
        lo.push(a);
        hi.push(b);
        typ.push(t);
    }
    let model_at = |th: &[f64]| {
        let mut mm = start.clone();
        for (s, x) in nl.iter().zip(th) {
            set_nl(&mut mm, *s, *x);
        }
        let v = solve_linear(&mut mm, &lin, data, mask);
        (mm, v)
    };
    let mut abandoned = false;
    let best = if nl.is_empty() || settled {
        (start.clone(), v_start)
    } else {
        // VarPro residual: the weighted complex error with the linear slots solved.
        let resid = |th: &[f64], out: &mut Vec<f64>| {
            let mut mm = start.clone();
            for (s, x) in nl.iter().zip(th) {
                set_nl(&mut mm, *s, *x);
            }
            out.clear();
            out.extend(solve_linear_res(&mut mm, &lin, data, mask).iter());
        };
        let vp = VarPro {
            start: &start,
            nl: &nl,
            lin: &lin,
            data,
            mask,
            typ: &typ,
        };
        // One count per accepted step's derivatives: the iteration count the listener hears.
        let iterations = std::sync::atomic::AtomicUsize::new(0);
        let tick = || {
            let k = iterations.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            tell(ITERATING, k, MAX_ITERATIONS);
        };
        let res = lm_box_normal(
            resid,
            &|th: &[f64], r: &[f64]| {
                let normal = vp.normal(th, r);
                if normal.is_some() {
                    tick();
                }
                normal
            },
            &|th: &[f64], _: &[f64], j: &mut DMatrix<f64>| {
                tick();
                vp.jacobian(th, j)
            },
            &theta0,
            &typ,
            &lo,
            &hi,
            &LmSettings {
                give_up: give_up.map(|v| (GIVE_UP_AFTER, v)),
                ..LmSettings::likelihood(MAX_ITERATIONS)
            },
        );
        abandoned = res.abandoned;
        model_at(&res.theta)
    };
    let n_params = lin.len() + nl.len();
    let refit = if best.1.is_finite() && best.1 < v_before {
        NominalRefit {
            model: best.0,
            n_params,
            v_before,
            v_after: best.1,
        }
    } else {
        NominalRefit {
            model: m.clone(),
            n_params,
            v_before,
            v_after: v_before,
        }
    };
    (refit, abandoned)
}

/// SISO form of [`retune`] (good start): refits every parameter of `m` on `(omega, g)` with
/// noise radii `radius`.
pub fn refit_nominal(
    m: &PhysicalModel,
    omega: &[f64],
    g: &[Complex64],
    radius: &[f64],
) -> NominalRefit {
    let data = Channels {
        path: "data".into(),
        omega: omega.to_vec(),
        entries: vec![(0, 0)],
        g: vec![g.to_vec()],
        radius: vec![radius.to_vec()],
        radius_source: vec![String::new()],
    };
    retune(m, &data, None, false)
}

#[cfg(test)]
mod tests;

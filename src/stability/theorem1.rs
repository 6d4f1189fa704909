//! The Theorem 1 test: closed-loop poles, exact margins, grid curves (see the module above).
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::certified_norm::{certified_gang_norm, certified_t_norm, sweep_applies};
use super::factor_loop::{
    gang_of_four, gang_sigma_max, t_sigma_max, theorem1_norm_system, theorem1_system,
};
use super::loop_poles::{loop_poles, loop_poles_told, LoopPoles};
use crate::error::{Error, Result};
use crate::model::controller::Controller;
use crate::model::Factorization;
use crate::system::eig::spectral_abscissa;
use crate::system::freq_eval::FreqEvaluator;
use crate::system::hinf::{hinf_norm, hinf_norm_near, hinf_norm_near_with_poles, HinfNorm};
use crate::system::{StateSpace, TransferFunction};
use num_complex::Complex64;
use serde::Serialize;

/// Relative tolerance of the in-program cross-checks of `α*` (the grid bound and `b/|r|`).
pub const CROSS_CHECK_RTOL: f64 = 1e-6;

/// The Theorem 1 verdict for one bound `r`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Proven: the certified margin `α*_lower = 1/upper(‖r·T‖∞)` is at least 1 and the
    /// cross-checks agree.
    Robust,
    /// Not robust: the certified margin is below 1 (cross-checks agreeing), or a grid
    /// frequency already violates `|r|·σ_max(T) ≤ 1`.
    NotRobust,
    /// The exact margin and its cross-checks disagree: no verdict (see `check`).
    Withheld,
}

/// The margin of one bound `r`.
#[derive(Debug, Clone, Serialize)]
pub struct MarginRow {
    /// Which `r` (`configured`, `fitted`, …).
    pub label: String,
    /// The bound.
    #[serde(skip)]
    pub r: TransferFunction,
    /// `α* = 1/‖r·T‖∞` (exact, Hamiltonian iteration); `r` is proven robust iff `α* ≥ 1`.
    pub alpha: f64,
    /// Frequency where `|r|·σ_max(T)` peaks (rad/s; `inf` at high frequency).
    pub omega: f64,
    /// The same margin on the grid: `min_ω 1/(|r|·σ_max(T))`.
    pub alpha_grid: f64,
    /// The certified lower bound `1/upper(‖r·T‖∞)` on the margin (`alpha` is within
    /// relative `2ε` above it); the verdict uses this one.
    pub alpha_lower: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// Whether Theorem 1 proves robust stability (`verdict == Robust`).
    pub robust: bool,
    /// Why the verdict is withheld (the cross-check that failed), when it is.
    pub check: Option<String>,
}

/// The verdict of one row: the exact margin `alpha` (certified lower bound `alpha_lower`)
/// must not exceed the grid margin `alpha_grid` (every grid point bounds `α*` from above),
/// and must equal `b_over_r` when given (normalized factors, constant `r`: `α* = b(G,K)/|r|`);
/// otherwise the verdict is withheld unless the grid alone proves the loop not robust.
pub fn decide(
    alpha: f64,
    alpha_lower: f64,
    alpha_grid: f64,
    b_over_r: Option<f64>,
) -> (Verdict, Option<String>) {
    let mut failed = None;
    if !(alpha.is_finite() && alpha_lower.is_finite()) {
        failed = Some(format!("the margin {alpha} is not finite"));
    } else if alpha > alpha_grid * (1.0 + CROSS_CHECK_RTOL) {
        failed = Some(format!(
            "the exact margin {alpha:.9} exceeds the grid margin {alpha_grid:.9}, an upper bound"
        ));
    } else if let Some(br) = b_over_r {
        if (alpha - br).abs() > CROSS_CHECK_RTOL * br {
            failed = Some(format!(
                "the exact margin {alpha:.9} differs from b(G,K)/|r| = {br:.9} (normalized factors, constant r)"
            ));
        }
    }
    if alpha_grid < 1.0 {
        return (Verdict::NotRobust, failed);
    }
    match failed {
        Some(why) => (Verdict::Withheld, Some(why)),
        None if alpha_lower >= 1.0 => (Verdict::Robust, None),
        None => (Verdict::NotRobust, None),
    }
}

/// Grid curves for the figure.
#[derive(Debug, Clone, Serialize)]
pub struct GridCurve {
    /// Frequencies (rad/s).
    pub omega: Vec<f64>,
    /// `1/σ_max(T(jω))`, the largest `|r(jω)|` allowed pointwise.
    pub inv_t: Vec<f64>,
    /// `|r(jω)|` per margin row, in the same order.
    pub r: Vec<Vec<f64>>,
}

/// The whole Theorem 1 report.
#[derive(Debug, Clone, Serialize)]
pub struct RobustStability {
    /// Eigenvalues of the closed-loop state matrix.
    #[serde(serialize_with = "complex_list")]
    pub closed_loop_poles: Vec<Complex64>,
    /// Largest real part of the closed-loop poles.
    pub abscissa: f64,
    /// Condition 1: `K` internally stabilizes `G`.
    pub internally_stable: bool,
    /// `‖T‖∞` and its frequency (when internally stable).
    pub t_norm: Option<HinfNorm>,
    /// `b(G, K) = 1/‖[K; I](I + GK)⁻¹[I G]‖∞` (when internally stable).
    pub b_gk: Option<f64>,
    /// Whether the factors are normalized (then `1/‖T‖∞ = b(G, K)`).
    pub normalized: bool,
    /// One row per bound `r`.
    pub margins: Vec<MarginRow>,
}

fn complex_list<S: serde::Serializer>(
    v: &[Complex64],
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for z in v {
        seq.serialize_element(&[z.re, z.im])?;
    }
    seq.end()
}

/// The closed-loop poles of `controller` on `f` (the eigenvalues of the Theorem 1 system's
/// `A`), without the norms [`analyze`] computes: what a caller needs to choose its grid.
pub fn closed_loop_poles(f: &Factorization, controller: &Controller) -> Result<Vec<Complex64>> {
    let k = controller_fits(f, controller)?;
    Ok(loop_poles(f, &k, &theorem1_system(f, &k)?)?.poles)
}

/// The controller as the negative-feedback gain `K`, checked to be `m×p` (plant inputs ×
/// plant outputs): the cheap test a command makes before it writes anything.
pub fn controller_fits(f: &Factorization, controller: &Controller) -> Result<StateSpace> {
    let k = controller.negative_feedback_gain();
    if k.d.shape() != (f.inputs(), f.outputs()) {
        return Err(Error::Input {
            path: controller.path.to_path_buf(),
            msg: format!(
                "the controller is {}×{} but must be {}×{} (plant inputs × plant outputs)",
                k.d.nrows(),
                k.d.ncols(),
                f.inputs(),
                f.outputs(),
            ),
        });
    }
    Ok(k)
}

/// Runs the Theorem 1 test of `controller` on `f` for each labelled `r`, with grid curves
/// on `grid`.
pub fn analyze(
    f: &Factorization,
    controller: &Controller,
    rs: &[(String, TransferFunction)],
    grid: &[f64],
) -> Result<(RobustStability, GridCurve)> {
    analyze_with_stages(f, controller, rs, grid, &|_| ())
}

/// [`analyze`], telling `stage` what it starts (the poles, each exact H∞ norm): on a model of
/// hundreds of states each is a dense eigenproblem of seconds to minutes (issue 34).
pub fn analyze_with_stages(
    f: &Factorization,
    controller: &Controller,
    rs: &[(String, TransferFunction)],
    grid: &[f64],
    stage: &dyn Fn(&str),
) -> Result<(RobustStability, GridCurve)> {
    analyze_gridded(f, controller, rs, &|_| grid.to_vec(), stage)
}

/// [`analyze_with_stages`] on the grid `grid(poles)` chosen from the closed-loop poles (the
/// loop realized and its poles computed once: on a model of a thousand modes each is
/// minutes).
pub fn analyze_gridded(
    f: &Factorization,
    controller: &Controller,
    rs: &[(String, TransferFunction)],
    grid: &dyn Fn(&[Complex64]) -> Vec<f64>,
    stage: &dyn Fn(&str),
) -> Result<(RobustStability, GridCurve)> {
    let k = controller_fits(f, controller)?;
    stage("the loop's realization");
    let t = theorem1_system(f, &k)?;
    let LoopPoles { poles, row_loop } = loop_poles_told(f, &k, &t, stage)?;
    let abscissa = spectral_abscissa(&poles);
    let grid = &grid(&poles)[..];
    stage(&format!(
        "the grid curve sigma_max(T(jw)) at {} frequencies",
        grid.len()
    ));
    let internally_stable = abscissa < 0.0;
    let normalized = f.realization.is_some();
    let kev = FreqEvaluator::new(&k);
    let inv_t: Vec<f64> = grid
        .iter()
        .map(|w| t_sigma_max(f, &kev, *w).map_or(0.0, |s| 1.0 / s))
        .collect();
    let r_curves: Vec<Vec<f64>> = rs
        .iter()
        .map(|(_, r)| grid.iter().map(|w| r.freq(*w).norm()).collect())
        .collect();
    let curve = GridCurve {
        omega: grid.to_vec(),
        inv_t: inv_t.clone(),
        r: r_curves.clone(),
    };
    if !internally_stable {
        return Ok((
            RobustStability {
                closed_loop_poles: poles,
                abscissa,
                internally_stable,
                t_norm: None,
                b_gk: None,
                normalized,
                margins: Vec::new(),
            },
            curve,
        ));
    }
    // The norms on the same T without the factors' hidden modes (large diagonal-M̃ loops).
    let t_full_states = t.states();
    // The structured poles already realized that system and know its poles (the same
    // matrix): no second dense eigenproblem of its size in the norm's start.
    let (t, t_poles) = match row_loop {
        Some((rl, own)) => (rl, Some(own)),
        None => (theorem1_norm_system(f, &k, &t)?, None),
    };
    let nt = t.states();
    // A large loop: its peaks located by the grid values (structured, cheap) at the grid and
    // at every lightly damped closed-loop pole, instead of one dense response per pole in
    // the norm's own start; the Hamiltonian iteration proves the bound either way.
    let peaks: Option<Vec<(f64, f64)>> = (nt < t_full_states).then(|| {
        let mut c: Vec<(f64, f64)> = grid
            .iter()
            .zip(&inv_t)
            .filter(|(_, i)| **i > 0.0)
            .map(|(w, i)| (*w, 1.0 / i))
            .collect();
        c.extend(
            poles
                .iter()
                .filter(|z| z.im > 0.0 && z.re.abs() < 0.5 * z.norm())
                .filter_map(|z| t_sigma_max(f, &kev, z.im).map(|s| (z.im, s))),
        );
        c
    });
    let near = |weight: &dyn Fn(f64) -> f64| -> Vec<f64> {
        let mut c: Vec<(f64, f64)> = peaks
            .iter()
            .flatten()
            .map(|(w, s)| (*w, s * weight(*w)))
            .collect();
        c.sort_by(|a, b| b.1.total_cmp(&a.1));
        c.iter().take(4).map(|(w, _)| *w).collect()
    };
    // A large loop: the certified sweep over the factor values first (no Hamiltonian of
    // twice the loop's states); the Hamiltonian iteration if it cannot close.
    let breaks = peaks
        .as_ref()
        .filter(|_| sweep_applies(f, &k))
        .map(|_| sweep_breaks(grid, &poles));
    type Run<'r> = &'r dyn Fn(&[f64], &[f64]) -> Option<HinfNorm>;
    let swept = |what: &str, run: Run, starts: &[f64]| {
        let breaks = breaks.as_deref()?;
        stage(&format!(
            "{what}, exact (certified frequency sweep on the factors, {} modal coordinates)",
            f.states()
        ));
        let done = run(breaks, starts);
        if done.is_none() {
            stage(&format!(
                "{what}: the sweep did not close; Hamiltonian iteration instead"
            ));
        }
        done
    };
    let t_swept = swept(
        "||T||_inf",
        &|b, s| certified_t_norm(f, &k, b, s),
        &near(&|_| 1.0),
    );
    let t_norm = match t_swept {
        Some(h) => h,
        None => {
            stage(&format!(
                "||T||_inf, exact (Hamiltonian iteration, {} x {} eigenproblems)",
                2 * nt,
                2 * nt
            ));
            let sig = |w: f64| t_sigma_max(f, &kev, w);
            let starts = near(&|_| 1.0);
            hamiltonian_norm(
                &t,
                peaks
                    .is_some()
                    .then_some((&starts[..], &sig as &dyn Fn(f64) -> _)),
                t_poles.as_deref(),
            )?
        }
    };
    // A large loop: the iteration started from the peaks of the gang's own value on the
    // grid and at the lightly damped poles (cheap from the factor values) instead of one
    // dense response per pole of the plant-and-controller loop (a synthesized controller
    // doubles it); the Hamiltonian proves the bound either way.
    // Evaluated once: the sweep and, if it cannot close, the Hamiltonian start from them.
    let gang_starts: Vec<f64> = if peaks.is_some() {
        let sig = |w: f64| gang_sigma_max(f, &kev, w);
        let mut c: Vec<(f64, f64)> = grid
            .iter()
            .copied()
            .chain(
                poles
                    .iter()
                    .filter(|z| z.im > 0.0 && z.re.abs() < 0.5 * z.norm())
                    .map(|z| z.im),
            )
            .filter_map(|w| sig(w).map(|s| (w, s)))
            .collect();
        c.sort_by(|a, b| b.1.total_cmp(&a.1));
        c.iter().take(4).map(|(w, _)| *w).collect()
    } else {
        Vec::new()
    };
    let g_swept = if peaks.is_some() {
        swept(
            "b(G,K)",
            &|b, s| certified_gang_norm(f, &k, b, s),
            &gang_starts,
        )
    } else {
        None
    };
    let b_gk = 1.0
        / match g_swept {
            Some(h) => h,
            None => {
                let g4 = gang_of_four(f, &k)?;
                let n4 = g4.states();
                stage(&format!(
                    "b(G,K), exact (Hamiltonian iteration, {} x {} eigenproblems)",
                    2 * n4,
                    2 * n4
                ));
                let sig = |w: f64| gang_sigma_max(f, &kev, w);
                // The gang's loop is the plant's rows closed by K, the matrix of the norm
                // system up to rounding (K·(C·X) against (K·C)·X): its poles are known then.
                hamiltonian_norm(
                    &g4,
                    peaks
                        .is_some()
                        .then_some((&gang_starts[..], &sig as &dyn Fn(f64) -> _)),
                    t_poles.as_deref().filter(|_| same_matrix(&g4.a, &t.a)),
                )?
            }
        }
        .gamma;
    let mut margins = Vec::new();
    for ((label, r), rc) in rs.iter().zip(&r_curves) {
        if !r.is_proper() {
            return Err(Error::Invalid(format!("the {label} r is not proper")));
        }
        let constant_r = r.num.degree() == 0 && r.den.degree() == 0;
        // ‖r·T‖∞ = |r|·‖T‖∞ for a constant r (exact scaling, the proven bound included): no
        // third Hamiltonian iteration on a large model.
        let h = if constant_r {
            let g = r.at_infinity().abs();
            HinfNorm {
                gamma: g * t_norm.gamma,
                omega: t_norm.omega,
                upper: g * t_norm.upper * (1.0 + f64::EPSILON),
                iterations: 0,
            }
        } else {
            stage(&format!("||r T||_inf of the {label} r, exact"));
            let rt = t.times_scalar(&StateSpace::from_tf(r));
            let sig = |w: f64| t_sigma_max(f, &kev, w).map(|s| s * r.freq(w).norm());
            let starts = near(&|w| r.freq(w).norm());
            hamiltonian_norm(
                &rt,
                peaks
                    .is_some()
                    .then_some((&starts[..], &sig as &dyn Fn(f64) -> _)),
                None,
            )
            .map_err(|e| Error::Invalid(format!("the {label} r: {e}")))?
        };
        let alpha = 1.0 / h.gamma;
        let alpha_lower = 1.0 / h.upper;
        // A grid point where T could not be evaluated (0 in the figure's curve) bounds nothing.
        let alpha_grid = inv_t
            .iter()
            .zip(rc)
            .filter(|(i, _)| **i > 0.0)
            .map(|(i, r)| i / r)
            .fold(f64::INFINITY, f64::min);
        let b_over_r = (normalized && constant_r).then(|| b_gk / r.at_infinity().abs());
        let (verdict, check) = decide(alpha, alpha_lower, alpha_grid, b_over_r);
        margins.push(MarginRow {
            label: label.clone(),
            r: r.clone(),
            alpha,
            omega: h.omega,
            alpha_grid,
            alpha_lower,
            verdict,
            robust: verdict == Verdict::Robust,
            check,
        });
    }
    Ok((
        RobustStability {
            closed_loop_poles: poles,
            abscissa,
            internally_stable,
            t_norm: Some(t_norm),
            b_gk: Some(b_gk),
            normalized,
            margins,
        },
        curve,
    ))
}

/// A large loop's start of the Hamiltonian iteration: frequencies and the structured `σ_max`.
type Starts<'a> = (&'a [f64], &'a dyn Fn(f64) -> Option<f64>);

/// `‖G‖∞` by the Hamiltonian iteration (exact, the bound proven whatever the start): on a large
/// loop started from the caller's frequencies with the structured `σ_max` evaluation, and from
/// the loop's poles where they are already known; otherwise from the system's own poles and grid.
fn hamiltonian_norm(
    ss: &StateSpace,
    large: Option<Starts>,
    poles: Option<&[Complex64]>,
) -> Result<HinfNorm> {
    match (large, poles) {
        (Some((starts, sig)), Some(p)) => hinf_norm_near_with_poles(ss, starts, Some(sig), p),
        (Some((starts, sig)), None) => hinf_norm_near(ss, starts, Some(sig)),
        (None, _) => hinf_norm(ss),
    }
}

/// The cuts that start the certified sweep: the grid and, for every lightly damped
/// closed-loop pole `λ`, `Im λ` and `Im λ ± 2|Re λ|` (the resonance's half-power band).
fn sweep_breaks(grid: &[f64], poles: &[Complex64]) -> Vec<f64> {
    let mut b = grid.to_vec();
    for z in poles
        .iter()
        .filter(|z| z.im > 0.0 && z.re.abs() < 0.5 * z.norm())
    {
        b.extend([z.im - 2.0 * z.re.abs(), z.im, z.im + 2.0 * z.re.abs()]);
    }
    b.retain(|w| w.is_finite() && *w > 0.0);
    b
}

/// Whether two state matrices are the same to rounding (`‖A − B‖_max ≤ 1e-13·‖A‖_max`).
fn same_matrix(a: &nalgebra::DMatrix<f64>, b: &nalgebra::DMatrix<f64>) -> bool {
    a.shape() == b.shape() && (a - b).amax() <= 1e-13 * a.amax().max(f64::MIN_POSITIVE)
}

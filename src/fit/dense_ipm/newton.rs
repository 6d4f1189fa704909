//! Damped Newton on the log barrier `φ_t(x) = t·cᵀx − Σ_i ln(a_iᵀx − b_i)` over dense rows
//! (row-major, few columns): each step solves `H Δx = −∇φ` with `H = Aᵀ diag(1/s²) A`, an
//! `n × n` system solved by a QR factorization of `S⁻¹A` (Boyd &
//! Vandenberghe, *Convex Optimization*, §9.5–9.6 and §11.3: the barrier is
//! self-concordant, so the damped step converges from any strictly feasible point).

use nalgebra::{DMatrix, DVector};

/// Dense rows `a_iᵀ x ≥ b_i`, row-major with `n` columns.
pub(crate) struct Rows {
    pub n: usize,
    pub a: Vec<f64>,
    pub b: Vec<f64>,
}

impl Rows {
    pub fn m(&self) -> usize {
        self.b.len()
    }

    /// `A·x`.
    pub fn times(&self, x: &[f64]) -> Vec<f64> {
        self.a
            .chunks_exact(self.n)
            .map(|r| r.iter().zip(x).map(|(u, v)| u * v).sum::<f64>())
            .collect()
    }

    /// The slacks `a_iᵀx − b_i`.
    pub fn slacks(&self, x: &[f64]) -> Vec<f64> {
        let mut s = self.times(x);
        s.iter_mut().zip(&self.b).for_each(|(v, b)| *v -= b);
        s
    }
}

/// How a centring ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Centring {
    /// The Newton decrement fell below the tolerance.
    Converged,
    /// The iteration cap was reached (the point is strictly feasible, not centred).
    Capped,
    /// The Newton system could not be factored or no step decreased the barrier.
    Stalled,
}

/// Result of [`centre`].
pub(crate) struct Centred {
    pub x: Vec<f64>,
    pub s: Vec<f64>,
    pub iters: usize,
    pub end: Centring,
}

/// `φ_t` at a point with slacks `s` (all positive).
fn barrier(t: f64, c: Option<&[f64]>, x: &[f64], s: &[f64]) -> f64 {
    let lin = c.map_or(0.0, |c| c.iter().zip(x).map(|(u, v)| u * v).sum::<f64>());
    t * lin - s.iter().map(|v| v.ln()).sum::<f64>()
}

/// The Newton step `Δx` and `λ²` at slacks `s`, or `None` when `J = S⁻¹A` is rank
/// deficient.  `H = JᵀJ` is never formed: with `J = QR` (Householder), `Δx = R⁻¹Qᵀ1 −
/// t·R⁻¹R⁻ᵀc`, whose error grows with `cond(J) = √cond(H)` — the slacks span 20 decades
/// near the end of phase 1, where the normal equations' Cholesky lost the step (phase 1
/// stalled with `τ` and its bound 5·10⁻⁷ apart on envelope 0 of the sweep).
fn newton_step(rows: &Rows, t: f64, c: Option<&[f64]>, s: &[f64]) -> Option<(Vec<f64>, f64)> {
    let (n, m) = (rows.n, rows.m());
    let mut j = DMatrix::<f64>::zeros(m, n);
    for (i, (r, si)) in rows.a.chunks_exact(n).zip(s).enumerate() {
        let inv = 1.0 / si;
        for k in 0..n {
            j[(i, k)] = r[k] * inv;
        }
    }
    // g = t·c − Jᵀ1.
    let mut g = vec![0.0; n];
    if let Some(c) = c {
        g.iter_mut().zip(c).for_each(|(gi, ci)| *gi = t * ci);
    }
    for (k, gk) in g.iter_mut().enumerate() {
        *gk -= j.column(k).sum();
    }
    let qr = j.qr();
    let r = qr.r();
    let mut ones = DVector::from_element(m, 1.0);
    qr.q_tr_mul(&mut ones);
    let qt1 = DVector::from_iterator(n, ones.iter().take(n).copied());
    let mut dx = r.solve_upper_triangular(&qt1)?;
    if let Some(c) = c {
        let cv = DVector::from_column_slice(c);
        let y = r.tr_solve_upper_triangular(&cv)?;
        let z = r.solve_upper_triangular(&y)?;
        dx -= z * t;
    }
    let dx: Vec<f64> = dx.iter().copied().collect();
    let lambda2 = -g.iter().zip(&dx).map(|(u, v)| u * v).sum::<f64>();
    if !lambda2.is_finite() || dx.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some((dx, lambda2.max(0.0)))
}

/// The multipliers `y_i = (1 − (AΔx)_i/s_i)/(t·s_i)` of the Newton step `Δx` at slacks `s`:
/// by the Newton equations `t·c = Aᵀ(1/s) − Aᵀdiag(1/s²)AΔx = t·Aᵀy`, so `Aᵀy = c` holds to
/// round-off, not only at the exact centre (the plain `1/(t s)` is off by `∇φ/t`); they are
/// nonnegative where `λ < 1` (`‖AΔx/s‖₂ = λ`); a negative one is set to zero.
pub(crate) fn newton_multipliers(rows: &Rows, t: f64, c: &[f64], s: &[f64]) -> Option<Vec<f64>> {
    let (dx, _) = newton_step(rows, t, Some(c), s)?;
    let adx = rows.times(&dx);
    Some(
        s.iter()
            .zip(&adx)
            .map(|(si, ai)| ((1.0 - ai / si) / (t * si)).max(0.0))
            .collect(),
    )
}

/// Minimizes `φ_t` from the strictly feasible `x0` by damped Newton with a backtracking line
/// search, until `λ²/2 ≤ tol` or `cap` steps; `stop(x, s)` ends the loop early when it
/// returns true (phase 1 stops at the first strictly feasible point of the level set).
pub(crate) fn centre(
    rows: &Rows,
    t: f64,
    c: Option<&[f64]>,
    x0: Vec<f64>,
    tol: f64,
    cap: usize,
    stop: &dyn Fn(&[f64]) -> bool,
) -> Centred {
    let mut x = x0;
    let mut s = rows.slacks(&x);
    let out = |x: Vec<f64>, s: Vec<f64>, _lambda2: f64, iters, end| Centred { x, s, iters, end };
    let mut lambda2 = f64::INFINITY;
    for it in 0..cap {
        let Some((dx, l2)) = newton_step(rows, t, c, &s) else {
            return out(x, s, lambda2, it, Centring::Stalled);
        };
        // Near the centre λ² falls quadratically; where it stops falling (by 4× per step) below
        // 10⁻¹⁰ it is at the round-off of the gradient's sum (λ² ≈ 4e-14 on 215 rows).
        let floor = l2 <= 1e-10 && l2 > 0.25 * lambda2;
        lambda2 = l2;
        if l2 / 2.0 <= tol || floor {
            return out(x, s, lambda2, it, Centring::Converged);
        }
        // Largest step keeping every slack positive, then backtracking (Armijo, 1/4).
        let adx = rows.times(&dx);
        let mut amax = f64::INFINITY;
        for (si, di) in s.iter().zip(&adx) {
            if *di < 0.0 {
                amax = amax.min(-si / di);
            }
        }
        let mut alpha = (0.99 * amax).min(1.0);
        let f0 = barrier(t, c, &x, &s);
        let slope = -l2;
        let mut moved = false;
        for _ in 0..60 {
            let xn: Vec<f64> = x.iter().zip(&dx).map(|(u, v)| u + alpha * v).collect();
            let sn: Vec<f64> = s.iter().zip(&adx).map(|(u, v)| u + alpha * v).collect();
            if sn.iter().all(|v| *v > 0.0) {
                // In the quadratic region (λ < 0.1: the full step stays inside the Dikin
                // ellipsoid and decreases φ) the step is taken without the test, whose
                // decrease λ² would drown in the round-off of φ near the centre.
                let f1 = barrier(t, c, &xn, &sn);
                if (l2 < 1e-2 && alpha == 1.0) || f1 <= f0 + 0.25 * alpha * slope {
                    // Slacks recomputed from the rows: no drift from the updates.
                    let sr = rows.slacks(&xn);
                    if sr.iter().all(|v| *v > 0.0) {
                        x = xn;
                        s = sr;
                        moved = true;
                        break;
                    }
                }
            }
            alpha *= 0.5;
        }
        if !moved {
            // No decrease: at round-off level of the centre when λ² is small.
            let end = if l2 <= 1e-6 {
                Centring::Converged
            } else {
                Centring::Stalled
            };
            return out(x, s, lambda2, it, end);
        }
        if stop(&x) {
            return out(x, s, lambda2, it + 1, Centring::Converged);
        }
    }
    out(x, s, lambda2, cap, Centring::Capped)
}

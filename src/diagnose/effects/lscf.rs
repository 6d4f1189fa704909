//! Mode proposals from a frequency response by the least-squares complex-frequency (LSCF)
//! estimator with a stabilization test across model orders (Guillaume, Verboven, Vanlanduit,
//! Van der Auweraer & Peeters 2003, "A poly-reference implementation of the least-squares
//! complex frequency-domain estimator", IMAC XXI; the common-denominator form of Peeters et
//! al. 2004, PolyMAX).
//!
//! Every channel `c` of the (residual) FRF is modelled with one common denominator,
//! `H_c(ω) ≈ N_c(z)/d(z)`, `z = e^{jωT}`, `T = π/ω_max` (the band prescaled onto the upper
//! half of the unit circle), `N_c(z) = Σ_r β_{c,r} z^r`, `d(z) = Σ_r α_r z^r`, `r = 0 … n`,
//! real coefficients (poles in conjugate pairs).  The linearized, noise-weighted equations
//! `w_{c,k} (N_c(z_k) − H_c(ω_k) d(z_k)) = 0` are solved in least squares with `α_n = 1`:
//!
//! * per channel, one Householder QR of the real `2F × 2(N+1)` matrix with the columns of
//!   `N_c` and `d` interleaved (`β_0, α_0, β_1, α_1, …`): the `R` of every order `n ≤ N` is
//!   then the leading block of that one `R` (the columns of order `n` are a prefix);
//! * per order, `β_c` is eliminated by a QR of that small block with the `β` columns first
//!   (the `R₂₂` block is what is left for `α`: the reduced normal equations of LSCF,
//!   `Σ_c (T_c − S_cᵀ R_c⁻¹ S_c) α = 0`, without forming them);
//! * the stacked `R₂₂` of every channel give `α` by a column-scaled QR least squares.
//!
//! The poles are the roots of `d(z)`, `s = ln z / T`, `ω_n = |s|`, `ζ = −Re s/|s|`; only stable
//! (`0 < ζ < 1`), in-band ones are kept.  A pole is **stable** across orders when the next
//! lower order has one within `tol_f` in frequency and `tol_zeta` in damping; the proposals
//! are the poles stable over `min_stable` consecutive orders (the stabilization diagram),
//! one per cluster, from the highest order that has it.

use crate::system::Polynomial;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// A proposed mode: natural frequency (rad/s) and damping ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Proposal {
    /// `ω_n` (rad/s).
    pub omega_n: f64,
    /// `ζ`.
    pub zeta: f64,
    /// Number of consecutive orders over which the pole is stable.
    pub stable_orders: usize,
}

/// Settings of the stabilization diagram.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    /// Highest order of the common denominator (capped by the data: `n < F`).
    pub max_order: usize,
    /// Relative frequency tolerance between orders.
    pub tol_f: f64,
    /// Relative damping tolerance between orders.
    pub tol_zeta: f64,
    /// Consecutive orders a pole must be stable over.
    pub min_stable: usize,
}

impl Default for Settings {
    fn default() -> Self {
        // The usual frequency criterion (1 %) with a loose damping test (a factor of about
        // two): the residual is noisy and a resonance narrower than a line leaves its damping
        // undetermined, so its ζ wanders between orders while its frequency stays.  Orders
        // up to 40 (20 pole pairs): on the 981-line × 3-channel beam the diagrams stay below
        // 2 % of a step's `perf` samples.  The proposals are only starting points, judged by
        // the fits that follow (a spurious one costs one trial).
        Self {
            max_order: 40,
            tol_f: 0.01,
            tol_zeta: 1.0,
            min_stable: 4,
        }
    }
}

/// The weighted FRF to fit: `h[c][k]` at `omega[k]`, weights `w[c][k]` (`1/σ`).
pub(crate) struct Frf<'a> {
    pub omega: &'a [f64],
    pub h: &'a [Vec<Complex64>],
    pub w: &'a [Vec<f64>],
}

/// The `R` factor of each channel's interleaved `[β_0, α_0, …, β_N, α_N]` matrix.
fn channel_factors(frf: &Frf<'_>, n_max: usize, t: f64) -> Vec<DMatrix<f64>> {
    let f = frf.omega.len();
    let ncol = 2 * (n_max + 1);
    frf.h
        .iter()
        .zip(frf.w)
        .map(|(h, w)| {
            let mut a = DMatrix::<f64>::zeros(2 * f, ncol);
            for k in 0..f {
                let zk = Complex64::from_polar(1.0, frf.omega[k] * t);
                let mut zr = Complex64::new(w[k], 0.0);
                let hk = -h[k];
                for r in 0..=n_max {
                    let b = zr;
                    let d = zr * hk;
                    a[(2 * k, 2 * r)] = b.re;
                    a[(2 * k + 1, 2 * r)] = b.im;
                    a[(2 * k, 2 * r + 1)] = d.re;
                    a[(2 * k + 1, 2 * r + 1)] = d.im;
                    zr *= zk;
                }
            }
            a.qr().r()
        })
        .collect()
}

/// Least squares `min ‖A x − b‖` by a column-scaled Householder QR; `None` when a pivot is
/// below `1e-13` of the largest or the result is not finite.
fn lstsq(mut a: DMatrix<f64>, b: DVector<f64>) -> Option<DVector<f64>> {
    let n = a.ncols();
    let scale = crate::system::linalg::equilibrate_columns(&mut a);
    let qr = a.qr();
    let r = qr.r();
    let rmax = (0..n).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    if rmax.is_nan() || rmax <= 0.0 || (0..n).any(|i| r[(i, i)].abs() <= 1e-13 * rmax) {
        return None;
    }
    let mut qtb = b;
    qr.q_tr_mul(&mut qtb);
    let x = r.solve_upper_triangular(&qtb.rows(0, n).into_owned())?;
    let x = DVector::from_fn(n, |i, _| x[i] / scale[i]);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The denominator coefficients `α_0 … α_n` (`α_n = 1`) of order `n` from the channels'
/// factors, or `None` when the reduced problem is rank-deficient.
fn denominator(factors: &[DMatrix<f64>], n: usize) -> Option<Vec<f64>> {
    let m = n + 1;
    let mut stacked = DMatrix::<f64>::zeros(factors.len() * m, m);
    for (c, r) in factors.iter().enumerate() {
        // The leading block, columns reordered to [β_0 … β_n | α_0 … α_n].
        let blk = DMatrix::from_fn(2 * m, 2 * m, |i, j| {
            let col = if j < m { 2 * j } else { 2 * (j - m) + 1 };
            r[(i, col)]
        });
        let r2 = blk.qr().r();
        stacked
            .view_mut((c * m, 0), (m, m))
            .copy_from(&r2.view((m, m), (m, m)));
    }
    let a = stacked.columns(0, n).into_owned();
    let b = -stacked.column(n).into_owned();
    let x = lstsq(a, b)?;
    let mut alpha: Vec<f64> = x.iter().copied().collect();
    alpha.push(1.0);
    Some(alpha)
}

/// The stable, in-band poles `(ω_n, ζ)` of the order-`n` denominator, sorted by `ω_n`.
fn poles_of(alpha: &[f64], t: f64, w_lo: f64, w_hi: f64) -> Option<Vec<(f64, f64)>> {
    let desc: Vec<f64> = alpha.iter().rev().copied().collect();
    let roots = Polynomial::new(desc).roots();
    if !roots.converged {
        return None;
    }
    let mut out: Vec<(f64, f64)> = roots
        .roots
        .iter()
        .filter(|z| z.im > 0.0 && z.norm() < 1.0 && z.norm() > 0.0)
        .map(|z| {
            let s = Complex64::new(z.norm().ln(), z.arg()) / t;
            (s.norm(), -s.re / s.norm())
        })
        .filter(|(w, zeta)| *w >= w_lo && *w <= w_hi && *zeta > 0.0 && *zeta < 1.0)
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(out)
}

/// The poles of every order `n = 2, 4, … ≤ max_order` (the stabilization diagram's rows);
/// an order whose least squares or roots fail has no row.
pub(crate) fn diagram(frf: &Frf<'_>, s: &Settings) -> Vec<(usize, Vec<(f64, f64)>)> {
    let f = frf.omega.len();
    let (Some(w_lo), Some(w_hi)) = (
        frf.omega.iter().copied().reduce(f64::min),
        frf.omega.iter().copied().reduce(f64::max),
    ) else {
        return vec![];
    };
    // 2F real equations per channel for 2(n+1) unknowns; the QR needs F ≥ n + 1.
    let n_max = s.max_order.min(f.saturating_sub(1));
    if n_max < 2 || frf.h.is_empty() || w_hi.is_nan() || w_hi <= 0.0 {
        return vec![];
    }
    let t = std::f64::consts::PI / w_hi;
    let factors = channel_factors(frf, n_max, t);
    (2..=n_max)
        .step_by(2)
        .filter_map(|n| {
            let alpha = denominator(&factors, n)?;
            Some((n, poles_of(&alpha, t, w_lo, w_hi)?))
        })
        .collect()
}

/// The mode proposals: poles stable over `min_stable` consecutive orders of [`diagram`],
/// one per cluster (within `tol_f`), sorted by frequency.
pub(crate) fn propose(frf: &Frf<'_>, s: &Settings) -> Vec<Proposal> {
    let rows = diagram(frf, s);
    let close = |a: (f64, f64), b: (f64, f64)| {
        (a.0 - b.0).abs() <= s.tol_f * b.0 && (a.1 - b.1).abs() <= s.tol_zeta * b.1
    };
    // Chain length of every pole: 1 + that of its match in the previous order.
    let mut prev: Vec<((f64, f64), usize)> = Vec::new();
    let mut found: Vec<Proposal> = Vec::new();
    let mut prev_order = 0;
    for (n, poles) in rows {
        let consecutive = n == prev_order + 2;
        let cur: Vec<((f64, f64), usize)> = poles
            .iter()
            .map(|p| {
                let chain = prev
                    .iter()
                    .filter(|(q, _)| consecutive && close(*p, *q))
                    .map(|(_, c)| *c)
                    .max()
                    .map_or(1, |c| c + 1);
                (*p, chain)
            })
            .collect();
        for (p, chain) in &cur {
            if *chain < s.min_stable {
                continue;
            }
            let prop = Proposal {
                omega_n: p.0,
                zeta: p.1,
                stable_orders: *chain,
            };
            // One per cluster: the highest order's (the latest) replaces the earlier.
            match found
                .iter_mut()
                .find(|q| (q.omega_n - p.0).abs() <= s.tol_f * q.omega_n)
            {
                Some(q) => *q = prop,
                None => found.push(prop),
            }
        }
        prev = cur;
        prev_order = n;
    }
    found.sort_by(|a, b| a.omega_n.total_cmp(&b.omega_n));
    found
}

#[cfg(test)]
mod tests;

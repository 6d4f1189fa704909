//! Chebyshev series `p(u) = Σ c_k T_k(u)` on the disk variable `u ∈ [−1, 1]`: evaluation,
//! roots, and an exact positivity test — the numerics of [`super::polyfit`].
//!
//! Everything works on the series in `u` itself.  Rewriting it as a polynomial in
//! `x = x₀(1 + u)/(1 − u)` first (as the first version of the polynomial fitter did) loses
//! the roots near `u = ±1`: a rising `|r|` puts roots of `A` and `B` at `x ≈ 3·10⁴`, where
//! the monomial coefficients in `x` cancel to a few digits (GitHub issue 11, defect 3).  The
//! roots are computed from the monomial form in `u`, which is well conditioned on `[−1, 1]`
//! for the degrees used here (its coefficients are at most `2^{n−1}` times the Chebyshev
//! ones), then polished by Newton steps on the series (Clenshaw's recurrence, whose error is
//! a few ulps of `Σ|c_k|`).

use crate::system::Polynomial;
use num_complex::Complex64;

/// `[T_0(u), …, T_n(u)]` (the three-term recurrence `T_{k+1} = 2u·T_k − T_{k−1}`).
pub(crate) fn cheb(n: usize, u: f64) -> Vec<f64> {
    let mut t = vec![1.0, u];
    for k in 2..=n {
        let v = 2.0 * u * t[k - 1] - t[k - 2];
        t.push(v);
    }
    t.truncate(n + 1);
    t
}

/// `Σ c_k T_k(u)` and its derivative at a complex `u` (Clenshaw's recurrence and its
/// derivative, Rivlin, *Chebyshev Polynomials*, §1.5).
pub(crate) fn eval_d(c: &[f64], u: Complex64) -> (Complex64, Complex64) {
    let zero = Complex64::new(0.0, 0.0);
    let (mut b1, mut b2, mut d1, mut d2) = (zero, zero, zero, zero);
    for k in (1..c.len()).rev() {
        let b = 2.0 * u * b1 - b2 + c[k];
        let d = 2.0 * b1 + 2.0 * u * d1 - d2;
        (b2, b1) = (b1, b);
        (d2, d1) = (d1, d);
    }
    let f = u * b1 - b2 + c[0];
    let df = b1 + u * d1 - d2;
    (f, df)
}

/// `Σ c_k T_k(u)` at a real `u`.
pub(crate) fn eval(c: &[f64], u: f64) -> f64 {
    eval_d(c, Complex64::new(u, 0.0)).0.re
}

/// Chebyshev coefficients → monomial coefficients in `u`, ascending.
pub(crate) fn to_monomial(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    let mut out = vec![0.0; n];
    let (mut tkm1, mut tk) = (vec![1.0], vec![0.0, 1.0]);
    for (k, ck) in c.iter().enumerate() {
        let tcur: &Vec<f64> = if k == 0 { &tkm1 } else { &tk };
        for (j, v) in tcur.iter().enumerate() {
            out[j] += ck * v;
        }
        if k >= 1 {
            let mut next = vec![0.0; tk.len() + 1];
            for (j, v) in tk.iter().enumerate() {
                next[j + 1] += 2.0 * v;
            }
            for (j, v) in tkm1.iter().enumerate() {
                next[j] -= v;
            }
            tkm1 = std::mem::replace(&mut tk, next);
        }
    }
    out
}

/// The roots in `u` of `Σ c_k T_k(u)` (complex pairs adjacent), `None` when the iteration
/// did not converge.  A leading coefficient below `1e-13·Σ|c_k|` counts as a degree drop:
/// those roots are at `u = ∞` and are returned as `None` entries of the second vector's
/// length (the caller maps `u = ∞` to `x = −x₀`).
pub(crate) fn roots(c: &[f64], cap: usize) -> Option<(Vec<Complex64>, usize)> {
    let scale: f64 = c.iter().map(|v| v.abs()).sum();
    let mut mono = to_monomial(c);
    let mut dropped = 0;
    while mono.len() > 1 && mono.last().is_some_and(|v| v.abs() <= 1e-13 * scale) {
        mono.pop();
        dropped += 1;
    }
    if mono.len() == 1 {
        return Some((Vec::new(), dropped));
    }
    let desc: Vec<f64> = mono.iter().rev().copied().collect();
    let r = Polynomial::new(desc).roots_capped(cap);
    if !r.converged {
        return None;
    }
    let polished = r
        .roots
        .iter()
        .map(|z| {
            let mut z = *z;
            let (mut f, _) = eval_d(c, z);
            for _ in 0..6 {
                let (fz, dz) = eval_d(c, z);
                if !(dz.norm() > 0.0) {
                    break;
                }
                let mut nz = z - fz / dz;
                if z.im == 0.0 {
                    nz.im = 0.0;
                }
                let (nf, _) = eval_d(c, nz);
                if nf.is_finite() && nf.norm() < f.norm() {
                    z = nz;
                    f = nf;
                } else {
                    break;
                }
            }
            z
        })
        .collect::<Vec<_>>();
    // Keep the pairs exactly conjugate.
    let mut out = polished;
    for i in 0..out.len() {
        if out[i].im > 0.0 {
            if let Some(j) = (0..out.len())
                .find(|&j| j != i && (out[j] - out[i].conj()).norm() < 1e-6 * (1.0 + out[i].norm()))
            {
                out[j] = out[i].conj();
            }
        }
    }
    Some((out, dropped))
}

/// Points of `[−1, 1]` where `Σ c_k T_k(u) < floor`, one per interval of violation (its
/// minimum among the probe points), or an empty list when the series stays above `floor`.
pub(crate) fn below(c: &[f64], floor: f64, cap: usize) -> Vec<f64> {
    below_on(c, -1.0, 1.0, floor, cap)
}

/// [`below`] on `[lo, hi] ⊂ [−1, 1]`.
///
/// Exact up to rounding: the series is a polynomial of degree `n`, so between two
/// consecutive real critical points (roots of the derivative, computed as roots of the
/// derivative's own series) it is monotone; its minimum over `[lo, hi]` is attained at an
/// endpoint or at one of those points.  Evaluating there finds every interval where it
/// falls below `floor`, however narrow — no sampling.
pub(crate) fn below_on(c: &[f64], lo: f64, hi: f64, floor: f64, cap: usize) -> Vec<f64> {
    let n = c.len().saturating_sub(1);
    let mut probes = vec![lo, hi];
    if n >= 2 {
        let d = derivative(c);
        match roots(&d, cap) {
            Some((rs, _)) => {
                for z in rs {
                    // A complex pair close to the axis is a near-critical point: probe its
                    // real part too.
                    if z.im.abs() <= 1e-3 && z.re > lo && z.re < hi {
                        probes.push(z.re);
                    }
                }
            }
            None => {
                // No convergence: fall back to a dense Chebyshev-node probe (never silent:
                // the candidate's certificate verifies again).
                probes.extend((0..4096).map(|j| {
                    let v = (std::f64::consts::PI * (j as f64 + 0.5) / 4096.0).cos();
                    0.5 * (lo + hi) + 0.5 * (hi - lo) * v
                }));
            }
        }
    }
    probes.sort_by(f64::total_cmp);
    let vals: Vec<f64> = probes.iter().map(|u| eval(c, *u)).collect();
    let mut out = Vec::new();
    for i in 0..probes.len() {
        let local_min =
            (i == 0 || vals[i] <= vals[i - 1]) && (i + 1 == vals.len() || vals[i] <= vals[i + 1]);
        if local_min && !(vals[i] >= floor) {
            out.push(probes[i]);
        }
    }
    out
}

/// Stable spectral roots `s` of `(x + x₀)^n Σ c_k T_k(u)`, or why not: each root `u` of the
/// series maps to `x = x₀(1 + u)/(1 − u)` (a dropped degree in `u` to `x = −x₀`), and `x`
/// to `s = −√(−x)` (see [`super::spectral`], whose positivity argument applies).
pub(crate) fn spectral_roots(
    c: &[f64],
    x0: f64,
    axis_tol: f64,
    cap: usize,
) -> Result<Vec<Complex64>, String> {
    let Some((us, dropped)) = roots(c, cap) else {
        return Err("root iteration did not converge".into());
    };
    let one = Complex64::new(1.0, 0.0);
    let mut xs: Vec<Complex64> = vec![Complex64::new(-x0, 0.0); dropped];
    for u in us {
        if (one - u).norm() == 0.0 {
            return Err("degree drop at infinity (r not biproper)".into());
        }
        xs.push(x0 * (one + u) / (one - u));
    }
    let mut out = Vec::with_capacity(xs.len());
    for x in xs {
        let s = -(-x).sqrt();
        let s = if x.im == 0.0 {
            Complex64::new(s.re, 0.0)
        } else {
            s
        };
        if !(s.re < -axis_tol * s.norm()) || s.norm() == 0.0 {
            return Err(format!(
                "root on the jω-axis at scaled ω = {:.4e}",
                s.im.abs()
            ));
        }
        out.push(s);
    }
    Ok(out)
}

/// Chebyshev coefficients of the derivative (`c'_{k−1} = c'_{k+1} + 2k·c_k`).
fn derivative(c: &[f64]) -> Vec<f64> {
    let n = c.len() - 1;
    let mut d = vec![0.0; n + 1];
    for k in (1..=n).rev() {
        d[k - 1] = d.get(k + 1).copied().unwrap_or(0.0) + 2.0 * k as f64 * c[k];
    }
    d[0] *= 0.5;
    d.truncate(n.max(1));
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clenshaw_matches_the_recurrence_and_its_derivative() {
        let c = [0.3, -1.2, 0.7, 0.05, -0.4];
        for u in [-1.0, -0.3, 0.0, 0.61, 1.0] {
            let direct: f64 = cheb(4, u).iter().zip(&c).map(|(a, b)| a * b).sum();
            let (f, df) = eval_d(&c, Complex64::new(u, 0.0));
            assert!((f.re - direct).abs() < 1e-14);
            let h = 1e-6;
            let fd = (eval(&c, u + h) - eval(&c, u - h)) / (2.0 * h);
            assert!((df.re - fd).abs() < 1e-7, "{u}: {} vs {fd}", df.re);
        }
    }

    #[test]
    fn roots_near_the_end_of_the_interval_are_exact() {
        // (u − (1 − 1e-5))(u − (1 − 3e-5)) as a Chebyshev series: u² = (T0 + T2)/2.
        let (r1, r2) = (1.0 - 1e-5, 1.0 - 3e-5);
        let c = [0.5 + r1 * r2, -(r1 + r2), 0.5];
        let (rs, dropped) = roots(&c, 500).unwrap();
        assert_eq!(dropped, 0);
        // The coefficients themselves carry a rounding of 1e-16; two roots 2e-5 apart move
        // by about 1e-16/2e-5 = 5e-12 under it (their condition number), so 2e-11 is the
        // accuracy a correct method can promise.
        for r in [r1, r2] {
            assert!(
                rs.iter().any(|z| (z.re - r).abs() < 2e-11 && z.im == 0.0),
                "{rs:?}"
            );
        }
    }

    #[test]
    fn positivity_test_finds_a_narrow_dip() {
        // (u − 0.999)² − 1e-12: negative on an interval of width 2e-6 only.
        let a = 0.999f64;
        let c = [0.5 + a * a - 1e-12, -2.0 * a, 0.5];
        let found = below(&c, 0.0, 500);
        assert_eq!(found.len(), 1);
        assert!((found[0] - a).abs() < 1e-9, "{found:?}");
        assert!(below(&[0.5 + a * a + 1e-9, -2.0 * a, 0.5], 0.0, 500).is_empty());
        // Derivative: d/du Σ c_k T_k for c = T3 → 3·U2 = 3(4u² − 1) = 6 T2 + 3 T0.
        let d = derivative(&[0.0, 0.0, 0.0, 1.0]);
        assert!((d[0] - 3.0).abs() < 1e-14 && d[1].abs() < 1e-14 && (d[2] - 6.0).abs() < 1e-14);
    }
}

//! Eigenvalues of an upper Hessenberg matrix by the Francis double-shift QR iteration as
//! LAPACK's `dlahqr` does it (eigenvalues only): the deflation test of Ahues & Tisseur (1997),
//! a bulge started between two small subdiagonal entries, two real shifts replaced by the one
//! nearer `h_nn` used twice, exceptional shifts after every ten iterations without deflation,
//! and a cap of `30·max(10, n)` iterations per eigenvalue.
//!
//! Why not only nalgebra's `Schur`: it stalls (100 000 sweeps, with any of three deflation
//! tolerances, balanced or not, after a random reflection) on the weighted H∞ loop `r·T` of
//! the robot (`configs/robot.toml`, `synthesize --method hinf`, issue 34): a well-scaled
//! 26 × 26 matrix (entries ≤ 1.5e5, finite) whose eigenvalue −1 has multiplicity six and is
//! semisimple (`rank(A + I) = 20`: the pole of `r` on five inputs and the factors' pole at
//! −1) and whose modes appear twice (the observer-based controller's copies, nearly
//! defective pairs). This iteration converges on it in 0.13 ms (LAPACK and `faer` agree to
//! 1e-9). Only the active window is updated and no Schur vectors are formed, so it is also
//! about twice as fast as nalgebra's Schur form on large matrices.

use nalgebra::DMatrix;
use num_complex::Complex64;

/// Iterations without deflation after which an exceptional shift is used.
const EXCEPTIONAL_EVERY: usize = 10;

/// The eigenvalues of the upper Hessenberg `h` (entries below the subdiagonal are ignored),
/// or `None` when an eigenvalue took more than `30·max(10, n)` iterations (LAPACK's cap).
pub(crate) fn hessenberg_eigenvalues(mut h: DMatrix<f64>) -> Option<Vec<Complex64>> {
    let n = h.nrows();
    let mut w = vec![Complex64::new(0.0, 0.0); n];
    if n == 0 {
        return Some(w);
    }
    let ulp = f64::EPSILON;
    let smlnum = f64::MIN_POSITIVE * (n as f64 / ulp);
    let itmax = 30 * n.max(10);
    let mut kdefl = 0usize;
    // `i` is the last row of the active block; eigenvalues below it are found.
    let mut i = n as isize - 1;
    while i >= 0 {
        let iu = i as usize;
        let mut l = 0usize;
        let mut converged = false;
        for _ in 0..=itmax {
            // A negligible subdiagonal entry splits the block: search upwards from `i`.
            let mut k = iu;
            while k > l {
                let sub = h[(k, k - 1)].abs();
                if sub <= smlnum {
                    break;
                }
                let mut tst = h[(k - 1, k - 1)].abs() + h[(k, k)].abs();
                if tst == 0.0 {
                    if k >= 2 {
                        tst += h[(k - 1, k - 2)].abs();
                    }
                    if k + 1 < n {
                        tst += h[(k + 1, k)].abs();
                    }
                }
                if sub <= ulp * tst {
                    // Ahues & Tisseur: the product of the off-diagonal pair against the
                    // diagonal gap.
                    let up = h[(k - 1, k)].abs();
                    let (ab, ba) = (sub.max(up), sub.min(up));
                    let gap = (h[(k - 1, k - 1)] - h[(k, k)]).abs();
                    let hkk = h[(k, k)].abs();
                    let (aa, bb) = (hkk.max(gap), hkk.min(gap));
                    let s = aa + ab;
                    if ba * (ab / s) <= smlnum.max(ulp * (bb * (aa / s))) {
                        break;
                    }
                }
                k -= 1;
            }
            l = k;
            if l > 0 {
                h[(l, l - 1)] = 0.0;
            }
            if l + 1 >= iu {
                converged = true;
                break;
            }
            kdefl += 1;
            let (mut h11, mut h12, mut h21, mut h22);
            if kdefl.is_multiple_of(2 * EXCEPTIONAL_EVERY) {
                let s = h[(iu, iu - 1)].abs() + h[(iu - 1, iu - 2)].abs();
                h11 = 0.75 * s + h[(iu, iu)];
                h12 = -0.4375 * s;
                h21 = s;
                h22 = h11;
            } else if kdefl.is_multiple_of(EXCEPTIONAL_EVERY) {
                let s = h[(l + 1, l)].abs() + h[(l + 2, l + 1)].abs();
                h11 = 0.75 * s + h[(l, l)];
                h12 = -0.4375 * s;
                h21 = s;
                h22 = h11;
            } else {
                h11 = h[(iu - 1, iu - 1)];
                h21 = h[(iu, iu - 1)];
                h12 = h[(iu - 1, iu)];
                h22 = h[(iu, iu)];
            }
            // The two shifts: the eigenvalues of the trailing 2×2 (or the exceptional one);
            // two real ones are replaced by the one closer to h22, used twice.
            let s = h11.abs() + h12.abs() + h21.abs() + h22.abs();
            let (rt1r, rt1i, rt2r, rt2i);
            if s == 0.0 {
                (rt1r, rt1i, rt2r, rt2i) = (0.0, 0.0, 0.0, 0.0);
            } else {
                h11 /= s;
                h21 /= s;
                h12 /= s;
                h22 /= s;
                let tr = (h11 + h22) / 2.0;
                let det = (h11 - tr) * (h22 - tr) - h12 * h21;
                let rtdisc = det.abs().sqrt();
                if det >= 0.0 {
                    rt1r = tr * s;
                    rt2r = rt1r;
                    rt1i = rtdisc * s;
                    rt2i = -rt1i;
                } else {
                    let (a, b) = (tr + rtdisc, tr - rtdisc);
                    let pick = if (a - h22).abs() <= (b - h22).abs() {
                        a
                    } else {
                        b
                    };
                    rt1r = pick * s;
                    rt2r = rt1r;
                    rt1i = 0.0;
                    rt2i = 0.0;
                }
            }
            // Start the bulge where two consecutive subdiagonal entries are small enough.
            let mut v = [0.0f64; 3];
            let mut m = iu - 2;
            loop {
                let s = (h[(m, m)] - rt2r).abs() + rt2i.abs() + h[(m + 1, m)].abs();
                let h21s = h[(m + 1, m)] / s;
                v[0] = h21s * h[(m, m + 1)] + (h[(m, m)] - rt1r) * ((h[(m, m)] - rt2r) / s)
                    - rt1i * (rt2i / s);
                v[1] = h21s * (h[(m, m)] + h[(m + 1, m + 1)] - rt1r - rt2r);
                v[2] = h21s * h[(m + 2, m + 1)];
                let s = v[0].abs() + v[1].abs() + v[2].abs();
                v.iter_mut().for_each(|x| *x /= s);
                if m == l {
                    break;
                }
                let h00 = h[(m, m - 1)].abs() * (v[1].abs() + v[2].abs());
                let h01 = v[0].abs()
                    * (h[(m - 1, m - 1)].abs() + h[(m, m)].abs() + h[(m + 1, m + 1)].abs());
                if h00 <= ulp * h01 {
                    break;
                }
                m -= 1;
            }
            // The double-shift QR sweep (chase the bulge from m to i), on the active block
            // `l..=i` only (eigenvalues only: no update outside it).
            for k in m..iu {
                let nr = 3.min(iu - k + 1);
                if k > m {
                    for (r, x) in v.iter_mut().enumerate().take(nr) {
                        *x = h[(k + r, k - 1)];
                    }
                }
                let (beta, tau) = householder(&mut v[..nr]);
                if k > m {
                    h[(k, k - 1)] = beta;
                    h[(k + 1, k - 1)] = 0.0;
                    if k + 2 < iu + 1 {
                        h[(k + 2, k - 1)] = 0.0;
                    }
                } else if m > l {
                    // LAPACK: not h = −h, which fails when v[1], v[2] underflow.
                    h[(k, k - 1)] *= 1.0 - tau;
                }
                let v2 = v[1];
                let t2 = tau * v2;
                if nr == 3 {
                    let v3 = v[2];
                    let t3 = tau * v3;
                    for j in k..=iu {
                        let sum = h[(k, j)] + v2 * h[(k + 1, j)] + v3 * h[(k + 2, j)];
                        h[(k, j)] -= sum * tau;
                        h[(k + 1, j)] -= sum * t2;
                        h[(k + 2, j)] -= sum * t3;
                    }
                    for j in l..=(k + 3).min(iu) {
                        let sum = h[(j, k)] + v2 * h[(j, k + 1)] + v3 * h[(j, k + 2)];
                        h[(j, k)] -= sum * tau;
                        h[(j, k + 1)] -= sum * t2;
                        h[(j, k + 2)] -= sum * t3;
                    }
                } else {
                    for j in k..=iu {
                        let sum = h[(k, j)] + v2 * h[(k + 1, j)];
                        h[(k, j)] -= sum * tau;
                        h[(k + 1, j)] -= sum * t2;
                    }
                    for j in l..=iu {
                        let sum = h[(j, k)] + v2 * h[(j, k + 1)];
                        h[(j, k)] -= sum * tau;
                        h[(j, k + 1)] -= sum * t2;
                    }
                }
            }
        }
        if !converged {
            return None;
        }
        if l == iu {
            w[iu] = Complex64::new(h[(iu, iu)], 0.0);
        } else {
            let (a, b) = two_by_two(h[(l, l)], h[(l, iu)], h[(iu, l)], h[(iu, iu)]);
            w[l] = a;
            w[iu] = b;
        }
        kdefl = 0;
        i = l as isize - 1;
    }
    Some(w)
}

/// An elementary reflector `I − τ·[1; u]·[1; u]ᵀ` mapping `x` to `β·e₁` (LAPACK `dlarfg`):
/// on return `x = [1; u]` scaled so that `x[0]` is irrelevant, `(β, τ)` returned.
fn householder(x: &mut [f64]) -> (f64, f64) {
    let alpha = x[0];
    let xnorm = x[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
    if xnorm == 0.0 {
        return (alpha, 0.0);
    }
    let beta = -alpha.signum() * alpha.hypot(xnorm);
    let tau = (beta - alpha) / beta;
    let scale = 1.0 / (alpha - beta);
    x[1..].iter_mut().for_each(|v| *v *= scale);
    x[0] = 1.0;
    (beta, tau)
}

/// The eigenvalues of `[a b; c d]`, computed without cancellation (as LAPACK `dlanv2`: the
/// larger real root from the sum, the other from the product).
fn two_by_two(a: f64, b: f64, c: f64, d: f64) -> (Complex64, Complex64) {
    let scale = a.abs().max(b.abs()).max(c.abs()).max(d.abs());
    if scale == 0.0 {
        return (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
    }
    let (a, b, c, d) = (a / scale, b / scale, c / scale, d / scale);
    let p = 0.5 * (a - d);
    let disc = p * p + b * c;
    if disc >= 0.0 {
        let z = p + p.signum() * disc.sqrt();
        if z == 0.0 {
            let x = Complex64::new(d * scale, 0.0);
            return (x, x);
        }
        let l1 = d + z;
        let l2 = d - (b / z) * c;
        (
            Complex64::new(l1 * scale, 0.0),
            Complex64::new(l2 * scale, 0.0),
        )
    } else {
        let re = 0.5 * (a + d) * scale;
        let im = (-disc).sqrt() * scale;
        (Complex64::new(re, im), Complex64::new(re, -im))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::linalg::Hessenberg;

    /// A small deterministic generator in (−0.5, 0.5).
    fn noise(seed: f64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x = (x * 3.987_654_321 + 0.1).fract();
            x - 0.5
        }
    }

    fn hqr(a: &DMatrix<f64>) -> Vec<Complex64> {
        hessenberg_eigenvalues(Hessenberg::new(a.clone()).h()).expect("converges")
    }

    /// Every computed eigenvalue `λ` makes `A − λI` singular to rounding (its smallest
    /// singular value, from an SVD, not from a Schur form), and they add up to the trace.
    fn assert_eigenvalues_of(a: &DMatrix<f64>, w: &[Complex64], rtol: f64) {
        let n = a.nrows();
        assert_eq!(w.len(), n);
        let scale = a.norm();
        for z in w {
            let m = a.map(|x| Complex64::new(x, 0.0)) - DMatrix::identity(n, n) * *z;
            let s = m.singular_values().min();
            assert!(s <= rtol * scale, "λ = {z}: σ_min(A − λI) = {s:e}");
        }
        let tr: f64 = (0..n).map(|i| a[(i, i)]).sum();
        let sum: Complex64 = w.iter().sum();
        assert!((sum.re - tr).abs() <= 1e-10 * scale && sum.im.abs() <= 1e-10 * scale);
    }

    #[test]
    fn clustered_spectrum_like_the_robot_loop() {
        // V·Λ·V⁻¹ with the robot loop's kind of spectrum: −1 six times (semisimple), two
        // copies of three lightly damped modes, one fast pole at −1.5e5 and one at −40.2.
        let mut spec: Vec<Complex64> = vec![Complex64::new(-1.0, 0.0); 6];
        for (re, im) in [(-4.5125, 45.13), (-2.85, 17.87), (-2.0125, 20.11)] {
            for _ in 0..2 {
                spec.push(Complex64::new(re, im));
                spec.push(Complex64::new(re, -im));
            }
        }
        spec.push(Complex64::new(-1.5e5, 0.0));
        spec.push(Complex64::new(-40.2, 0.0));
        let n = spec.len();
        let mut lam = DMatrix::zeros(n, n);
        let mut i = 0;
        while i < n {
            let z = spec[i];
            if z.im != 0.0 {
                lam[(i, i)] = z.re;
                lam[(i + 1, i + 1)] = z.re;
                lam[(i, i + 1)] = z.im;
                lam[(i + 1, i)] = -z.im;
                i += 2;
            } else {
                lam[(i, i)] = z.re;
                i += 1;
            }
        }
        let mut r = noise(0.317);
        let v = DMatrix::from_fn(n, n, |i, j| f64::from(u8::from(i == j)) + 0.3 * r());
        let vinv = v.clone().lu().try_inverse().expect("invertible");
        let a = &v * lam * vinv;
        // nalgebra's Schur iteration stalls on it at every deflation tolerance tried.
        for ulps in [1.0, 8.0, 64.0] {
            let schur = nalgebra::linalg::Schur::try_new(a.clone(), ulps * f64::EPSILON, 100_000);
            assert!(schur.is_none(), "nalgebra converges now ({ulps} ulps)");
        }
        assert_eq!(crate::system::eigenvalues(&a, "test").unwrap().len(), n);
        let w = hqr(&a);
        for want in &spec {
            let near = w
                .iter()
                .map(|z| (z - want).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                near <= 1e-6 * want.norm().max(1.0),
                "{want} not found in {w:?}"
            );
        }
        assert_eigenvalues_of(&a, &w, 1e-12);
    }

    #[test]
    fn random_matrices() {
        for (n, seed) in [(3, 0.11), (7, 0.23), (30, 0.37), (120, 0.41)] {
            let mut r = noise(seed);
            let a = DMatrix::from_fn(n, n, |_, _| r());
            assert_eigenvalues_of(&a, &hqr(&a), 1e-12);
        }
    }

    #[test]
    fn triangular_and_split_matrices() {
        // Already triangular: the diagonal, exactly.
        let a = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 3.0, 0.0, -4.0, 5.0, 0.0, 0.0, 7.0]);
        let mut w: Vec<f64> = hqr(&a).iter().map(|z| z.re).collect();
        w.sort_by(f64::total_cmp);
        assert_eq!(w, vec![-4.0, 1.0, 7.0]);
        // Two decoupled oscillators (a zero subdiagonal between them): ±j and −1 ± 2j.
        let a = DMatrix::from_row_slice(
            4,
            4,
            &[
                0.0, 1.0, 9.0, 9.0, -1.0, 0.0, 9.0, 9.0, 0.0, 0.0, -1.0, 2.0, 0.0, 0.0, -2.0, -1.0,
            ],
        );
        let w = hqr(&a);
        for want in [(0.0, 1.0), (0.0, -1.0), (-1.0, 2.0), (-1.0, -2.0)] {
            let want = Complex64::new(want.0, want.1);
            assert!(
                w.iter().any(|z| (z - want).norm() < 1e-14),
                "{want} in {w:?}"
            );
        }
        assert!(hessenberg_eigenvalues(DMatrix::zeros(0, 0))
            .unwrap()
            .is_empty());
        assert_eq!(
            hqr(&DMatrix::from_element(1, 1, 2.5)),
            vec![Complex64::new(2.5, 0.0)]
        );
    }
}

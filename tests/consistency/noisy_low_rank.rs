//! Theorem 4 on a large physical model (issue 21): where `M̃` is diagonal the μ search of the
//! noisy envelope runs on `F_L = E + a·bᴴ` in O(n) per step (`src/mu/low_rank.rs`).  Checked
//! here against the dense route on the same data — the same factors with one off-diagonal
//! entry of `M̃` at 1e-15 of its size, which sends every step to the dense eigenproblem — on
//! random lightly damped models of 8 to 60 modes, noisy data near and away from resonances,
//! and against the dense μ of the same matrices.

use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::consistency::{gamma_lft, r_min_noisy, BisectionSettings};
use rshape::model::FactorsAt;
use rshape::mu::{
    mu_full_scalar, mu_full_scalar_low_rank, mu_full_scalar_structured, FullPlusScalar, LowRank,
    MuSettings,
};

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Factors of `modes` lightly damped modes at `ω` (the `[physical]` export with
/// `q_k = (s + ω_k)²`), and the nominal plant there.
fn factors(modes: &[(f64, f64, f64, f64)], w: f64, off_diagonal: bool) -> (FactorsAt, Complex64) {
    let n = modes.len();
    let s = Complex64::new(0.0, w);
    let mut m = DMatrix::zeros(n, n);
    let mut nn = DMatrix::zeros(n, 1);
    let mut c = DMatrix::zeros(1, n);
    let mut g = Complex64::default();
    for (k, &(wk, z, b, cc)) in modes.iter().enumerate() {
        let q = (s + wk) * (s + wk);
        let d = s * s + 2.0 * z * wk * s + wk * wk;
        m[(k, k)] = d / q;
        nn[(k, 0)] = Complex64::new(b, 0.0) / q;
        c[(0, k)] = Complex64::new(cc, 0.0);
        g += cc * b / d;
    }
    if off_diagonal {
        m[(0, 1)] = m[(0, 0)] * 1e-15;
    }
    (FactorsAt::new(c, m, nn, vec![Complex64::new(1.0, 0.0)]), g)
}

#[test]
fn structured_noisy_envelope_matches_the_dense_route() {
    let mut rng = Rng(2026);
    let settings = BisectionSettings::default();
    let (mut compared, mut positive) = (0, 0);
    for n in [8usize, 13, 25, 60] {
        let modes: Vec<(f64, f64, f64, f64)> = (0..n)
            .map(|k| {
                let wk = 10.0 * 100f64.powf(k as f64 / (n - 1) as f64) * (1.0 + 0.02 * rng.next());
                let z = 0.005 + 0.03 * rng.next();
                (wk, z, 2.0 * rng.next() - 1.0, 2.0 * rng.next() - 1.0)
            })
            .collect();
        for i in 0..12 {
            // Half of the frequencies on a resonance, half anywhere in the band.
            let w = if i % 2 == 0 {
                modes[(i * 7) % n].0 * (1.0 + 0.002 * (rng.next() - 0.5))
            } else {
                10.0 * 100f64.powf(rng.next())
            };
            let (fast, g) = factors(&modes, w, false);
            let (dense, _) = factors(&modes, w, true);
            // A datum off the model by 1..30 % of |g|, noise radius 0.5..5 % of |g|.
            let dev =
                Complex64::from_polar(g.norm() * (0.01 + 0.29 * rng.next()), 6.3 * rng.next());
            let phi = g + dev;
            let la = g.norm() * (0.005 + 0.045 * rng.next());
            let a = r_min_noisy(&fast, phi, la, &settings).expect("fast route");
            let b = r_min_noisy(&dense, phi, la, &settings).expect("dense route");
            let tol = 1e-7 * a.r_min.max(b.r_min);
            assert!(
                (a.r_min - b.r_min).abs() <= tol
                    || (a.r_min.is_infinite() && b.r_min.is_infinite()),
                "n {n}, w {w}: structured r_min {} vs dense {}",
                a.r_min,
                b.r_min
            );
            compared += 1;
            if a.r_min > 0.0 && a.r_min.is_finite() {
                positive += 1;
                // The μ of the matrix at the answer, both ways: 1 to the bisection's tolerance.
                let m = gamma_lft(&fast, phi, Complex64::new(a.r_min, 0.0), la).unwrap();
                let s = FullPlusScalar::gamma(n);
                let d = mu_full_scalar(&m, s, &MuSettings::default()).unwrap();
                assert!(
                    (d.upper - 1.0).abs() < 1e-6,
                    "dense μ at r_min = {}",
                    d.upper
                );
            }
        }
    }
    assert_eq!(compared, 48);
    assert!(positive >= 20, "only {positive} data with 0 < r_min < ∞");
}

/// `mu_full_scalar_low_rank` with a description of the matrix gives the dense bounds; a
/// description that does not match the matrix is ignored (the dense result, not a wrong one).
#[test]
fn low_rank_mu_matches_dense_and_ignores_a_wrong_description() {
    let mut rng = Rng(7);
    let mut lazy_dense_free = 0;
    for n in [8usize, 20, 50] {
        for _ in 0..5 {
            let (q, k) = (n, n + 1);
            let mut c = || Complex64::new(rng.next() - 0.5, rng.next() - 0.5);
            let entries: Vec<(usize, usize, Complex64)> =
                (0..n).map(|j| (j + 1, j, c() * 10.0)).collect();
            let a = nalgebra::DVector::from_fn(k + 1, |_, _| c());
            let b = nalgebra::DVector::from_fn(q + 1, |_, _| c());
            let mut m = DMatrix::from_fn(k + 1, q + 1, |i, j| a[i] * b[j].conj());
            for &(i, j, v) in &entries {
                m[(i, j)] += v;
            }
            let lr = LowRank { entries, a, b };
            let s = FullPlusScalar::gamma(n);
            let set = MuSettings::default();
            let dense = mu_full_scalar(&m, s, &set).unwrap();
            let fast = mu_full_scalar_low_rank(&m, s, &set, None, Some(&lr)).unwrap();
            assert!((fast.upper - dense.upper).abs() <= 1e-9 * dense.upper);
            assert!(fast.lower <= dense.upper * (1.0 + 1e-12));
            assert!(fast.rel_gap <= 1e-9, "gap {}", fast.rel_gap);
            // Without the dense matrix (issue 34): the same bounds, and the dense M built
            // at most once, only where a step falls back to the dense eigenproblem.
            let built = std::cell::Cell::new(0);
            let make = || {
                built.set(built.get() + 1);
                m.clone()
            };
            let lazy = mu_full_scalar_structured(&lr, &make, s, &set, None).unwrap();
            assert!(
                (lazy.upper - dense.upper).abs() <= 1e-9 * dense.upper,
                "structured {} vs dense {}",
                lazy.upper,
                dense.upper
            );
            assert!(lazy.lower <= dense.upper * (1.0 + 1e-12));
            assert!(lazy.rel_gap <= 1e-9, "gap {}", lazy.rel_gap);
            assert!(built.get() <= 1, "dense M built {} times", built.get());
            lazy_dense_free += usize::from(built.get() == 0);
            let mut wrong = lr.clone();
            wrong.a[0] += Complex64::new(0.5, 0.0);
            let ignored = mu_full_scalar_low_rank(&m, s, &set, None, Some(&wrong)).unwrap();
            assert!((ignored.upper - dense.upper).abs() <= 1e-9 * dense.upper);
        }
    }
    assert!(
        lazy_dense_free >= 10,
        "only {lazy_dense_free} of 15 structured μ stayed without the dense matrix"
    );
}

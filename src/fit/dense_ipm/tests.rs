//! The dense solver against Clarabel (zero objective) on random LPs, its centre against the
//! optimality condition, its certificates re-verified by another computation.

use super::*;
use crate::fit::problem::SolverStatus;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn randn(rng: &mut ChaCha8Rng) -> f64 {
    // Box–Muller.
    let u: f64 = rng.gen_range(1e-12..1.0);
    let v: f64 = rng.gen_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

fn row(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| randn(rng)).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(u, v)| u * v).sum()
}

/// A feasible LP with an interior and a bounded set: `m` random rows slack at a random
/// point, plus `2n` rows of a box of half-width 3 around it; one equality through it.
fn feasible(seed: u64, n: usize, m: usize, spread: f64) -> Lp {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x: Vec<f64> = row(&mut rng, n);
    let mut ge = Vec::new();
    for _ in 0..m {
        let g = row(&mut rng, n);
        let h = dot(&g, &x) - rng.gen_range(0.01..1.0);
        ge.push((g, h));
    }
    for j in 0..n {
        let mut g = vec![0.0; n];
        g[j] = 1.0;
        ge.push((g.clone(), x[j] - 3.0));
        g[j] = -1.0;
        ge.push((g, -x[j] - 3.0));
    }
    let e = row(&mut rng, n);
    let eq = vec![(e.clone(), dot(&e, &x))];
    let mut lp = Lp {
        n,
        c: vec![0.0; n],
        ge,
        eq,
    };
    spread_rows(&mut lp, &mut rng, spread);
    lp
}

/// Rows (and right-hand sides) multiplied by `10^U(−spread/2, spread/2)`.
fn spread_rows(lp: &mut Lp, rng: &mut ChaCha8Rng, spread: f64) {
    if spread == 0.0 {
        return;
    }
    for (g, h) in lp.ge.iter_mut() {
        let f = 10f64.powf(rng.gen_range(-spread / 2.0..spread / 2.0));
        g.iter_mut().for_each(|v| *v *= f);
        *h *= f;
    }
}

/// An infeasible LP: `k` random rows, and a row `−Σ c_i g_i v ≥ −Σ c_i h_i + δ` that
/// contradicts their positive combination, among feasible random rows.
fn infeasible(seed: u64, n: usize, m: usize, spread: f64) -> Lp {
    let mut lp = feasible(seed, n, m, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let k = 3.min(lp.ge.len());
    let mut g = vec![0.0; n];
    let mut h = 0.0;
    for i in 0..k {
        let c: f64 = rng.gen_range(0.2..2.0);
        g.iter_mut().zip(&lp.ge[i].0).for_each(|(a, b)| *a -= c * b);
        h -= c * lp.ge[i].1;
    }
    let delta = rng.gen_range(0.05..1.0);
    let at = rng.gen_range(0..lp.ge.len());
    lp.ge.insert(at, (g, h + delta));
    spread_rows(&mut lp, &mut rng, spread);
    lp
}

fn clarabel(lp: &Lp) -> SolverStatus {
    // Rows normalized (Clarabel's own scaling is not enough over 12 decades).
    let mut l = lp.clone();
    for (g, h) in l.ge.iter_mut() {
        let m = g.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        g.iter_mut().for_each(|v| *v /= m);
        *h /= m;
    }
    l.solve(200, true).status
}

/// `Σ g_i/s_i − Σ_j e_j (1/(R − v_j) − 1/(R + v_j))` minus its projection on range(Eᵀ),
/// relative to `Σ |g_i|/s_i`: zero at the analytic centre (first-order condition).
fn centre_residual(lp: &Lp, v: &[f64]) -> f64 {
    let n = lp.n;
    let mut g = DVector::<f64>::zeros(n);
    let mut size = 0.0;
    for (gi, hi) in &lp.ge {
        let s = dot(gi, v) - hi;
        assert!(s > 0.0, "the centre is strictly feasible");
        for j in 0..n {
            g[j] += gi[j] / s;
            size += gi[j].abs() / s;
        }
    }
    for j in 0..n {
        g[j] -= 1.0 / (RADIUS - v[j]) - 1.0 / (RADIUS + v[j]);
    }
    let p = lp.eq.len();
    let e = DMatrix::from_fn(p, n, |i, j| lp.eq[i].0[j]);
    // Least squares by SVD (another route than the solver's eigen-elimination).
    let svd = e.transpose().svd(true, true);
    let mu = svd.solve(&g, 1e-14).unwrap();
    let r = &g - e.transpose() * mu;
    r.norm() / size
}

/// The certificate re-verified: `max over the box of yᵀ(Gv − h) + μᵀ(Ev − e)` is attained at
/// the vertex `v = R·sign(r)` and must be negative (matrix products by nalgebra, not the
/// solver's loops).
fn certificate_refutes_box(lp: &Lp, cert: &Farkas) -> bool {
    let n = lp.n;
    if cert.y.iter().any(|v| *v < 0.0) {
        return false;
    }
    let g = DMatrix::from_fn(lp.ge.len(), n, |i, j| lp.ge[i].0[j]);
    let h = DVector::from_iterator(lp.ge.len(), lp.ge.iter().map(|r| r.1));
    let y = DVector::from_column_slice(&cert.y);
    let e = DMatrix::from_fn(lp.eq.len(), n, |i, j| lp.eq[i].0[j]);
    let ev = DVector::from_iterator(lp.eq.len(), lp.eq.iter().map(|r| r.1));
    let mu = DVector::from_column_slice(&cert.mu);
    let r = g.transpose() * &y + e.transpose() * &mu;
    let vertex = r.map(|x| RADIUS * x.signum());
    let value = r.dot(&vertex) - h.dot(&y) - ev.dot(&mu);
    value < 0.0
}

#[test]
fn feasible_lps_give_the_centre_and_agree_with_clarabel() {
    for seed in 0..40 {
        let n = 4 + (seed as usize % 12);
        let m = 20 + 37 * (seed as usize % 9);
        for spread in [0.0, 12.0] {
            let lp = feasible(seed, n, m, spread);
            let (out, _) = analytic_centre(&lp, None);
            let Outcome::Centre { v, converged } = out else {
                panic!("seed {seed} spread {spread}: {out:?}");
            };
            assert!(converged, "seed {seed} spread {spread}");
            let res = centre_residual(&lp, &v);
            assert!(res < 1e-7, "seed {seed} spread {spread}: residual {res:e}");
            let e = &lp.eq[0];
            assert!((dot(&e.0, &v) - e.1).abs() < 1e-9 * (1.0 + e.1.abs()));
            assert_eq!(clarabel(&lp), SolverStatus::Solved, "seed {seed}");
        }
    }
}

#[test]
fn infeasible_lps_give_a_certificate_that_clarabel_confirms() {
    for seed in 0..40 {
        let n = 3 + (seed as usize % 12);
        let m = 10 + 41 * (seed as usize % 7);
        for spread in [0.0, 12.0] {
            let lp = infeasible(seed, n, m, spread);
            let (out, _) = analytic_centre(&lp, None);
            let Outcome::Infeasible(cert) = out else {
                panic!("seed {seed} spread {spread}: {out:?}");
            };
            assert!(certificate_refutes_box(&lp, &cert), "seed {seed}");
            assert!(farkas_holds(&lp, &cert, RADIUS));
            assert_eq!(clarabel(&lp), SolverStatus::PrimalInfeasible, "seed {seed}");
        }
    }
}

/// The centre is a function of the LP: the same (to round-off) from another start and with
/// the rows in another order.
#[test]
fn centre_does_not_depend_on_start_or_row_order() {
    for seed in 0..20 {
        let lp = feasible(100 + seed, 12, 300, 6.0);
        let (Outcome::Centre { v: a, .. }, _) = analytic_centre(&lp, None) else {
            panic!("seed {seed}");
        };
        let mut perm = lp.clone();
        perm.ge.reverse();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let start: Vec<f64> = (0..lp.n).map(|_| 5.0 * randn(&mut rng)).collect();
        let (Outcome::Centre { v: b, .. }, _) = analytic_centre(&perm, Some(&start)) else {
            panic!("seed {seed}");
        };
        let scale = 1.0 + a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-9 * scale, "seed {seed}: {x} vs {y}");
        }
    }
}

/// Degenerate sets: an interval of zero width (`x₀ ≥ 1`, `x₀ ≤ 1`) has no interior and no
/// certificate (undecided, never "infeasible"); many rows through one vertex and duplicated
/// rows leave an interior (a centre, checked by its condition).
#[test]
fn degenerate_sets() {
    let n = 3;
    let unit = |j: usize, s: f64| {
        let mut g = vec![0.0; n];
        g[j] = s;
        g
    };
    let mut ge = vec![(unit(0, 1.0), 1.0), (unit(0, -1.0), -1.0)];
    for j in 1..n {
        ge.push((unit(j, 1.0), -1.0));
        ge.push((unit(j, -1.0), -1.0));
    }
    let flat = Lp {
        n,
        c: vec![0.0; n],
        ge,
        eq: vec![],
    };
    let (out, _) = analytic_centre(&flat, None);
    assert!(matches!(out, Outcome::Undecided(_)), "{out:?}");
    // A simplex-like cone cut at a vertex by 50 rows through the origin, the same rows twice.
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut ge = Vec::new();
    for _ in 0..50 {
        // Rows with positive coefficients: all hold with equality at 0, strictly at (1,1,1).
        let g: Vec<f64> = (0..n).map(|_| rng.gen_range(0.1..1.0)).collect();
        ge.push((g.clone(), 0.0));
        ge.push((g, 0.0));
    }
    ge.push((vec![-1.0; n], -3.0));
    let cone = Lp {
        n,
        c: vec![0.0; n],
        ge,
        eq: vec![],
    };
    let (out, _) = analytic_centre(&cone, None);
    let Outcome::Centre { v, converged } = out else {
        panic!("{out:?}");
    };
    assert!(converged);
    let lp_eq = Lp {
        eq: vec![(vec![0.0; n], 0.0)],
        ..cone.clone()
    };
    // (A zero equality row is consistent and changes nothing.)
    let (Outcome::Centre { v: w, .. }, _) = analytic_centre(&lp_eq, None) else {
        panic!("zero equality");
    };
    for (a, b) in v.iter().zip(&w) {
        assert!((a - b).abs() < 1e-9);
    }
    // Condition without equalities: the gradient itself vanishes.
    let mut g = [0.0; 3];
    let mut size = 0.0;
    for (gi, hi) in &lp_eq.ge {
        let s = dot(gi, &v) - hi;
        for j in 0..n {
            g[j] += gi[j] / s;
            size += gi[j].abs() / s;
        }
    }
    for j in 0..n {
        g[j] -= 1.0 / (RADIUS - v[j]) - 1.0 / (RADIUS + v[j]);
        assert!(g[j].abs() < 1e-9 * size, "{g:?}");
    }
}

/// Bad input gives a status, never a panic; inconsistent equalities are proved infeasible.
#[test]
fn bad_input_and_inconsistent_equalities() {
    let nan = Lp {
        n: 2,
        c: vec![0.0; 2],
        ge: vec![(vec![f64::NAN, 1.0], 0.0)],
        eq: vec![],
    };
    assert!(matches!(
        analytic_centre(&nan, None).0,
        Outcome::Undecided(_)
    ));
    let none = Lp {
        n: 0,
        c: vec![],
        ge: vec![],
        eq: vec![],
    };
    assert!(matches!(
        analytic_centre(&none, None).0,
        Outcome::Undecided(_)
    ));
    let short = Lp {
        n: 2,
        c: vec![0.0; 2],
        ge: vec![(vec![1.0], 0.0)],
        eq: vec![],
    };
    assert!(matches!(
        analytic_centre(&short, None).0,
        Outcome::Undecided(_)
    ));
    // x + y = 1 and 2x + 2y = 3.
    let clash = Lp {
        n: 2,
        c: vec![0.0; 2],
        ge: vec![(vec![1.0, 0.0], 0.0)],
        eq: vec![(vec![1.0, 1.0], 1.0), (vec![2.0, 2.0], 3.0)],
    };
    let Outcome::Infeasible(cert) = analytic_centre(&clash, None).0 else {
        panic!("inconsistent equalities");
    };
    assert!(certificate_refutes_box(&clash, &cert));
    // A row constant on the equality and violated: x + y ≥ 2 with x + y = 1.
    let violated = Lp {
        n: 2,
        c: vec![0.0; 2],
        ge: vec![(vec![1.0, 1.0], 2.0), (vec![1.0, 0.0], -5.0)],
        eq: vec![(vec![1.0, 1.0], 1.0)],
    };
    let Outcome::Infeasible(cert) = analytic_centre(&violated, None).0 else {
        panic!("violated constant row");
    };
    assert!(certificate_refutes_box(&violated, &cert));
    // The check rejects a negative weight and a certificate whose gap the box beats.
    assert!(!farkas_holds(
        &violated,
        &Farkas {
            y: vec![-1.0, 0.0],
            mu: vec![0.0]
        },
        RADIUS
    ));
    assert!(!farkas_holds(
        &violated,
        &Farkas {
            y: vec![0.0, 1.0],
            mu: vec![0.0]
        },
        RADIUS
    ));
}

//! Tests of [`super`]: the bound against closed forms and brute force, the check of the
//! certificates, and rows over 12 decades.

use super::*;
use crate::consistency::{Envelope, EnvelopeMethod};
use crate::fit::context::prepare;
use crate::fit::FitSettings;

fn envelope(omega: Vec<f64>, r_min: Vec<f64>) -> Envelope {
    Envelope {
        omega,
        r_min,
        a1_limit: None,
        method: EnvelopeMethod::File,
    }
}

fn prepared(env: &Envelope) -> Prepared {
    prepare(env, None, &FitSettings::default()).unwrap().prep
}

/// The relaxation's optimum at order 1 by brute force, independent of any LP: every
/// `|r̂|² = g²·(cos θ + sin θ·x)/(cos φ + sin φ·x)` with `θ, φ ∈ [0, π/2]` (all pairs of
/// linear forms ≥ 0 on `x ∈ [0, ∞]`, up to scale), the gain the smallest that meets every
/// loosened lower bound on the grid, the level the largest `|r̂|²/U` at the data.  The
/// angles run over `tan θ = 10^k` (roots from 10⁻²⁰ to 10²⁰ in `x`, and both ends), a coarse
/// pass then three zooms around the best.
fn brute_force_order1(prep: &Prepared) -> f64 {
    let pts: Vec<(f64, f64, Option<f64>)> = prep
        .grid
        .iter()
        .map(|g| (g.x, g.lower, g.upper.filter(|_| g.kind == PointKind::Datum)))
        .collect();
    let form = |k: f64, x: f64| -> f64 {
        // cos θ + sin θ·x with tan θ = 10^k (k = ±∞: the ends); at x = ∞ its leading term.
        let th = if k == f64::NEG_INFINITY {
            0.0
        } else if k == f64::INFINITY {
            std::f64::consts::FRAC_PI_2
        } else {
            10f64.powf(k).atan()
        };
        if x.is_infinite() {
            th.sin()
        } else {
            th.cos() + th.sin() * x
        }
    };
    let level = |ka: f64, kb: f64| -> f64 {
        let mut g2 = 0.0f64;
        for (x, lower, _) in &pts {
            let (a, b) = (form(ka, *x), form(kb, *x));
            if *lower > 0.0 && b > 0.0 {
                if !(a > 0.0) {
                    return f64::INFINITY;
                }
                g2 = g2.max((1.0 - FEASIBLE_TOL) * lower * b / a);
            }
        }
        let mut t = 0.0f64;
        for (x, _, up) in &pts {
            if let Some(up) = up {
                let (a, b) = (form(ka, *x), form(kb, *x));
                if !(b > 0.0) {
                    return f64::INFINITY;
                }
                t = t.max(g2 * a / (up * b));
            }
        }
        t
    };
    let mut ks: Vec<f64> = (-200..=200).map(|i| i as f64 * 0.1).collect();
    ks.push(f64::NEG_INFINITY);
    ks.push(f64::INFINITY);
    let (mut best, mut at) = (f64::INFINITY, (0.0, 0.0));
    for ka in &ks {
        for kb in &ks {
            let t = level(*ka, *kb);
            if t < best {
                (best, at) = (t, (*ka, *kb));
            }
        }
    }
    let mut h = 0.1;
    for _ in 0..3 {
        let centre = at;
        let grid = |c: f64| -> Vec<f64> {
            if c.is_infinite() {
                vec![c]
            } else {
                (-50..=50).map(|i| c + h * i as f64 / 25.0).collect()
            }
        };
        for ka in grid(centre.0) {
            for kb in grid(centre.1) {
                let t = level(ka, kb);
                if t < best {
                    (best, at) = (t, (ka, kb));
                }
            }
        }
        h /= 25.0;
    }
    best
}

/// The smallest upper bound at the data (the constant's level is `max lower / min upper`).
fn min_upper(prep: &Prepared) -> f64 {
    prep.grid
        .iter()
        .filter(|g| g.kind == PointKind::Datum)
        .filter_map(|g| g.upper)
        .fold(f64::INFINITY, f64::min)
}

/// Order 0: `r` is a constant `c`, so the optimum is `(1 − 10⁻⁶)·max lower/min U` over the
/// grid, `(max r_min/min r_min)²` up to the fit's safety factor: the bound reaches it from
/// below, a level just under it is proved and one just over it is feasible.
#[test]
fn order_zero_bound_is_the_closed_form() {
    let r = [1.0, 3.0, 0.5, 2.0, 1.5];
    let env = envelope(vec![0.1, 0.3, 1.0, 3.0, 10.0], r.to_vec());
    let prep = prepared(&env);
    let lmax = prep.grid.iter().map(|g| g.lower).fold(0.0, f64::max);
    let umin = min_upper(&prep);
    let t_star = (1.0 - FEASIBLE_TOL) * lmax / umin;
    // The same in the data's own terms: the magnitudes' ratio, squared.
    assert!((t_star / 36.0 - 1.0).abs() < 1e-5, "{t_star}");
    assert!(matches!(
        prove_below(&prep, 0, t_star * (1.0 - 1e-4)),
        Verdict::Proved(m) if m > 0.0
    ));
    assert_eq!(
        prove_below(&prep, 0, t_star * (1.0 + 1e-4)),
        Verdict::Feasible
    );
    let b = lower_bound(&prep, 0, 100.0, 1e-6, 60);
    let t = b.t.expect("a bound");
    assert!(t <= t_star * (1.0 + 1e-9), "{t} > {t_star}");
    // The certificate's margin shrinks with the distance below the optimum, and Clarabel's
    // residuals are ~1e-11 of its weights: a proof is found to within 1e-4 (4e-5 decade).
    assert!(t >= t_star * (1.0 - 1e-4), "{t} ≪ {t_star}");
    // In decades: half the level's log plus the offset is log10(max/min r_min) = log10 6.
    let d = 0.5 * t.log10() + log10_offset(&prep);
    assert!((d - 6f64.log10()).abs() < 5e-5, "{d}");
}

/// Order 1 on 3–5 data: the bound is below the brute-force optimum of the relaxation (every
/// brute-force point is feasible for it) and within 1 % of it (at order 1 the relaxation is
/// exact: a linear form ≥ 0 at both ends of `[−1, 1]` is ≥ 0 on it).
#[test]
fn order_one_bound_meets_brute_force() {
    let cases = [
        (vec![0.1, 1.0, 10.0], vec![1.0, 4.0, 0.5]),
        (vec![0.5, 1.0, 2.0, 4.0], vec![2.0, 1.0, 3.0, 0.7]),
        (
            vec![0.01, 0.1, 1.0, 10.0, 100.0],
            vec![0.1, 0.3, 1.0, 3.0, 10.0],
        ),
    ];
    for (w, r) in cases {
        let prep = prepared(&envelope(w.clone(), r.clone()));
        let bf = brute_force_order1(&prep);
        let b = lower_bound(&prep, 1, bf * 4.0, 1e-5, 60);
        let t = b.t.expect("a bound");
        assert!(
            t <= bf * (1.0 + 1e-9),
            "{w:?} {r:?}: bound {t} above brute force {bf}"
        );
        assert!(
            t >= bf * 0.99,
            "{w:?} {r:?}: bound {t} far below brute force {bf}"
        );
    }
}

/// The check accepts Clarabel's certificate and rejects a tampered one: a negative weight,
/// a weight doubled, the same certificate at a level where a feasible point is known (the
/// constant at the largest lower bound, checked by hand), and NaN.
#[test]
fn certificates_are_checked_not_trusted() {
    let env = envelope(vec![0.1, 1.0, 10.0], vec![1.0, 4.0, 0.5]);
    let prep = prepared(&env);
    let bf = brute_force_order1(&prep);
    let t = 0.9 * bf;
    let (ids, y, mu) = certificate(&prep, 1, t, &mut 0).expect("infeasible below the optimum");
    assert!(check(&prep, 1, t, &ids, &y, mu).is_some());
    let big = (0..y.len()).max_by(|&i, &j| y[i].total_cmp(&y[j])).unwrap();
    let mut neg = y.clone();
    neg[big] = -y[big];
    assert!(check(&prep, 1, t, &ids, &neg, mu).is_none());
    let mut twice = y.clone();
    twice[big] *= 2.0;
    assert!(check(&prep, 1, t, &ids, &twice, mu).is_none());
    assert!(check(&prep, 1, t, &ids, &y, f64::NAN).is_none());
    assert!(check(&prep, 1, t, &ids, &y[1..], mu).is_none());
    // At the constant's level the constant is feasible: no certificate may pass there.
    let c2 = prep.grid.iter().map(|g| g.lower).fold(0.0, f64::max);
    let umin = min_upper(&prep);
    let t_const = c2 / umin;
    assert!(check(&prep, 1, t_const, &ids, &y, mu).is_none());
    assert_eq!(prove_below(&prep, 1, t_const), Verdict::Feasible);
    // The witness of that level meets every row as the check builds them.
    let v = [c2 / (1.0 + c2), 0.0, 1.0 / (1.0 + c2), 0.0];
    for id in row_ids(&prep, 1) {
        let g = row(&prep, 1, t_const, id, by_cosine);
        let s: f64 = g.iter().zip(&v).map(|(a, b)| a * b).sum();
        assert!(s >= -1e-12, "{id:?}: {s}");
    }
}

/// Rows over 12 decades of frequency (24 of `x`) and 6 of magnitude: the bounds at orders 0
/// and 1 still reach the closed form and the brute force from below, every proof checked.
#[test]
fn twelve_decades() {
    let w: Vec<f64> = (0..25).map(|i| 10f64.powf(-6.0 + 0.5 * i as f64)).collect();
    let r: Vec<f64> = w
        .iter()
        .enumerate()
        .map(|(i, x)| x.powf(0.25) * if i % 3 == 0 { 1.5 } else { 1.0 })
        .collect();
    let prep = prepared(&envelope(w, r.clone()));
    let rmax = r.iter().copied().fold(0.0, f64::max);
    let rmin = r.iter().copied().fold(f64::INFINITY, f64::min);
    let t0 = (1.0 - FEASIBLE_TOL) * (rmax / rmin).powi(2);
    let b0 = lower_bound(&prep, 0, 2.0 * t0, 1e-6, 60);
    let t = b0.t.expect("order 0 bound");
    // Near the optimum the certificate's weights grow as 1/(distance) times the 6 decades
    // of `r_min²` the rows span, and the round-off bound with them: proofs reach within
    // 1 % of the level here (0.002 decade), within 1e-4 on the 2-decade case above.
    assert!(t <= t0 * (1.0 + 1e-6) && t >= t0 * 0.99, "{t} vs {t0}");
    let bf = brute_force_order1(&prep);
    let b1 = lower_bound(&prep, 1, 2.0 * bf, 1e-5, 60);
    let t1 = b1.t.expect("order 1 bound");
    assert!(t1 <= bf * (1.0 + 1e-9) && t1 >= 0.98 * bf, "{t1} vs {bf}");
    assert!(t1 < t, "order 1 must beat order 0 here: {t1} {t}");
}

/// Bad levels and a bracket with nothing to prove give no bound, never a panic.
#[test]
fn degenerate_inputs_prove_nothing() {
    let prep = prepared(&envelope(vec![1.0, 2.0], vec![1.0, 1.0]));
    for t in [f64::NAN, -1.0, 0.0, f64::INFINITY] {
        assert!(matches!(prove_below(&prep, 2, t), Verdict::Undecided(_)));
    }
    assert_eq!(lower_bound(&prep, 2, 1.0, 1e-3, 10).t, None);
    assert_eq!(lower_bound(&prep, 2, f64::NAN, 1e-3, 10).lp_solves, 0);
    assert!(lower_bound(&prep, 2, 100.0, 1e-3, 10).lp_solves >= 1);
}

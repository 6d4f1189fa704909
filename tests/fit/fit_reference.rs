//! rshape's fit against a reference fitter written here, independently (GitHub issue 11,
//! defect 3): the classical log-Chebyshev LP bisection (`fitmagfrd`-style) on the full
//! numerator and denominator of `|r|² = A(x)/B(x)`, `x = ω̂²`, with rshape's extra rules
//! (data covered, no dip between data, floor outside the band and at 0 and ∞).
//!
//! Independence: the reference uses its own parametrization (Chebyshev polynomials in the
//! disk variable `u = (x − x₀)/(x + x₀)`, so `A(x) = (x + x₀)^N Σ a_k T_k(u)`, at three
//! centres `x₀`: 1 and the two ends of the band), its own constraint points, a pure
//! feasibility LP per level (no slack maximization, no working set, no cuts) solved with
//! the clarabel crate directly, and plain bisection on the level.  A level counts only when
//! the LP's solution is a unit that meets the bounds: `A, B > 0` on 40,001 points of
//! `[0, ∞]` and its bounds relative to 1e-6 at the data and on 40 points between
//! consecutive data (an interior-point solution meets its rows only to ~1e-8 absolute, which
//! lets the Chebyshev series change sign where they are tiny).  Its bounds hold on its
//! sample points only, so it can only be optimistic; rshape's fits are certified between
//! the data exactly.
//!
//! Checked on 30 envelopes (smooth, jagged, noisy with zero rows, steeply rising, 1 to 7
//! decades) at every order 1–8: rshape's `max log10(|r|/r_min)` is within 0.01 decade of
//! the reference's, and rshape's fit is always certified.
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use rshape::consistency::{Envelope, EnvelopeMethod};
use rshape::fit::{fit_unit, FitSettings};
use rshape::system::logspace;

/// `[T_0(u), …, T_n(u)]`.
fn cheb(n: usize, u: f64) -> Vec<f64> {
    let mut t = vec![1.0, u];
    for k in 2..=n {
        let v = 2.0 * u * t[k - 1] - t[k - 2];
        t.push(v);
    }
    t.truncate(n + 1);
    t
}

/// Feasibility of `G v ≥ 0`-type rows (each `(row, rhs)`: `row·v ≥ rhs`) and one equality.
fn feasible(n: usize, rows: &[(Vec<f64>, f64)], eq: &(Vec<f64>, f64)) -> Option<Vec<f64>> {
    let m = rows.len() + 1;
    let mut colptr = vec![0];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for j in 0..n {
        if eq.0[j] != 0.0 {
            rowval.push(0);
            nzval.push(eq.0[j]);
        }
        for (i, (r, _)) in rows.iter().enumerate() {
            if r[j] != 0.0 {
                rowval.push(i + 1);
                nzval.push(-r[j]);
            }
        }
        colptr.push(rowval.len());
    }
    let a = CscMatrix::new(m, n, colptr, rowval, nzval);
    let mut b = vec![eq.1];
    b.extend(rows.iter().map(|(_, h)| -h));
    let cones = [
        SupportedConeT::ZeroConeT(1),
        SupportedConeT::NonnegativeConeT(rows.len()),
    ];
    let p = CscMatrix::<f64>::zeros((n, n));
    let q = vec![0.0; n];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .build()
        .unwrap();
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).unwrap();
    solver.solve();
    matches!(solver.solution.status, SolverStatus::Solved).then(|| solver.solution.x.clone())
}

/// The reference level: the smallest `max log10(|r|/r_min)` (to 0.002 decade) at order `n`,
/// or `None` if no level up to 12 decades is feasible on its grid.
/// The reference level: the best over three disk-map centres (`x₀ = 1`, the top and the
/// bottom of the band in `x`) of [`reference_level_at`].
fn reference_level(omega: &[f64], r_min: &[f64], n: usize, floor_rel: f64) -> Option<f64> {
    let w0 = (omega[0] * omega[omega.len() - 1]).sqrt();
    let x_hi = (omega[omega.len() - 1] / w0).powi(2);
    [1.0, x_hi, 1.0 / x_hi]
        .iter()
        .filter_map(|x0| reference_level_at(omega, r_min, n, floor_rel, *x0))
        .min_by(f64::total_cmp)
}

/// `Σ c_k T_k(u)`.
fn series(c: &[f64], u: f64) -> f64 {
    cheb(c.len() - 1, u).iter().zip(c).map(|(a, b)| a * b).sum()
}

/// A level is reached only by a *unit*: `A > 0` and `B > 0` on all of `x ∈ [0, ∞]`, not
/// only at the LP's points.  An interior-point solution meets its rows to about 1e-8, and a
/// Chebyshev series that is tiny near `u = ±1` (a rising `|r|`) can change sign there
/// within that tolerance: such a solution is no fit (its spectral factors have poles on
/// the axis), so the level is not counted as feasible.  Checked on 40,001 points
/// log-spaced in `x` from 1e-20 to 1e20 (spacing 0.001 decade) and at `u = ±1`.
fn valid_unit(a: &[f64], b: &[f64], x0: f64) -> bool {
    (0..=40_000)
        .map(|i| {
            let x = 10f64.powf(-20.0 + 40.0 * i as f64 / 40_000.0);
            (x - x0) / (x + x0)
        })
        .chain([-1.0, 1.0])
        .all(|u| series(a, u) > 0.0 && series(b, u) > 0.0)
}

/// The reference level with the disk map centred at `x₀`: the smallest
/// `max log10(|r|/r_min)` (to 0.002 decade) at order `n` whose LP solution is a unit, or
/// `None` if no level up to 12 decades is.
fn reference_level_at(
    omega: &[f64],
    r_min: &[f64],
    n: usize,
    floor_rel: f64,
    x0: f64,
) -> Option<f64> {
    let w0 = (omega[0] * omega[omega.len() - 1]).sqrt();
    let pos: Vec<f64> = r_min.iter().copied().filter(|r| *r > 0.0).collect();
    let rho = (pos.iter().map(|r| r.ln()).sum::<f64>() / pos.len() as f64).exp();
    let fl = floor_rel * pos.iter().copied().fold(f64::INFINITY, f64::min) / rho;
    let x = |w: f64| (w / w0) * (w / w0);
    let u = |x: f64| {
        if x.is_infinite() {
            1.0
        } else {
            (x - x0) / (x + x0)
        }
    };
    let l: Vec<f64> = r_min.iter().map(|r| (r / rho) * (r / rho)).collect();
    let nv = 2 * (n + 1);
    // A row `c_a·A − c_b·B ≥ rhs` at point u, normalized.
    let row = |uu: f64, ca: f64, cb: f64, rhs: f64| -> (Vec<f64>, f64) {
        let t = cheb(n, uu);
        let mut r = vec![0.0; nv];
        for k in 0..=n {
            r[k] = ca * t[k];
            r[n + 1 + k] = -cb * t[k];
        }
        let m = r.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
        (r.iter().map(|v| v / m).collect(), rhs / m)
    };
    let mut fixed = Vec::new();
    let mut points = Vec::new();
    let mut bounds: Vec<(f64, f64)> = Vec::new();
    for (i, w) in omega.iter().enumerate() {
        points.push(u(x(*w)));
        if l[i] > 0.0 {
            fixed.push(row(u(x(*w)), 1.0, l[i], 0.0));
            bounds.push((u(x(*w)), l[i]));
        }
    }
    for i in 1..omega.len() {
        let m = l[i - 1].min(l[i]);
        for (j, w) in logspace(omega[i - 1], omega[i], 42)
            .iter()
            .enumerate()
            .skip(1)
            .take(40)
        {
            // Four points between data are LP rows; all forty are checked afterwards (a
            // unit that dips between the rows does not count, as in rshape's certificate).
            if j % 8 == 4 {
                points.push(u(x(*w)));
                if m > 0.0 {
                    fixed.push(row(u(x(*w)), 1.0, m, 0.0));
                }
            }
            if m > 0.0 {
                bounds.push((u(x(*w)), m));
            }
        }
    }
    let (lo, hi) = (omega[0], omega[omega.len() - 1]);
    let mut outside: Vec<f64> = logspace(lo / 100.0, lo, 41);
    outside.extend(logspace(hi, hi * 100.0, 41));
    for w in outside {
        points.push(u(x(w)));
    }
    points.push(-1.0); // ω = 0
    points.push(1.0); // ω = ∞
    for p in &points {
        bounds.push((*p, fl * fl));
        fixed.push(row(*p, 1.0, fl * fl, 0.0)); // floor everywhere
        fixed.push(row(*p, 0.0, -1.0, 1e-9)); // B > 0
    }
    let mut eq = vec![0.0; nv];
    eq[n + 1..].copy_from_slice(&cheb(n, 0.0));
    let eq = (eq, 1.0);
    let feasible_at = |lev: f64| -> bool {
        let t = 10f64.powf(2.0 * lev);
        let mut rows = fixed.clone();
        for (i, w) in omega.iter().enumerate() {
            if l[i] > 0.0 {
                rows.push(row(u(x(*w)), -1.0, -t * l[i], 0.0));
            }
        }
        feasible(nv, &rows, &eq).is_some_and(|v| {
            let (a, b) = (&v[..=n], &v[n + 1..]);
            // Its own bounds, relative: `A/B ≥ lower` and `A/B ≤ t·r_min²` to 1e-6 (the LP
            // meets them only to ~1e-8 absolute, nothing where the series are tiny).
            let ok = bounds
                .iter()
                .all(|(uu, l)| series(a, *uu) >= (1.0 - 1e-6) * l * series(b, *uu))
                && omega.iter().zip(&l).all(|(w, li)| {
                    let uu = u(x(*w));
                    *li == 0.0 || series(a, uu) <= (1.0 + 1e-6) * t * li * series(b, uu)
                });
            ok && valid_unit(a, b, x0)
        })
    };
    let mut hi_lev = 0.25;
    while !feasible_at(hi_lev) {
        hi_lev *= 2.0;
        if hi_lev > 12.0 {
            return None;
        }
    }
    let mut lo_lev = 0.0;
    while hi_lev - lo_lev > 0.002 {
        let mid = 0.5 * (lo_lev + hi_lev);
        if feasible_at(mid) {
            hi_lev = mid;
        } else {
            lo_lev = mid;
        }
    }
    Some(hi_lev)
}

/// Envelope `k` of 30: kinds cycle through smooth, jagged, noisy (zero rows), rising; the
/// band spans 1 to 7 decades.
fn envelope(k: usize) -> (Vec<f64>, Vec<f64>) {
    let decades = 1.0 + (k % 7) as f64;
    let omega = logspace(1.0, 10f64.powf(decades), 40);
    let mut seed = 1234567u64 + 7919 * k as u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let c = 10f64.powf(decades * (0.2 + 0.6 * rnd()));
    let res = 10f64.powf(decades * (0.2 + 0.6 * rnd()));
    let base = |w: f64| {
        0.1 * (1.0 + (w / c).powi(2)).sqrt() * (1.0 + 3.0 / (1.0 + (8.0 * (w / res).ln()).powi(2)))
    };
    let r_min: Vec<f64> = omega
        .iter()
        .map(|w| match k % 4 {
            0 => base(*w),
            1 => base(*w) * (0.4 + 0.6 * rnd()),
            2 => {
                if rnd() < 0.3 {
                    0.0
                } else {
                    base(*w) * (0.6 + 0.4 * rnd())
                }
            }
            _ => {
                let top = omega[omega.len() - 1] / 10f64.powf(decades.min(2.0) / 2.0);
                0.01 * if *w > top { (w / top).powi(2) } else { 1.0 }
            }
        })
        .collect();
    (omega, r_min)
}

/// Every order 1–8 on all 30 envelopes (240 pairs): rshape's certified level is within
/// 0.01 decade of the reference's wherever the reference reaches a unit, and a fixed order
/// `N + 1` fitted alone (not chained) is never worse than order `N` by more than the
/// tolerance the fit is solved to (see [`alone_tolerance`]; chained orders are exactly
/// monotone, tested below).  Run with
/// `cargo test --release --test fit fit_reference:: -- --ignored --nocapture` to see the table.
#[test]
#[ignore = "about 3 min in release, too long for CI at the test profile; the CI subset below holds the pairs that failed before"]
fn rshape_reaches_the_reference_optimum_at_every_order() {
    // The measurement switches of issue 38's eleventh step, if set (RSHAPE_SWEEP_FAST, …).
    super::fit_sweep::apply_switches();
    let pairs: Vec<(usize, usize)> = (0..30).flat_map(|k| (1..=8).map(move |n| (k, n))).collect();
    sweep(&pairs, 200);
}

/// How much worse order `N + 1` alone may end than order `N` alone: each order's minimax
/// level is found by bisection to `bisection_tol` (relative, on `|r|`), and the ranking
/// then prefers the smallest mean among candidates within that much of the best maximum
/// (src/fit/engine.rs), so two independent searches can each stop anywhere within
/// `2·log10(1 + bisection_tol)` (0.0017 decade by default) of the same optimum.
fn alone_tolerance(set: &FitSettings) -> f64 {
    2.0 * (1.0 + set.bisection_tol).log10()
}

/// The part of the sweep that runs in CI: the pairs that failed before the disk-map
/// centres and the positivity cuts of `src/fit/polyfit.rs` (rising envelopes 11, 19, 27 at
/// orders 2–3, up to 0.94 decade; envelope 3 at order 3), the three that stayed above the
/// reference before the relative cuts and the band-end centres (13/o4 +0.017, 27/o4
/// +0.011, 27/o5 +0.014 decade), and smooth, jagged and noisy envelopes of 1–7 decades.
#[test]
fn rshape_reaches_the_reference_optimum_on_a_subset() {
    let pairs = [
        (3, 3),
        (11, 2),
        (19, 2),
        (27, 2),
        (0, 1),
        (1, 4),
        (12, 5),
        (16, 2),
        (13, 4),
        (27, 4),
        (27, 5),
    ];
    sweep(&pairs, 11);
}

fn sweep(list: &[(usize, usize)], min_pairs: usize) {
    let start = std::time::Instant::now();
    let mut worst_gap = f64::NEG_INFINITY;
    let mut pairs = 0;
    let mut no_reference = 0;
    let mut failures = Vec::new();
    let mut levels: Vec<((usize, usize), f64)> = Vec::new();
    for &(k, order) in list {
        let (omega, r_min) = envelope(k);
        let env = Envelope {
            omega: omega.clone(),
            r_min: r_min.clone(),
            a1_limit: None,
            method: EnvelopeMethod::File,
        };
        let set = FitSettings {
            order,
            ..Default::default()
        };
        let fit = fit_unit(&env, None, &set, &Default::default())
            .unwrap_or_else(|e| panic!("envelope {k}, order {order}: {e}"));
        assert!(fit.certificate.passed, "envelope {k}, order {order}");
        let ours = fit.certificate.max_log10_ratio;
        if let Some(((pk, pn), prev)) = levels.last() {
            if *pk == k && *pn + 1 == order && ours > prev + alone_tolerance(&set) {
                failures.push(format!(
                    "envelope {k}: order {order} ({ours:.6}) worse than order {pn} ({prev:.6})"
                ));
            }
        }
        levels.push(((k, order), ours));
        match reference_level(&omega, &r_min, order, set.floor_rel) {
            Some(reference) => {
                let gap = ours - reference;
                worst_gap = worst_gap.max(gap);
                pairs += 1;
                eprintln!("envelope {k} order {order}: rshape {ours:.4}, reference {reference:.4}, gap {gap:+.4}");
                if gap > 0.01 {
                    failures.push(format!("envelope {k} order {order}: rshape {ours:.4} > reference {reference:.4} + 0.01"));
                }
            }
            None => {
                no_reference += 1;
                eprintln!("envelope {k} order {order}: rshape {ours:.4}, no reference unit");
            }
        }
    }
    eprintln!(
        "{pairs} pairs compared ({no_reference} without a reference unit); {} failures; worst gap {worst_gap:+.4} decade; {:.1} s",
        failures.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(
        pairs >= min_pairs,
        "only {pairs} pairs had a reference level"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Order `N+1` is never worse than order `N` (chained; the objective's promise), and `--order auto` is never worse
/// than the best order of its sweep by more than its documented tolerance (issue 11,
/// defect 3), on smooth, jagged, noisy and rising envelopes.
#[test]
fn higher_order_never_worse_and_auto_never_worse_than_its_best() {
    for k in [1, 3, 6, 11] {
        let (omega, r_min) = envelope(k);
        let env = Envelope {
            omega,
            r_min,
            a1_limit: None,
            method: EnvelopeMethod::File,
        };
        let set = FitSettings::default();
        let (fit, rows) = rshape::fit::fit_auto(&env, None, &set, 4, &Default::default())
            .unwrap_or_else(|e| panic!("envelope {k}: {e}"));
        assert!(fit.certificate.passed, "envelope {k}");
        let ok: Vec<_> = rows.iter().filter(|r| r.status == "ok").collect();
        assert!(ok.len() >= 4, "envelope {k}: {rows:?}");
        for w in ok.windows(2) {
            let (p, c) = (
                (w[0].max_log10, w[0].mean_log10),
                (w[1].max_log10, w[1].mean_log10),
            );
            assert!(
                crate::fit_paper::promise_kept(set.objective, set.bisection_tol, p, c),
                "envelope {k}: order {} worse than order {}: {rows:?}",
                w[1].order,
                w[0].order
            );
        }
        let best = ok.iter().map(|r| r.max_log10).fold(f64::INFINITY, f64::min);
        assert!(
            fit.certificate.max_log10_ratio <= best + set.auto_tolerance + 1e-9,
            "envelope {k}: auto {} vs best {best}",
            fit.certificate.max_log10_ratio
        );
    }
}

/// GitHub issue 11, defect 5, with the reproduction: an envelope flat at 1e-3 up to
/// 1e3 rad/s, then rising two decades per decade to 1e6 rad/s.  The order-1–3 fits were
/// the constant at the largest bound (6 decades above the data at low frequency) after
/// "no feasible level up to t = 1e24"; they must now be within 0.01 decade of the
/// reference (or better), and not the constant.  Measured: order 1 rshape 2.940, reference
/// 2.949 (one pole pair cannot follow a slope of 2); order 2 rshape 0.034, reference 1.408;
/// order 3 rshape 0.035, reference 1.121 (the reference's own units stop well above it).
#[test]
fn steep_rise_is_fitted_near_the_reference_at_orders_1_to_3() {
    let omega = logspace(1.0, 1e6, 50);
    let r_min: Vec<f64> = omega
        .iter()
        .map(|w| 1e-3 * if *w < 1e3 { 1.0 } else { (w / 1e3).powi(2) })
        .collect();
    let env = Envelope {
        omega: omega.clone(),
        r_min: r_min.clone(),
        a1_limit: None,
        method: EnvelopeMethod::File,
    };
    for order in 1..=3 {
        let set = FitSettings {
            order,
            ..Default::default()
        };
        let fit = fit_unit(&env, None, &set, &Default::default())
            .unwrap_or_else(|e| panic!("order {order}: {e}"));
        assert!(fit.certificate.passed, "order {order}");
        let ours = fit.certificate.max_log10_ratio;
        let reference = reference_level(&omega, &r_min, order, set.floor_rel)
            .unwrap_or_else(|| panic!("order {order}: no reference unit"));
        eprintln!("steep rise order {order}: rshape {ours:.4}, reference {reference:.4}");
        assert!(
            ours <= reference + 0.01,
            "order {order}: rshape {ours} vs reference {reference}"
        );
        assert!(
            fit.origin != rshape::fit::Origin::Constant,
            "order {order}: {}",
            fit.origin
        );
        if order >= 2 {
            assert!(ours < 0.05, "order {order}: {ours}");
        }
    }
}

/// A chosen list of pairs (`PAIRS=3:4,14:6`), for investigating the sweep.
#[test]
#[ignore = "manual: PAIRS=k:n,... cargo test --release --test fit fit_reference::pairs -- --ignored"]
fn pairs_from_the_environment() {
    let list: Vec<(usize, usize)> = std::env::var("PAIRS")
        .unwrap_or_default()
        .split(',')
        .filter_map(|p| {
            let (k, n) = p.split_once(':')?;
            Some((k.parse().ok()?, n.parse().ok()?))
        })
        .collect();
    sweep(&list, 0);
}

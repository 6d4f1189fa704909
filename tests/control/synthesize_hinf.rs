//! H∞ synthesis with a frequency-dependent r (issue 22): the γ-iteration's optimum
//! `γ_opt = min_K ‖r·[K; I](I+GK)⁻¹M̃⁻¹‖∞` against
//!
//! * a second route: a *different realization* of the same problem — `r` at the error
//!   output `z` (m + p copies of r's states, a different `C₁`, `D₁₁`, `D₁₂`, `B₂`) instead
//!   of at the disturbance `w` — bisected finely from a wide bracket;
//! * the controller itself: its closed loop evaluated on a dense grid from the factor values
//!   (`M̃(jω)`, `G(jω)`, `K(jω)`, no state-space interconnection) must stay below the level,
//!   and the Theorem 1 test (`analyze`) must prove the margin `1/γ`;
//! * Glover–McFarlane: with a constant r the dynamic route must reproduce `b_opt`.

use nalgebra::DMatrix;
use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rshape::model::Factorization;
use rshape::model::{Controller, Feedback};
use rshape::stability::{analyze, Verdict};
use rshape::synthesis::{gamma_test, weighted_plant, IterationStatus};
use rshape::synthesis::{normalize, GeneralizedPlant};
use rshape::synthesis::{optimum, synthesize_weighted, WeightedSettings};
use rshape::system::{
    eigenvalues, logspace, spectral_abscissa, NormalizedLcf, StateSpace, TransferFunction,
};
use std::path::PathBuf;

/// A random plant: stable or unstable, SISO or MIMO, with or without feedthrough.
fn random_plant(seed: u64) -> StateSpace {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let n = rng.gen_range(1..=4);
    let p = if seed % 4 < 2 { 1 } else { 2 };
    let m = if seed.is_multiple_of(4) || seed % 4 == 3 {
        1
    } else {
        2
    };
    let mut r = |_, _| rng.gen_range(-1.0..1.0);
    let a0 = DMatrix::from_fn(n, n, &mut r) * 2.0;
    let shift = if seed.is_multiple_of(3) { 1.0 } else { -0.7 };
    let a = a0 - DMatrix::identity(n, n) * shift;
    let b = DMatrix::from_fn(n, m, &mut r);
    let c = DMatrix::from_fn(p, n, &mut r);
    let d = if seed.is_multiple_of(2) {
        DMatrix::from_fn(p, m, &mut r) * 0.5
    } else {
        DMatrix::zeros(p, m)
    };
    StateSpace { a, b, c, d }
}

/// A random unit of RH∞ of the given order (real or complex poles and zeros in the left
/// half-plane, gain 0.05…5).
fn random_unit(seed: u64, order: usize) -> TransferFunction {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let roots = |rng: &mut rand_chacha::ChaCha8Rng| {
        let mut v = Vec::new();
        while v.len() < order {
            if order - v.len() >= 2 && rng.gen_bool(0.4) {
                let (re, im) = (-rng.gen_range(0.1..3.0), rng.gen_range(0.2..5.0));
                v.push(Complex64::new(re, im));
                v.push(Complex64::new(re, -im));
            } else {
                v.push(Complex64::new(-10f64.powf(rng.gen_range(-1.0..1.0)), 0.0));
            }
        }
        v
    };
    let z = roots(&mut rng);
    let p = roots(&mut rng);
    let k = 10f64.powf(rng.gen_range(-1.3..0.7));
    TransferFunction::from_zpk(&z, &p, k)
}

/// The second realization: `z = r·[u; y]` with r on the m + p error channels, for
/// `r̂ = r/r(∞)` (so `D₁₂ = [I; D]`).
fn output_weighted_plant(ncf: &NormalizedLcf, r: &TransferFunction) -> (GeneralizedPlant, f64) {
    let g = &ncf.plant;
    let (p, m) = g.d.shape();
    let n = g.states();
    let scale = r.at_infinity();
    let rs = TransferFunction::new(
        r.num.coeffs().iter().map(|c| c / scale).collect(),
        r.den.coeffs().to_vec(),
    );
    let w1 = StateSpace::from_tf(&rs);
    let k = m + p;
    let nr = w1.states();
    let mut aw = DMatrix::zeros(nr * k, nr * k);
    let mut bw = DMatrix::zeros(nr * k, k);
    let mut cw = DMatrix::zeros(k, nr * k);
    for i in 0..k {
        aw.view_mut((i * nr, i * nr), (nr, nr)).copy_from(&w1.a);
        bw.view_mut((i * nr, i), (nr, 1)).copy_from(&w1.b);
        cw.view_mut((i, i * nr), (1, nr)).copy_from(&w1.c);
    }
    let dr = w1.d[(0, 0)];
    // z₀ = [u; y] = C₀x + D₀ᵤu + D₀w·w, y = Cx + Du + R̃^(1/2)w, ẋ = Ax + Bu − L R̃^(1/2) w.
    let dw = ncf.r_half.clone();
    let bdist = -(&ncf.l * &ncf.r_half);
    let mut c0 = DMatrix::zeros(k, n);
    c0.view_mut((m, 0), (p, n)).copy_from(&g.c);
    let mut d0u = DMatrix::zeros(k, m);
    d0u.view_mut((0, 0), (m, m))
        .copy_from(&DMatrix::identity(m, m));
    d0u.view_mut((m, 0), (p, m)).copy_from(&g.d);
    let mut d0w = DMatrix::zeros(k, p);
    d0w.view_mut((m, 0), (p, p)).copy_from(&dw);
    let nn = n + nr * k;
    let mut a = DMatrix::zeros(nn, nn);
    a.view_mut((0, 0), (n, n)).copy_from(&g.a);
    a.view_mut((n, 0), (nr * k, n)).copy_from(&(&bw * &c0));
    a.view_mut((n, n), (nr * k, nr * k)).copy_from(&aw);
    let mut b1 = DMatrix::zeros(nn, p);
    b1.view_mut((0, 0), (n, p)).copy_from(&bdist);
    b1.view_mut((n, 0), (nr * k, p)).copy_from(&(&bw * &d0w));
    let mut b2 = DMatrix::zeros(nn, m);
    b2.view_mut((0, 0), (n, m)).copy_from(&g.b);
    b2.view_mut((n, 0), (nr * k, m)).copy_from(&(&bw * &d0u));
    let mut c1 = DMatrix::zeros(k, nn);
    c1.view_mut((0, 0), (k, n)).copy_from(&(&c0 * dr));
    c1.view_mut((0, n), (k, nr * k)).copy_from(&cw);
    let mut c2 = DMatrix::zeros(p, nn);
    c2.view_mut((0, 0), (p, n)).copy_from(&g.c);
    (
        GeneralizedPlant {
            a,
            b1,
            b2,
            c1,
            c2,
            d11: &d0w * dr,
            d12: &d0u * dr,
            d21: dw,
            d22: g.d.clone(),
        },
        scale.abs(),
    )
}

/// `γ_opt` of the second realization by bisection to 1e-9 between `lo` and `hi`.
fn gamma_opt_second_route(ncf: &NormalizedLcf, r: &TransferFunction, lo: f64, hi: f64) -> f64 {
    let (plant, scale) = output_weighted_plant(ncf, r);
    let np = normalize(&plant).unwrap();
    let (mut lo, mut hi) = (lo / scale, hi / scale);
    assert!(
        gamma_test(&np.plant, hi).is_ok(),
        "upper end not achievable"
    );
    assert!(gamma_test(&np.plant, lo).is_err(), "lower end achievable");
    for _ in 0..200 {
        if hi <= lo * (1.0 + 1e-9) {
            break;
        }
        let mid = (lo * hi).sqrt();
        if gamma_test(&np.plant, mid).is_ok() {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi * scale
}

/// `sup_ω |r|·σ_max([K; I](I + GK)⁻¹M̃⁻¹)` on a grid, from the frequency values only
/// (`u = −K·y`).
fn grid_norm(ncf: &NormalizedLcf, k: &StateSpace, r: &TransferFunction, grid: &[f64]) -> f64 {
    let (p, m) = ncf.shape();
    let mut best: f64 = 0.0;
    for &w in grid {
        let (mt, _) = ncf.at(w).unwrap();
        let g = ncf.plant.freq(w).unwrap();
        let kw = k.freq(w).unwrap();
        let s = (DMatrix::<Complex64>::identity(p, p) + &g * &kw)
            .try_inverse()
            .unwrap();
        let mi = mt.try_inverse().unwrap();
        let mut t = DMatrix::<Complex64>::zeros(m + p, p);
        t.view_mut((0, 0), (m, p)).copy_from(&(&kw * &s * &mi));
        t.view_mut((m, 0), (p, p)).copy_from(&(&s * &mi));
        let sv = t.svd(false, false).singular_values.max();
        best = best.max(r.freq(w).norm() * sv);
    }
    best
}

#[test]
fn dynamic_r_optimum_matches_a_second_realization_and_the_controller_attains_it() {
    let (mut checked, mut unstable, mut mimo) = (0, 0, 0);
    let (mut second_route, mut at_infinity, mut riccati_limited) = (0, 0, 0);
    let mut theorem1_strained = Vec::new();
    let mut orders = [0usize; 4];
    for seed in 0..30u64 {
        let plant = random_plant(seed);
        let ncf = NormalizedLcf::new(plant.clone()).unwrap();
        let order = 1 + (seed as usize % 3);
        let r = random_unit(seed, order);
        assert!(r.is_unit());
        let settings = WeightedSettings {
            gamma_factor: 1.0 + 1e-4,
            rtol: 1e-9,
            ..Default::default()
        };
        let b_opt = optimum(&ncf).unwrap().b_opt;
        let syn = match synthesize_weighted(&ncf, &r, &settings) {
            Ok(s) => s,
            // A nearly unstabilizable plant (b_opt < 0.01): a one-line failure is the
            // right answer; the count below requires enough others.
            Err(e) if b_opt < 1e-2 => {
                assert!(!e.to_string().contains('\n'));
                println!("seed {seed}: b_opt {b_opt:.2e}: {e}");
                continue;
            }
            Err(e) => {
                // The controller at 1.1·γ_opt (the default factor) must then exist.
                let again = synthesize_weighted(
                    &ncf,
                    &r,
                    &WeightedSettings {
                        gamma_factor: 1.1,
                        ..settings.clone()
                    },
                );
                panic!(
                    "seed {seed}: {e}; at 1.1: {:?}",
                    again.map(|s| (s.gamma_opt, s.gamma_achieved, s.status))
                );
            }
        };
        // Near the feedthrough bound σ̄(D₁₁₁₂) (the ω = ∞ value of the problem, a lower bound
        // on γ_opt: Parrott) the Hamiltonians blow up and neither route can bisect closer;
        // there the bracket [σ̄(D₁₁₁₂), γ_opt] is the proof (γ_opt is attained by the
        // controller, whose norm is checked below).
        let floor = {
            let (plant2, scale2) = output_weighted_plant(&ncf, &r);
            let np = normalize(&plant2).unwrap();
            let (p2, m2) = (np.plant.c2.nrows(), np.plant.b2.ncols());
            let d1112 = np.plant.d11.view((0, 0), (p2, p2)).into_owned();
            let _ = m2;
            d1112.svd(false, false).singular_values.max() * scale2
        };
        assert!(
            syn.gamma_opt >= floor * (1.0 - 1e-9),
            "seed {seed}: below the ω = ∞ bound"
        );
        if syn.gamma_opt <= floor * (1.0 + 1e-4) {
            at_infinity += 1;
        } else {
            let second = gamma_opt_second_route(&ncf, &r, syn.gamma_opt * 0.5, syn.gamma_opt * 2.0);
            let rel = (syn.gamma_opt - second).abs() / second;
            println!(
                "seed {seed}: {} {second} {rel:.2e} {:?}",
                syn.gamma_opt, syn.status
            );
            // Where the Riccati equations fail above the level the controller reaches, the
            // controller's verified level is the better answer: the second route may then
            // only be worse (higher).
            let limited = syn.status == IterationStatus::RiccatiLimited && syn.gamma_opt <= second;
            assert!(
                limited || rel < 1e-4,
                "seed {seed}: γ_opt {} vs second realization {second} (rel {rel:.2e})",
                syn.gamma_opt
            );
            if limited {
                riccati_limited += 1;
            } else {
                second_route += 1;
            }
        }
        // The controller: proper (a finite state space), stabilizing, at its level.
        assert!(syn.k.d.iter().all(|v| v.is_finite()));
        let cl = rshape::synthesis::closed_loop_matrix(&plant, &syn.k).unwrap();
        let abscissa = spectral_abscissa(&eigenvalues(&cl, "cl").unwrap());
        assert!(
            abscissa < 0.0,
            "seed {seed}: closed-loop abscissa {abscissa}"
        );
        assert!(
            syn.gamma_achieved <= syn.gamma * (1.0 + 1e-4),
            "seed {seed}"
        );
        assert!(
            syn.gamma_achieved >= syn.gamma_opt * (1.0 - 1e-6),
            "seed {seed}: below the optimum"
        );
        let grid = logspace(1e-3, 1e3, 3000);
        let gn = grid_norm(&ncf, &syn.k, &r, &grid);
        assert!(
            // Two evaluations of an ill-conditioned loop (γ up to 330) agree to ~1e-6.
            gn <= syn.gamma_achieved * (1.0 + 1e-5),
            "seed {seed}: grid {gn} above the achieved {}",
            syn.gamma_achieved
        );
        // Theorem 1 (the stability module, its own realization of the loop) proves the
        // margin with r scaled to 0.9999/γ_achieved, refuses it 1 % above, and agrees on
        // the margin to 1e-4 (seed 17, γ = 328, a nearly unstabilizable plant: the two
        // realizations differ by 1.6e-5 at ω = 0).
        let f = Factorization::normalized(ncf.clone());
        let controller = Controller {
            path: PathBuf::from("hinf"),
            k: syn.k.clone(),
            feedback: Feedback::Negative,
        };
        let scaled = |c: f64| {
            TransferFunction::new(
                r.num.coeffs().iter().map(|x| x * c).collect(),
                r.den.coeffs().to_vec(),
            )
        };
        let ok = scaled(syn.alpha_achieved * (1.0 - 1e-4));
        let bad = scaled(syn.alpha_achieved * 1.01);
        let (rep, _) = analyze(
            &f,
            &controller,
            &[("ok".into(), ok), ("bad".into(), bad)],
            &grid,
        )
        .unwrap();
        assert!(rep.internally_stable, "seed {seed}");
        let proved = rep.margins[0].verdict == Verdict::Robust
            && rep.margins[1].verdict == Verdict::NotRobust
            && (rep.margins[0].alpha * (1.0 - 1e-4) - 1.0).abs() < 1e-4;
        // Nearly unstabilizable plants (b_opt < 0.05, γ_opt in the hundreds) strain the
        // Theorem 1 test's own evaluation of the loop (one such seed: its grid, from the
        // factors' transfer functions, read 1.55× the state-space norm); they are reported,
        // the others must be proved.
        if !proved {
            assert!(
                b_opt < 0.05,
                "seed {seed} (b_opt {b_opt}): Theorem 1 {:?}",
                rep.margins
            );
            theorem1_strained.push(seed);
        }
        if spectral_abscissa(&eigenvalues(&plant.a, "p").unwrap()) > 0.0 {
            unstable += 1;
        }
        if plant.d.nrows() > 1 || plant.d.ncols() > 1 {
            mimo += 1;
        }
        orders[order] += 1;
        checked += 1;
    }
    println!("{checked} plants: {second_route} by the second realization, {at_infinity} at the ω = ∞ bound, {riccati_limited} Riccati-limited");
    println!("Theorem 1 not proved on the ill-conditioned seeds {theorem1_strained:?}");
    assert!(theorem1_strained.len() <= 4);
    // Riccati-limited: the bisection's Riccati equations fail on levels the verified
    // controller then beats (seeds 21, 23, 27, 29 with the fixed seeds: the γ_opt reported
    // is the controller's verified level, 1e-6 … 20 % below the second route's).
    assert!(
        riccati_limited <= 6,
        "{riccati_limited} Riccati-limited optima"
    );
    assert!(
        second_route >= 10,
        "only {second_route} plants compared with the second route"
    );
    assert!(
        checked >= 20 && unstable >= 5 && mimo >= 10,
        "{checked} {unstable} {mimo}"
    );
    assert!(orders[1] > 0 && orders[2] > 0 && orders[3] > 0);
}

#[test]
fn constant_r_by_the_dynamic_route_reproduces_glover_mcfarlane() {
    for seed in 100..120u64 {
        let ncf = NormalizedLcf::new(random_plant(seed)).unwrap();
        let b_opt = optimum(&ncf).unwrap().b_opt;
        let c = 0.37;
        let r = TransferFunction::gain(c);
        let gm = c / b_opt;
        // A wide bracket: the bisection finds the optimum, it is not handed it.
        let settings = WeightedSettings {
            gamma_factor: 1.01,
            rtol: 1e-9,
            bracket: Some((gm * 0.1, gm * 10.0)),
            ..Default::default()
        };
        let syn =
            synthesize_weighted(&ncf, &r, &settings).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let rel = (syn.gamma_opt - gm).abs() / gm;
        assert!(
            rel < 1e-6,
            "seed {seed}: γ_opt {} vs c/b_opt {gm} (rel {rel:.2e})",
            syn.gamma_opt
        );
        assert!(
            syn.gamma_lower <= gm * (1.0 + 1e-6),
            "seed {seed}: lower {} opt {} gm {gm} {:?}",
            syn.gamma_lower,
            syn.gamma_opt,
            syn.steps
        );
        assert!(syn.gamma_achieved <= syn.gamma * (1.0 + 1e-6));
    }
}

#[test]
fn the_generalized_plant_realizes_the_factor_loop() {
    // With K = 0 the closed loop w ↦ z is [0; M̃⁻¹ r]: compare with the factors' values.
    for seed in 0..6u64 {
        let ncf = NormalizedLcf::new(random_plant(seed)).unwrap();
        let r = random_unit(seed, 2);
        let (plant, scale, _) = weighted_plant(&ncf, &r).unwrap();
        let (p, m) = ncf.shape();
        let zero = StateSpace {
            a: DMatrix::zeros(0, 0),
            b: DMatrix::zeros(0, p),
            c: DMatrix::zeros(m, 0),
            d: DMatrix::zeros(m, p),
        };
        let cl = plant.closed_loop(&zero).unwrap();
        for w in [0.01, 0.7, 3.0, 40.0] {
            let (mt, _) = ncf.at(w).unwrap();
            let want = mt.try_inverse().unwrap() * (r.freq(w) / scale);
            let got = cl.freq(w).unwrap();
            let err = (got.view((m, 0), (p, p)) - &want).norm() / want.norm();
            assert!(err < 1e-9, "seed {seed} ω {w}: {err}");
            assert!(got.view((0, 0), (m, p)).norm() < 1e-12);
        }
    }
}

#[test]
fn a_bound_that_is_not_a_unit_is_refused_in_one_line() {
    let ncf = NormalizedLcf::new(random_plant(1)).unwrap();
    for r in [
        TransferFunction::new(vec![1.0, -1.0], vec![1.0, 2.0]),
        TransferFunction::new(vec![1.0], vec![1.0, 2.0]),
        TransferFunction::new(vec![1.0, 1.0], vec![1.0, -2.0]),
    ] {
        let e = synthesize_weighted(&ncf, &r, &WeightedSettings::default()).unwrap_err();
        assert!(!e.to_string().contains('\n'));
        assert!(e.to_string().contains("unit"), "{e}");
    }
}

/// `b_opt < 0.02` (nearly unstabilizable plants, where tests/control/synthesize.rs's Hankel route
/// is too inaccurate and only a sandwich pins b_opt): the γ-iteration of the weighted
/// problem with r = 1 — a different formula (the X∞ Riccati of the generalized plant at each
/// level, bisected from a bracket 100× wide) — must give γ_opt = 1/b_opt.
#[test]
fn small_b_opt_by_the_gamma_iteration() {
    let mut compared = 0;
    for seed in 0..64u64 {
        let ncf = NormalizedLcf::new(crate::synthesize::random_plant(seed)).unwrap();
        let b_opt = optimum(&ncf).unwrap().b_opt;
        if b_opt >= 0.02 {
            continue;
        }
        let settings = WeightedSettings {
            gamma_factor: 1.01,
            rtol: 1e-10,
            bracket: Some((0.1 / b_opt, 10.0 / b_opt)),
            ..Default::default()
        };
        let syn = synthesize_weighted(&ncf, &TransferFunction::gain(1.0), &settings)
            .unwrap_or_else(|e| panic!("seed {seed} (b_opt {b_opt:.3e}): {e}"));
        let rel = (syn.gamma_opt * b_opt - 1.0).abs();
        println!(
            "seed {seed}: b_opt {b_opt:.6e}, 1/gamma_opt {:.6e}, rel {rel:.1e}",
            1.0 / syn.gamma_opt
        );
        assert!(
            rel < 1e-6,
            "seed {seed}: b_opt {b_opt:.9e} vs 1/γ_opt {:.9e}",
            1.0 / syn.gamma_opt
        );
        compared += 1;
    }
    assert!(compared >= 15, "only {compared} plants with b_opt < 0.02");
}

//! Noisy SISO envelope (Theorem 4): cross-check against an independent characterization,
//! agreement with the noise-free Theorem 3, Proposition 1, assumptions, noise models.

use nalgebra::DMatrix;
use num_complex::Complex64;
use proptest::prelude::*;
use rshape::consistency::{
    check, gamma_lft, noisy_envelope, noisy_envelope_report, r_min_noisy, r_min_special,
    r_min_standard, v_matrix, BisectionSettings, NoisyFailure,
};
use rshape::data::FrfData;
use rshape::model::{Config, Factorization, FactorsAt};
use rshape::mu::{mu_full_scalar, FullPlusScalar, MuSettings};
use rshape::system::{TfMatrix, TransferFunction};
use rshape::Error;
use std::f64::consts::TAU;
use std::path::Path;

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

fn robot() -> Config {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml");
    Config::load(&p).expect("configs/robot.toml loads")
}

fn robot_data(cfg: &Config) -> FrfData {
    rshape::data::read_frf_csv(cfg.data.as_ref().unwrap()).expect("configs/robot.csv reads")
}

/// Undamped natural frequencies `√(b_k/4)` of the five modes of eq. (19).
const MODES: [f64; 5] = [5.1234753, 45.355126, 20.211383, 70.914738, 18.098895];

fn nominal(at: &FactorsAt) -> Complex64 {
    at.plant().unwrap()[(0, 0)]
}

/// Theorem 3 closed form (noise free) for the scalar datum `ψ`.  A5 fails only at `ψ = g`
/// (the nominal model), where the smallest `|r|` is 0.
fn theorem3(at: &FactorsAt, psi: Complex64) -> f64 {
    r_min_special(at, &DMatrix::from_element(1, 1, psi)).unwrap_or(0.0)
}

/// Independent characterization of the noisy envelope: `min over |ψ − φ| ≤ L_a` of the
/// noise-free Theorem 3 value `1/σ₁(X(ψ))`.  Dense polar grid over the disk, then two local
/// refinements: golden-section search along the boundary around the best boundary angle,
/// and a projected compass search in the plane from the best grid point.
fn disk_minimum(at: &FactorsAt, phi: Complex64, la: f64) -> f64 {
    let g = nominal(at);
    if (phi - g).norm() <= la {
        return 0.0;
    }
    let f = |psi: Complex64| theorem3(at, psi);
    let angles = 720;
    let (mut best, mut best_psi) = (f(phi), phi);
    let mut best_edge = (f64::INFINITY, 0.0);
    for ri in 1..=8 {
        let rad = la * ri as f64 / 8.0;
        for k in 0..angles {
            let th = TAU * k as f64 / angles as f64;
            let psi = phi + Complex64::from_polar(rad, th);
            let v = f(psi);
            if v < best {
                (best, best_psi) = (v, psi);
            }
            if ri == 8 && v < best_edge.0 {
                best_edge = (v, th);
            }
        }
    }
    // Golden section on the boundary around the best boundary angle.
    let h = TAU / angles as f64;
    let (mut a, mut b) = (best_edge.1 - h, best_edge.1 + h);
    let gr = 0.5 * (5f64.sqrt() - 1.0);
    let on = |th: f64| f(phi + Complex64::from_polar(la, th));
    let (mut x1, mut x2) = (b - gr * (b - a), a + gr * (b - a));
    let (mut f1, mut f2) = (on(x1), on(x2));
    for _ in 0..80 {
        if f1 < f2 {
            b = x2;
            (x2, f2) = (x1, f1);
            x1 = b - gr * (b - a);
            f1 = on(x1);
        } else {
            a = x1;
            (x1, f1) = (x2, f2);
            x2 = a + gr * (b - a);
            f2 = on(x2);
        }
    }
    best = best.min(f1).min(f2);
    // Projected compass search in the disk.
    let project = |p: Complex64| {
        let d = p - phi;
        if d.norm() > la {
            phi + d * (la / d.norm())
        } else {
            p
        }
    };
    let (mut p, mut fp) = (best_psi, f(best_psi));
    let mut step = la / 8.0;
    const H: f64 = std::f64::consts::FRAC_1_SQRT_2;
    let dirs = [
        c(1.0, 0.0),
        c(-1.0, 0.0),
        c(0.0, 1.0),
        c(0.0, -1.0),
        c(H, H),
        c(-H, H),
        c(H, -H),
        c(-H, -H),
    ];
    let mut evals = 0;
    while step > 1e-13 * la && evals < 20_000 {
        let mut improved = false;
        for d in dirs {
            let q = project(p + d * step);
            let fq = f(q);
            evals += 1;
            if fq < fp {
                (p, fp) = (q, fq);
                improved = true;
            }
        }
        if !improved {
            step *= 0.5;
        }
    }
    best.min(fp)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs())
}

/// Acceptance: the μ envelope equals the disk minimum of the Theorem 3 closed form on the
/// robot model, at ≥ 20 frequencies including each mode, to 1e-4 relative.  Where the μ
/// envelope says `inf`, the disk minimum must be at least the A1 limit.
#[test]
fn cross_check_against_disk_minimum_robot() {
    let cfg = robot();
    let f = &cfg.factorization;
    let settings = BisectionSettings::default();
    let mut omegas: Vec<f64> = (0..24).map(|i| 64f64.powf(i as f64 / 23.0)).collect();
    for w in MODES {
        omegas.extend([w * 0.99, w, w * 1.01]);
    }
    let (mut finite, mut infinite) = (0, 0);
    let mut worst: f64 = 0.0;
    for (i, &omega) in omegas.iter().enumerate() {
        let at = f.at(omega);
        let g = nominal(&at);
        // A datum off the nominal by 30–60 % of |g|, noise radius 30–70 % of the offset.
        let kappa = 0.3 + 0.3 * ((i * 7 % 11) as f64 / 10.0);
        let lambda = 0.3 + 0.4 * ((i * 5 % 7) as f64 / 6.0);
        let phi = g * (1.0 + Complex64::from_polar(kappa, 0.37 + 1.3 * i as f64));
        let la = lambda * (phi - g).norm();
        let got = r_min_noisy(&at, phi, la, &settings).unwrap();
        let want = disk_minimum(&at, phi, la);
        if got.r_min.is_finite() {
            finite += 1;
            assert!(
                got.r_min > 0.0,
                "ω = {omega}: datum outside the noise must need r > 0"
            );
            let e = rel(got.r_min, want);
            worst = worst.max(e);
            assert!(
                e <= 1e-4,
                "ω = {omega}: μ envelope {} vs disk minimum {want} (rel {e:.2e})",
                got.r_min
            );
        } else {
            infinite += 1;
            assert!(
                want >= got.a1_limit * (1.0 - 1e-4),
                "ω = {omega}: inf but disk minimum {want} < A1 limit {}",
                got.a1_limit
            );
        }
    }
    eprintln!("cross-check: {finite} finite, {infinite} inf, worst rel. difference {worst:.2e}");
    assert!(
        finite >= 20,
        "only {finite} frequencies with a finite positive r_min"
    );
}

/// The same cross-check on the shipped data set with the configured L_a = 0.06.
#[test]
fn cross_check_on_robot_dataset() {
    let cfg = robot();
    let data = robot_data(&cfg);
    let la = cfg.raw.noise.radius.unwrap();
    let rep = noisy_envelope_report(
        &cfg.factorization,
        &data,
        &vec![la; data.len()],
        &BisectionSettings::default(),
        &Default::default(),
    )
    .unwrap();
    let (mut compared, mut zero, mut finite, mut inf, mut worst) = (0, 0, 0, 0, 0.0f64);
    for (k, omega) in data.omega.iter().enumerate() {
        if k % 5 != 0 && rep.envelope.r_min[k] == 0.0 {
            continue;
        }
        let at = cfg.factorization.at(*omega);
        let phi = data.response[k][(0, 0)];
        let want = disk_minimum(&at, phi, la);
        let got = rep.envelope.r_min[k];
        if got == 0.0 {
            assert_eq!(want, 0.0, "ω = {omega}");
            zero += 1;
        } else if got.is_finite() {
            worst = worst.max(rel(got, want));
            assert!(rel(got, want) <= 1e-4, "ω = {omega}: {got} vs {want}");
            finite += 1;
        } else {
            assert!(want >= rep.data[k].a1_limit * (1.0 - 1e-4), "ω = {omega}");
            inf += 1;
        }
        compared += 1;
    }
    eprintln!("robot data, L_a = {la}: {compared} compared: {zero} zero, {finite} finite (worst rel. {worst:.2e}), {inf} inf");
    assert!(
        compared >= 40 && finite >= 5,
        "{compared} compared, {finite} finite"
    );
}

/// With `L_a = 0` the noisy envelope equals the noise-free Theorem 3 closed form where it is
/// below the A1 limit, and is `inf` where it is above.
#[test]
fn zero_noise_equals_theorem3() {
    let cfg = robot();
    let data = robot_data(&cfg);
    let env = noisy_envelope(
        &cfg.factorization,
        &data,
        &vec![0.0; data.len()],
        &BisectionSettings::default(),
        &Default::default(),
    )
    .unwrap();
    let (mut eq, mut inf) = (0, 0);
    for (k, omega) in data.omega.iter().enumerate() {
        let at = cfg.factorization.at(*omega);
        let t3 = r_min_special(&at, &data.response[k]).unwrap();
        let a1 = env.a1_limit.as_ref().unwrap()[k];
        if t3 < a1 * (1.0 - 1e-6) {
            assert!(
                rel(env.r_min[k], t3) <= 1e-8,
                "ω = {omega}: {} vs {t3}",
                env.r_min[k]
            );
            eq += 1;
        } else if t3 > a1 * (1.0 + 1e-6) {
            assert!(env.r_min[k].is_infinite(), "ω = {omega}");
            inf += 1;
        }
    }
    assert!(eq >= 20, "only {eq} comparable data ({inf} beyond A1)");
}

/// The scalar factorization (`n = 1`, `C = 1`): with `L_a = 0`, Theorem 4 reduces to the
/// Theorem 2 minimum-norm perturbation of eq. (8).
#[test]
fn scalar_factorization_zero_noise_equals_theorem2() {
    // g = (1/(s+1)) / ((s+2)/(s+1)) = 1/(s+2); r-independent checks at a few frequencies.
    let m = TfMatrix::from_rows(vec![vec![TransferFunction::new(
        vec![1.0, 2.0],
        vec![1.0, 1.0],
    )]])
    .unwrap();
    let n =
        TfMatrix::from_rows(vec![vec![TransferFunction::new(vec![1.0], vec![1.0, 1.0])]]).unwrap();
    let f = Factorization::standard(m, n).unwrap();
    for omega in [0.1, 1.0, 3.0, 10.0] {
        let at = f.at(omega);
        let g = nominal(&at);
        let phi = g * c(1.1, 0.05);
        let t2 = r_min_standard(&at, &DMatrix::from_element(1, 1, phi)).unwrap();
        let got = r_min_noisy(&at, phi, 0.0, &BisectionSettings::default()).unwrap();
        assert!(t2 < got.a1_limit);
        assert!(
            rel(got.r_min, t2) <= 1e-8,
            "ω = {omega}: {} vs {t2}",
            got.r_min
        );
        // With noise, the disk minimum again.
        let la = 0.5 * (phi - g).norm();
        let got = r_min_noisy(&at, phi, la, &BisectionSettings::default()).unwrap();
        let want = disk_minimum(&at, phi, la);
        assert!(
            rel(got.r_min, want) <= 1e-4,
            "ω = {omega}: {} vs {want}",
            got.r_min
        );
    }
}

/// `V` has the block pattern of eq. (14) and `F_L` is `V₁₁ + V₁₂(φ − V₂₂)⁻¹V₂₁`; with
/// `M(|r|) = diag(|r|I, 1)·M(1)`, the phase of `r` does not change `μ`.
#[test]
fn v_matrix_structure_and_r_scaling() {
    let cfg = robot();
    let at = cfg.factorization.at(7.0);
    let r = Complex64::from_polar(0.3, 1.1);
    let v = v_matrix(&at, r, 0.06).unwrap();
    assert_eq!(v.shape(), (8, 7));
    for j in 0..6 {
        assert_eq!(v[(0, j)], c(0.0, 0.0));
        assert_eq!(v[(6, j)], c(0.0, 0.0));
    }
    assert_eq!(v[(6, 6)], c(1.0, 0.0));
    assert_eq!(v[(7, 5)], c(0.06, 0.0));
    assert!((v[(0, 6)] - r).norm() < 1e-15);
    assert!((v[(7, 6)] - nominal(&at)).norm() < 1e-12 * nominal(&at).norm());
    let phi = nominal(&at) * c(0.7, 0.2);
    let m_r = gamma_lft(&at, phi, r, 0.06).unwrap();
    let m_abs = gamma_lft(&at, phi, c(0.3, 0.0), 0.06).unwrap();
    let m1 = gamma_lft(&at, phi, c(1.0, 0.0), 0.06).unwrap();
    for i in 0..6 {
        for j in 0..6 {
            assert!((m_abs[(i, j)] - m1[(i, j)] * 0.3).norm() <= 1e-12 * m1.norm());
        }
    }
    let s = FullPlusScalar::gamma(5);
    let a = mu_full_scalar(&m_r, s, &MuSettings::default()).unwrap();
    let b = mu_full_scalar(&m_abs, s, &MuSettings::default()).unwrap();
    assert!(rel(a.upper, b.upper) <= 1e-9);
}

/// The μ certificate of the LFT is a consistent perturbation (Lemma 1): with
/// `‖Δ̃_s‖ = 1/μ`, scaling by `μ` gives a unit-norm `Δ_s` for which `F_U(V, Δ_s) = φ`.
#[test]
fn certificate_reproduces_the_datum() {
    let cfg = robot();
    let at = cfg.factorization.at(3.0);
    let phi = nominal(&at) * c(1.4, -0.3);
    let r = c(0.5, 0.0);
    let v = v_matrix(&at, r, 0.01).unwrap();
    let m = gamma_lft(&at, phi, r, 0.01).unwrap();
    let b = mu_full_scalar(&m, FullPlusScalar::gamma(5), &MuSettings::default()).unwrap();
    let delta = b.certificate(&m).unwrap();
    // F_U(V, Δ) = V₂₂ + V₂₁Δ(I − V₁₁Δ)⁻¹V₁₂.
    let (v11, v12) = (v.view((0, 0), (7, 6)), v.view((0, 6), (7, 1)));
    let (v21, v22) = (v.view((7, 0), (1, 6)), v[(7, 6)]);
    let inner = (DMatrix::identity(6, 6) - &delta * v11)
        .lu()
        .solve(&(&delta * v12))
        .unwrap();
    let fu = v22 + (v21 * inner)[(0, 0)];
    assert!(
        (fu - phi).norm() <= 1e-9 * phi.norm(),
        "F_U = {fu}, φ = {phi}"
    );
}

/// Inside the noise disk of the nominal model the answer is 0; outside, positive.
#[test]
fn within_noise_is_zero() {
    let cfg = robot();
    let at = cfg.factorization.at(12.0);
    let g = nominal(&at);
    let la = 0.06;
    let inside = r_min_noisy(
        &at,
        g + c(0.0, 0.99 * la),
        la,
        &BisectionSettings::default(),
    )
    .unwrap();
    assert_eq!(inside.r_min, 0.0);
    let outside = r_min_noisy(
        &at,
        g + c(0.0, 1.01 * la),
        la,
        &BisectionSettings::default(),
    )
    .unwrap();
    assert!(outside.r_min > 0.0);
}

/// A6 (`φ = 0`) and A7 (`φ = V₂₂`) are errors naming the frequency.
#[test]
fn assumptions_a6_a7() {
    let cfg = robot();
    let at = cfg.factorization.at(2.0);
    let s = BisectionSettings::default();
    assert_eq!(
        r_min_noisy(&at, c(0.0, 0.0), 0.06, &s).unwrap_err(),
        NoisyFailure::A6
    );
    assert_eq!(
        r_min_noisy(&at, nominal(&at), 0.06, &s).unwrap_err(),
        NoisyFailure::A7
    );
    let mut data = robot_data(&cfg);
    data.response[3][(0, 0)] = c(0.0, 0.0);
    let err = noisy_envelope(
        &cfg.factorization,
        &data,
        &vec![0.06; data.len()],
        &s,
        &Default::default(),
    )
    .unwrap_err();
    match err {
        Error::Assumption { omega, msg } => {
            assert_eq!(omega, data.omega[3]);
            assert!(msg.contains("A6"), "{msg}");
        }
        other => panic!("expected an assumption error, got {other}"),
    }
}

/// A1: |r(jω)| ≥ σ_min(M̃(jω)) is reported by `check` at exactly those data.
#[test]
fn a1_violations_are_reported() {
    let cfg = robot();
    let data = robot_data(&cfg);
    let env = noisy_envelope(
        &cfg.factorization,
        &data,
        &vec![0.06; data.len()],
        &BisectionSettings::default(),
        &Default::default(),
    )
    .unwrap();
    let r = cfg.r.as_ref().unwrap();
    let rep = check(r, &env);
    let expected: Vec<f64> = data
        .omega
        .iter()
        .copied()
        .filter(|w| r.freq(*w).norm() >= cfg.factorization.a1_limit(*w))
        .collect();
    assert_eq!(rep.a1_violations, expected);
    // With the paper's numbers A1 fails near every mode in the data range.
    for w in [MODES[0], MODES[4], MODES[2], MODES[1]] {
        assert!(r.freq(w).norm() > cfg.factorization.a1_limit(w), "ω = {w}");
    }
}

/// Larger noise can only make a datum easier to explain: r_min is nonincreasing in L_a.
#[test]
fn r_min_nonincreasing_in_noise() {
    let cfg = robot();
    let data = robot_data(&cfg);
    for k in (0..data.len()).step_by(10) {
        let at = cfg.factorization.at(data.omega[k]);
        let phi = data.response[k][(0, 0)];
        let mut prev = f64::INFINITY;
        for la in [0.0, 0.005, 0.01, 0.02, 0.04, 0.06] {
            let r = r_min_noisy(&at, phi, la, &BisectionSettings::default())
                .unwrap()
                .r_min;
            assert!(
                r <= prev * (1.0 + 1e-9),
                "ω = {}: r_min({la}) = {r} > {prev}",
                data.omega[k]
            );
            prev = r;
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Proposition 1: μ_Γ{F_L[V, φ⁻¹]} is nondecreasing in |r| on [0, σ_min(M̃)).
    #[test]
    fn proposition_1_monotone(
        lw in 0.0f64..(64f64).ln(),
        kappa in 0.05f64..2.0,
        th in 0.0f64..TAU,
        la_frac in 0.0f64..1.5,
        t1 in 0.0f64..1.0,
        t2 in 0.0f64..1.0,
    ) {
        let cfg = robot();
        let at = cfg.factorization.at(lw.exp());
        let g = nominal(&at);
        let phi = g * (1.0 + Complex64::from_polar(kappa, th));
        let la = la_frac * (phi - g).norm();
        let a1 = cfg.factorization.a1_limit(lw.exp());
        let (lo, hi) = (t1.min(t2) * a1, t1.max(t2) * a1);
        let s = FullPlusScalar::gamma(5);
        let mu = |rho: f64| mu_full_scalar(&gamma_lft(&at, phi, c(rho, 0.0), la).unwrap(), s, &MuSettings::default()).unwrap();
        let (a, b) = (mu(lo), mu(hi));
        // Compare the certified bounds: μ(lo) ≤ upper(lo) and lower(hi) ≤ μ(hi).
        prop_assert!(a.lower <= b.upper * (1.0 + 1e-13), "μ({lo}) ≥ {} > μ({hi}) ≤ {}", a.lower, b.upper);
        prop_assert!(a.upper <= b.upper * (1.0 + 1e-9));
    }
}

/// The envelope is the crossing of Theorem 4's test: just above `r_min`, `μ > 1` (certified
/// by the lower bound); just below, `μ ≤ 1` (certified by the upper bound).
#[test]
fn r_min_is_the_mu_crossing() {
    let cfg = robot();
    let data = robot_data(&cfg);
    let s = FullPlusScalar::gamma(5);
    let mut checked = 0;
    for la in [0.0, 0.005, 0.02] {
        for k in (0..data.len()).step_by(7) {
            let at = cfg.factorization.at(data.omega[k]);
            let phi = data.response[k][(0, 0)];
            let d = r_min_noisy(&at, phi, la, &BisectionSettings::default()).unwrap();
            if !(d.r_min > 0.0 && d.r_min.is_finite()) {
                continue;
            }
            let mu = |rho: f64| {
                let m = gamma_lft(&at, phi, c(rho, 0.0), la).unwrap();
                mu_full_scalar(&m, s, &MuSettings::default()).unwrap()
            };
            let above = mu(d.r_min * (1.0 + 1e-8));
            let below = mu(d.r_min * (1.0 - 1e-8));
            assert!(
                above.lower > 1.0,
                "ω = {}, L_a = {la}: μ above r_min ≥ {}",
                data.omega[k],
                above.lower
            );
            assert!(
                below.upper <= 1.0,
                "ω = {}, L_a = {la}: μ below r_min ≤ {}",
                data.omega[k],
                below.upper
            );
            checked += 1;
        }
    }
    assert!(checked >= 30, "{checked}");
}

/// An input factor `J(s)` (here `(s + 3)/(s + 5)`) enters `V₁₂` and `V₂₂`: the zero-noise
/// envelope equals Theorem 3 (which uses `Φ̂ = ΦJ⁻¹`), and the noisy one the disk minimum.
#[test]
fn input_factor_j_is_handled() {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml"))
            .unwrap();
    let text = text.replace(
        "c = [[-3.30e-3",
        "j = [{ num = [1.0, 3.0], den = [1.0, 5.0] }]\nc = [[-3.30e-3",
    );
    let cfg = Config::parse(&text, Path::new("j.toml")).unwrap();
    assert!((cfg.factorization.j[0].freq(2.0) - c(1.0, 0.0)).norm() > 0.05);
    let settings = BisectionSettings::default();
    let mut compared = 0;
    for omega in [1.5, 3.0, 5.0, 11.0, 20.0, 40.0] {
        let at = cfg.factorization.at(omega);
        let g = nominal(&at);
        let phi = g * c(1.3, 0.2);
        let t3 = r_min_special(&at, &DMatrix::from_element(1, 1, phi)).unwrap();
        let got = r_min_noisy(&at, phi, 0.0, &settings).unwrap();
        if t3 < got.a1_limit {
            assert!(
                rel(got.r_min, t3) <= 1e-8,
                "ω = {omega}: {} vs {t3}",
                got.r_min
            );
            compared += 1;
        }
        let la = 0.4 * (phi - g).norm();
        let got = r_min_noisy(&at, phi, la, &settings).unwrap();
        let want = disk_minimum(&at, phi, la);
        if got.r_min.is_finite() {
            assert!(
                rel(got.r_min, want) <= 1e-4,
                "ω = {omega}: {} vs {want}",
                got.r_min
            );
            compared += 1;
        }
    }
    assert!(compared >= 6, "{compared}");
}

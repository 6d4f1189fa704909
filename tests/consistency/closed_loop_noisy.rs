//! Noisy closed-loop SISO envelope (Crowder & de Callafon, Theorem 2, eqs. (15)–(18)):
//! the exact-μ bisection and the closed form of eq. (18) against an independent brute-force
//! minimum of the noise-free `|Δ̄|` over the noise disk (polar grid plus zooming), for
//! `C̄ = C` and `C̄ ≠ C`; the two-scalar μ against the general full-plus-scalar μ.

use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::consistency::closed_loop::{closed_loop_envelope, mu_per_datum};
use rshape::consistency::closed_loop::{
    mu_at, theorem2_g1, v_min_eq18, v_min_mu_bisection, v_min_noisy, NoisyRoute, VBisectionSettings,
};
use rshape::consistency::EnvelopeMethod;
use rshape::data::FrfData;
use rshape::model::closed_loop::ClosedLoopAt;
use rshape::model::Config;
use rshape::mu::{mu_full_scalar, FullPlusScalar, MuSettings};
use rshape::system::{logspace, TransferFunction};
use std::path::{Path, PathBuf};

const SISO: &str = r#"
[closed_loop]
n_hat = [[{ num = [1], den = [1, 2, 1] }]]
d_hat = [[{ num = [1, 0], den = [1, 1] }]]
controller = [[{ num = [10, 5], den = [0.05, 1] }]]
"#;
const RETUNED: &str = "experiment_controller = [[{ num = [6, 3], den = [0.04, 1] }]]\n";

fn p0() -> TransferFunction {
    TransferFunction::new(vec![480.0], vec![1.0, 4.8, 403.2, 320.0, 0.0])
}

fn c0(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

/// `|Δ̄|` for the closed-loop value `Φ`, by a separate route: `P = Φ/(1 − ΦC̄)`, then
/// `Δ̄ = (P − P̂)D̂/(D_c(1 + PC))` (Corollary 2's form, scalars).
fn delta_abs(at: &ClosedLoopAt, phi: Complex64) -> f64 {
    let cb = at.c_bar[(0, 0)];
    let p = phi / (1.0 - phi * cb);
    let (ph, dh, dc, c) = (
        at.p_hat[(0, 0)],
        at.d_hat[(0, 0)],
        at.d_c[(0, 0)],
        at.c[(0, 0)],
    );
    ((p - ph) * dh / (dc * (1.0 + p * c))).norm()
}

/// Brute-force `min_{|ε| ≤ 1} |Δ̄(Φ − ρε)|`: a polar grid, then 12 zoom steps of a 41×41
/// grid around the best point (the disk is clipped).
fn brute_force(at: &ClosedLoopAt, phi: Complex64, rho: f64) -> f64 {
    let f = |e: Complex64| delta_abs(at, phi - rho * e);
    let mut best = (f64::INFINITY, c0(0.0, 0.0));
    for i in 0..=200 {
        let r = i as f64 / 200.0;
        for k in 0..720 {
            let e = Complex64::from_polar(r, k as f64 * std::f64::consts::TAU / 720.0);
            let v = f(e);
            if v < best.0 {
                best = (v, e);
            }
        }
    }
    let mut h = 0.02;
    for _ in 0..14 {
        let centre = best.1;
        for i in -20..=20 {
            for k in -20..=20 {
                let mut e = centre + c0(i as f64, k as f64) * (h / 20.0);
                if e.norm() > 1.0 {
                    e /= e.norm();
                }
                let v = f(e);
                if v < best.0 {
                    best = (v, e);
                }
            }
        }
        h *= 0.25;
    }
    best.0
}

fn model(text: &str) -> rshape::model::closed_loop::ClosedLoopModel {
    Config::parse(text, Path::new("t.toml"))
        .unwrap()
        .closed_loop
        .unwrap()
}

/// Noisy data: the true closed loop plus a deterministic offset of 0.7ρ; the radius is a
/// fraction of the distance to the nominal closed loop, so that v_min > 0 at most data,
/// and 3× that distance at every 7th datum (the noise alone explains it).
fn cases(text: &str) -> Vec<(ClosedLoopAt, Complex64, f64)> {
    let cl = model(text);
    logspace(0.05, 200.0, 36)
        .into_iter()
        .enumerate()
        .map(|(i, w)| {
            let at = cl.at(w).unwrap();
            let p = p0().freq(w);
            let phi_true = p / (1.0 + p * at.c_bar[(0, 0)]);
            let m22 = at.nominal_closed_loop().unwrap()[(0, 0)];
            let dist = (phi_true - m22).norm();
            let rho = if i % 7 == 3 {
                3.0 * dist
            } else {
                dist * [0.05, 0.3, 0.6][i % 3]
            };
            let phi = phi_true + Complex64::from_polar(0.7 * rho, 1.3 * i as f64);
            (at, phi, rho)
        })
        .collect()
}

#[test]
fn mu_bisection_equals_brute_force_for_both_experiments() {
    for text in [SISO.to_string(), format!("{SISO}{RETUNED}")] {
        let mut zeros = 0;
        for (at, phi, rho) in cases(&text) {
            let got = v_min_mu_bisection(&at, phi, rho, &VBisectionSettings::default());
            assert!(!got.hit_iteration_cap);
            let want = brute_force(&at, phi, rho);
            if want < 1e-12 {
                assert_eq!(got.v_min, 0.0, "noise explains the datum");
                zeros += 1;
                continue;
            }
            let e = (got.v_min - want).abs() / want;
            assert!(
                e < 1e-6,
                "μ route {} vs brute force {want}: {e:e}",
                got.v_min
            );
            // Noisy ≤ noise-free at the centre.
            assert!(got.v_min <= delta_abs(&at, phi) * (1.0 + 1e-12));
        }
        assert!(zeros >= 4, "the large-radius data must give 0");
    }
}

#[test]
fn eq18_closed_form_agrees_with_the_mu_route_when_c_bar_is_c() {
    for (at, phi, rho) in cases(SISO) {
        let closed = v_min_eq18(&at, phi, rho).unwrap();
        let mu = v_min_mu_bisection(&at, phi, rho, &VBisectionSettings::default()).v_min;
        assert!(
            (closed - mu).abs() <= 1e-10 * closed.max(1e-300),
            "eq. (18) {closed} vs μ {mu}"
        );
        let routed = v_min_noisy(&at, phi, rho, &VBisectionSettings::default());
        assert_eq!(routed.route, NoisyRoute::Eq18ClosedForm);
    }
    let (at, phi, rho) = cases(&format!("{SISO}{RETUNED}")).remove(5);
    assert_eq!(
        v_min_noisy(&at, phi, rho, &VBisectionSettings::default()).route,
        NoisyRoute::MuBisection
    );
}

#[test]
fn two_scalar_mu_matches_the_general_full_plus_scalar_mu_and_is_monotone() {
    let s = FullPlusScalar { rows: 1, cols: 1 };
    for (at, phi, rho) in cases(&format!("{SISO}{RETUNED}")) {
        let g1 = theorem2_g1(&at, phi, rho).unwrap();
        let mut last = 0.0;
        for v in logspace(1e-5, 1.0, 25) {
            let mu = mu_at(&g1, v);
            let m = DMatrix::from_row_slice(2, 2, &[v * g1[0], v * g1[1], g1[2], g1[3]]);
            let b = mu_full_scalar(&m, s, &MuSettings::default()).unwrap();
            assert!(
                (mu - b.upper).abs() <= 1e-8 * b.upper,
                "closed form {mu} vs {}",
                b.upper
            );
            assert!(mu >= last * (1.0 - 1e-14), "μ must not decrease with |V|");
            last = mu;
        }
    }
}

#[test]
fn envelope_and_mu_per_datum_agree_on_the_verdict() {
    let text = format!("{SISO}{RETUNED}");
    let cl = model(&text);
    let cs = cases(&text);
    let data = FrfData {
        path: PathBuf::from("noisy.csv"),
        omega: logspace(0.05, 200.0, 36),
        response: cs
            .iter()
            .map(|c| DMatrix::from_element(1, 1, c.1))
            .collect(),
        noise_radius: None,
        lines: (1..=36).collect(),
    };
    let radii: Vec<f64> = cs.iter().map(|c| c.2).collect();
    let rep =
        closed_loop_envelope(&cl, &data, Some(&radii), &VBisectionSettings::default()).unwrap();
    assert_eq!(rep.envelope.method, EnvelopeMethod::ClosedLoopTheorem2);
    let v = TransferFunction::new(vec![0.004], vec![1.0]);
    let mu = mu_per_datum(&cl, &data, &radii, &v).unwrap();
    let mut both = [0, 0];
    for (m, r) in mu.iter().zip(&rep.envelope.r_min) {
        // μ > 1 ⇔ |V| > v_min (away from the boundary).
        if (0.004 - r).abs() > 1e-9 {
            assert_eq!(*m > 1.0, 0.004 > *r, "μ = {m}, v_min = {r}");
            both[(*m > 1.0) as usize] += 1;
        }
    }
    assert!(
        both[0] > 0 && both[1] > 0,
        "V must split the data: {both:?}"
    );
}

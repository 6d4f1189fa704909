//! Closed-loop noise-free envelope (Crowder & de Callafon, Theorem 1, Corollaries 1–2):
//! the perturbation computed from a closed-loop datum reproduces the true plant, the printed
//! Corollary 1 does not, the LFT route of eq. (10) agrees, and the check fails exactly where
//! an independently computed `|Δ̄(jω)|` says it must.

use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::consistency::closed_loop::{closed_loop_envelope, VBisectionSettings};
use rshape::consistency::closed_loop::{
    delta_bar, delta_bar_corollary1_printed, delta_bar_from_plant, lft_m, perturbed_plant,
    recover_plant, theorem1_n11, upper_lft,
};
use rshape::consistency::{check, EnvelopeMethod};
use rshape::data::FrfData;
use rshape::model::Config;
use rshape::system::{logspace, Polynomial, TransferFunction};
use std::path::{Path, PathBuf};

// Nominal P̂ = 1/(s(s+1)) (a rigid-body pole at 0): rcf N̂ = 1/(s+1)², D̂ = s/(s+1).
// Controller C = (10s+5)/(0.05s+1) (stable, trivial rcf); retuned C̄ = (6s+3)/(0.04s+1).
// True plant P₀ = 1.2/(s(s+0.8)) · 400/(s²+4s+400): gain error, shifted pole, flexible mode.
const SISO: &str = r#"
name = "closed-loop test"
[closed_loop]
n_hat = [[{ num = [1], den = [1, 2, 1] }]]
d_hat = [[{ num = [1, 0], den = [1, 1] }]]
controller = [[{ num = [10, 5], den = [0.05, 1] }]]
"#;
const RETUNED: &str = "experiment_controller = [[{ num = [6, 3], den = [0.04, 1] }]]\n";

fn config(text: &str) -> Config {
    Config::parse(text, Path::new("closed_loop_test.toml")).expect("valid config")
}

fn p0() -> TransferFunction {
    TransferFunction::new(vec![480.0], vec![1.0, 4.8, 403.2, 320.0, 0.0])
}
fn p_hat() -> TransferFunction {
    TransferFunction::new(vec![1.0], vec![1.0, 1.0, 0.0])
}
fn c() -> TransferFunction {
    TransferFunction::new(vec![10.0, 5.0], vec![0.05, 1.0])
}
fn c_bar() -> TransferFunction {
    TransferFunction::new(vec![6.0, 3.0], vec![0.04, 1.0])
}

/// The true perturbation as one rational function, from (*) with polynomials only:
/// `Δ̄ = (n₀d̂ − n̂d₀)·d_c / (q·(d₀d_c + n₀n_c))`, `q = (s+1)²` the denominator of N̂.
fn true_delta_bar() -> TransferFunction {
    let (n0, d0) = (p0().num, p0().den);
    let (nh, dh) = (p_hat().num, p_hat().den);
    let (nc, dc) = (c().num, c().den);
    let q = Polynomial::new(vec![1.0, 2.0, 1.0]);
    let num = n0.mul(&dh).add(&nh.mul(&d0).scale(-1.0)).mul(&dc);
    let den = q.mul(&d0.mul(&dc).add(&n0.mul(&nc)));
    TransferFunction { num, den }
}

fn one(z: Complex64) -> DMatrix<Complex64> {
    DMatrix::from_element(1, 1, z)
}

/// Closed-loop data `Φ = P₀/(1 + P₀C̄)` of the experiment.
fn data(experiment: &TransferFunction, omega: &[f64]) -> FrfData {
    FrfData {
        path: PathBuf::from("synthetic.csv"),
        omega: omega.to_vec(),
        response: omega
            .iter()
            .map(|&w| {
                let p = p0().freq(w);
                one(p / (1.0 + p * experiment.freq(w)))
            })
            .collect(),
        noise_radius: None,
        lines: (1..=omega.len()).collect(),
    }
}

fn rel(a: &DMatrix<Complex64>, b: &DMatrix<Complex64>) -> f64 {
    (a - b).norm() / b.norm()
}

#[test]
fn delta_bar_reproduces_the_true_plant_for_both_experiments() {
    let omega = logspace(0.05, 200.0, 120);
    for (text, exp) in [
        (SISO.to_string(), c()),
        (format!("{SISO}{RETUNED}"), c_bar()),
    ] {
        let cfg = config(&text);
        let cl = cfg.closed_loop.as_ref().unwrap();
        assert_eq!(cl.same_controller, text == SISO);
        let d = data(&exp, &omega);
        for (&w, phi) in d.omega.iter().zip(&d.response) {
            let at = cl.at(w).unwrap();
            let p_true = one(p0().freq(w));
            let db = delta_bar(&at, phi);
            let delta = db.delta.expect("finite Δ̄");
            assert!(!db.uninformative);
            // Eq. (2): (N̂ + D_cΔ̄)(D̂ − N_cΔ̄)⁻¹ = P₀.
            let e = rel(&perturbed_plant(&at, &delta).unwrap(), &p_true);
            assert!(e < 1e-9, "ω = {w}: plant from Δ̄ off by {e:e}");
            // Recovering P₀ from Φ and C̄.
            assert!(rel(&recover_plant(&at, phi).unwrap(), &p_true) < 1e-9);
            // (*) from the plant gives the same Δ̄, and so does the rational Δ̄(s).
            assert!(rel(&delta_bar_from_plant(&at, &p_true).unwrap(), &delta) < 1e-9);
            let want = true_delta_bar().freq(w);
            assert!((delta[(0, 0)] - want).norm() < 1e-9 * want.norm());
            // The LFT of eq. (6) maps Δ̄ back to the datum.
            let m = lft_m(&at).unwrap();
            assert!(rel(&upper_lft(&m, &delta).unwrap(), phi) < 1e-9);
            // Theorem 1 (eq. (10)): μ(V·N₁₁) = |V·N₁₁| > 1 ⇔ |V| > 1/|N₁₁| = |Δ̄|.
            let n11 = theorem1_n11(&at, phi).unwrap()[(0, 0)].norm();
            assert!((1.0 / n11 - db.v_min).abs() < 1e-9 * db.v_min, "ω = {w}");
        }
    }
}

#[test]
fn printed_corollary_1_does_not_reproduce_the_plant_but_corollary_2_does() {
    let cfg = config(SISO);
    let cl = cfg.closed_loop.as_ref().unwrap();
    let mut worst_printed: f64 = 0.0;
    for w in logspace(0.05, 200.0, 60) {
        let at = cl.at(w).unwrap();
        let p_true = one(p0().freq(w));
        let printed = delta_bar_corollary1_printed(&at, &p_true).unwrap();
        worst_printed = worst_printed.max(rel(&perturbed_plant(&at, &printed).unwrap(), &p_true));
        // Corollary 2 (C̄ = C): the invalidation quantity |D_c⁻¹D̂(P₀ − P̂)/(1 + P₀C̄)|.
        let (p, ph) = (p0().freq(w), p_hat().freq(w));
        let cor2 =
            (at.d_hat[(0, 0)] * (p - ph) / (at.d_c[(0, 0)] * (1.0 + p * c().freq(w)))).norm();
        let dbar = delta_bar(&at, &one(p / (1.0 + p * c().freq(w)))).v_min;
        assert!((cor2 - dbar).abs() < 1e-10 * dbar);
    }
    assert!(
        worst_printed > 0.1,
        "the printed Corollary 1 reproduced P₀ to {worst_printed:e}: the test cannot tell the forms apart"
    );
}

#[test]
fn printed_sign_of_m11_does_not_reproduce_the_data() {
    // Eq. (6) prints M₁₁ = V(D̂ + C̄N̂)⁻¹(C̄ − C)D_c; the derivation gives (C − C̄).
    let cfg = config(&format!("{SISO}{RETUNED}"));
    let cl = cfg.closed_loop.as_ref().unwrap();
    let omega = logspace(0.05, 200.0, 60);
    let d = data(&c_bar(), &omega);
    let mut worst_printed: f64 = 0.0;
    for (&w, phi) in d.omega.iter().zip(&d.response) {
        let at = cl.at(w).unwrap();
        let delta = delta_bar(&at, phi).delta.unwrap();
        let mut m = lft_m(&at).unwrap();
        assert!(rel(&upper_lft(&m, &delta).unwrap(), phi) < 1e-9);
        m[0] = -m[0].clone();
        worst_printed = worst_printed.max(rel(&upper_lft(&m, &delta).unwrap(), phi));
    }
    assert!(
        worst_printed > 1e-2,
        "printed sign reproduced Φ to {worst_printed:e}"
    );
}

#[test]
fn the_envelope_does_not_depend_on_the_experiment_controller() {
    // Δ̄ belongs to the plant and the model's C, not to the experiment: data taken with C̄ ≠ C
    // give the same envelope.
    let omega = logspace(0.05, 200.0, 80);
    let a = config(SISO);
    let b = config(&format!("{SISO}{RETUNED}"));
    let s = VBisectionSettings::default();
    let ea = closed_loop_envelope(
        a.closed_loop.as_ref().unwrap(),
        &data(&c(), &omega),
        None,
        &s,
    )
    .unwrap();
    let eb = closed_loop_envelope(
        b.closed_loop.as_ref().unwrap(),
        &data(&c_bar(), &omega),
        None,
        &s,
    )
    .unwrap();
    assert_eq!(ea.envelope.method, EnvelopeMethod::ClosedLoopTheorem1);
    for (x, y) in ea.envelope.r_min.iter().zip(&eb.envelope.r_min) {
        assert!((x - y).abs() < 1e-9 * x);
    }
}

#[test]
fn check_passes_at_1_01_and_fails_exactly_where_it_must() {
    let omega = logspace(0.05, 200.0, 150);
    let cfg = config(&format!("{SISO}{RETUNED}"));
    let env = closed_loop_envelope(
        cfg.closed_loop.as_ref().unwrap(),
        &data(&c_bar(), &omega),
        None,
        &VBisectionSettings::default(),
    )
    .unwrap()
    .envelope;
    let truth = true_delta_bar();
    let scaled = |k: f64| TransferFunction {
        num: truth.num.scale(k),
        den: truth.den.clone(),
    };
    let pass = check(&scaled(1.01), &env);
    assert!(pass.consistent, "failing at {:?}", pass.failing_omegas);
    let fail = check(&scaled(0.99), &env);
    assert_eq!(
        fail.failing_omegas, omega,
        "0.99·|Δ̄| must fail at every datum"
    );
    // A weight that crosses the envelope: it must fail exactly where |V| ≤ |Δ̄_true(jω)|,
    // computed from the rational Δ̄(s) and not from the data.
    let v = TransferFunction::new(vec![0.01, 0.1], vec![1.0, 10.0]);
    let expect: Vec<f64> = omega
        .iter()
        .copied()
        .filter(|&w| v.freq(w).norm() <= truth.freq(w).norm())
        .collect();
    let rep = check(&v, &env);
    assert!(
        !expect.is_empty() && expect.len() < omega.len(),
        "V must cross the envelope"
    );
    assert_eq!(rep.failing_omegas, expect);
}

const MIMO: &str = r#"
[closed_loop]
plant = [[{ num = [2], den = [1, 1] }, { num = [0.5], den = [1, 3] }],
         [{ num = [0.3], den = [1, 2] }, { num = [1], den = [1, 0.5] }]]
controller = [[{ num = [3, 1], den = [1, 4] }, 0.2],
              [0.1, { num = [2], den = [0.1, 1] }]]
"#;

#[test]
fn mimo_delta_bar_reproduces_the_plant_and_bounds_theorem_1() {
    let cfg = config(MIMO);
    let cl = cfg.closed_loop.as_ref().unwrap();
    assert!(cl.plant.trivial && cl.controller.trivial);
    for w in logspace(0.01, 100.0, 40) {
        let at = cl.at(w).unwrap();
        // A true 2×2 plant: the nominal with a multiplicative output error and a lag.
        let lag = Complex64::new(1.0, 0.0) / Complex64::new(1.0, 0.05 * w);
        let e = DMatrix::from_row_slice(
            2,
            2,
            &[
                Complex64::new(1.1, 0.0) * lag,
                Complex64::new(0.05, 0.0),
                Complex64::new(-0.1, 0.0),
                Complex64::new(0.9, 0.0),
            ],
        );
        let p_true = &e * &at.p_hat;
        let s = DMatrix::identity(2, 2) + &p_true * &at.c_bar;
        let phi = s.lu().solve(&p_true).unwrap();
        let db = delta_bar(&at, &phi);
        let delta = db.delta.unwrap();
        assert!(rel(&perturbed_plant(&at, &delta).unwrap(), &p_true) < 1e-9);
        // Δ̄ makes I − N₁₁Δ̄ singular, so σ̄(Δ̄) ≥ 1/σ̄(N₁₁) (Theorem 1's unstructured test
        // finds the smallest singularizing perturbation, which need not reproduce Φ).
        let n11 = theorem1_n11(&at, &phi).unwrap();
        let sv = n11.clone().svd(false, false).singular_values;
        assert!(db.v_min >= (1.0 - 1e-9) / sv.max(), "ω = {w}");
        let k = DMatrix::identity(2, 2) - &n11 * &delta;
        assert!(k.determinant().norm() < 1e-8 * (1.0 + (&n11 * &delta).norm().powi(2)));
    }
}

fn load_err(text: &str) -> String {
    Config::parse(text, Path::new("bad.toml"))
        .unwrap_err()
        .to_string()
}

#[test]
fn load_time_errors_name_the_loop_or_the_missing_factors() {
    // C = 0.5 does not stabilize 1/(s−1): closed-loop pole at s = 0.5.
    let e = load_err(
        r#"[closed_loop]
n_hat = [[{ num = [1], den = [1, 1] }]]
d_hat = [[{ num = [1, -1], den = [1, 1] }]]
controller = [[0.5]]
"#,
    );
    assert!(
        e.contains("bad.toml") && e.contains("controller C does not stabilize"),
        "{e}"
    );
    assert!(e.contains("0.5000"), "the pole is named: {e}");
    let e = load_err(
        r#"[closed_loop]
n_hat = [[{ num = [1], den = [1, 1] }]]
d_hat = [[{ num = [1, -1], den = [1, 1] }]]
controller = [[2]]
experiment_controller = [[0.9]]
"#,
    );
    assert!(
        e.contains("experiment controller C̄ does not stabilize"),
        "{e}"
    );
    // An unstable plant without factors.
    let e =
        load_err("[closed_loop]\nplant = [[{ num = [1], den = [1, -1] }]]\ncontroller = [[2]]\n");
    assert!(e.contains("n_hat and d_hat"), "{e}");
    // An unstable controller without factors.
    let e = load_err(
        "[closed_loop]\nplant = [[{ num = [1], den = [1, 1] }]]\ncontroller = [[{ num = [1, 1], den = [1, 0] }]]\n",
    );
    assert!(e.contains("n_c and d_c"), "{e}");
    // Wrong controller size, [r] in a closed-loop config, [v] without [closed_loop].
    let e = load_err(&MIMO.replace("0.2],", "0.2, 0],"));
    assert!(
        e.contains("row 2 has 2 entries") || e.contains("controller"),
        "{e}"
    );
    let e = load_err(&format!("{SISO}\n[r]\nnum = [1]\nden = [1]\n"));
    assert!(e.contains("[v]"), "{e}");
    let e = load_err(
        "[model]\nfactorization = \"standard\"\nm = [[1]]\nn = [[1]]\n[v]\nnum = [1]\nden = [1]\n",
    );
    assert!(e.contains("[closed_loop]"), "{e}");
}

#[test]
fn a_datum_no_plant_of_the_set_explains_gets_inf() {
    // E = (1 − ΦC̄)D_c + ΦN_c = 0 at Φ* = −D_c/(N_c − C̄D_c): the plant P₀ = Φ*/(1 − Φ*C̄)
    // has 1 + P₀C = 0 (a closed-loop pole of (P₀, C) at jω), and no finite Δ̄ exists.
    let cfg = config(&format!("{SISO}{RETUNED}"));
    let cl = cfg.closed_loop.as_ref().unwrap();
    let w = 3.0;
    let at = cl.at(w).unwrap();
    let (nc, dc, cb) = (at.n_c[(0, 0)], at.d_c[(0, 0)], at.c_bar[(0, 0)]);
    let phi = -dc / (nc - cb * dc);
    let p = phi / (1.0 - phi * cb);
    assert!((1.0 + p * at.c[(0, 0)]).norm() < 1e-12);
    let db = delta_bar(&at, &one(phi));
    assert!(db.delta.is_none() && db.v_min.is_infinite());
    let d = FrfData {
        path: PathBuf::from("x.csv"),
        omega: vec![w],
        response: vec![one(phi)],
        noise_radius: None,
        lines: vec![2],
    };
    let env = closed_loop_envelope(cl, &d, None, &VBisectionSettings::default()).unwrap();
    assert!(env.envelope.r_min[0].is_infinite());
    // With noise around it, some nearby Φ' is explained: finite.
    let env = closed_loop_envelope(
        cl,
        &d,
        Some(&[0.01 * phi.norm()]),
        &VBisectionSettings::default(),
    )
    .unwrap();
    assert!(env.envelope.r_min[0].is_finite());
}

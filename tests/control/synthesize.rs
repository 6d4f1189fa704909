//! Glover–McFarlane synthesis (issue 22): `b_opt = (1 + ρ(XZ))^(−1/2)` against the
//! independent Hankel-norm route `b_opt = √(1 − ‖[Ñ M̃]‖_H²)` (Gramians by a Kronecker
//! solve, not the crate's Lyapunov/Riccati code), the central controller re-proved by the
//! Theorem 1 test, and the `rshape synthesize` command (files, exit codes, bad input).
use crate::common;

use common::{rshape, stderr, stdout};
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rshape::model::Factorization;
use rshape::model::{Controller, Feedback};
use rshape::stability::{analyze, gang_of_four, Verdict};
use rshape::synthesis::{optimum, synthesize};
use rshape::system::hinf_norm;
use rshape::system::NormalizedLcf;
use rshape::system::{logspace, StateSpace, TransferFunction};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `rshape synthesize CFG ARGS… --out OUT`.
fn synthesize_cli(cfg: &Path, args: &[&str], out: &Path) -> std::process::Output {
    let mut all = vec!["synthesize", cfg.to_str().unwrap()];
    all.extend_from_slice(args);
    all.extend(["--out", out.to_str().unwrap()]);
    rshape(&all)
}

/// `rshape synthesize CFG ARGS… --out OUT` gives a verdict, not an error (exit 0 proven
/// robust, 1 not): its exit code, stdout and `synthesis.json`.
fn synthesize_verdict(cfg: &Path, args: &[&str], out: &Path) -> (i32, String, serde_json::Value) {
    let o = synthesize_cli(cfg, args, out);
    let code = o.status.code();
    assert!(
        matches!(code, Some(0) | Some(1)),
        "{}{}",
        stdout(&o),
        stderr(&o)
    );
    let text = std::fs::read_to_string(out.join("synthesis.json")).unwrap();
    (
        code.unwrap(),
        stdout(&o),
        serde_json::from_str(&text).unwrap(),
    )
}

/// `rshape stability CFG --controller OUT/controller.toml` exits with `code`: the written
/// controller is what `stability` reads, and it gets the verdict `synthesize` gave.
fn assert_stability_agrees(cfg: &Path, out: &Path, code: i32) {
    let ctl = out.join("controller.toml");
    let s = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        ctl.to_str().unwrap(),
    ]);
    assert_eq!(s.status.code(), Some(code), "{}{}", stdout(&s), stderr(&s));
}

/// `rshape synthesize CFG ARGS… --out OUT` refuses bad input: exit 2, one line on stderr
/// (naming `name` when given), nothing written.
fn assert_refused(cfg: &Path, args: &[&str], out: &Path, name: Option<&str>) {
    let o = synthesize_cli(cfg, args, out);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    assert_eq!(stderr(&o).trim().lines().count(), 1, "{}", stderr(&o));
    if let Some(name) = name {
        assert!(stderr(&o).contains(name), "{}", stderr(&o));
    }
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

/// `AX + XAᵀ + Q = 0` by the Kronecker form `(I⊗A + A⊗I)vec(X) = −vec(Q)`, dense LU.
pub(crate) fn lyap_kron(a: &DMatrix<f64>, q: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let id = DMatrix::<f64>::identity(n, n);
    let k = id.kronecker(a) + a.kronecker(&id);
    let v = DMatrix::from_column_slice(n * n, 1, (-q).as_slice());
    let x = k.lu().solve(&v).unwrap();
    DMatrix::from_column_slice(n, n, x.as_slice())
}

/// The Hankel norm of a stable system: `√λ_max(PQ)` with its Gramians.
pub(crate) fn hankel_norm(ss: &StateSpace) -> f64 {
    let p = lyap_kron(&ss.a, &(&ss.b * ss.b.transpose()));
    let q = lyap_kron(&ss.a.transpose(), &(ss.c.transpose() * &ss.c));
    let e = rshape::system::eigenvalues(&(p * q), "pq").unwrap();
    e.iter().map(|z| z.re).fold(0.0, f64::max).sqrt()
}

/// A random plant: stable or unstable, MIMO, with or without feedthrough (also the plants of
/// synthesize_hinf.rs's `small_b_opt_by_the_gamma_iteration`).
pub(crate) fn random_plant(seed: u64) -> StateSpace {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let n = rng.gen_range(2..=6);
    let p = rng.gen_range(1..=3);
    let m = rng.gen_range(1..=3);
    let mut r = |_, _| rng.gen_range(-1.0..1.0);
    let a0 = DMatrix::from_fn(n, n, &mut r) * 2.0;
    let shift = if seed.is_multiple_of(3) { 1.5 } else { -0.5 };
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

#[test]
fn b_opt_matches_the_hankel_norm_route_and_the_central_controller_attains_it() {
    let (mut unstable, mut matched) = (0, 0);
    for seed in 0..64u64 {
        let plant = random_plant(seed);
        let poles = rshape::system::eigenvalues(&plant.a, "p").unwrap();
        if rshape::system::spectral_abscissa(&poles) > 0.0 {
            unstable += 1;
        }
        let ncf = NormalizedLcf::new(plant.clone()).unwrap();
        let opt = optimum(&ncf).unwrap();
        let hankel = hankel_norm(&ncf.factors);
        let b_hankel = (1.0 - hankel * hankel).sqrt();
        // √(1 − h²) amplifies an error δ of h by h/b: for a nearly unstabilizable plant
        // (b_opt < 0.02; seed 58 has b_opt = 4.25e-4, which scipy's Riccati solvers confirm
        // to 1e-8 while this Kronecker-Gramian route is off by 2 %) the Hankel route is the
        // inaccurate one. There b_opt is pinned instead by the controller sandwich below,
        // b_opt/1.01 ≤ b(G,K) ≤ b_opt, with b(G,K) from an H∞ norm; the acceptance count is
        // on the well-conditioned rest.
        if opt.b_opt >= 0.02 {
            assert!(
                (opt.b_opt - b_hankel).abs() <= 1e-8,
                "seed {seed}: b_opt {} vs Hankel route {b_hankel}",
                opt.b_opt
            );
            matched += 1;
        }
        // The central controller at γ = 1.01 γ_min: b(G,K) ≥ 1/γ, and no better than b_opt.
        let factor = 1.01;
        let gm = synthesize(&ncf, factor).unwrap();
        let f = Factorization::normalized(ncf.clone());
        let b_gk = 1.0 / hinf_norm(&gang_of_four(&f, &gm.k).unwrap()).unwrap().gamma;
        assert!(
            b_gk >= opt.b_opt / factor * (1.0 - 1e-9),
            "seed {seed}: b(G,K) = {b_gk} < b_opt/γ-factor = {}",
            opt.b_opt / factor
        );
        assert!(
            b_gk <= opt.b_opt * (1.0 + 1e-8),
            "seed {seed}: {b_gk} > b_opt {}",
            opt.b_opt
        );
        // Theorem 1 proves it for a constant r just below b(G,K), and refuses r above b_opt.
        let controller = Controller {
            path: PathBuf::from("synthesized"),
            k: gm.k.clone(),
            feedback: Feedback::Negative,
        };
        let r_ok = TransferFunction::gain(opt.b_opt / factor * 0.999);
        let r_bad = TransferFunction::gain(opt.b_opt * 1.001);
        let grid = logspace(1e-3, 1e3, 400);
        let (rep, _) = analyze(
            &f,
            &controller,
            &[("ok".into(), r_ok), ("bad".into(), r_bad)],
            &grid,
        )
        .unwrap();
        assert!(rep.internally_stable, "seed {seed}");
        assert_eq!(
            rep.margins[0].verdict,
            Verdict::Robust,
            "seed {seed}: {:?}",
            rep.margins[0]
        );
        assert_eq!(rep.margins[1].verdict, Verdict::NotRobust, "seed {seed}");
    }
    assert!(unstable >= 10, "only {unstable} unstable plants");
    assert!(matched >= 40, "only {matched} plants compared to 1e-8");
}

#[test]
fn gamma_factor_near_one_approaches_b_opt() {
    let ncf = NormalizedLcf::new(random_plant(7)).unwrap();
    let f = Factorization::normalized(ncf.clone());
    for factor in [1.5, 1.1, 1.001] {
        let gm = synthesize(&ncf, factor).unwrap();
        let b_gk = 1.0 / hinf_norm(&gang_of_four(&f, &gm.k).unwrap()).unwrap().gamma;
        assert!(b_gk >= gm.b_opt / factor * (1.0 - 1e-9), "{factor}: {b_gk}");
    }
    assert!(synthesize(&ncf, 1.0).is_err());
    assert!(synthesize(&ncf, f64::NAN).is_err());
}

/// b_opt of 1/(s − 1) in closed form: X = Z = 1 + √2, b_opt = (1 + (1 + √2)²)^(−1/2).
#[test]
fn first_order_unstable_closed_form() {
    let plant = StateSpace {
        a: DMatrix::from_element(1, 1, 1.0),
        b: DMatrix::from_element(1, 1, 1.0),
        c: DMatrix::from_element(1, 1, 1.0),
        d: DMatrix::zeros(1, 1),
    };
    let ncf = NormalizedLcf::new(plant).unwrap();
    let opt = optimum(&ncf).unwrap();
    let x = 1.0 + 2f64.sqrt();
    let exact = 1.0 / (1.0 + x * x).sqrt();
    assert!(
        (opt.b_opt - exact).abs() < 1e-13,
        "{} vs {exact}",
        opt.b_opt
    );
}

const CONFIG: &str = r#"
[plant]
tf = [[{ num = [5, 15], den = [1, -0.98, 99.98, -100] }]]
[r]
num = [R]
den = [1]
"#;

#[test]
fn cli_writes_a_controller_that_stability_proves() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "c.toml", &CONFIG.replace("R", "0.01"));
    let out = dir.path().join("out");
    let (code, text, syn) = synthesize_verdict(&cfg, &[], &out);
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("PROVEN robust"), "{text}");
    for f in [
        "controller.toml",
        "controller.json",
        "controller.m",
        "controller.py",
        "controller.jl",
        "synthesis.json",
        "stability.svg",
        "stability.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let b_opt = syn["b_opt"].as_f64().unwrap();
    let b_gk = syn["b_gk"].as_f64().unwrap();
    assert!(b_gk >= b_opt / 1.1 * (1.0 - 1e-9) && b_gk <= b_opt * (1.0 + 1e-9));
    assert_stability_agrees(&cfg, &out, 0);
    // An r above b_opt: no controller can be proven robust: exit 1, the reason in one line.
    let big = format!("{}", b_opt * 1.05);
    let cfg2 = write(dir.path(), "c2.toml", &CONFIG.replace("R", &big));
    let out2 = dir.path().join("out2");
    let (code, text, _) = synthesize_verdict(&cfg2, &[], &out2);
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("no controller reaches alpha >= 1"), "{text}");
}

#[test]
fn bad_input_exits_2_with_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "c.toml", &CONFIG.replace("R", "0.01"));
    let out = dir.path().join("out");
    for args in [
        vec!["--gamma-factor", "1.0"],
        vec!["--gamma-factor", "nan"],
        vec!["--r-json", "missing.json"],
    ] {
        assert_refused(&cfg, &args, &out, None);
    }
    // r not a unit (a zero in the right half-plane).
    let nonunit = write(
        dir.path(),
        "n.toml",
        "[plant]\ntf = [[{ num = [1], den = [1, -1] }]]\n[r]\nnum = [1, -2]\nden = [1, 3]\n",
    );
    assert_refused(&nonunit, &[], &out, None);
    // Not detectable: an unstable mode the output does not see.
    let undetectable = write(
        dir.path(),
        "u.toml",
        "[plant]\na = [[1, 0], [0, -1]]\nb = [[1], [1]]\nc = [[0, 1]]\nd = [[0]]\n",
    );
    assert_refused(&undetectable, &[], &out, None);
}

/// A `[model]` config (the robot's special factorization): the controller is designed for
/// the normalized factors of the plant the factors define and proved with the config's own
/// factors; `stability --controller` on the written controller gives the same verdict.
#[test]
fn special_factorization_config_is_synthesized_for_its_plant_and_proved_with_its_factors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = common::repo("configs/robot.toml");
    let (code, text, syn) = synthesize_verdict(&cfg, &[], &out);
    assert!(text.contains("not the normalized ones"), "{text}");
    let b_opt = syn["b_opt"].as_f64().unwrap();
    let b_gk = syn["b_gk"].as_f64().unwrap();
    assert!(
        b_gk >= b_opt / 1.1 * (1.0 - 1e-9) && b_gk <= b_opt * (1.0 + 1e-8),
        "{b_gk} {b_opt}"
    );
    let poles = syn["closed_loop_poles"].as_array().unwrap();
    assert!(poles.iter().all(|z| z[0].as_f64().unwrap() < 0.0));
    assert_stability_agrees(&cfg, &out, code);
}

fn toml_rows(m: &DMatrix<f64>) -> String {
    let rows: Vec<String> = (0..m.nrows())
        .map(|i| {
            let v: Vec<String> = m.row(i).iter().map(|x| format!("{x:?}")).collect();
            format!("[{}]", v.join(", "))
        })
        .collect();
    format!("[{}]", rows.join(", "))
}

/// `--reduce N`: the stable central controller is cut by balanced truncation and the proof
/// is of the reduced controller (`stability` on the written file agrees); `--reduce 0` is
/// bad input.
#[test]
fn reduced_controller_is_re_proved() {
    let dir = tempfile::tempdir().unwrap();
    let mut done = 0;
    for seed in 100..200u64 {
        let plant = random_plant(seed);
        if plant.states() < 4 {
            continue;
        }
        let Ok(ncf) = NormalizedLcf::new(plant.clone()) else {
            continue;
        };
        let gm = synthesize(&ncf, 1.1).unwrap();
        let kp = rshape::system::eigenvalues(&gm.k.a, "k").unwrap();
        if rshape::system::spectral_abscissa(&kp) >= -1e-6 {
            continue;
        }
        let n = plant.states();
        let cfg = write(
            dir.path(),
            &format!("p{seed}.toml"),
            &format!(
                "[plant]\na = {}\nb = {}\nc = {}\nd = {}\n[r]\nnum = [{:?}]\nden = [1]\n",
                toml_rows(&plant.a),
                toml_rows(&plant.b),
                toml_rows(&plant.c),
                toml_rows(&plant.d),
                0.5 * gm.b_opt / 1.1
            ),
        );
        let out = dir.path().join(format!("out{seed}"));
        let reduce = (n - 1).to_string();
        let (code, text, syn) = synthesize_verdict(&cfg, &["--reduce", &reduce], &out);
        assert!(text.contains("reduced by balanced truncation"), "{text}");
        assert_eq!(syn["controller_order"].as_u64(), Some(n as u64 - 1));
        assert_eq!(syn["reduction"]["from"].as_u64(), Some(n as u64));
        assert_stability_agrees(&cfg, &out, code);
        if done == 0 {
            assert_refused(&cfg, &["--reduce", "0"], &dir.path().join("bad"), None);
        }
        done += 1;
        if done == 3 {
            break;
        }
    }
    assert_eq!(
        done, 3,
        "fewer than 3 plants with a stable central controller"
    );
}

/// Loop shaping: a PI pre-weight `(s + 2)/s` gives the controller integral action (a pole at
/// s = 0, |K(jω)| growing like 1/ω at low frequency) and the proof is of `K = W₁·K∞·W₂` on
/// the plant (`stability` on the written file agrees); an improper weight or a wrong count is
/// bad input.
#[test]
fn loop_shaping_weights_give_integral_action_and_are_proved_on_the_plant() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "c.toml", &CONFIG.replace("R", "0.005"));
    let w = write(
        dir.path(),
        "w.toml",
        "[weights]\nw1 = [{ num = [1, 2], den = [1, 0] }]\nw2 = [2]\n",
    );
    let out = dir.path().join("out");
    let (code, text, syn) = synthesize_verdict(&cfg, &["--weights", w.to_str().unwrap()], &out);
    assert!(text.contains("loop shaping"), "{text}");
    let kp = syn["controller_poles"].as_array().unwrap();
    assert!(
        kp.iter()
            .any(|z| z[0].as_f64().unwrap().abs() < 1e-9 && z[1].as_f64().unwrap() == 0.0),
        "no integrator among {kp:?}"
    );
    assert!(syn["closed_loop_poles"]
        .as_array()
        .unwrap()
        .iter()
        .all(|z| z[0].as_f64().unwrap() < 0.0));
    let ctl = Controller::load(&out.join("controller.toml")).unwrap();
    let mag = |w: f64| ctl.k.freq(w).unwrap()[(0, 0)].norm();
    let ratio = mag(1e-4) / mag(1e-3);
    assert!(
        (ratio - 10.0).abs() < 0.1,
        "|K| ratio over a decade at low frequency {ratio}"
    );
    assert_stability_agrees(&cfg, &out, code);
    for (name, text) in [
        (
            "improper.toml",
            "[weights]\nw1 = [{ num = [1, 0, 1], den = [1, 1] }]\n",
        ),
        ("count.toml", "[weights]\nw2 = [1, 2, 3]\n"),
        (
            "strict.toml",
            "[weights]\nw1 = [{ num = [1], den = [1, 1] }]\n",
        ),
    ] {
        let w = write(dir.path(), name, text);
        let bad = dir.path().join("bad");
        assert_refused(&cfg, &["--weights", w.to_str().unwrap()], &bad, Some(name));
    }
}

/// `--fit`: r is fitted from the config's data first (its exports in DIR), then the
/// controller is proved with the configured and the fitted r; the tighter fitted r gives
/// the larger margin.
#[test]
fn fit_then_synthesize_proves_both_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = common::repo("configs/plant_first.toml");
    let (code, text, syn) = synthesize_verdict(&cfg, &["--fit", "--method", "gm"], &out);
    assert_eq!(code, 0, "{text}");
    assert!(out.join("r.json").is_file() && out.join("controller.toml").is_file());
    let bounds = syn["bounds"].as_array().unwrap();
    assert_eq!(bounds.len(), 2);
    assert_eq!(bounds[1]["label"], "fitted");
    let (ac, af) = (
        bounds[0]["alpha"].as_f64().unwrap(),
        bounds[1]["alpha"].as_f64().unwrap(),
    );
    assert!(af > ac && ac >= 1.0, "configured {ac}, fitted {af}");
    // With --method hinf the controller is the H∞ optimum for the fitted r: its
    // optimum is at least the Glover–McFarlane controller's margin with that r (a
    // candidate), the controller at γ = 1.1·γ_opt reaches at least α_opt/1.1, Theorem 1
    // proves it, and the figure of merit is reported.
    let out2 = dir.path().join("out2");
    let r_json = out.join("r.json");
    let o = rshape(&[
        "synthesize",
        cfg.to_str().unwrap(),
        "--r-json",
        r_json.to_str().unwrap(),
        "--method",
        "hinf",
        "--out",
        out2.to_str().unwrap(),
    ]);
    let syn: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out2.join("synthesis.json")).unwrap())
            .unwrap();
    assert_eq!(syn["method"], "hinf_weighted", "{}", stdout(&o));
    let h = &syn["hinf"]["synthesis"];
    assert_eq!(syn["hinf"]["r"], "fitted");
    let alpha_opt = h["alpha_opt"].as_f64().unwrap();
    let fitted = &syn["bounds"][1];
    assert_eq!(fitted["label"], "fitted");
    let alpha = fitted["alpha"].as_f64().unwrap();
    assert!(
        alpha_opt >= af * (1.0 - 1e-6),
        "H∞ optimum {alpha_opt} below the GM controller's {af}"
    );
    assert!(
        alpha >= alpha_opt / 1.1 * (1.0 - 1e-6) && alpha <= alpha_opt * (1.0 + 1e-6),
        "{alpha} vs {alpha_opt}"
    );
    assert!((alpha - h["alpha_achieved"].as_f64().unwrap()).abs() < 1e-6 * alpha);
    assert_eq!(fitted["verdict"], "robust");
    assert!(
        stdout(&o).contains("H∞ synthesis with the fitted r as weight"),
        "{}",
        stdout(&o)
    );
    assert!(syn["merit"]["peak_sensitivity"].as_f64().unwrap() >= 1.0);
}

/// Every output names the method that made the controller and carries that method's γ
/// (issue 35): with `--method hinf` the text, `controller.toml`'s header, the `.m`/`.py`/`.jl`
/// exports, `synthesis.json` and `stability.svg` say H∞ with the H∞ γ and γ_opt (not
/// Glover–McFarlane's 1.94/1.76); with `gm` they say Glover–McFarlane with its γ and γ_min.
#[test]
fn outputs_carry_the_method_and_its_gamma() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::repo("configs/plant_first.toml");
    let gm_out = dir.path().join("gm");
    let (_, gm_text, gm) = synthesize_verdict(&cfg, &["--fit", "--method", "gm"], &gm_out);
    let r_json = gm_out.join("r.json");
    let h_out = dir.path().join("hinf");
    let (_, h_text, h) = synthesize_verdict(
        &cfg,
        &["--r-json", r_json.to_str().unwrap(), "--method", "hinf"],
        &h_out,
    );
    let read = |d: &Path, f: &str| std::fs::read_to_string(d.join(f)).unwrap();

    // Glover–McFarlane.
    let g = &gm["glover_mcfarlane"];
    assert_eq!(gm["method"], "glover_mcfarlane");
    assert_eq!(gm["gamma"], g["gamma"]);
    assert_eq!(gm["gamma_min"], g["gamma_min"]);
    assert!(gm["gamma_opt"].is_null());
    let toml = read(&gm_out, "controller.toml");
    let head: Vec<&str> = toml.lines().take(2).collect();
    assert!(head[0].contains("Glover–McFarlane"), "{toml}");
    assert!(
        head[1].contains(&format!("gamma = {:?}", g["gamma"].as_f64().unwrap()))
            && head[1].contains(&format!(
                "gamma_min = {:?}",
                g["gamma_min"].as_f64().unwrap()
            )),
        "{toml}"
    );
    for f in ["controller.m", "controller.py", "controller.jl"] {
        let t = read(&gm_out, f);
        assert!(
            t.lines()
                .next()
                .unwrap()
                .contains("Glover–McFarlane controller"),
            "{f}: {t}"
        );
    }
    let svg = read(&gm_out, "stability.svg");
    assert!(svg.contains("Glover–McFarlane controller: γ = ") && svg.contains("γ_min = "));
    assert!(svg.contains("α* = ") && !svg.contains("H∞"), "GM figure");
    assert!(
        gm_text.contains("central controller at gamma = "),
        "{gm_text}"
    );

    // H∞.
    let hs = &h["hinf"]["synthesis"];
    assert_eq!(h["method"], "hinf_weighted");
    assert_eq!(h["gamma"], hs["gamma"]);
    assert_eq!(h["gamma_opt"], hs["gamma_opt"]);
    assert!(h["gamma_min"].is_null());
    assert_ne!(h["gamma"], h["glover_mcfarlane"]["gamma"]);
    let toml = read(&h_out, "controller.toml");
    let head: Vec<&str> = toml.lines().take(2).collect();
    assert!(
        head[0].contains("H∞") && !head[0].contains("Glover"),
        "{toml}"
    );
    assert!(
        head[1].contains(&format!("gamma = {:?}", hs["gamma"].as_f64().unwrap()))
            && head[1].contains(&format!(
                "gamma_opt = {:?}",
                hs["gamma_opt"].as_f64().unwrap()
            ))
            && !head[1].contains("gamma_min"),
        "{toml}"
    );
    for f in ["controller.m", "controller.py", "controller.jl"] {
        let t = read(&h_out, f);
        let first = t.lines().next().unwrap();
        assert!(
            first.contains("H∞") && !first.contains("Glover"),
            "{f}: {t}"
        );
    }
    let svg = read(&h_out, "stability.svg");
    assert!(svg.contains("H∞") && svg.contains("γ_opt = ") && svg.contains("α* = "));
    assert!(
        !svg.contains("Glover–McFarlane controller"),
        "H∞ figure says GM"
    );
    // The text: GM is the reference only (no controller order under its name).
    assert!(
        h_text.contains("Glover–McFarlane (reference, not the controller)")
            && !h_text.contains("central controller at gamma = 1."),
        "{h_text}"
    );
    assert!(!h_text.contains("- rad/s"), "{h_text}");
}

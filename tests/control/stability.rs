//! Theorem 1 robust stability: exact H∞ norms, b(G, K), the margin with the configured and
//! the fitted r, and bad input (exit 1 for a non-stabilizing controller, exit 2 for errors).
use crate::common;

use common::{repo, rshape, stderr, stdout};
use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::model::{Config, Controller};
use rshape::stability::{analyze, gang_of_four};
use rshape::system::{hinf_norm, logspace, StateSpace, TransferFunction};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Peak of σ_max over a grid by the dense-LU evaluation (independent of the Hessenberg one),
/// then refined on a 20 001-point grid between the neighbours of the best point.
fn grid_peak(ss: &StateSpace, grid: &[f64]) -> (f64, f64) {
    let sig = |w: f64| ss.freq(w).unwrap().svd(false, false).singular_values.max();
    let (k, _) = grid
        .iter()
        .enumerate()
        .map(|(k, w)| (k, sig(*w)))
        .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let lo = grid[k.saturating_sub(1)];
    let hi = grid[(k + 1).min(grid.len() - 1)];
    (0..=20_000)
        .map(|i| lo + (hi - lo) * i as f64 / 20_000.0)
        .map(|w| (sig(w), w))
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

/// Independent H∞ norm for D = 0 by bisection: γ > ‖G‖∞ iff
/// [A, BBᵀ/γ; −CᵀC/γ, −Aᵀ] has no eigenvalue on the imaginary axis.
fn bisection_norm(ss: &StateSpace, lo: f64, hi: f64) -> f64 {
    let n = ss.a.nrows();
    let has_imag = |g: f64| {
        let mut h = DMatrix::zeros(2 * n, 2 * n);
        h.view_mut((0, 0), (n, n)).copy_from(&ss.a);
        h.view_mut((0, n), (n, n))
            .copy_from(&(&ss.b * ss.b.transpose() / g));
        h.view_mut((n, 0), (n, n))
            .copy_from(&(-(ss.c.transpose() * &ss.c) / g));
        h.view_mut((n, n), (n, n)).copy_from(&(-ss.a.transpose()));
        let e = nalgebra::linalg::Schur::try_new(h, 1e-15, 100_000)
            .unwrap()
            .complex_eigenvalues();
        e.iter().any(|z| z.re.abs() < 1e-7 * z.norm().max(1e-3))
    };
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if has_imag(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

#[test]
fn lightly_damped_mode_closed_form() {
    // ω_n²/(s² + 2ζω_n s + ω_n²): peak 1/(2ζ√(1−ζ²)) at ω_n√(1−2ζ²).
    for zeta in [1e-4, 5e-3, 0.3] {
        let wn = 3.0;
        let tf = TransferFunction::new(vec![wn * wn], vec![1.0, 2.0 * zeta * wn, wn * wn]);
        let h = hinf_norm(&StateSpace::from_tf(&tf)).unwrap();
        let peak = 1.0 / (2.0 * zeta * (1.0 - zeta * zeta).sqrt());
        let wp = wn * (1.0 - 2.0 * zeta * zeta).sqrt();
        assert!(
            (h.gamma - peak).abs() < 1e-8 * peak,
            "ζ={zeta}: {} vs {peak}",
            h.gamma
        );
        assert!(
            (h.omega - wp).abs() < 1e-4 * wp,
            "ζ={zeta}: {} vs {wp}",
            h.omega
        );
    }
}

fn random_stable(seed: u64, n: usize, p: usize, m: usize, with_d: bool) -> StateSpace {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut r = |_, _| rng.gen_range(-1.0..1.0);
    let a0 = DMatrix::from_fn(n, n, &mut r) * 3.0;
    // Shift to make A stable with a moderately damped slowest mode.
    let abscissa =
        rshape::system::spectral_abscissa(&rshape::system::eigenvalues(&a0, "a").unwrap());
    let a = a0 - DMatrix::identity(n, n) * (abscissa + 0.3);
    let b = DMatrix::from_fn(n, m, &mut r);
    let c = DMatrix::from_fn(p, n, &mut r);
    let d = if with_d {
        DMatrix::from_fn(p, m, &mut r) * 0.3
    } else {
        DMatrix::zeros(p, m)
    };
    StateSpace { a, b, c, d }
}

#[test]
fn random_mimo_norms_match_dense_grid_and_independent_bisection() {
    let mut grid = vec![0.0];
    grid.extend(logspace(1e-3, 1e3, 100_000));
    for seed in 0..4u64 {
        let ss = random_stable(seed, 8, 2, 3, seed % 2 == 1);
        let h = hinf_norm(&ss).unwrap();
        let (gp, _) = grid_peak(&ss, &grid);
        // Never below the grid, and within the grid's resolution above it.
        assert!(
            h.gamma >= gp * (1.0 - 1e-12),
            "seed {seed}: {} < {gp} (ω {})",
            h.gamma,
            h.omega
        );
        assert!(
            h.gamma <= gp * (1.0 + 1e-9),
            "seed {seed}: {} vs {gp} (ω {})",
            h.gamma,
            h.omega
        );
        if seed % 2 == 0 {
            let b = bisection_norm(&ss, gp * 0.5, gp * 2.0);
            assert!(
                (h.gamma - b).abs() < 1e-7 * b,
                "seed {seed}: {} vs {b}",
                h.gamma
            );
        }
    }
}

#[test]
fn several_lightly_damped_modes_mimo() {
    // Three modes with ζ = 1e-4 at 1, 5 and 20 rad/s, 2×2; grids dense around each peak.
    let zeta = 1e-4;
    let wns = [1.0, 5.0, 20.0];
    let n = 2 * wns.len();
    let mut a = DMatrix::zeros(n, n);
    for (k, w) in wns.iter().enumerate() {
        a[(2 * k, 2 * k + 1)] = 1.0;
        a[(2 * k + 1, 2 * k)] = -w * w;
        a[(2 * k + 1, 2 * k + 1)] = -2.0 * zeta * w;
    }
    let b = DMatrix::from_row_slice(n, 2, &[0., 0., 1., 0.2, 0., 0., 0.3, 1., 0., 0., 1., -1.]);
    let c = DMatrix::from_row_slice(2, n, &[1., 0., 2., 0., 40., 0., 0., 0.5, 1., 0., 100., 0.]);
    let ss = StateSpace {
        a,
        b,
        c,
        d: DMatrix::zeros(2, 2),
    };
    let h = hinf_norm(&ss).unwrap();
    let mut grid = Vec::new();
    for w in wns {
        grid.extend(logspace(
            w * (1.0 - 20.0 * zeta),
            w * (1.0 + 20.0 * zeta),
            30_000,
        ));
    }
    let (gp, wp) = grid_peak(&ss, &grid);
    assert!(
        h.gamma >= gp * (1.0 - 1e-12) && h.gamma <= gp * (1.0 + 1e-6),
        "{} vs {gp}",
        h.gamma
    );
    assert!((h.omega - wp).abs() < 1e-5 * wp);
    let bis = bisection_norm(&ss, gp * 0.5, gp * 2.0);
    assert!((h.gamma - bis).abs() < 1e-6 * bis, "{} vs {bis}", h.gamma);
}

#[test]
fn high_order_companion_weight_times_lightly_damped_modes() {
    // A companion-form realization of an order-8 weight with poles from 0.03 to 3000 rad/s
    // (entries up to ~1e16) in series with a ζ = 5e-3 mode: without balancing, both the
    // frequency response and the Hamiltonian eigenvalues lose ~6 digits and the norm came out
    // 0.1% low. Checked against a dense-LU grid refined around its best point.
    let zeros: Vec<Complex64> = [0.05, 0.3, 2.0, 8.0, 40.0, 200.0, 900.0, 3000.0]
        .iter()
        .map(|z| Complex64::new(-z, 0.0))
        .collect();
    let poles: Vec<Complex64> = [0.03, 0.2, 1.5, 6.0, 30.0, 150.0, 700.0, 2500.0]
        .iter()
        .map(|p| Complex64::new(-p, 0.0))
        .collect();
    let r = TransferFunction::from_zpk(&zeros, &poles, 1.0);
    let (wn, zeta) = (0.54, 5e-3);
    let mode = TransferFunction::new(vec![wn * wn], vec![1.0, 2.0 * zeta * wn, wn * wn]);
    let ss = StateSpace::from_tf(&mode).times_scalar(&StateSpace::from_tf(&r));
    let h = hinf_norm(&ss).unwrap();
    // Reference: the product form |mode(jω)|·Π|jω − zᵢ|/|jω − pᵢ|, on a grid refined twice
    // around its best point.
    let mag = |w: f64| {
        let s = Complex64::new(0.0, w);
        let m = wn * wn / (s * s + 2.0 * zeta * wn * s + wn * wn);
        let rz: Complex64 = zeros.iter().map(|z| s - z).product();
        let rp: Complex64 = poles.iter().map(|p| s - p).product();
        (m * rz / rp).norm()
    };
    let (mut lo, mut hi) = (1e-3f64, 1e4f64);
    let mut best = (0.0, 0.0);
    for pass in 0..3 {
        let pts: Vec<f64> = if pass == 0 {
            logspace(lo, hi, 100_000)
        } else {
            (0..=20_000)
                .map(|i| lo + (hi - lo) * i as f64 / 20_000.0)
                .collect()
        };
        let k = (0..pts.len())
            .max_by(|a, b| mag(pts[*a]).total_cmp(&mag(pts[*b])))
            .unwrap();
        best = (mag(pts[k]), pts[k]);
        lo = pts[k.saturating_sub(1)];
        hi = pts[(k + 1).min(pts.len() - 1)];
    }
    assert!(
        (h.gamma - best.0).abs() < 1e-9 * best.0,
        "{} vs {:?}",
        h.gamma,
        best
    );
    assert!((h.omega - best.1).abs() < 1e-5 * best.1);
}

#[test]
fn b_of_unstable_first_order_with_gain_two_is_one_over_sqrt_ten() {
    // G = 1/(s−1), K = 2: [K; 1](1 + GK)⁻¹[1 G] = [2; 1]·[(s−1)/(s+1), 1/(s+1)], whose
    // largest singular value √5·√((ω² + 2)/(ω² + 1)) peaks at ω = 0: b = 1/√10.
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "g.toml",
        "[plant]\ntf = [[{ num = [1], den = [1, -1] }]]\n[r]\nnum = [0.1]\nden = [1]\n",
    );
    let k = write(dir.path(), "k.toml", "[controller]\ntf = [[2]]\n");
    let config = Config::load(&cfg).unwrap();
    let ctrl = Controller::load(&k).unwrap();
    let b = 1.0
        / hinf_norm(&gang_of_four(&config.factorization, &ctrl.k).unwrap())
            .unwrap()
            .gamma;
    assert!((b - 1.0 / 10f64.sqrt()).abs() < 1e-9, "{b}");
    let r = config.r.clone().unwrap();
    let (rep, _) = analyze(
        &config.factorization,
        &ctrl,
        &[("configured".into(), r)],
        &logspace(0.01, 100.0, 50),
    )
    .unwrap();
    assert!(rep.internally_stable);
    assert!((rep.abscissa + 1.0).abs() < 1e-9);
    // Normalized factors, constant r = 0.1: α* = b/|r|.
    let alpha = rep.margins[0].alpha;
    assert!((alpha - b / 0.1).abs() < 1e-8 * alpha, "{alpha}");
    // Through the CLI.
    let out = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        k.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        stdout(&out),
        stderr(&out)
    );
    assert!(
        stdout(&out).contains("b(G,K) = 0.316228"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn theorem1_margin_equals_b_over_r_on_the_iss_reduced_model() {
    // Normalized factors of a 3×3, 20-state plant; static controller; constant r.
    let dir = tempfile::tempdir().unwrap();
    let model = repo("configs/data/iss1r/model.json");
    let cfg = write(
        dir.path(),
        "iss.toml",
        &format!(
            "[plant]\nfile = \"{}\"\nreduce_order = 20\n[r]\nnum = [0.02]\nden = [1]\n",
            model.display()
        ),
    );
    let k = write(
        dir.path(),
        "k.toml",
        "[controller]\nd = [[5, 0, 0], [0, 5, 0], [0, 0, 5]]\n",
    );
    let config = Config::load(&cfg).unwrap();
    let ctrl = Controller::load(&k).unwrap();
    let (rep, _) = analyze(
        &config.factorization,
        &ctrl,
        &[("configured".into(), config.r.clone().unwrap())],
        &logspace(0.1, 100.0, 200),
    )
    .unwrap();
    assert!(rep.internally_stable);
    let b = rep.b_gk.unwrap();
    let t = rep.t_norm.unwrap().gamma;
    assert!((1.0 / t - b).abs() < 1e-7 * b, "{} vs {b}", 1.0 / t);
    assert!((rep.margins[0].alpha - b / 0.02).abs() < 1e-7 * b / 0.02);
}

#[test]
fn paper_example_fitted_r_buys_a_strictly_larger_margin() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let out = rshape(&[
        "stability",
        repo("configs/paper_mimo.toml").to_str().unwrap(),
        "--controller",
        repo("configs/paper_mimo_controller.toml").to_str().unwrap(),
        "--fit",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        stdout(&out),
        stderr(&out)
    );
    let text = stdout(&out);
    assert!(text.contains("what the tighter r buys"), "{text}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("stability.json")).unwrap())
            .unwrap();
    let m = v["report"]["margins"].as_array().unwrap();
    let (conf, fit) = (
        m[0]["alpha"].as_f64().unwrap(),
        m[1]["alpha"].as_f64().unwrap(),
    );
    assert_eq!(m[0]["label"], "configured");
    assert!(fit > conf * 1.05, "fitted {fit} vs configured {conf}");
    // The exact margin is never above the grid estimate (the grid can only miss the peak).
    for row in m {
        assert!(
            row["alpha"].as_f64().unwrap() <= row["alpha_grid"].as_f64().unwrap() * (1.0 + 1e-9)
        );
    }
    let svg = std::fs::read_to_string(out_dir.join("stability.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("fitted"));
}

#[test]
fn non_stabilizing_controller_exits_1_with_the_unstable_poles() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "g.toml",
        "[plant]\ntf = [[{ num = [1], den = [1, -1] }]]\n",
    );
    let k = write(dir.path(), "k.toml", "[controller]\ntf = [[0.5]]\n");
    let out = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        k.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    // Closed loop s − 1 + 0.5: the pole 0.5.
    assert!(
        stdout(&out).contains("NOT internally stable") && stdout(&out).contains("0.5+0j"),
        "{}",
        stdout(&out)
    );
    // Positive feedback with K = −2 is the same stabilizing loop as negative with 2.
    let kp = write(
        dir.path(),
        "kp.toml",
        "[controller]\ntf = [[-2]]\nfeedback = \"positive\"\n",
    );
    let out = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        kp.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
}

#[test]
fn bad_input_is_one_line_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let paper = repo("configs/paper_mimo.toml");
    let cases = [
        // 2×3 plant: the controller must be 3×2.
        (
            "wrong_size.toml",
            "[controller]\ntf = [[1, 0], [0, 1]]\n",
            "must be 3×2",
        ),
        (
            "nan.toml",
            "[controller]\nd = [[nan, 0], [0, 1], [0, 0]]\n",
            "D[1][1] is not finite",
        ),
        (
            "ragged.toml",
            "[controller]\ntf = [[1, 0], [0], [0, 0]]\n",
            "row 2 has 1 entries",
        ),
    ];
    for (name, text, expect) in cases {
        let k = write(dir.path(), name, text);
        let out = rshape(&[
            "stability",
            paper.to_str().unwrap(),
            "--controller",
            k.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{name}: {}", stdout(&out));
        let e = stderr(&out);
        assert!(e.contains(expect), "{name}: {e}");
        assert_eq!(e.trim_end().lines().count(), 1, "{name}: {e}");
        assert!(!out_dir.exists(), "{name}: wrote output");
    }
    // A plant whose filter Riccati equation has no stabilizing solution.
    let bad = write(
        dir.path(),
        "bad.toml",
        "[plant]\na = [[1, 0], [0, -1]]\nb = [[1], [1]]\nc = [[0, 1]]\n",
    );
    let k = write(dir.path(), "k.toml", "[controller]\ntf = [[1]]\n");
    let out = rshape(&[
        "stability",
        bad.to_str().unwrap(),
        "--controller",
        k.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(
        e.contains("no stabilizing solution") && e.trim_end().lines().count() == 1,
        "{e}"
    );
    assert!(!out_dir.exists());
    let _ = Complex64::new(0.0, 0.0);
}

/// The title of `stability.svg` never drops the controller's name: a long model name is cut in
/// the middle first (its beginning and end stay), the title stays within one caption line, and
/// short titles are untouched.  End to end, the figure written by `rshape stability` carries
/// the controller's file name.
#[test]
fn stability_title_keeps_the_controller_name() {
    use rshape::pipeline::stability::{figure_title, FIGURE_TITLE_CHARS};
    let long_name = format!(
        "flexible robot arm {} five modes, tip sensor, revision 7",
        "with a very long description ".repeat(3)
    );
    let config = |name: &str| {
        Config::parse(
            &format!("name = \"{name}\"\n[plant]\ntf = [[{{ num = [1], den = [1, 1, 0] }}]]\n"),
            Path::new("t.toml"),
        )
        .unwrap()
    };
    let k = "K = robot_controller.toml";
    let t = figure_title(&config(&long_name), k);
    assert!(t.chars().count() <= FIGURE_TITLE_CHARS, "{t}");
    assert!(t.ends_with(&format!(", {k}")), "{t}");
    assert!(
        t.contains("— flexible") && t.contains("revision 7, K") && t.contains('…'),
        "{t}"
    );
    let short = figure_title(&config("robot"), k);
    assert_eq!(short, format!("Theorem 1: 1/σ_max(T) vs |r| — robot, {k}"));
    // An absurdly long controller name is cut in the middle too, keeping its end.
    let long_k = format!("K = {}final.toml", "controller_".repeat(10));
    let t = figure_title(&config(&long_name), &long_k);
    assert!(t.chars().count() <= FIGURE_TITLE_CHARS, "{t}");
    assert!(t.ends_with("final.toml") && t.contains("flexible"), "{t}");

    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo("configs/plant_first.toml"))
        .unwrap()
        .replace(
            "name = \"integrator plus lag, plant given as a transfer function\"",
            &format!("name = \"{long_name}\""),
        )
        .replace(
            "data = \"plant_first.csv\"",
            &format!("data = \"{}\"", repo("configs/plant_first.csv").display()),
        );
    let cfg = write(dir.path(), "long.toml", &text);
    let out = dir.path().join("out");
    let o = rshape(&[
        "stability",
        cfg.to_str().unwrap(),
        "--controller",
        repo("configs/plant_first_controller.toml")
            .to_str()
            .unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        matches!(o.status.code(), Some(0) | Some(1)),
        "{}",
        stderr(&o)
    );
    let svg = std::fs::read_to_string(out.join("stability.svg")).unwrap();
    assert!(
        svg.contains(", K = plant_first_controller.toml\n</text>"),
        "{}",
        stdout(&o)
    );
}

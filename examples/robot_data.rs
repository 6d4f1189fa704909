//! Generates `configs/robot.csv`: synthetic frequency-response data of the five-mode flexible
//! robot of Boulet & Francis (1998), eqs. (18)–(21), from a *perturbed* plant plus bounded
//! complex noise.
//!
//! * plant: `g_p(s) = Σ_k c_k·n_k(1 + ε_k) / (4s² + a_k(1 + α_k)s + b_k(1 + β_k))` (the common
//!   denominator `s² + 41.2s + 40.2` of `M̃` and `Ñ` cancels), i.e. the modal stiffnesses `b_k`
//!   perturbed by up to ±6 %, the modal dampings `a_k` by up to ±25 %, the input gains by
//!   up to ±5 %: a perturbation of the numerators of `M̃` and `Ñ`;
//! * noise: uniform in the disk of radius 0.05 (< L_a = 0.06);
//! * 211 log-spaced frequencies from 1 to 64 rad/s; ChaCha8 with seed 1998.
//!
//! Run: `cargo run --example robot_data` (writes `configs/robot.csv`).

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;
use std::path::Path;

const A: [f64; 5] = [4.1, 36.1, 16.1, 90.8, 22.8];
const B: [f64; 5] = [105.0, 8228.6, 1634.0, 20116.0, 1310.3];
const N: [f64; 5] = [1800.0, -1800.0, -1800.0, 1800.0, 1800.0];
const C: [f64; 5] = [-3.30e-3, 3.40e-3, -3.39e-3, 0.0, -0.01e-3];
const NOISE: f64 = 0.05;
const POINTS: usize = 211;

fn plant(s: Complex64, eps: &[f64; 5], alpha: &[f64; 5], beta: &[f64; 5]) -> Complex64 {
    (0..5)
        .map(|k| {
            C[k] * N[k] * (1.0 + eps[k])
                / (4.0 * s * s + A[k] * (1.0 + alpha[k]) * s + B[k] * (1.0 + beta[k]))
        })
        .sum()
}

fn main() -> anyhow::Result<()> {
    let mut rng = ChaCha8Rng::seed_from_u64(1998);
    let mut draw = |w: f64| -> [f64; 5] { std::array::from_fn(|_| rng.gen_range(-w..=w)) };
    let (beta, alpha, eps) = (draw(0.06), draw(0.25), draw(0.05));
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    // Sanity check against the library's factorization of configs/robot.toml.
    let cfg = rshape::model::Config::load(&root.join("robot.toml"))?;
    let mut worst = 0.0f64;
    let mut out = String::new();
    writeln!(
        out,
        "# Synthetic data for configs/robot.toml, written by examples/robot_data.rs (seed 1998)."
    )?;
    writeln!(
        out,
        "# Perturbed plant: stiffness factors 1+beta = {:?}",
        beta.map(|b| 1.0 + b)
    )?;
    writeln!(
        out,
        "#   damping factors 1+alpha = {:?}",
        alpha.map(|a| 1.0 + a)
    )?;
    writeln!(
        out,
        "#   input-gain factors 1+eps = {:?}",
        eps.map(|e| 1.0 + e)
    )?;
    writeln!(
        out,
        "# Noise: uniform in the disk of radius {NOISE} (L_a = 0.06 in the config)."
    )?;
    writeln!(out, "omega_rad_s,re_1_1,im_1_1")?;
    for i in 0..POINTS {
        let omega = 64f64.powf(i as f64 / (POINTS - 1) as f64);
        let s = Complex64::new(0.0, omega);
        let nominal = plant(s, &[0.0; 5], &[0.0; 5], &[0.0; 5]);
        let lib = cfg.factorization.plant(omega).expect("M̃ is invertible")[(0, 0)];
        worst = worst.max((nominal - lib).norm() / lib.norm());
        let g = plant(s, &eps, &alpha, &beta);
        // Uniform in the disk: radius NOISE·√u, angle uniform.
        let (u, th): (f64, f64) = (rng.gen(), rng.gen_range(0.0..std::f64::consts::TAU));
        let phi = g + Complex64::from_polar(NOISE * u.sqrt(), th);
        writeln!(out, "{omega:.12e},{:.12e},{:.12e}", phi.re, phi.im)?;
    }
    anyhow::ensure!(
        worst < 1e-10,
        "the example's nominal plant disagrees with robot.toml ({worst:e})"
    );
    std::fs::write(root.join("robot.csv"), out)?;
    println!(
        "wrote configs/robot.csv ({POINTS} points); nominal model check: max rel. diff {worst:.1e}"
    );
    Ok(())
}

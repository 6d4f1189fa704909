//! Generates the closed-loop example data of `configs/closed_loop_*.toml` (Crowder &
//! de Callafon): a flexible servo with a rigid-body mode, measured in closed loop.
//!
//! * nominal model: the rigid body `P̂ = 1/s²` (open-loop unstable: a double pole at 0),
//!   rcf `N̂ = 1/(s+2)²`, `D̂ = s²/(s+2)²`;
//! * true plant: `P₀ = 1.15/s² · ω_r²/(s² + 2ζω_r s + ω_r²) · 1/(0.004s + 1)`, a lightly
//!   damped flexible mode (`ω_r = 50` rad/s, `ζ = 0.01`), a 15 % gain error and a lag;
//! * controller of the model: the lead `C = 20(s+1)/(s+10)`; retuned experiment controller
//!   `C̄ = 12(s+0.8)/(s+8)` (both stabilize `P̂` and `P₀`);
//! * 160 log-spaced frequencies from 0.1 to 300 rad/s, a multisine reference `R` of unit
//!   amplitude with Schroeder phases;
//! * noisy sets: complex noise uniform in the disk of radius `0.8·W`, `W = 0.02·|Φ| + 1e-4`
//!   (the `noise_radius` column is `W`, a radius on `Φ = Y/R`, eq. (8)); ChaCha8, seed 2000.
//!
//! Files (in `configs/data/closed_loop/`): `same.csv` (C̄ = C, noise-free, FRF format),
//! `retuned.csv` (C̄ ≠ C, noise-free, `Y`/`R` spectra), `same_noisy.csv`,
//! `retuned_noisy.csv` (spectra with `noise_radius`), and `open_loop.csv` (the true
//! plant's FRF, for comparison with the open-loop path).
//!
//! Run: `cargo run --example closed_loop_data`.

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;
use std::path::Path;

const POINTS: usize = 160;

fn j(w: f64) -> Complex64 {
    Complex64::new(0.0, w)
}

fn p0(w: f64) -> Complex64 {
    let s = j(w);
    let (wr, z) = (50.0, 0.01);
    1.15 / (s * s) * (wr * wr) / (s * s + 2.0 * z * wr * s + wr * wr) / (0.004 * s + 1.0)
}

fn c(w: f64) -> Complex64 {
    20.0 * (j(w) + 1.0) / (j(w) + 10.0)
}

fn c_bar(w: f64) -> Complex64 {
    12.0 * (j(w) + 0.8) / (j(w) + 8.0)
}

/// Asserts that both controllers stabilize the true plant (the experiments are feasible):
/// `P₀ = N/D` with `N = 2875/q`, `D = s²(s² + s + 2500)(0.004s + 1)/q`, `q = (s+2)⁵`.
fn check_experiments() -> anyhow::Result<()> {
    use rshape::model::closed_loop::check_loop;
    use rshape::system::{Polynomial, TfMatrix, TransferFunction};
    let q = (0..5).fold(Polynomial::constant(1.0), |a, _| {
        a.mul(&Polynomial::new(vec![1.0, 2.0]))
    });
    let d = Polynomial::new(vec![1.0, 0.0, 0.0])
        .mul(&Polynomial::new(vec![1.0, 1.0, 2500.0]))
        .mul(&Polynomial::new(vec![0.004, 1.0]));
    let one = |t: TransferFunction| TfMatrix::from_rows(vec![vec![t]]).expect("1×1");
    let n = one(TransferFunction {
        num: Polynomial::constant(2875.0),
        den: q.clone(),
    });
    let d = one(TransferFunction { num: d, den: q });
    let eye = one(TransferFunction::gain(1.0));
    for (name, k) in [
        (
            "C",
            TransferFunction::new(vec![20.0, 20.0], vec![1.0, 10.0]),
        ),
        ("C̄", TransferFunction::new(vec![12.0, 9.6], vec![1.0, 8.0])),
    ] {
        check_loop(&n, &d, &one(k), &eye)
            .map_err(|e| anyhow::anyhow!("{name} does not stabilize the true plant: {e}"))?;
    }
    Ok(())
}

fn main() -> anyhow::Result<()> {
    check_experiments()?;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/data/closed_loop");
    std::fs::create_dir_all(&dir)?;
    let omega: Vec<f64> = (0..POINTS)
        .map(|k| 0.1 * (3000f64).powf(k as f64 / (POINTS - 1) as f64))
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(2000);
    let head = "# closed-loop data written by examples/closed_loop_data.rs (see its doc comment)\n";
    let mut ol = format!("{head}omega_rad_s,re_1_1,im_1_1\n");
    for &w in &omega {
        let p = p0(w);
        writeln!(ol, "{w:.12e},{:.15e},{:.15e}", p.re, p.im)?;
    }
    std::fs::write(dir.join("open_loop.csv"), ol)?;
    for (name, ctrl, noisy, spectra) in [
        ("same", c as fn(f64) -> Complex64, false, false),
        ("retuned", c_bar as fn(f64) -> Complex64, false, true),
        ("same_noisy", c as fn(f64) -> Complex64, true, true),
        ("retuned_noisy", c_bar as fn(f64) -> Complex64, true, true),
    ] {
        let mut out = String::from(head);
        out.push_str(if spectra {
            "omega_rad_s,re_y,im_y,re_r,im_r"
        } else {
            "omega_rad_s,re_1_1,im_1_1"
        });
        out.push_str(if noisy { ",noise_radius\n" } else { "\n" });
        for (k, &w) in omega.iter().enumerate() {
            let p = p0(w);
            let phi = p / (1.0 + p * ctrl(w));
            let radius = 0.02 * phi.norm() + 1e-4;
            let noise = if noisy {
                let (r, t): (f64, f64) = (
                    rng.gen_range(0.0..1.0),
                    rng.gen_range(0.0..std::f64::consts::TAU),
                );
                Complex64::from_polar(0.8 * radius * r.sqrt(), t)
            } else {
                Complex64::new(0.0, 0.0)
            };
            // Schroeder phases of a unit-amplitude multisine.
            let kk = k as f64;
            let r =
                Complex64::from_polar(1.0, -std::f64::consts::PI * kk * (kk + 1.0) / POINTS as f64);
            let y = (phi + noise) * r;
            if spectra {
                write!(
                    out,
                    "{w:.12e},{:.15e},{:.15e},{:.15e},{:.15e}",
                    y.re, y.im, r.re, r.im
                )?;
            } else {
                write!(out, "{w:.12e},{:.15e},{:.15e}", phi.re, phi.im)?;
            }
            if noisy {
                write!(out, ",{radius:.6e}")?;
            }
            out.push('\n');
        }
        std::fs::write(dir.join(format!("{name}.csv")), out)?;
    }
    println!("wrote {}", dir.display());
    Ok(())
}

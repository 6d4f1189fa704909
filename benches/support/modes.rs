//! A large lightly damped structure for the issue-21 target "a 200-mode physical model's
//! `run` ≤ 30 s": a `[physical]` config with `modes` flexible modes and noisy data from a
//! perturbed copy of it (seeded, so the benchmark and `examples/modes_data.rs` are
//! reproducible).
//!
//! * mode k (k = 1..K): `ω_k` log-spaced over 10..10⁴ rad/s, `ζ_k` = 0.01..0.02, modal mass 1,
//!   input and output gains the mode shapes `√2·sin(kπx)` of a string at the actuator
//!   (`x = 0.137`) and the sensor (`x = 0.613`): a non-collocated pair, so the residues
//!   change sign from mode to mode;
//! * data: `points` log-spaced frequencies over 5..2·10⁴ rad/s of a perturbed plant (`ω_k`
//!   ±0.3 %, `ζ_k` ±10 %, gains ±3 %) plus complex noise uniform in a disk of 0.8 times the
//!   per-datum radius `0.02·|g(jω)|` written in the `noise_radius` column (Theorem 4).

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;

/// One mode: natural frequency, damping ratio, input and output gain.
#[derive(Debug, Clone, Copy)]
pub struct Mode {
    pub omega: f64,
    pub zeta: f64,
    pub b: f64,
    pub c: f64,
}

/// The nominal modes of the `k`-mode structure.
pub fn modes(k: usize) -> Vec<Mode> {
    let shape = |i: usize, x: f64| 2f64.sqrt() * (i as f64 * std::f64::consts::PI * x).sin();
    (1..=k)
        .map(|i| {
            let t = if k > 1 {
                (i - 1) as f64 / (k - 1) as f64
            } else {
                0.0
            };
            Mode {
                omega: 10.0 * 1000f64.powf(t),
                zeta: 0.01 + 0.01 * (0.5 + 0.5 * (3.1 * i as f64).sin()),
                b: shape(i, 0.137),
                c: shape(i, 0.613),
            }
        })
        .collect()
}

/// `Σ c_k b_k / (s² + 2ζ_kω_k s + ω_k²)` at `s = jω` (modal mass 1).
pub fn response(modes: &[Mode], omega: f64) -> Complex64 {
    let s = Complex64::new(0.0, omega);
    modes
        .iter()
        .map(|m| m.c * m.b / (s * s + 2.0 * m.zeta * m.omega * s + m.omega * m.omega))
        .sum()
}

/// The `[physical]` config (TOML) of the nominal modes, reading `data_file`.
pub fn config_toml(modes: &[Mode], data_file: &str) -> String {
    let mut s = format!(
        "# {} lightly damped modes (benches/support/modes.rs): the issue-21 large physical model.\n\
         name = \"{}-mode lightly damped structure\"\ndata = \"{data_file}\"\n\n[physical]\n",
        modes.len(),
        modes.len()
    );
    for m in modes {
        let _ = write!(
            s,
            "\n[[physical.mode]]\nomega_n = {:e}\nzeta = {:e}\ninput_gain = {:e}\noutput_gain = {:e}\n",
            m.omega, m.zeta, m.b, m.c
        );
    }
    s
}

/// The data file (CSV with a `noise_radius` column) of a perturbed copy of `modes`.
pub fn data_csv(modes: &[Mode], points: usize, seed: u64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let truth: Vec<Mode> = modes
        .iter()
        .map(|m| Mode {
            omega: m.omega * (1.0 + rng.gen_range(-0.003..=0.003)),
            zeta: m.zeta * (1.0 + rng.gen_range(-0.1..=0.1)),
            b: m.b * (1.0 + rng.gen_range(-0.03..=0.03)),
            c: m.c,
        })
        .collect();
    let mut s = format!(
        "# {} modes, perturbed (omega ±0.3 %, zeta ±10 %, gains ±3 %), noise in 0.8·noise_radius (seed {seed})\n\
         omega_rad_s,re_1_1,im_1_1,noise_radius\n",
        modes.len()
    );
    for i in 0..points {
        let w = 5.0 * 4000f64.powf(i as f64 / (points.max(2) - 1) as f64);
        let radius = 0.02 * response(modes, w).norm();
        let (u, th): (f64, f64) = (rng.gen(), rng.gen_range(0.0..std::f64::consts::TAU));
        let phi = response(&truth, w) + Complex64::from_polar(0.8 * radius * u.sqrt(), th);
        let _ = writeln!(s, "{w:.15e},{:.15e},{:.15e},{radius:.15e}", phi.re, phi.im);
    }
    s
}

/// Writes `dir/modesK.toml` and `dir/modesK.csv`; returns the config's path.
pub fn write(dir: &std::path::Path, k: usize, points: usize) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).expect("create the output directory");
    let m = modes(k);
    let data = format!("modes{k}.csv");
    std::fs::write(dir.join(&data), data_csv(&m, points, 2026)).expect("write the data");
    let cfg = dir.join(format!("modes{k}.toml"));
    std::fs::write(&cfg, config_toml(&m, &data)).expect("write the config");
    cfg
}

//! A roving-hammer test of a suspended free–free beam, generated (issue 33): one
//! accelerometer at the end `x = 0`, the hammer at nine points `x_j = j/8` (1 output × 9
//! inputs), accelerance.  Shared by `tests/diagnose/diagnose_free_beam.rs` and
//! `benches/diagnose.rs` (`#[path]`).
//!
//! * Euler–Bernoulli beam of unit length and mass `M`, free at both ends: bending modes
//!   `φ_r(x) = cosh βx + cos βx − σ_r (sinh βx + sin βx)`, `β_r L` = 4.7300, 7.8532, 10.9956,
//!   14.1372, 17.2788 (`σ_r = (cosh βL − cos βL)/(sinh βL − sin βL)`), frequencies in the
//!   ratios `(β_r L)²` from `F1` Hz; `∫φ_r² = 1`, so each modal mass is `M`; the rigid body
//!   (translation `1`, rotation `√12 (x − ½)`) gives the mass line
//!   `(1 + 12 (x_o − ½)(x_j − ½))/M`.
//! * Four modes in the band (ζ 1.0–1.5e-4, the metal specimen on soft supports of the issue)
//!   and a fifth above it (the upper residual a real beam has).
//! * Lines: 0.625 Hz from 20 Hz (1632 lines, to 1039.375 Hz) and, with `dense`, eight lines
//!   around each in-band peak at `ω_n(1 + ζu)`, `u` = −2.13 … 1.87 by 0.57 (four in the
//!   half-power band), as a zoom measurement around the peaks seen would give: 1664 lines.
//! * Noise uniform in the disk of radius `r = 0.01 |H| + 0.002` (the noise model `diagnose`
//!   states: `σ = r/√2`), drawn from a seeded ChaCha generator.

// Shared by a test and a bench, each using part of it.
#![allow(dead_code)]

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rshape::diagnose::Channels;
use rshape::model::physical::{Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec, Quantity};

/// First bending frequency, Hz.
pub const F1: f64 = 110.0;
/// Beam mass, kg.
pub const MASS: f64 = 1.2;
/// `β_r L` of the first five free–free bending modes.
pub const BETA_L: [f64; 5] = [
    4.730_040_7,
    7.853_204_6,
    10.995_607_8,
    14.137_165_5,
    17.278_759_6,
];
/// Damping ratio of each mode.
pub const ZETA: [f64; 5] = [1.0e-4, 1.2e-4, 1.35e-4, 1.5e-4, 1.5e-4];
/// Modes inside the band.
pub const IN_BAND: usize = 4;
/// Hammer points.
pub const N_IN: usize = 9;

/// The generated test: the true model, the data, and a start from the rigid body.
pub struct FreeBeam {
    /// The beam as generated (displacement model times `s²`).
    pub truth: PhysicalModel,
    /// The measured FRFs with their noise radii.
    pub data: Channels,
    /// The rigid body only, its mass line 5 % off: where discovery starts.
    pub rigid: PhysicalModel,
}

/// The bending mode shape `r` (0-based) at `x ∈ [0, 1]`, normalized to `∫φ² = 1`.
pub fn shape(r: usize, x: f64) -> f64 {
    let b = BETA_L[r];
    let s = (b.cosh() - b.cos()) / (b.sinh() - b.sin());
    let bx = b * x;
    bx.cosh() + bx.cos() - s * (bx.sinh() + bx.sin())
}

/// Natural frequency of bending mode `r`, rad/s.
pub fn omega_n(r: usize) -> f64 {
    std::f64::consts::TAU * F1 * (BETA_L[r] / BETA_L[0]).powi(2)
}

fn inputs() -> Vec<f64> {
    (0..N_IN).map(|j| j as f64 / (N_IN - 1) as f64).collect()
}

/// The beam model (`scale` multiplies the rigid body's mass line).
fn model(modes: usize, scale: f64) -> PhysicalModel {
    let x_o = 0.0;
    let xs = inputs();
    // Translation and rotation share the one output: one rigid body with the summed row.
    let rigid_row: Vec<f64> = xs
        .iter()
        .map(|x| scale * (1.0 + 12.0 * (x_o - 0.5) * (x - 0.5)))
        .collect();
    PhysicalModel {
        quantity: Quantity::Acceleration,
        rigid_body: vec![PoleAtZeroSpec {
            name: None,
            mass: MASS,
            input_gain: Gains::Vector(rigid_row),
            output_gain: Gains::Scalar(1.0),
            friction_pole: None,
        }],
        mode: (0..modes)
            .map(|r| ModeSpec {
                name: None,
                omega_n: omega_n(r),
                zeta: ZETA[r],
                mass: MASS,
                input_gain: Gains::Vector(xs.iter().map(|x| shape(r, *x)).collect()),
                output_gain: Gains::Scalar(shape(r, x_o)),
            })
            .collect(),
        inputs: Some(N_IN),
        outputs: Some(1),
        ..Default::default()
    }
}

/// The lines (rad/s, ascending): 0.625 Hz from 20 Hz, and with `dense` eight around each
/// in-band peak.
pub fn lines(dense: bool) -> Vec<f64> {
    let tau = std::f64::consts::TAU;
    let mut om: Vec<f64> = (0..1632).map(|k| tau * (20.0 + 0.625 * k as f64)).collect();
    if dense {
        for (r, z) in ZETA.iter().enumerate().take(IN_BAND) {
            om.extend((0..8).map(|k| omega_n(r) * (1.0 + z * (-2.13 + 0.57 * k as f64))));
        }
        om.sort_by(f64::total_cmp);
    }
    om
}

/// The generated test (see the module docs), noise from `seed`.
pub fn free_beam(seed: u64, dense: bool) -> FreeBeam {
    let truth = model(BETA_L.len(), 1.0);
    let omega = lines(dense);
    let entries: Vec<(usize, usize)> = (0..N_IN).map(|i| (0, i)).collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let clean: Vec<_> = omega.iter().map(|w| truth.eval(*w)).collect();
    let (mut g, mut radius) = (Vec::new(), Vec::new());
    for e in &entries {
        let (mut gc, mut rc) = (Vec::new(), Vec::new());
        for h in &clean {
            let v: Complex64 = h[*e];
            let r = 0.01 * v.norm() + 0.002;
            // Uniform in the disk: radius √u, angle uniform.
            let (u, a): (f64, f64) = (rng.gen(), rng.gen::<f64>() * std::f64::consts::TAU);
            gc.push(v + Complex64::from_polar(r * u.sqrt(), a));
            rc.push(r);
        }
        g.push(gc);
        radius.push(rc);
    }
    let data = Channels {
        path: "free_beam".into(),
        omega,
        entries,
        g,
        radius,
        radius_source: vec!["generated: 0.01 |H| + 0.002".into(); N_IN],
    };
    FreeBeam {
        truth,
        data,
        rigid: model(0, 1.05),
    }
}

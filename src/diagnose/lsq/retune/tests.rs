/// Fewer rows than parameters: no panic, the answer fits the data exactly (the system is
/// consistent), and it is the least-norm one in the equilibrated columns, checked by the
/// normal equations of the rows: `x̃ = Bᵀ(BBᵀ)⁻¹y`, `B = A·diag(1/‖aⱼ‖)`, `x = x̃/‖aⱼ‖`.
#[test]
fn qr_solve_with_more_parameters_than_rows() {
    use nalgebra::{DMatrix, DVector};
    let a = DMatrix::from_row_slice(2, 4, &[1.0, 2.0, 0.5, -1.0, 0.0, 3.0, 1.0, 2.0]);
    let y = DVector::from_row_slice(&[1.0, -2.0]);
    let x = super::qr_solve(a.clone(), y.clone());
    assert_eq!(x.len(), 4);
    assert!((&a * &x - &y).norm() < 1e-12, "{x}");
    let norms: Vec<f64> = a.column_iter().map(|c| c.norm()).collect();
    let b = DMatrix::from_fn(2, 4, |i, j| a[(i, j)] / norms[j]);
    let xt = b.transpose() * (&b * b.transpose()).try_inverse().unwrap() * &y;
    for j in 0..4 {
        assert!((x[j] - xt[j] / norms[j]).abs() < 1e-12, "{x} vs {xt}");
    }
}

use super::*;
use crate::model::physical::{EffectKind, Gains, ModeSpec, PoleAtZeroSpec};

fn two_mass(k: f64, w: f64, z: f64, rho: f64, tau: f64) -> PhysicalModel {
    let mut e = crate::model::physical::EffectSpec::new(EffectKind::Delay);
    e.tau_s = Some(tau);
    PhysicalModel {
        rigid_body: vec![PoleAtZeroSpec {
            friction_pole: None,
            name: None,
            mass: 2.0,
            input_gain: Gains::Scalar(2.0),
            output_gain: Gains::Scalar(k),
        }],
        mode: vec![ModeSpec {
            name: None,
            omega_n: w,
            zeta: z,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(rho),
        }],
        effect: vec![e],
        ..Default::default()
    }
}

/// The retune from the two-mass start (k 100, ω_n 480 rad/s, ζ 0.02, ρ 100, τ 100 µs) on
/// noise-free data of `truth` at 11…250 Hz in 1 Hz steps, radius 1 % of |G|.
fn retune_towards(truth: &PhysicalModel) -> NominalRefit {
    let start = two_mass(100.0, 480.0, 0.02, 100.0, 1.0e-4);
    let omega: Vec<f64> = (11..=250)
        .map(|f| std::f64::consts::TAU * f as f64)
        .collect();
    let g: Vec<Complex64> = omega.iter().map(|w| truth.eval_siso(*w)).collect();
    let radius: Vec<f64> = g.iter().map(|x| 0.01 * x.norm()).collect();
    refit_nominal(&start, &omega, &g, &radius)
}

#[test]
fn recovers_every_parameter_of_a_noise_free_two_mass() {
    let r = retune_towards(&two_mass(103.0, 490.0, 0.025, 95.0, 1.2e-4));
    assert_eq!(r.n_params, 5);
    assert!(r.v_before > 1e4, "{}", r.v_before);
    assert!(r.v_after < 1e-12, "{}", r.v_after);
    let m = &r.model;
    let rel = |a: f64, b: f64| ((a - b) / b).abs();
    assert!(rel(m.rigid_body[0].output_gain.to_vec(1)[0], 103.0) < 1e-6);
    assert!(rel(m.mode[0].omega_n, 490.0) < 1e-8);
    assert!(rel(m.mode[0].zeta, 0.025) < 1e-6);
    assert!(rel(m.mode[0].output_gain.to_vec(1)[0], 95.0) < 1e-6);
    assert!(rel(m.effect[0].tau_s.unwrap(), 1.2e-4) < 1e-6);
}

#[test]
fn bounds_hold_and_the_cost_never_rises() {
    // The true mode is 3× the start: ω_n may move only to 1.3×.
    let r = retune_towards(&two_mass(100.0, 1440.0, 0.02, 100.0, 1.0e-4));
    assert!(r.v_after <= r.v_before);
    assert!(r.model.mode[0].omega_n <= 480.0 * MODE_BOX * (1.0 + 1e-12));
    assert!(r.model.mode[0].zeta >= 1e-4 && r.model.mode[0].zeta <= 0.7);
}

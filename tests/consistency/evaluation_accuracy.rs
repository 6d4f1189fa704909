//! Frequency evaluation stays accurate for lightly damped, high-order models over
//! 0.001 to 1e5 rad/s: the expanded transfer function, its state-space realization and the
//! factored product agree.
use num_complex::Complex64;
use rshape::system::{logspace, StateSpace, TransferFunction};

fn lightly_damped(modes: &[f64], zeta: f64) -> (TransferFunction, Vec<Complex64>) {
    let mut poles = Vec::new();
    for w in modes {
        let re = -zeta * w;
        let im = w * (1.0 - zeta * zeta).sqrt();
        poles.push(Complex64::new(re, im));
        poles.push(Complex64::new(re, -im));
    }
    let gain: f64 = modes.iter().map(|w| w * w).product();
    (TransferFunction::from_zpk(&[], &poles, gain), poles)
}

#[test]
fn twelfth_order_lightly_damped_model_is_accurate_from_1e_3_to_1e5() {
    let modes = [0.5, 3.0, 40.0, 700.0, 9e3, 6e4];
    let (tf, poles) = lightly_damped(&modes, 0.005);
    let gain: f64 = modes.iter().map(|w| w * w).product();
    let ss = StateSpace::from_tf(&tf);
    let mut grid = logspace(1e-3, 1e5, 400);
    // Include each resonance peak, where cancellation in the expanded form is worst.
    grid.extend(
        modes
            .iter()
            .map(|w| w * (1.0 - 2.0 * 0.005f64.powi(2)).sqrt()),
    );
    for w in grid {
        let s = Complex64::new(0.0, w);
        let exact = poles
            .iter()
            .fold(Complex64::new(gain, 0.0), |acc, p| acc / (s - p));
        let rel_tf = (tf.freq(w) - exact).norm() / exact.norm();
        let rel_ss = (ss.freq(w).unwrap()[(0, 0)] - exact).norm() / exact.norm();
        assert!(rel_tf < 1e-10, "tf at {w}: {rel_tf:e}");
        assert!(rel_ss < 1e-10, "state space at {w}: {rel_ss:e}");
    }
}

#[test]
fn paper_robot_mode_factor_evaluates_exactly_at_high_frequency() {
    let m = TransferFunction::new(vec![4.0, 90.8, 20116.0], vec![1.0, 41.2, 40.2]);
    for w in [1e-3, 1.0, 70.9, 1e3, 1e5] {
        let s = Complex64::new(0.0, w);
        let direct = (4.0 * s * s + 90.8 * s + 20116.0) / (s * s + 41.2 * s + 40.2);
        assert!((m.freq(w) - direct).norm() / direct.norm() < 1e-14);
    }
}

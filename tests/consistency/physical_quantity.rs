//! `[physical] quantity`: the model is `s^k` times the displacement model (receptance,
//! mobility, accelerance).  The exact evaluation is checked against the closed form of every
//! term, and the rational export (the special factorization, with the powers of `s`
//! cancelled against the poles at zero) against the exact evaluation.

use num_complex::Complex64;
use rshape::model::physical::{PhysicalModel, Quantity};
use rshape::model::Config;
use std::path::Path;

/// Every kind of term: a rigid body with friction, one without, an integrator, a mode, a
/// feedthrough, and a first-order lag on the input.
fn text(quantity: &str) -> String {
    format!(
        r#"
[physical]
quantity = "{quantity}"
factor_pole = 10.0
feedthrough = 2.0e-4
[[physical.rigid_body]]
mass = 2.0
output_gain = -1.5
[[physical.rigid_body]]
output_gain = 0.3
friction_pole = 4.0
[[physical.integrator]]
output_gain = 0.7
[[physical.mode]]
omega_n = 484.0
zeta = 0.02
input_gain = 1.0
output_gain = 110.0
[[physical.effect]]
kind = "lag"
omega_c = 3000.0
"#
    )
}

fn closed_form(w: f64, k: u32) -> Complex64 {
    let s = Complex64::new(0.0, w);
    let core = -1.5 / (2.0 * s * s)
        + 0.3 / (s * (s + 4.0))
        + 0.7 / s
        + 110.0 / (s * s + 2.0 * 0.02 * 484.0 * s + 484.0 * 484.0)
        + 2.0e-4;
    core * s.powu(k) / (1.0 + s / 3000.0)
}

#[test]
fn the_model_is_s_to_the_k_times_the_displacement_model_and_exports_exactly() {
    for (name, k, q) in [
        ("displacement", 0, Quantity::Displacement),
        ("velocity", 1, Quantity::Velocity),
        ("acceleration", 2, Quantity::Acceleration),
    ] {
        let c = Config::parse(&text(name), Path::new("q.toml")).unwrap();
        let pm = c.physical.as_ref().unwrap();
        assert_eq!(pm.quantity, q);
        for w in [0.3, 3.0, 70.0, 484.0, 2000.0, 1e5] {
            let exact = pm.eval_siso(w);
            let want = closed_form(w, k);
            assert!(
                (exact - want).norm() <= 1e-12 * want.norm(),
                "{name} at {w}: {exact} vs {want}"
            );
            let export = c.factorization.plant(w).unwrap()[(0, 0)];
            assert!(
                (export - want).norm() <= 1e-9 * want.norm(),
                "{name} export at {w}: {export} vs {want}"
            );
        }
    }
}

#[test]
fn on_an_accelerance_the_rigid_body_is_the_mass_line() {
    let text = "[physical]\nquantity = \"acceleration\"\n[[physical.rigid_body]]\nmass = 0.8\n";
    let c = Config::parse(text, Path::new("a.toml")).unwrap();
    for w in [1e-3, 1.0, 1e4] {
        let g = c.physical.as_ref().unwrap().eval_siso(w);
        assert!((g - Complex64::new(1.25, 0.0)).norm() < 1e-12, "{g}");
        // The export is the constant 1/m too (M̃ = m, Ñ = 1: a unit, no zero at s = 0).
        let e = c.factorization.plant(w).unwrap()[(0, 0)];
        assert!((e - Complex64::new(1.25, 0.0)).norm() < 1e-12, "{e}");
    }
}

#[test]
fn a_bad_quantity_is_a_one_line_error_naming_the_key() {
    for bad in ["\"accel\"", "\"Acceleration\"", "2"] {
        let text =
            format!("[physical]\nquantity = {bad}\n[[physical.mode]]\nomega_n = 1\nzeta = 0.1\n");
        let e = Config::parse(&text, Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.toml") && e.contains("quantity"), "{e}");
        assert!(!e.contains('\n'), "{e}");
        if bad.starts_with('"') {
            assert!(e.contains("\"acceleration\" (accelerance)"), "{e}");
        }
    }
}

#[test]
fn the_quantity_is_written_back_and_the_default_is_not() {
    let c = Config::parse(&text("velocity"), Path::new("q.toml")).unwrap();
    let t = toml::to_string(c.physical.as_ref().unwrap()).unwrap();
    assert!(t.contains("quantity = \"velocity\""), "{t}");
    let back: PhysicalModel = toml::from_str(&t).unwrap();
    assert_eq!(back.quantity, Quantity::Velocity);
    let d = toml::to_string(&PhysicalModel::default()).unwrap();
    assert!(!d.contains("quantity"), "{d}");
}

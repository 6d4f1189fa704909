//! The physical model layer: the robot of Boulet & Francis 1998 written physically gives the
//! same frequency response as its factor form (eqs. (19)–(21)), and the exported special
//! factorization reproduces the exact evaluation (rational effects exactly, delays to the
//! Padé accuracy).

use num_complex::Complex64;
use rshape::model::physical::{pade, EffectKind, EffectSpec};
use rshape::model::Config;
use rshape::system::logspace;
use std::path::Path;

const ROBOT_FACTORS: &str = r#"
[model]
factorization = "special"
m_diag = [
  { num = [4.0, 4.1, 105.0],    den = [1, 41.2, 40.2] },
  { num = [4.0, 36.1, 8228.6],  den = [1, 41.2, 40.2] },
  { num = [4.0, 16.1, 1634.0],  den = [1, 41.2, 40.2] },
  { num = [4.0, 90.8, 20116.0], den = [1, 41.2, 40.2] },
  { num = [4.0, 22.8, 1310.3],  den = [1, 41.2, 40.2] },
]
n = [[{ num = [1800], den = [1, 41.2, 40.2] }],
     [{ num = [-1800], den = [1, 41.2, 40.2] }],
     [{ num = [-1800], den = [1, 41.2, 40.2] }],
     [{ num = [1800], den = [1, 41.2, 40.2] }],
     [{ num = [1800], den = [1, 41.2, 40.2] }]]
c = [[-3.30e-3, 3.40e-3, -3.39e-3, 0.0, -0.01e-3]]
"#;

fn robot_physical() -> Config {
    Config::load(Path::new("configs/robot_physical.toml")).expect("robot_physical.toml loads")
}

#[test]
fn robot_physical_equals_factor_form() {
    let fact = Config::parse(ROBOT_FACTORS, Path::new("robot.toml")).unwrap();
    let phys = robot_physical();
    let pm = phys.physical.as_ref().expect("physical model");
    let mut worst: f64 = 0.0;
    for w in logspace(0.1, 1000.0, 400) {
        let g_f = fact.factorization.plant(w).unwrap()[(0, 0)];
        let g_p = pm.eval_siso(w);
        let g_x = phys.factorization.plant(w).unwrap()[(0, 0)];
        worst = worst
            .max((g_p - g_f).norm() / g_f.norm())
            .max((g_x - g_f).norm() / g_f.norm());
    }
    assert!(worst < 1e-10, "relative difference {worst:e}");
    // The exported factors are the paper's factors (same q(s)), entry by entry.
    for w in [1.0, 10.0, 64.0] {
        let a = fact.factorization.at(w);
        let b = phys.factorization.at(w);
        assert!((a.m.clone() - b.m.clone()).norm() < 1e-10 * a.m.norm());
        assert!((a.n.clone() - b.n.clone()).norm() < 1e-10 * a.n.norm());
    }
}

#[test]
fn effects_evaluate_exactly_and_export_rationally() {
    let mut pm = robot_physical().physical.unwrap();
    let mut delay = EffectSpec::new(EffectKind::Delay);
    delay.tau_s = Some(0.012);
    let mut lag = EffectSpec::new(EffectKind::Lag);
    lag.omega_c = Some(30.0);
    let mut nmp = EffectSpec::new(EffectKind::NmpZero);
    nmp.z = Some(40.0);
    let base = pm.clone();
    pm.effect = vec![delay, lag, nmp];
    pm.validate().unwrap();
    let f = pm.to_factorization().unwrap();
    for w in [1.0, 5.0, 20.0, 64.0] {
        let s = Complex64::new(0.0, w);
        let expect = base.eval_siso(w) * (-s * 0.012).exp() / (1.0 + s / 30.0) * (1.0 - s / 40.0)
            / (1.0 + s / 40.0);
        let exact = pm.eval_siso(w);
        assert!(
            (exact - expect).norm() <= 1e-12 * expect.norm(),
            "exact at {w}"
        );
        // Padé(6) of a 12 ms delay: ωτ ≤ 0.77 here, error below 1e-9 relative.
        let export = f.plant(w).unwrap()[(0, 0)];
        assert!(
            (export - exact).norm() <= 1e-9 * exact.norm(),
            "export at {w}"
        );
    }
    let p = pade(0.012, 6);
    assert!(p.is_unit() || p.zeros().iter().all(|z| z.re > 0.0));
}

#[test]
fn rigid_body_exports_a_coprime_pair() {
    let text = r#"
[physical]
factor_pole = 10.0
[[physical.rigid_body]]
output_gain = 100.0
[[physical.mode]]
omega_n = 484.0
zeta = 0.02
input_gain = 1.0
output_gain = 110.0
[[physical.effect]]
kind = "zoh"
t_s = 0.0004
"#;
    let c = Config::parse(text, Path::new("twomass.toml")).unwrap();
    let pm = c.physical.as_ref().unwrap();
    for w in [70.0, 300.0, 484.0, 1500.0] {
        let s = Complex64::new(0.0, w);
        let core = 100.0 / (s * s) + 110.0 / (s * s + 2.0 * 0.02 * 484.0 * s + 484.0 * 484.0);
        let x = w * 0.0004 / 2.0;
        let zoh = (-s * 0.0002).exp() * (x.sin() / x);
        let exact = pm.eval_siso(w);
        assert!((exact - core * zoh).norm() <= 1e-12 * exact.norm());
        // The export keeps the ZOH's mean delay (Padé) and drops its sinc droop.
        let export = c.factorization.plant(w).unwrap()[(0, 0)];
        assert!((export - core * (-s * 0.0002).exp()).norm() <= 1e-9 * exact.norm());
    }
    // M̃ of the rigid body is s²/(s+10)²: in RH∞, zero at s = 0.
    assert!(c.factorization.m.entry(1, 1).freq(0.0).norm() < 1e-15);
}

#[test]
fn bad_physical_configs_name_the_key() {
    let bad = [
        ("[physical]\n[[physical.mode]]\nomega_n = -1\nzeta = 0.1\n", "omega_n"),
        ("[physical]\n[[physical.mode]]\nomega_n = 1\nzeta = 0.1\n[[physical.effect]]\nkind = \"delay\"\n", "tau_s"),
        ("[physical]\n[[physical.mode]]\nomega_n = 1\nzeta = 0.1\nfoo = 1\n", "foo"),
        ("[physical]\n", "no dynamics"),
    ];
    for (text, key) in bad {
        let e = Config::parse(text, Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(key) && e.contains("x.toml"), "{e}");
    }
    // physical and model together is an error
    let both = format!("{ROBOT_FACTORS}\n[physical]\n[[physical.mode]]\nomega_n = 1\nzeta = 0.1\n");
    assert!(Config::parse(&both, Path::new("x.toml")).is_err());
}

use super::*;
use crate::diagnose::lsq::retune::solve_linear_res;
use crate::diagnose::lsq::slots::{get_nl, slots};
use crate::model::physical::{
    EffectKind, EffectSpec, Feedthrough, Gains, ModeSpec, PoleAtZeroSpec,
};

fn mode(w: f64, z: f64, b: [f64; 3]) -> ModeSpec {
    ModeSpec {
        name: None,
        omega_n: w,
        zeta: z,
        mass: 1.3,
        input_gain: Gains::Vector(b.to_vec()),
        output_gain: Gains::Scalar(50.0),
    }
}

/// One output, three inputs: a rigid body with friction, two light modes, a
/// feedthrough, an input delay and a lag on input 2.
pub(in crate::diagnose::lsq) fn model(scale: f64) -> PhysicalModel {
    let mut delay = EffectSpec::new(EffectKind::Delay);
    delay.tau_s = Some(1.0e-4 * scale);
    let mut lag = EffectSpec::new(EffectKind::Lag);
    lag.omega_c = Some(2500.0 * scale);
    lag.channel = Some(2);
    PhysicalModel {
        rigid_body: vec![PoleAtZeroSpec {
            friction_pole: Some(20.0 * scale),
            name: None,
            mass: 2.0,
            input_gain: Gains::Vector(vec![1.0, 0.7, -0.4]),
            output_gain: Gains::Scalar(100.0),
        }],
        mode: vec![
            mode(300.0 * scale, 0.01, [1.0, -0.5 * scale, 0.8]),
            mode(950.0 / scale, 0.003 * scale, [1.0, 0.9, -0.3 / scale]),
        ],
        feedthrough: Some(Feedthrough::Matrix(vec![vec![1e-3, 2e-3, -1e-3]])),
        effect: vec![delay, lag],
        ..Default::default()
    }
}

pub(in crate::diagnose::lsq) fn channels(truth: &PhysicalModel) -> Channels {
    let omega = crate::system::logspace(100.0, 3000.0, 150);
    Channels::of_model(
        truth,
        omega,
        vec![(0, 0), (0, 1), (0, 2)],
        1.0,
        (0.01, 1e-4),
    )
}

/// Asserts that the variable-projection Jacobian of `start` on `data` matches fourth-order
/// central differences of the residual with the linear slots solved by the refit's own
/// least squares (an independent route: no derivative formula, one QR per point).
/// Returns the nonlinear slots.
fn assert_jacobian_matches(start: &PhysicalModel, data: &Channels) -> Vec<Nl> {
    let (lin, nl) = slots(start, data);
    let mask: Vec<usize> = (0..data.len()).collect();
    let th: Vec<f64> = nl.iter().map(|s| get_nl(start, *s)).collect();
    let typ: Vec<f64> = th.iter().map(|x| x.abs().max(1e-3)).collect();
    let vp = VarPro {
        start,
        nl: &nl,
        lin: &lin,
        data,
        mask: &mask,
        typ: &typ,
    };
    let resid = |t: &[f64]| {
        let mut m = vp.model(t);
        solve_linear_res(&mut m, &lin, data, &mask)
    };
    let r_norm = resid(&th).norm();
    let mut jac = DMatrix::zeros(2 * data.n_ch() * data.len(), nl.len());
    assert!(vp.jacobian(&th, &mut jac));
    for k in 0..nl.len() {
        // Fourth-order central differences (truncation ~(h/ζ)⁴, rounding ~ε‖r‖/h).
        let h = 1e-5 * th[k].abs().max(typ[k]);
        let at = |d: f64| {
            let mut t = th.clone();
            t[k] += d;
            resid(&t)
        };
        let cd = (8.0 * (at(h) - at(-h)) - (at(2.0 * h) - at(-2.0 * h))) / (12.0 * h);
        let err = (jac.column(k) - &cd).norm();
        assert!(
            err <= 1e-6 * cd.norm() + 1e-9 * r_norm,
            "{:?}: |J − CD| = {err:e}, |CD| = {:e}, |r| = {r_norm:e}",
            nl[k],
            cd.norm()
        );
    }
    nl
}

/// One output, three inputs: every kind of nonlinear slot in one block.
#[test]
fn the_jacobian_matches_central_differences_of_the_projected_residual() {
    let nl = assert_jacobian_matches(&model(1.0), &channels(&model(1.07)));
    assert!(nl.len() >= 10, "{nl:?}");
}

/// The normal equations formed without `J` against `JᵀJ` and `Jᵀr` of the Jacobian
/// itself (one output, three inputs: every kind of nonlinear slot, input gains on one
/// channel each), at a point off the optimum (`r` not small).
#[test]
fn the_normal_equations_match_those_of_the_jacobian() {
    let (start, data) = (model(1.0), channels(&model(1.07)));
    let (lin, nl) = slots(&start, &data);
    let mask: Vec<usize> = (0..data.len()).collect();
    let th: Vec<f64> = nl.iter().map(|s| get_nl(&start, *s)).collect();
    let typ: Vec<f64> = th.iter().map(|x| x.abs().max(1e-3)).collect();
    let vp = VarPro {
        start: &start,
        nl: &nl,
        lin: &lin,
        data: &data,
        mask: &mask,
        typ: &typ,
    };
    let mut m = vp.model(&th);
    let r = solve_linear_res(&mut m, &lin, &data, &mask);
    assert!(r.norm() > 1.0, "{}", r.norm());
    let mut jac = DMatrix::zeros(r.len(), nl.len());
    assert!(vp.jacobian(&th, &mut jac));
    let (jtj, g) = vp.normal(&th, r.as_slice()).expect("one block");
    let (jtj0, g0) = (jac.transpose() * &jac, jac.transpose() * &r);
    assert!(
        (&jtj - &jtj0).norm() <= 1e-10 * jtj0.norm(),
        "{:e}",
        (&jtj - &jtj0).norm() / jtj0.norm()
    );
    assert!(
        (&g - &g0).norm() <= 1e-9 * g0.norm(),
        "{:e}",
        (&g - &g0).norm() / g0.norm()
    );
    // A wrong residual length declines.
    assert!(vp.normal(&th, &r.as_slice()[1..]).is_none());
}

/// Two copies of one mode make the design rank-deficient: the Jacobian declines (the
/// refit then differentiates the whole residual).
#[test]
fn a_rank_deficient_design_declines() {
    let mut start = model(1.0);
    start.mode[1] = start.mode[0].clone();
    start.effect.clear();
    let data = channels(&model(1.0));
    let (lin, nl) = slots(&start, &data);
    let mask: Vec<usize> = (0..data.len()).collect();
    let th: Vec<f64> = nl.iter().map(|s| get_nl(&start, *s)).collect();
    let typ = vec![1.0; nl.len()];
    let vp = VarPro {
        start: &start,
        nl: &nl,
        lin: &lin,
        data: &data,
        mask: &mask,
        typ: &typ,
    };
    let mut jac = DMatrix::zeros(2 * 3 * data.len(), nl.len());
    assert!(!vp.jacobian(&th, &mut jac));
}

/// Two outputs, one input: one least-squares block per output (the gather–scatter
/// path), against fourth-order central differences.
#[test]
fn the_jacobian_matches_with_one_block_per_output() {
    let two = |scale: f64| {
        let mut delay = EffectSpec::new(EffectKind::Delay);
        delay.tau_s = Some(1.0e-4 * scale);
        let m = |w: f64, z: f64, c: [f64; 2]| ModeSpec {
            name: None,
            omega_n: w,
            zeta: z,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Vector(c.to_vec()),
        };
        PhysicalModel {
            rigid_body: vec![PoleAtZeroSpec {
                friction_pole: None,
                name: None,
                mass: 2.0,
                input_gain: Gains::Scalar(1.0),
                output_gain: Gains::Vector(vec![100.0, -60.0]),
            }],
            mode: vec![
                m(400.0 * scale, 0.02, [40.0, -30.0]),
                m(1300.0 / scale, 0.005 * scale, [20.0, 25.0]),
            ],
            feedthrough: Some(Feedthrough::Matrix(vec![vec![1e-3], vec![-2e-3]])),
            effect: vec![delay],
            ..Default::default()
        }
    };
    let truth = two(1.05);
    let omega = crate::system::logspace(100.0, 3000.0, 120);
    let data = Channels::of_model(&truth, omega, vec![(0, 0), (1, 0)], 1.0, (0.01, 1e-4));
    let start = two(1.0);
    assert_eq!(blocks(&slots(&start, &data).0, &data).len(), 2);
    assert_jacobian_matches(&start, &data);
}

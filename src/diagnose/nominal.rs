//! Joint refit of a SISO physical model's own parameters (effects.md step 5: "greedy forward
//! selection with a joint refit of every accepted parameter").
//!
//! Free parameters, in internal units, each in a box (bounded Levenberg–Marquardt):
//!
//! | term | parameters | box |
//! |---|---|---|
//! | rigid body, integrator | residue `ρ = c·b/m` | `[ρ₀/3, 3ρ₀]` |
//! | rigid body with friction | also `ln p` | `p₀/10 … 10 p₀` |
//! | mode | `ln ω_n`, `ln ζ`, residue `ρ` | `ω_n₀/1.5 … 1.5 ω_n₀`, `ζ ∈ [1e-4, 0.7]`, `[ρ₀/3, 3ρ₀]` |
//! | feedthrough | `D` | free |
//! | delay | `τ` | `[0, 10 τ₀ + 1/ω_max]` |
//! | lag, NMP zero, ZOH | `ln ω_c`, `ln z`, `ln T` | a decade either side |
//!
//! A gain or sign effect is not refit (a gain is not identifiable beside the residues).  The
//! residue is written back as `output_gain = ρ·m/b` (input gain and mass kept).  The cost is
//! the diagnose cost `V = Σ|G_d − G(θ)|²/σ_k²`, `σ_k = r_k/√2`; the refit never raises it.

use super::fit::lm_box;
use crate::model::physical::{EffectKind, Feedthrough, Gains, PhysicalModel};
use num_complex::Complex64;

#[derive(Debug, Clone, Copy)]
enum Slot {
    RigidRho(usize),
    RigidPole(usize),
    IntRho(usize),
    ModeW(usize),
    ModeZ(usize),
    ModeRho(usize),
    Feed,
    Delay(usize),
    LogEffect(usize),
}

fn rho_of(c: &Gains, b: &Gains, m: f64) -> f64 {
    c.to_vec(1)[0] * b.to_vec(1)[0] / m
}

fn slots(m: &PhysicalModel) -> Vec<Slot> {
    let mut v = Vec::new();
    for (i, r) in m.rigid_body.iter().enumerate() {
        if rho_of(&r.output_gain, &r.input_gain, r.mass) != 0.0 {
            v.push(Slot::RigidRho(i));
        }
        if r.friction_pole.is_some_and(|p| p > 0.0) {
            v.push(Slot::RigidPole(i));
        }
    }
    for (i, r) in m.integrator.iter().enumerate() {
        if rho_of(&r.output_gain, &r.input_gain, r.mass) != 0.0 {
            v.push(Slot::IntRho(i));
        }
    }
    for (i, md) in m.mode.iter().enumerate() {
        v.push(Slot::ModeW(i));
        v.push(Slot::ModeZ(i));
        if rho_of(&md.output_gain, &md.input_gain, md.mass) != 0.0 {
            v.push(Slot::ModeRho(i));
        }
    }
    if matches!(m.feedthrough, Some(Feedthrough::Scalar(_))) {
        v.push(Slot::Feed);
    }
    for (i, e) in m.effect.iter().enumerate() {
        match e.kind {
            EffectKind::Delay if e.tau_s.is_some() => v.push(Slot::Delay(i)),
            EffectKind::Lag if e.omega_c.is_some_and(|x| x > 0.0) => v.push(Slot::LogEffect(i)),
            EffectKind::NmpZero if e.z.is_some_and(|x| x > 0.0) => v.push(Slot::LogEffect(i)),
            EffectKind::Zoh if e.t_s.is_some_and(|x| x > 0.0) => v.push(Slot::LogEffect(i)),
            _ => {}
        }
    }
    v
}

fn get(m: &PhysicalModel, s: Slot) -> f64 {
    match s {
        Slot::RigidRho(i) => {
            let r = &m.rigid_body[i];
            rho_of(&r.output_gain, &r.input_gain, r.mass)
        }
        Slot::RigidPole(i) => m.rigid_body[i].friction_pole.unwrap_or(1.0).ln(),
        Slot::IntRho(i) => {
            let r = &m.integrator[i];
            rho_of(&r.output_gain, &r.input_gain, r.mass)
        }
        Slot::ModeW(i) => m.mode[i].omega_n.ln(),
        Slot::ModeZ(i) => m.mode[i].zeta.ln(),
        Slot::ModeRho(i) => {
            let r = &m.mode[i];
            rho_of(&r.output_gain, &r.input_gain, r.mass)
        }
        Slot::Feed => match m.feedthrough {
            Some(Feedthrough::Scalar(d)) => d,
            _ => 0.0,
        },
        Slot::Delay(i) => m.effect[i].tau_s.unwrap_or(0.0),
        Slot::LogEffect(i) => {
            let e = &m.effect[i];
            match e.kind {
                EffectKind::Lag => e.omega_c,
                EffectKind::NmpZero => e.z,
                _ => e.t_s,
            }
            .unwrap_or(1.0)
            .ln()
        }
    }
}

fn set(m: &mut PhysicalModel, s: Slot, x: f64) {
    let gain = |b: &Gains, mass: f64| Gains::Scalar(x * mass / b.to_vec(1)[0]);
    match s {
        Slot::RigidRho(i) => {
            let r = &mut m.rigid_body[i];
            r.output_gain = gain(&r.input_gain, r.mass);
        }
        Slot::RigidPole(i) => m.rigid_body[i].friction_pole = Some(x.exp()),
        Slot::IntRho(i) => {
            let r = &mut m.integrator[i];
            r.output_gain = gain(&r.input_gain, r.mass);
        }
        Slot::ModeW(i) => m.mode[i].omega_n = x.exp(),
        Slot::ModeZ(i) => m.mode[i].zeta = x.exp(),
        Slot::ModeRho(i) => {
            let r = &mut m.mode[i];
            r.output_gain = gain(&r.input_gain, r.mass);
        }
        Slot::Feed => m.feedthrough = Some(Feedthrough::Scalar(x)),
        Slot::Delay(i) => m.effect[i].tau_s = Some(x),
        Slot::LogEffect(i) => {
            let e = &mut m.effect[i];
            let v = Some(x.exp());
            match e.kind {
                EffectKind::Lag => e.omega_c = v,
                EffectKind::NmpZero => e.z = v,
                _ => e.t_s = v,
            }
        }
    }
}

/// `(lo, hi, typ)` of a slot at its start value `x0`.
fn bounds(s: Slot, x0: f64, omega_max: f64) -> (f64, f64, f64) {
    let rho = |x: f64| {
        let (a, b) = (x / 3.0, 3.0 * x);
        (a.min(b), a.max(b), x.abs().max(1e-300))
    };
    match s {
        Slot::RigidRho(_) | Slot::IntRho(_) | Slot::ModeRho(_) => rho(x0),
        Slot::ModeW(_) => (x0 - 1.5f64.ln(), x0 + 1.5f64.ln(), 1.0),
        Slot::ModeZ(_) => (1e-4f64.ln(), 0.7f64.ln(), 1.0),
        Slot::RigidPole(_) | Slot::LogEffect(_) => (x0 - 10f64.ln(), x0 + 10f64.ln(), 1.0),
        Slot::Feed => (f64::NEG_INFINITY, f64::INFINITY, x0.abs().max(1e-12)),
        Slot::Delay(_) => (0.0, 10.0 * x0.abs() + 1.0 / omega_max, 1.0 / omega_max),
    }
}

/// The result of a nominal refit.
#[derive(Debug, Clone)]
pub struct NominalRefit {
    /// The refit model.
    pub model: PhysicalModel,
    /// Number of refit parameters.
    pub n_params: usize,
    /// Cost before.
    pub v_before: f64,
    /// Cost after (≤ `v_before`).
    pub v_after: f64,
}

/// Refits every parameter of the SISO model `m` jointly on the data `(omega, g)` with noise
/// radii `radius` (see the module documentation).
pub fn refit_nominal(
    m: &PhysicalModel,
    omega: &[f64],
    g: &[Complex64],
    radius: &[f64],
) -> NominalRefit {
    let sl = slots(m);
    let inv_sigma: Vec<f64> = radius
        .iter()
        .map(|r| std::f64::consts::SQRT_2 / r)
        .collect();
    let omega_max = omega.iter().cloned().fold(0.0, f64::max).max(1e-300);
    let theta0: Vec<f64> = sl.iter().map(|s| get(m, *s)).collect();
    let mut lo = Vec::new();
    let mut hi = Vec::new();
    let mut typ = Vec::new();
    for (s, x) in sl.iter().zip(&theta0) {
        let (a, b, t) = bounds(*s, *x, omega_max);
        lo.push(a);
        hi.push(b);
        typ.push(t);
    }
    let model_at = |th: &[f64]| {
        let mut mm = m.clone();
        for (s, x) in sl.iter().zip(th) {
            set(&mut mm, *s, *x);
        }
        mm
    };
    let resid = |th: &[f64], out: &mut Vec<f64>| {
        let mm = model_at(th);
        out.clear();
        for k in 0..omega.len() {
            let e = (g[k] - mm.eval_siso(omega[k])) * inv_sigma[k];
            out.push(e.re);
            out.push(e.im);
        }
    };
    let mut r0 = Vec::new();
    resid(&theta0, &mut r0);
    let v_before: f64 = r0.iter().map(|x| x * x).sum();
    if sl.is_empty() {
        return NominalRefit {
            model: m.clone(),
            n_params: 0,
            v_before,
            v_after: v_before,
        };
    }
    let res = lm_box(resid, &theta0, &typ, &lo, &hi, 200);
    if res.v.is_finite() && res.v < v_before {
        NominalRefit {
            model: model_at(&res.theta),
            n_params: sl.len(),
            v_before,
            v_after: res.v,
        }
    } else {
        NominalRefit {
            model: m.clone(),
            n_params: sl.len(),
            v_before,
            v_after: v_before,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::physical::{ModeSpec, PoleAtZeroSpec};

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

    #[test]
    fn recovers_every_parameter_of_a_noise_free_two_mass() {
        let truth = two_mass(103.0, 490.0, 0.025, 95.0, 1.2e-4);
        let start = two_mass(100.0, 480.0, 0.02, 100.0, 1.0e-4);
        let omega: Vec<f64> = (11..=250)
            .map(|f| std::f64::consts::TAU * f as f64)
            .collect();
        let g: Vec<Complex64> = omega.iter().map(|w| truth.eval_siso(*w)).collect();
        let radius: Vec<f64> = g.iter().map(|x| 0.01 * x.norm()).collect();
        let r = refit_nominal(&start, &omega, &g, &radius);
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
        // The true mode is 2.5× the start: ω_n may move only to 1.5×.
        let truth = two_mass(100.0, 1200.0, 0.02, 100.0, 1.0e-4);
        let start = two_mass(100.0, 480.0, 0.02, 100.0, 1.0e-4);
        let omega: Vec<f64> = (11..=250)
            .map(|f| std::f64::consts::TAU * f as f64)
            .collect();
        let g: Vec<Complex64> = omega.iter().map(|w| truth.eval_siso(*w)).collect();
        let radius: Vec<f64> = g.iter().map(|x| 0.01 * x.norm()).collect();
        let r = refit_nominal(&start, &omega, &g, &radius);
        assert!(r.v_after <= r.v_before);
        assert!(r.model.mode[0].omega_n <= 480.0 * 1.5 * (1.0 + 1e-12));
        assert!(r.model.mode[0].zeta >= 1e-4 && r.model.mode[0].zeta <= 0.7);
    }
}

//! Plain-plant configs in `diagnose`: a SISO transfer function `P(s)` (a `[plant]` given as
//! `tf`, or the nominal `P̂ = N̂·D̂⁻¹` of `[closed_loop]`) is converted to `[physical]` when it
//! is a sum of physical terms, so effects can be added to it; otherwise the message says why.
//!
//! After cancelling common roots of numerator and denominator, the poles of `P` must be
//! * at `s = 0`, at most twice: a rigid body `c/s²` and an integrator `c/s`;
//! * one real pole `−p` together with a pole at 0: a rigid body with viscous friction
//!   `c/(s(s + p))`;
//! * damped complex pairs: modes `c/(s² + 2ζω_n s + ω_n²)` (a constant residue);
//!
//! plus a feedthrough when `P` is biproper. The residues are the weighted least-squares
//! solution on a log grid around the poles, and the conversion is accepted only when the
//! converted model reproduces `P(jω)` to `1e-7` relative on a second grid (a pair whose
//! residue has an `s` term, `(a s + b)/d(s)`, is not a physical mode and fails there).

use crate::model::config::TfEntry;
use crate::model::physical::{Feedthrough, Gains, ModeSpec, PhysicalModel, PoleAtZeroSpec};
use crate::model::Config;
use crate::system::{Polynomial, TransferFunction};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Relative accuracy the converted model must reach on the check grid.
pub const CONVERSION_TOL: f64 = 1e-7;

/// `P = num/den` with the common roots of `num` and `den` cancelled.
fn cancel(g: &TransferFunction) -> Result<(f64, Vec<Complex64>, Vec<Complex64>), String> {
    let (nr, dr) = (g.num.roots(), g.den.roots());
    if !nr.converged || !dr.converged {
        return Err("the roots of the plant did not converge".into());
    }
    let k = g.num.leading() / g.den.leading();
    let mut zeros = if g.num.is_zero() { vec![] } else { nr.roots };
    let mut poles = dr.roots;
    let mut i = 0;
    while i < zeros.len() {
        let z = zeros[i];
        let tol = 1e-6 * z.norm().max(1.0);
        if let Some(j) = poles.iter().position(|p| (p - z).norm() <= tol) {
            poles.remove(j);
            zeros.remove(i);
        } else {
            i += 1;
        }
    }
    Ok((k, zeros, poles))
}

/// One basis term of the converted model.
#[derive(Debug, Clone, Copy)]
enum Term {
    Rigid,
    Friction(f64),
    Integrator,
    Mode(f64, f64),
    Feed,
}

impl Term {
    fn at(&self, s: Complex64) -> Complex64 {
        match *self {
            Term::Rigid => (s * s).inv(),
            Term::Friction(p) => (s * (s + p)).inv(),
            Term::Integrator => s.inv(),
            Term::Mode(w, z) => (s * s + 2.0 * z * w * s + w * w).inv(),
            Term::Feed => Complex64::new(1.0, 0.0),
        }
    }
}

/// The `[physical]` form of a SISO rational plant, or why there is none.
pub fn physical_from_tf(g: &TransferFunction) -> Result<PhysicalModel, String> {
    if g.num.degree() > g.den.degree() && !g.num.is_zero() {
        return Err("the plant is improper (more zeros than poles)".into());
    }
    let (k, zeros, poles) = cancel(g)?;
    let scale = poles.iter().map(|p| p.norm()).fold(1.0, f64::max);
    let tol = 1e-7 * scale;
    let mut terms = Vec::new();
    let n0 = poles.iter().filter(|p| p.norm() <= tol).count();
    let reals: Vec<f64> = poles
        .iter()
        .filter(|p| p.norm() > tol && p.im.abs() <= tol)
        .map(|p| p.re)
        .collect();
    if n0 > 2 {
        return Err(format!(
            "{n0} poles at s = 0: at most a rigid body (two) has a [physical] term"
        ));
    }
    if let Some(r) = reals.iter().find(|r| **r > 0.0) {
        return Err(format!("an unstable real pole at s = {r}"));
    }
    match (n0, reals.len()) {
        (_, 0) => {}
        (1 | 2, 1) => terms.push(Term::Friction(-reals[0])),
        _ => {
            return Err(format!(
                "a real pole at s = {} (a lag or an overdamped mode) has no [physical] term; write it as a [[physical.effect]] kind = \"lag\"",
                reals[0]
            ))
        }
    }
    if n0 == 2 {
        terms.push(Term::Rigid);
    }
    if n0 >= 1 {
        terms.push(Term::Integrator);
    }
    for p in poles.iter().filter(|p| p.im > tol) {
        if p.re >= 0.0 {
            return Err(format!("an undamped or unstable pole pair at s = {p}"));
        }
        terms.push(Term::Mode(p.norm(), -p.re / p.norm()));
    }
    if zeros.len() == poles.len() {
        terms.push(Term::Feed);
    }
    if terms.is_empty() {
        return Err("the plant has no dynamics".into());
    }
    let num = Polynomial::from_roots(&zeros).scale(k);
    let den = Polynomial::from_roots(&poles);
    let reduced = TransferFunction { num, den };
    // Log grids around the poles: fit on one, check on the other (offset by half a step).
    let (lo, hi) = (
        poles
            .iter()
            .map(|p| p.norm())
            .filter(|x| *x > tol)
            .fold(scale, f64::min)
            / 30.0,
        scale * 30.0,
    );
    let grid = |off: f64| -> Vec<f64> {
        (0..200)
            .map(|i| lo * (hi / lo).powf((i as f64 + off) / 199.5))
            .collect()
    };
    let (fit, check) = (grid(0.0), grid(0.5));
    let n = terms.len();
    let mut a = DMatrix::<f64>::zeros(2 * fit.len(), n);
    let mut y = DVector::<f64>::zeros(2 * fit.len());
    for (r, w) in fit.iter().enumerate() {
        let s = Complex64::new(0.0, *w);
        let gv = reduced.eval(s);
        let wt = 1.0 / gv.norm().max(f64::MIN_POSITIVE);
        for (j, t) in terms.iter().enumerate() {
            let v = t.at(s) * wt;
            a[(2 * r, j)] = v.re;
            a[(2 * r + 1, j)] = v.im;
        }
        y[2 * r] = gv.re * wt;
        y[2 * r + 1] = gv.im * wt;
    }
    let col = crate::system::linalg::equilibrate_columns(&mut a);
    let x = a
        .svd(true, true)
        .solve(&y, 1e-13)
        .map_err(|e| format!("the residues could not be solved: {e}"))?;
    let c: Vec<f64> = (0..n).map(|j| x[j] / col[j]).collect();
    let eval = |s: Complex64| -> Complex64 { terms.iter().zip(&c).map(|(t, c)| t.at(s) * c).sum() };
    let worst = check
        .iter()
        .map(|w| {
            let s = Complex64::new(0.0, *w);
            let gv = reduced.eval(s);
            (eval(s) - gv).norm() / gv.norm()
        })
        .fold(
            0.0,
            |a: f64, x| if x.is_nan() { f64::INFINITY } else { a.max(x) },
        );
    if worst > CONVERSION_TOL {
        return Err(format!(
            "it is not a sum of physical terms (rigid body, integrator, friction, modes c/(s² + 2ζω_n s + ω_n²), feedthrough): the best such sum is off by {:.1e} relative (a mode whose residue has an s term, or zeros that no modal residues give)",
            worst
        ));
    }
    let pole_term = |c: f64, friction: Option<f64>| PoleAtZeroSpec {
        name: Some("converted from the plant".into()),
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Scalar(c),
        friction_pole: friction,
    };
    // Terms with a negligible coefficient (below 1e-12 of the largest, in the fit's own
    // scaling) are dropped.
    let big = x.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let mut m = PhysicalModel::default();
    for (j, (t, cj)) in terms.iter().zip(&c).enumerate() {
        if x[j].abs() <= 1e-12 * big {
            continue;
        }
        match *t {
            Term::Rigid => m.rigid_body.push(pole_term(*cj, None)),
            Term::Friction(p) => m.rigid_body.push(pole_term(*cj, Some(p))),
            Term::Integrator => m.integrator.push(pole_term(*cj, None)),
            Term::Mode(w, z) => m.mode.push(ModeSpec {
                name: Some("converted from the plant".into()),
                omega_n: w,
                zeta: z,
                mass: 1.0,
                input_gain: Gains::Scalar(1.0),
                output_gain: Gains::Scalar(*cj),
            }),
            Term::Feed => m.feedthrough = Some(Feedthrough::Scalar(*cj)),
        }
    }
    m.validate()?;
    Ok(m)
}

fn siso(rows: &[Vec<TfEntry>], what: &str) -> Result<TransferFunction, String> {
    match rows {
        [row] if row.len() == 1 => row[0].to_tf(what),
        _ => Err(format!(
            "{what} is {}×{}: only a SISO plant is converted",
            rows.len(),
            rows.first().map_or(0, |r| r.len())
        )),
    }
}

/// The SISO plant a `[plant]` or `[closed_loop]` config gives as a transfer function:
/// `(what, P)`, or `None` for other configs.
pub fn plant_tf(c: &Config) -> Option<Result<(&'static str, TransferFunction), String>> {
    if let Some(pl) = &c.raw.plant {
        return Some(match &pl.tf {
            Some(rows) => siso(rows, "[plant] tf").map(|t| ("[plant] transfer function", t)),
            None => Err("a state-space [plant] is not converted; give it as tf = ...".into()),
        });
    }
    let cl = c.raw.closed_loop.as_ref()?;
    let what = "[closed_loop] nominal plant";
    Some(match (&cl.plant, &cl.n_hat, &cl.d_hat) {
        (Some(p), _, _) => siso(p, "[closed_loop] plant").map(|t| (what, t)),
        (None, Some(n), Some(d)) => siso(n, "[closed_loop] n_hat").and_then(|n| {
            siso(d, "[closed_loop] d_hat").map(|d| {
                let p = TransferFunction {
                    num: n.num.mul(&d.den),
                    den: n.den.mul(&d.num),
                };
                (what, p)
            })
        }),
        _ => return None,
    })
}

/// A short list of the terms of a converted model (`1 rigid body, 2 modes`).
fn summary(m: &PhysicalModel) -> String {
    let mut v = Vec::new();
    let mut put = |n: usize, one: &str, many: &str| {
        if n > 0 {
            v.push(format!("{n} {}", if n == 1 { one } else { many }));
        }
    };
    let friction = m
        .rigid_body
        .iter()
        .filter(|r| r.friction_pole.is_some())
        .count();
    put(m.rigid_body.len() - friction, "rigid body", "rigid bodies");
    put(
        friction,
        "rigid body with friction",
        "rigid bodies with friction",
    );
    put(m.integrator.len(), "integrator", "integrators");
    put(m.mode.len(), "mode", "modes");
    put(
        usize::from(m.feedthrough.is_some()),
        "feedthrough",
        "feedthroughs",
    );
    v.join(", ")
}

/// The `[physical]` form of a config that is not `[physical]` and the sentence saying what
/// was converted: a `[plant]` or `[closed_loop]` transfer function ([`physical_from_tf`]) or
/// a modal `[model]` factor form ([`crate::diagnose::factor_form::physical_from_factors`]); else why
/// not.
pub fn physical_from_config(c: &Config) -> Result<(PhysicalModel, String), String> {
    match plant_tf(c) {
        Some(r) => {
            let (what, tf) = r?;
            let m = physical_from_tf(&tf)?;
            let how = format!(
                "the {what} is a sum of physical terms: converted to [physical] ({})",
                summary(&m)
            );
            Ok((m, how))
        }
        None => {
            let m = crate::diagnose::factor_form::physical_from_factors(&c.factorization)?;
            let how = format!(
                "the [model] factor form is a modal special factorization: converted to [physical] ({} modes)",
                m.mode.len()
            );
            Ok((m, how))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(m: &PhysicalModel, g: &TransferFunction) {
        for w in [0.01, 0.3, 1.0, 7.0, 49.0, 50.0, 51.0, 1e3] {
            let (a, b) = (m.eval_siso(w), g.eval(Complex64::new(0.0, w)));
            assert!((a - b).norm() <= 1e-8 * b.norm(), "{w}: {a} vs {b}");
        }
    }

    /// `1/(s² + s)`: a rigid body with friction pole 1 (the plant-first example).
    #[test]
    fn integrator_plus_lag_is_a_rigid_body_with_friction() {
        let g = TransferFunction::new(vec![1.0], vec![1.0, 1.0, 0.0]);
        let m = physical_from_tf(&g).unwrap();
        assert_eq!(m.rigid_body.len(), 1, "{m:?}");
        assert!((m.rigid_body[0].friction_pole.unwrap() - 1.0).abs() < 1e-9);
        assert!(m.integrator.is_empty() && m.mode.is_empty(), "{m:?}");
        close(&m, &g);
    }

    /// `N̂·D̂⁻¹` with a common `(s + 2)²`: the rigid body `1/s²`, and a rigid body + a mode
    /// at 50 rad/s (ζ = 0.01) with a feedthrough written as one polynomial ratio.
    #[test]
    fn common_factors_cancel_and_modes_are_found() {
        let g = TransferFunction::new(vec![1.0, 4.0, 4.0], vec![1.0, 4.0, 4.0, 0.0, 0.0]);
        let m = physical_from_tf(&g).unwrap();
        assert_eq!((m.rigid_body.len(), m.mode.len()), (1, 0), "{m:?}");
        close(&m, &g);
        // 2/s² + 3/(s² + s + 2500) + 0.1, over a common denominator.
        let d = Polynomial::new(vec![1.0, 1.0, 2500.0]);
        let s2 = Polynomial::new(vec![1.0, 0.0, 0.0]);
        let num = d.scale(2.0).add(&s2.scale(3.0)).add(&s2.mul(&d).scale(0.1));
        let g = TransferFunction {
            num,
            den: s2.mul(&d),
        };
        let m = physical_from_tf(&g).unwrap();
        assert_eq!((m.rigid_body.len(), m.mode.len()), (1, 1), "{m:?}");
        assert!((m.mode[0].omega_n - 50.0).abs() < 1e-9 && (m.mode[0].zeta - 0.01).abs() < 1e-9);
        assert!(matches!(m.feedthrough, Some(Feedthrough::Scalar(x)) if (x - 0.1).abs() < 1e-9));
        close(&m, &g);
    }

    /// A mode with an `s` term in its residue, and a lone lag, are refused with the reason.
    #[test]
    fn non_physical_plants_are_refused_with_a_reason() {
        let g = TransferFunction::new(vec![1.0, 3.0], vec![1.0, 1.0, 2500.0]);
        let e = physical_from_tf(&g).unwrap_err();
        assert!(e.contains("not a sum of physical terms"), "{e}");
        let g = TransferFunction::new(vec![1.0], vec![1.0, 10.0]);
        let e = physical_from_tf(&g).unwrap_err();
        assert!(e.contains("real pole at s = -10"), "{e}");
    }
}

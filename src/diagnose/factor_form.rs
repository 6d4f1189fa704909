//! Factor-form configs in `diagnose`: a special (modal) factorization `C·M̃⁻¹·Ñ·J` whose rows
//! are modes is converted to `[physical]`, so effects can be added to it; anything else gets a
//! message saying why not.
//!
//! Row `k` is a mode when `M̃_kk = d_k(s)/q_k(s)` with `d_k = m s² + 2mζω_n s + mω_n²`
//! (`ζ, ω_n > 0`), `M̃` is diagonal, every `Ñ_kj = b_kj/q'_kj(s)` with a constant numerator
//! and `q'_kj ∝ q_k` (so `M̃_kk⁻¹Ñ_kj = b_kj/(λ_kj d_k)`), and `J` is constant.  Then
//! `G = Σ_k C_{:,k} (b_k J)ᵀ/(λ d_k(s))`: mode `k` with mass `m`, input gains `b_kj J_j/λ_kj`
//! and output gains `C_{:,k}` (Sec. IV-A, the inverse of
//! [`crate::model::physical::PhysicalModel::to_factorization`]).

use crate::model::factorization::{Factorization, FactorizationKind};
use crate::model::physical::{Gains, ModeSpec, PhysicalModel};
use crate::system::Polynomial;

fn proportional(a: &Polynomial, b: &Polynomial) -> Option<f64> {
    let (a, b) = (a.coeffs(), b.coeffs());
    if a.len() != b.len() || b[0] == 0.0 {
        return None;
    }
    let l = a[0] / b[0];
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - l * y).abs() <= 1e-9 * x.abs().max(l.abs() * y.abs()).max(1e-300))
        .then_some(l)
}

/// The `[physical]` form of a modal special factorization, or why there is none.
pub fn physical_from_factors(f: &Factorization) -> Result<PhysicalModel, String> {
    if f.kind != FactorizationKind::Special {
        return Err("the factors are a standard factorization M̃⁻¹Ñ, not a modal one".into());
    }
    let (p, n) = (f.c.nrows(), f.c.ncols());
    let m_in = f.n.cols();
    let mut j = Vec::new();
    for (k, t) in f.j.iter().enumerate() {
        if t.num.degree() != 0 || t.den.degree() != 0 {
            return Err(format!(
                "J entry {} is dynamic: write it as a [[physical.effect]]",
                k + 1
            ));
        }
        j.push(t.num.leading() / t.den.leading());
    }
    let mut modes = Vec::new();
    for k in 0..n {
        for c in 0..n {
            if c != k && !f.m.entry(k, c).num.is_zero() {
                return Err(format!("M̃ is not diagonal (entry {},{})", k + 1, c + 1));
            }
        }
        let mk = f.m.entry(k, k);
        let d = mk.num.coeffs();
        if mk.num.degree() != 2 || d.len() != 3 {
            return Err(format!(
                "row {} of M̃ is not a second-order mode (numerator of degree {}); rigid bodies and feedthrough rows need the [physical] form",
                k + 1,
                mk.num.degree()
            ));
        }
        let mut b = Vec::new();
        for (jj, jgain) in j.iter().enumerate().take(m_in) {
            let e = f.n.entry(k, jj);
            if e.num.is_zero() {
                b.push(0.0);
                continue;
            }
            let lambda = proportional(&e.den, &mk.den).filter(|_| e.num.degree() == 0);
            let Some(lambda) = lambda else {
                return Err(format!(
                    "Ñ entry {},{} does not share the denominator of M̃ row {} over a constant",
                    k + 1,
                    jj + 1,
                    k + 1
                ));
            };
            b.push(e.num.leading() / lambda * jgain);
        }
        let (m2, m1, m0) = (d[0], d[1], d[2]);
        if !(m2 > 0.0 && m0 > 0.0 && m1 > 0.0) {
            return Err(format!(
                "row {} of M̃ is not a damped mode (s² coefficients {:?})",
                k + 1,
                d
            ));
        }
        let w = (m0 / m2).sqrt();
        let gains = |v: Vec<f64>| {
            if v.len() == 1 {
                Gains::Scalar(v[0])
            } else {
                Gains::Vector(v)
            }
        };
        modes.push(ModeSpec {
            name: Some(format!("row {} of the factor form", k + 1)),
            omega_n: w,
            zeta: m1 / (2.0 * m2 * w),
            mass: m2,
            input_gain: gains(b),
            output_gain: gains((0..p).map(|i| f.c[(i, k)]).collect()),
        });
    }
    let model = PhysicalModel {
        inputs: Some(m_in),
        outputs: Some(p),
        mode: modes,
        ..Default::default()
    };
    model.validate()?;
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Config;
    use std::path::Path;

    /// The robot's factor form (eqs. (19)–(21)) converts to a model with the same G(jω) as
    /// the factors, independently of the hand-written physical form.
    #[test]
    fn robot_factor_form_converts_to_the_same_plant() {
        let c = Config::load(Path::new("configs/robot.toml")).unwrap();
        let m = physical_from_factors(&c.factorization).unwrap();
        assert_eq!(m.mode.len(), 5);
        for w in [1.0, 5.0, 20.0, 45.0, 64.0] {
            let g = c.factorization.plant(w).unwrap()[(0, 0)];
            let h = m.eval_siso(w);
            assert!((g - h).norm() <= 1e-9 * g.norm(), "{w}: {g} vs {h}");
        }
    }
}

//! The nominal plant `P̂` of a closed-loop config given as `[physical]` (its rational
//! export) instead of `plant`/`n_hat`/`d_hat` in `[closed_loop]`.
//!
//! The physical model exports the special (modal) factorization `P̂ = c·M̃⁻¹·Ñ·J`
//! (Boulet & Francis, Sec. IV-A) with a diagonal `M̃ = diag(d_k/q_k)`, `Ñ_k = n_k/q_k` (the
//! same Hurwitz `q_k` in row `k` of `M̃` and of `Ñ`) and the path effects in `J`.  For a SISO
//! plant
//!
//! ```text
//!   P̂ = J·Σ_k c_k n_k/d_k = N̂·D̂⁻¹,   D̂ = det M̃ = Π_k d_k/q_k,
//!                                     N̂ = c·adj(M̃)·Ñ·J = J·Σ_k c_k n_k Π_{j≠k} d_j / Π_k q_k,
//! ```
//!
//! a right (and, SISO, left) factorization with stable proper factors (`q_k` Hurwitz,
//! `deg d_k = deg q_k`, `deg n_k ≤ deg q_k`, `J` stable).  It is coprime unless two modal
//! coordinates share an unstable pole (two rigid bodies: `D̂` and `N̂` both vanish at 0);
//! the loop check then reports the shared pole as a closed-loop pole in `Re s ≥ 0`.

use super::RightFactors;
use crate::model::Factorization;
use crate::system::{Polynomial, TfMatrix, TransferFunction};

/// The SISO right factorization `(N̂, D̂)` of a physical model's exported factorization
/// `c·M̃⁻¹·Ñ·J` (module docs); an error for MIMO models or a factorization whose `M̃` is not
/// diagonal with the denominators of `Ñ`.
pub fn rcf_from_modal(f: &Factorization) -> Result<RightFactors, String> {
    if f.outputs() != 1 || f.inputs() != 1 {
        return Err(format!(
            "[physical] with [closed_loop]: the nominal plant must be SISO (it is {}×{}); give a MIMO nominal in [closed_loop] as plant or n_hat/d_hat",
            f.outputs(),
            f.inputs()
        ));
    }
    let n = f.m.rows();
    let mut d_prod = Polynomial::constant(1.0);
    let mut q_prod = Polynomial::constant(1.0);
    for k in 0..n {
        for j in 0..n {
            if j != k && !f.m.entry(k, j).num.is_zero() {
                return Err(
                    "[physical] with [closed_loop]: the modal factor M̃ must be diagonal".into(),
                );
            }
        }
        let (mk, nk) = (f.m.entry(k, k), f.n.entry(k, 0));
        if !nk.num.is_zero() && nk.den != mk.den {
            return Err(
                "[physical] with [closed_loop]: rows of Ñ and M̃ must share their denominators"
                    .into(),
            );
        }
        d_prod = d_prod.mul(&mk.num);
        q_prod = q_prod.mul(&mk.den);
    }
    // Σ_k c_k n_k Π_{j≠k} d_j
    let mut num = Polynomial::constant(0.0);
    for k in 0..n {
        let ck = f.c[(0, k)];
        let nk = &f.n.entry(k, 0).num;
        if ck == 0.0 || nk.is_zero() {
            continue;
        }
        let term = (0..n)
            .filter(|&j| j != k)
            .fold(nk.scale(ck), |acc, j| acc.mul(&f.m.entry(j, j).num));
        num = num.add(&term);
    }
    let core = TransferFunction {
        num,
        den: q_prod.clone(),
    };
    let n_hat = f.j.iter().fold(core, |acc, j| acc.mul(j));
    let d_hat = TransferFunction {
        num: d_prod,
        den: q_prod,
    };
    let one = |t: TransferFunction| TfMatrix::from_rows(vec![vec![t]]).expect("1×1");
    Ok(RightFactors {
        n: one(n_hat),
        d: one(d_hat),
        trivial: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::physical::PhysicalModel;

    #[test]
    fn factors_reproduce_the_physical_model() {
        // rigid body 2/s² + mode 0.5/(s² + 2·0.02·30 s + 900), a lag 1/(s/100 + 1).
        let ph: PhysicalModel = toml::from_str(
            r#"
            factor_pole = 3.0
            [[rigid_body]]
            output_gain = 2.0
            [[mode]]
            omega_n = 30.0
            zeta = 0.02
            output_gain = 0.5
            [[effect]]
            kind = "lag"
            omega_c = 100.0
            "#,
        )
        .unwrap();
        let f = ph.to_factorization().unwrap();
        let rcf = rcf_from_modal(&f).unwrap();
        for w in [0.01, 0.7, 29.0, 30.0, 31.0, 1e3] {
            let want = ph.eval_siso(w);
            let got = rcf.value(w).unwrap()[(0, 0)];
            assert!(
                (got - want).norm() <= 1e-9 * want.norm(),
                "{w}: {got} vs {want}"
            );
        }
        assert!(super::super::stability::is_stable(&rcf.n));
        assert!(super::super::stability::is_stable(&rcf.d));
    }
}

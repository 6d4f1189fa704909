//! The rational export of a physical model: the special (modal) factorization
//! `C·M̃⁻¹·Ñ·J` of Sec. IV-A (see the module docs of [`super`]).

use super::{EffectPath, PhysicalModel};
use crate::model::factorization::Factorization;
use crate::system::{Polynomial, TfMatrix, TransferFunction};
use nalgebra::DMatrix;

impl PhysicalModel {
    /// The special factorization `C·M̃⁻¹·Ñ·J` (rational; see the module docs).
    pub fn to_factorization(&self) -> Result<Factorization, String> {
        self.validate()?;
        let (p, m) = (self.n_outputs(), self.n_inputs());
        let a = self.factor_pole.unwrap_or(1.0);
        let q_default = |w: f64| Polynomial::new(vec![1.0, 2.0 * w, w * w]);
        let q = |w: f64| match &self.factor_den {
            Some(c) => Polynomial::new(c.clone()),
            None => q_default(w),
        };
        let mut m_diag = Vec::new();
        let mut n_rows: Vec<Vec<TransferFunction>> = Vec::new();
        let mut c_cols: Vec<Vec<f64>> = Vec::new();
        // The measured quantity's s^k multiplies every term: a mode keeps its q(s) (degree 2
        // ≥ k); a pole at zero cancels against s^k; the rest is written over (s + a)^deg.
        let k = self.quantity.power() as usize;
        for md in &self.mode {
            let qk = q(md.omega_n);
            let d = Polynomial::new(vec![
                md.mass,
                md.mass * 2.0 * md.zeta * md.omega_n,
                md.mass * md.omega_n * md.omega_n,
            ]);
            m_diag.push(TransferFunction {
                num: d,
                den: qk.clone(),
            });
            n_rows.push(over(&md.input_gain.to_vec(m), &s_pow(k), &qk));
            c_cols.push(md.output_gain.to_vec(p));
        }
        for (list, order) in [(&self.rigid_body, 2usize), (&self.integrator, 1)] {
            for md in list {
                // c b s^k/(m s^z (s + p)): the powers of s cancel first.
                let friction = md.friction_pole.filter(|_| order == 2);
                let z = if friction.is_some() { 1 } else { order };
                let n_s = z.min(k);
                let num_order = k - n_s;
                let mut d = Polynomial::constant(md.mass).mul(&s_pow(z - n_s));
                if let Some(p) = friction {
                    d = d.mul(&Polynomial::new(vec![1.0, p]));
                }
                let deg = d.degree().max(num_order);
                let qk = if deg == 2 { q(a) } else { pole_power(a, deg) };
                m_diag.push(TransferFunction {
                    num: d,
                    den: qk.clone(),
                });
                n_rows.push(over(&md.input_gain.to_vec(m), &s_pow(num_order), &qk));
                c_cols.push(md.output_gain.to_vec(p));
            }
        }
        if let Some(d) = self.d_matrix() {
            // D s^k: M̃ = 1/(s + a)^k, Ñ = D s^k/(s + a)^k (a zero row stays M̃ = 1, Ñ = 0).
            for i in 0..p {
                let zero = (0..m).all(|j| d[(i, j)] == 0.0);
                let qk = if zero {
                    pole_power(a, 0)
                } else {
                    pole_power(a, k)
                };
                m_diag.push(TransferFunction {
                    num: Polynomial::constant(1.0),
                    den: qk.clone(),
                });
                let num = if zero { s_pow(0) } else { s_pow(k) };
                n_rows.push(over(
                    &d.row(i).iter().copied().collect::<Vec<_>>(),
                    &num,
                    &qk,
                ));
                let mut col = vec![0.0; p];
                col[i] = 1.0;
                c_cols.push(col);
            }
        }
        let order = self.pade_order.unwrap_or(6);
        let mut j = vec![TransferFunction::gain(1.0); m];
        for e in self.effect.iter().filter(|e| e.path == EffectPath::Input) {
            let tf = e.to_tf(order);
            for (k, jk) in j.iter_mut().enumerate() {
                if e.channel.is_none_or(|c| c == k + 1) {
                    *jk = jk.mul(&tf);
                }
            }
        }
        let rows = super::output_path::split_rows(
            self.output_chains(order),
            super::output_path::Rows {
                m: m_diag,
                n: n_rows,
                c: c_cols,
            },
            &mut j,
        );
        let (m_diag, n_rows, c_cols) = (rows.m, rows.n, rows.c);
        let n = m_diag.len();
        let c = DMatrix::from_fn(p, n, |i, k| c_cols[k][i]);
        let mm = TfMatrix::diagonal(m_diag);
        let nn = TfMatrix::from_rows(n_rows).ok_or("[physical]: inconsistent input gains")?;
        Factorization::special(c, mm, nn, j).map_err(|e| format!("[physical]: {e}"))
    }
}

/// The row of `Ñ` for one modal coordinate: the input gains times `num(s)` over the common
/// denominator `q(s)` of its row of `M̃`.
fn over(gains: &[f64], num: &Polynomial, q: &Polynomial) -> Vec<TransferFunction> {
    gains
        .iter()
        .map(|b| TransferFunction {
            num: num.scale(*b),
            den: q.clone(),
        })
        .collect()
}

/// `s^k`.
fn s_pow(k: usize) -> Polynomial {
    let mut c = vec![1.0];
    c.extend(std::iter::repeat_n(0.0, k));
    Polynomial::new(c)
}

/// `(s + a)^deg`.
fn pole_power(a: f64, deg: usize) -> Polynomial {
    (0..deg).fold(Polynomial::constant(1.0), |acc, _| {
        acc.mul(&Polynomial::new(vec![1.0, a]))
    })
}

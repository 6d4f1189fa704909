//! Interconnections of state-space systems: series connection, inversion, and the feedback
//! loop `u = −K·y` used by the robust-stability test.

use super::state_space::StateSpace;
use crate::error::{Error, Result};
use nalgebra::DMatrix;

impl StateSpace {
    /// `self ∘ first` (the output of `first` drives `self`); states `[x_first; x_self]`.
    pub fn series(&self, first: &StateSpace) -> StateSpace {
        let (n1, n2) = (first.states(), self.states());
        let n = n1 + n2;
        let (m, p) = (first.b.ncols(), self.c.nrows());
        let mut a = DMatrix::zeros(n, n);
        a.view_mut((0, 0), (n1, n1)).copy_from(&first.a);
        a.view_mut((n1, 0), (n2, n1))
            .copy_from(&(&self.b * &first.c));
        a.view_mut((n1, n1), (n2, n2)).copy_from(&self.a);
        let mut b = DMatrix::zeros(n, m);
        b.view_mut((0, 0), (n1, m)).copy_from(&first.b);
        b.view_mut((n1, 0), (n2, m))
            .copy_from(&(&self.b * &first.d));
        let mut c = DMatrix::zeros(p, n);
        c.view_mut((0, 0), (p, n1)).copy_from(&(&self.d * &first.c));
        c.view_mut((0, n1), (p, n2)).copy_from(&self.c);
        StateSpace {
            a,
            b,
            c,
            d: &self.d * &first.d,
        }
    }

    /// The inverse system `(A − BD⁻¹C, BD⁻¹, −D⁻¹C, D⁻¹)`; needs a square invertible `D`
    /// (a biproper system).
    pub fn inverse(&self, what: &str) -> Result<StateSpace> {
        let (p, m) = self.d.shape();
        let sv = if p == m {
            self.d.clone().svd(false, false).singular_values
        } else {
            nalgebra::DVector::zeros(1)
        };
        if p != m || sv.min().is_nan() || sv.min() <= 1e-12 * sv.max() {
            return Err(Error::Invalid(format!(
                "{what} is not biproper (its value at s = ∞ is singular), so it has no proper inverse"
            )));
        }
        let lu = self.d.clone().lu();
        let dinv = lu.try_inverse().expect("checked");
        Ok(StateSpace {
            a: &self.a - &self.b * &dinv * &self.c,
            b: &self.b * &dinv,
            c: -(&dinv * &self.c),
            d: dinv,
        })
    }

    /// The same system with every input and output scaled by a scalar system `r` placed at
    /// each of the `k` inputs: `self · (r·I_k)` (`k` = number of inputs).
    pub fn times_scalar(&self, r: &StateSpace) -> StateSpace {
        let k = self.b.ncols();
        let nr = r.states();
        let mut diag = StateSpace {
            a: DMatrix::zeros(nr * k, nr * k),
            b: DMatrix::zeros(nr * k, k),
            c: DMatrix::zeros(k, nr * k),
            d: DMatrix::identity(k, k) * r.d[(0, 0)],
        };
        for i in 0..k {
            diag.a.view_mut((i * nr, i * nr), (nr, nr)).copy_from(&r.a);
            diag.b.view_mut((i * nr, i), (nr, 1)).copy_from(&r.b);
            diag.c.view_mut((i, i * nr), (1, nr)).copy_from(&r.c);
        }
        self.series(&diag)
    }
}

/// The loop `u = −K·y` around a plant `P` with inputs `[u; w]` (`u` the first `m_u`) and
/// output `y`: the closed-loop system from `w` to `[u; y]`, states `[x_P; x_K]`. Errors
/// when the loop is ill-posed (`I + D_K·D_u` singular).
pub fn negative_feedback(p: &StateSpace, k: &StateSpace, m_u: usize) -> Result<StateSpace> {
    let (np, nk) = (p.states(), k.states());
    let py = p.c.nrows();
    let mw = p.b.ncols() - m_u;
    if k.d.shape() != (m_u, py) {
        return Err(Error::Invalid(format!(
            "the controller must be {m_u}×{py} (plant inputs × plant outputs), got {}×{}",
            k.d.nrows(),
            k.d.ncols()
        )));
    }
    let bu = p.b.columns(0, m_u);
    let bw = p.b.columns(m_u, mw);
    let du = p.d.columns(0, m_u);
    let dw = p.d.columns(m_u, mw);
    let e = DMatrix::<f64>::identity(m_u, m_u) + &k.d * du;
    let sv = e.clone().svd(false, false).singular_values;
    if sv.min().is_nan() || sv.min() <= 1e-12 * sv.max().max(1.0) {
        return Err(Error::Invalid(
            "the feedback loop is ill-posed: I + K(∞)·G(∞) is singular".into(),
        ));
    }
    let lu = e.lu();
    let ux = -lu.solve(&(&k.d * &p.c)).expect("checked");
    let uk = -lu.solve(&k.c).expect("checked");
    let uw = -lu.solve(&(&k.d * dw)).expect("checked");
    let yx = &p.c + du * &ux;
    let yk = du * &uk;
    let yw = dw + du * &uw;
    let n = np + nk;
    let mut a = DMatrix::zeros(n, n);
    a.view_mut((0, 0), (np, np)).copy_from(&(&p.a + bu * &ux));
    a.view_mut((0, np), (np, nk)).copy_from(&(bu * &uk));
    a.view_mut((np, 0), (nk, np)).copy_from(&(&k.b * &yx));
    a.view_mut((np, np), (nk, nk))
        .copy_from(&(&k.a + &k.b * &yk));
    let mut b = DMatrix::zeros(n, mw);
    b.view_mut((0, 0), (np, mw)).copy_from(&(bw + bu * &uw));
    b.view_mut((np, 0), (nk, mw)).copy_from(&(&k.b * &yw));
    let mut c = DMatrix::zeros(m_u + py, n);
    c.view_mut((0, 0), (m_u, np)).copy_from(&ux);
    c.view_mut((0, np), (m_u, nk)).copy_from(&uk);
    c.view_mut((m_u, 0), (py, np)).copy_from(&yx);
    c.view_mut((m_u, np), (py, nk)).copy_from(&yk);
    let mut d = DMatrix::zeros(m_u + py, mw);
    d.view_mut((0, 0), (m_u, mw)).copy_from(&uw);
    d.view_mut((m_u, 0), (py, mw)).copy_from(&yw);
    Ok(StateSpace { a, b, c, d })
}

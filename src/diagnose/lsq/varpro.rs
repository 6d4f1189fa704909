//! The Jacobian of the variable-projection residual of [`crate::diagnose::lsq::retune`] (Golub & Pereyra
//! 1973; Kaufman 1975 for the notation), from one Householder QR per point instead of one
//! per parameter.
//!
//! With the linear slots solved, the residual is `r(θ) = P⊥(θ) y`, `P⊥ = I − A A⁺`, `A(θ)`
//! the weighted design matrix of the linear slots ([`crate::diagnose::lsq::slots::design`]).  Its exact
//! derivative along a nonlinear parameter `θ_k` (Golub & Pereyra, eq. (4.3)) is
//!
//! `∂r/∂θ_k = −P⊥ A_k x − (A⁺)ᵀ A_kᵀ r`,   `A_k = ∂A/∂θ_k`, `x = A⁺ y`.
//!
//! With `Ã = A S = Q R` (columns scaled to unit norm, `S` diagonal; thin Householder QR of
//! each independent block, [`crate::diagnose::lsq::slots::blocks`]), `P⊥ v = v − Q Qᵀ v` and
//! `(A⁺)ᵀ w = Q R⁻ᵀ S w`.  `A_k` is analytic where the parameter acts on a few columns: a
//! mode's `ln ω_n` and `ln ζ` on its own columns,
//! `∂/∂ln ω_n [1/d(s)] = −(2ζω_n s + 2ω_n²)/d(s)²`, `∂/∂ln ζ [1/d(s)] = −2ζω_n s/d(s)²`,
//! `d(s) = s² + 2ζω_n s + ω_n²`; an input gain `b_i` on its term's columns, rows of input
//! `i`, `∂/∂b_i = 1/b_i` times the entry.  Path effects (delays, lags, …) and friction poles
//! change every column of a channel: their `A_k` is a forward difference of the design
//! matrix alone (no factorization).  Where a block is rank-deficient (a pivot below
//! `1e-12` of the largest, where the least squares drops a column) the caller falls back to
//! the forward-difference Jacobian of the whole residual.

use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::shapes::mode_log_slope;
use crate::diagnose::lsq::slots::{block_matrix, blocks, design, gains_of, set_nl, Lin, Nl, Term};
use crate::model::physical::PhysicalModel;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// One independent block of the least squares, factored: `Ã_b = Q R`.
struct Block {
    rows: Vec<usize>,
    cols: Vec<usize>,
    q: DMatrix<f64>,
    r: DMatrix<f64>,
    scale: Vec<f64>,
}

/// The variable-projection problem of a refit: the model with its nonlinear slots `nl` at
/// `θ` and its linear slots `lin` solved on the data at `mask`.
pub(crate) struct VarPro<'a> {
    pub start: &'a PhysicalModel,
    pub nl: &'a [Nl],
    pub lin: &'a [Lin],
    pub data: &'a Channels,
    pub mask: &'a [usize],
    /// Typical magnitudes of the nonlinear parameters (forward-difference steps).
    pub typ: &'a [f64],
}

/// The column-scaled Householder QR of `a` (`a S = Q R`, thin): `(Q, R, scale)`, or `None`
/// when it is rank-deficient (a pivot below `1e-12` of the largest, where the least squares
/// drops a column) or has more columns than rows.
pub(super) fn factor_block(mut a: DMatrix<f64>) -> Option<(DMatrix<f64>, DMatrix<f64>, Vec<f64>)> {
    let n = a.ncols();
    if a.nrows() < n {
        return None;
    }
    let scale = crate::system::linalg::equilibrate_columns(&mut a);
    let qr = a.qr();
    let r = qr.r();
    let rmax = (0..n).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    if !rmax.is_finite() || (0..n).any(|i| r[(i, i)].abs() <= 1e-12 * rmax) {
        return None;
    }
    Some((qr.q(), r, scale))
}

/// [`factor_block`] of every block of `a`, or `None` when one is rank-deficient.
fn factor(
    a: &DMatrix<f64>,
    lin: &[Lin],
    data: &Channels,
    rows_per_ch: usize,
) -> Option<Vec<Block>> {
    let mut out = Vec::new();
    for (chs, cols) in blocks(lin, data) {
        if cols.is_empty() {
            continue;
        }
        let (rows, ab) = block_matrix(a, &chs, &cols, rows_per_ch);
        let (q, r, scale) = factor_block(ab)?;
        out.push(Block {
            rows,
            cols,
            q,
            r,
            scale,
        });
    }
    Some(out)
}

impl VarPro<'_> {
    /// The model at `θ`.
    fn model(&self, th: &[f64]) -> PhysicalModel {
        let mut mm = self.start.clone();
        for (s, x) in self.nl.iter().zip(th) {
            set_nl(&mut mm, *s, *x);
        }
        mm
    }

    /// Accumulates `A_k = ∂A/∂θ_k` against the solution and the residual: adds
    /// `sign·A_k x` into `u` (one column of `U`, every row) and `sign·A_kᵀ r` into `t` (one
    /// column of `T`, a row per linear slot).  Analytic where the module documentation says
    /// so, else a forward difference of the design matrix.
    #[allow(clippy::too_many_arguments)]
    fn d_design(
        &self,
        mm: &PhysicalModel,
        a: &DMatrix<f64>,
        th: &[f64],
        k: usize,
        x: &DVector<f64>,
        res: &DVector<f64>,
        sign: f64,
        u: &mut [f64],
        t: &mut [f64],
    ) {
        let rows_per_ch = 2 * self.mask.len();
        // Columns of term `tm` on the channels `chs`, with a complex factor per frequency.
        let mut scaled = |tm: Term, chs: &dyn Fn(usize) -> bool, f: &dyn Fn(usize) -> Complex64| {
            for (j, _) in self
                .lin
                .iter()
                .enumerate()
                .filter(|(_, l)| matches!(l, Lin::Out(v, _) if *v == tm))
            {
                let (col, xj) = (a.column(j), sign * x[j]);
                let mut dot = 0.0;
                for ch in (0..self.data.n_ch()).filter(|c| chs(*c)) {
                    let base = ch * rows_per_ch;
                    for (q, kq) in (0..self.mask.len()).map(|q| (q, self.mask[q])) {
                        let row = base + 2 * q;
                        let c = Complex64::new(col[row], col[row + 1]) * f(kq);
                        u[row] += xj * c.re;
                        u[row + 1] += xj * c.im;
                        dot += c.re * res[row] + c.im * res[row + 1];
                    }
                }
                t[j] += sign * dot;
            }
        };
        match self.nl[k] {
            Nl::ModeW(i) | Nl::ModeZ(i) => {
                let (w, z) = (mm.mode[i].omega_n, mm.mode[i].zeta);
                let by_w = matches!(self.nl[k], Nl::ModeW(_));
                // The factor depends on the frequency only: computed once per line.
                let fac: Vec<Complex64> = self
                    .data
                    .omega
                    .iter()
                    .map(|om| mode_log_slope(Complex64::new(0.0, *om), w, z, by_w))
                    .collect();
                scaled(Term::Mode(i), &|_| true, &|kq| fac[kq]);
            }
            Nl::In(tm, i) => {
                let b = gains_of(mm, tm).1.to_vec(mm.n_inputs())[i];
                if b != 0.0 && b.is_finite() {
                    let inv = Complex64::new(1.0 / b, 0.0);
                    let entries = &self.data.entries;
                    scaled(tm, &|ch| entries[ch].1 == i, &|_| inv);
                } else {
                    self.forward_difference(a, th, k, x, res, sign, u, t);
                }
            }
            Nl::RigidPole(_) | Nl::Delay(_) | Nl::LogEffect(_) => {
                self.forward_difference(a, th, k, x, res, sign, u, t)
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn forward_difference(
        &self,
        a: &DMatrix<f64>,
        th: &[f64],
        k: usize,
        x: &DVector<f64>,
        res: &DVector<f64>,
        sign: f64,
        u: &mut [f64],
        t: &mut [f64],
    ) {
        let h = 1e-7 * th[k].abs().max(self.typ[k]).max(1e-300);
        let mut tt = th.to_vec();
        tt[k] += h;
        let (ah, _) = design(&self.model(&tt), self.lin, self.data, self.mask);
        for j in 0..a.ncols() {
            let (c1, c0) = (ah.column(j), a.column(j));
            let (xj, mut dot) = (sign * x[j], 0.0);
            for row in 0..a.nrows() {
                let d = (c1[row] - c0[row]) / h;
                u[row] += xj * d;
                dot += d * res[row];
            }
            t[j] += sign * dot;
        }
    }

    /// `(−U, −T)`, `U = [A_k x]_k` (`m × K`) and `T = [A_kᵀ r]_k` (`n × K`): the derivative
    /// columns both [`VarPro::jacobian`] and [`VarPro::normal`] are built from.
    fn negated_derivatives(
        &self,
        mm: &PhysicalModel,
        a: &DMatrix<f64>,
        th: &[f64],
        x: &DVector<f64>,
        res: &DVector<f64>,
    ) -> (DMatrix<f64>, DMatrix<f64>) {
        let kk = self.nl.len();
        let mut u = DMatrix::<f64>::zeros(a.nrows(), kk);
        let mut t = DMatrix::<f64>::zeros(self.lin.len(), kk);
        for k in 0..kk {
            self.d_design(
                mm,
                a,
                th,
                k,
                x,
                res,
                -1.0,
                u.column_mut(k).as_mut_slice(),
                t.column_mut(k).as_mut_slice(),
            );
        }
        (u, t)
    }

    /// The normal equations `(JᵀJ, Jᵀr)` of [`VarPro::jacobian`]'s `J` at `θ` against the
    /// residual `r`, without forming `J` (`m × K`, `m` the rows): with `J = u + Q c`
    /// (`u = −U`, `c = z − Qᵀu`, `z = −Z`) and `QᵀQ = I`,
    ///
    /// `JᵀJ = uᵀu − (Qᵀu)ᵀ(Qᵀu) + zᵀz`,   `Jᵀr = uᵀr + cᵀ(Qᵀr)`,
    ///
    /// and `uᵀu` is summed channel by channel over the columns that are not zero there (an
    /// input gain's `A_k` lives on its input's channels only): `Σ_ch n_ch² · rows` instead
    /// of `K² m`.  One least-squares block over every row only (one output, or SISO);
    /// `None` otherwise, where a block is rank-deficient or a value is not finite.
    pub fn normal(&self, th: &[f64], r: &[f64]) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let mm = self.model(th);
        let (a, y) = design(&mm, self.lin, self.data, self.mask);
        let rows_per_ch = 2 * self.mask.len();
        let m = a.nrows();
        if r.len() != m {
            return None;
        }
        let fact = factor(&a, self.lin, self.data, rows_per_ch)?;
        let [b] = fact.as_slice() else {
            return None;
        };
        if b.rows.len() != m || b.rows.iter().enumerate().any(|(i, r)| i != *r) {
            return None;
        }
        let n = self.lin.len();
        let mut x = DVector::<f64>::zeros(n);
        let qty = b.q.tr_mul(&y);
        let zsol = b.r.solve_upper_triangular(&qty)?;
        for (i, j) in b.cols.iter().enumerate() {
            x[*j] = zsol[i] / b.scale[i];
        }
        if x.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let res = &y - &a * &x;
        let kk = self.nl.len();
        let (u, t_all) = self.negated_derivatives(&mm, &a, th, &x, &res);
        let w = DMatrix::from_fn(b.cols.len(), kk, |i, k| t_all[(b.cols[i], k)] / b.scale[i]);
        let z = b.r.tr_solve_upper_triangular(&w)?;
        let qtu = b.q.tr_mul(&u);
        let mut jtj = z.tr_mul(&z) - qtu.tr_mul(&qtu);
        // `uᵀu` channel by channel, over the columns not zero on the channel's rows.
        for ch in 0..self.data.n_ch() {
            let rows = ch * rows_per_ch..(ch + 1) * rows_per_ch;
            let nz: Vec<usize> = (0..kk)
                .filter(|k| {
                    u.column(*k)
                        .rows_range(rows.clone())
                        .iter()
                        .any(|v| *v != 0.0)
                })
                .collect();
            if nz.is_empty() {
                continue;
            }
            let sub = DMatrix::from_fn(rows_per_ch, nz.len(), |i, j| u[(rows.start + i, nz[j])]);
            let p = sub.transpose() * &sub;
            for (i, a) in nz.iter().enumerate() {
                for (j, c) in nz.iter().enumerate() {
                    jtj[(*a, *c)] += p[(i, j)];
                }
            }
        }
        let rv = DVector::from_column_slice(r);
        let c = z - &qtu;
        let g = u.tr_mul(&rv) + c.tr_mul(&b.q.tr_mul(&rv));
        (jtj.iter().all(|v| v.is_finite()) && g.iter().all(|v| v.is_finite())).then_some((jtj, g))
    }

    /// Fills `jac` with `∂r/∂θ` at `θ` (the residual `r = y − A x`, rows as
    /// [`crate::diagnose::lsq::slots::design`]); `false` when a block is rank-deficient or the solution is
    /// not finite.
    pub fn jacobian(&self, th: &[f64], jac: &mut DMatrix<f64>) -> bool {
        let mm = self.model(th);
        let (a, y) = design(&mm, self.lin, self.data, self.mask);
        let rows_per_ch = 2 * self.mask.len();
        let Some(fact) = factor(&a, self.lin, self.data, rows_per_ch) else {
            return false;
        };
        let n = self.lin.len();
        let mut x = DVector::<f64>::zeros(n);
        for b in &fact {
            let yb = DVector::from_fn(b.rows.len(), |i, _| y[b.rows[i]]);
            let qty = b.q.tr_mul(&yb);
            let Some(z) = b.r.solve_upper_triangular(&qty) else {
                return false;
            };
            for (i, j) in b.cols.iter().enumerate() {
                x[*j] = z[i] / b.scale[i];
            }
        }
        let m = a.nrows();
        if x.iter().any(|v| !v.is_finite()) || jac.nrows() != m {
            return false;
        }
        let res = &y - &a * &x;
        // `∂r/∂θ = −(U + Q (Z − QᵀU))`, `U = [A_k x]_k`, `Z = R⁻ᵀ S T`, `T = [A_kᵀ r]_k`:
        // `U` and `T` are accumulated negated, so the sign needs no pass of its own.
        let kk = self.nl.len();
        let (mut u, t_all) = self.negated_derivatives(&mm, &a, th, &x, &res);
        let single = matches!(fact.as_slice(), [b] if b.rows.len() == m
            && b.rows.iter().enumerate().all(|(i, r)| i == *r));
        if single {
            // One block over every row (one output, or SISO): no gather, no scatter.
            let b = &fact[0];
            let w = DMatrix::from_fn(n, kk, |i, k| t_all[(b.cols[i], k)] / b.scale[i]);
            let Some(z) = b.r.tr_solve_upper_triangular(&w) else {
                return false;
            };
            // `Qᵀ U` through an explicit transpose (Q is thin): the blocked product, not
            // one dot product per entry.
            let c = z - b.q.transpose() * &u;
            std::mem::swap(jac, &mut u);
            jac.gemm(1.0, &b.q, &c, 1.0);
            return jac.iter().all(|v| v.is_finite());
        }
        jac.fill(0.0);
        for b in &fact {
            let ub = DMatrix::from_fn(b.rows.len(), kk, |i, k| u[(b.rows[i], k)]);
            let w = DMatrix::from_fn(b.cols.len(), kk, |i, k| t_all[(b.cols[i], k)] / b.scale[i]);
            let Some(z) = b.r.tr_solve_upper_triangular(&w) else {
                return false;
            };
            let c = z - b.q.transpose() * &ub;
            let col = ub + &b.q * c;
            for k in 0..kk {
                for (i, row) in b.rows.iter().enumerate() {
                    jac[(*row, k)] = col[(i, k)];
                }
            }
        }
        jac.iter().all(|v| v.is_finite())
    }
}

#[cfg(test)]
pub(super) mod tests;

//! Realizations: transfer-function matrices to state space, minimal realizations by
//! orthogonal (block-Arnoldi) staircase reduction, balanced truncation, and checks of
//! user-given `A, B, C, D`.

use super::riccati::lyapunov;
use super::state_space::StateSpace;
use super::tf_matrix::TfMatrix;
use crate::error::{Error, Result};
use nalgebra::DMatrix;

impl StateSpace {
    /// Number of states.
    pub fn states(&self) -> usize {
        self.a.nrows()
    }

    /// The same system after diagonal balancing of `A` (an exact similarity by powers of
    /// two, see `balancing` in `eig.rs`).
    pub fn balanced(&self) -> StateSpace {
        let d = super::eig::balancing(&self.a);
        StateSpace {
            a: super::eig::apply_balancing(&self.a, &d),
            b: DMatrix::from_fn(self.b.nrows(), self.b.ncols(), |i, j| self.b[(i, j)] / d[i]),
            c: DMatrix::from_fn(self.c.nrows(), self.c.ncols(), |i, j| self.c[(i, j)] * d[j]),
            d: self.d.clone(),
        }
    }

    /// Checks that the four matrices fit together (`A` n×n, `B` n×m, `C` p×n, `D` p×m) and
    /// that every entry is finite; `what` names the source in the message.
    pub fn validate(&self, what: &str) -> Result<()> {
        let n = self.a.nrows();
        let (p, m) = self.d.shape();
        let bad = |msg: String| Err(Error::Invalid(format!("{what}: {msg}")));
        if self.a.ncols() != n {
            return bad(format!("A must be square, got {}×{}", n, self.a.ncols()));
        }
        if self.b.shape() != (n, m) {
            return bad(format!(
                "B must be {n}×{m} (states × inputs, from A and D), got {}×{}",
                self.b.nrows(),
                self.b.ncols()
            ));
        }
        if self.c.shape() != (p, n) {
            return bad(format!(
                "C must be {p}×{n} (outputs × states, from A and D), got {}×{}",
                self.c.nrows(),
                self.c.ncols()
            ));
        }
        if p == 0 || m == 0 {
            return bad("D must have at least one row and one column".into());
        }
        for (name, mat) in [
            ("A", &self.a),
            ("B", &self.b),
            ("C", &self.c),
            ("D", &self.d),
        ] {
            if let Some(k) = mat.iter().position(|v| !v.is_finite()) {
                // nalgebra is column-major.
                let (i, j) = (k % mat.nrows(), k / mat.nrows());
                return bad(format!(
                    "{name}[{}][{}] is not finite; every entry must be a number",
                    i + 1,
                    j + 1
                ));
            }
        }
        Ok(())
    }

    /// A (generally non-minimal) realization of a proper transfer-function matrix: one
    /// controllable-canonical block per entry. Follow with [`StateSpace::minimal`].
    pub fn from_tf_matrix(g: &TfMatrix) -> Self {
        let (p, m) = (g.rows(), g.cols());
        let blocks: Vec<(usize, usize, StateSpace)> = (0..p)
            .flat_map(|i| (0..m).map(move |j| (i, j)))
            .map(|(i, j)| (i, j, StateSpace::from_tf(g.entry(i, j))))
            .collect();
        let n: usize = blocks.iter().map(|(_, _, s)| s.states()).sum();
        let mut ss = StateSpace {
            a: DMatrix::zeros(n, n),
            b: DMatrix::zeros(n, m),
            c: DMatrix::zeros(p, n),
            d: DMatrix::zeros(p, m),
        };
        let mut k = 0;
        for (i, j, s) in blocks {
            let ni = s.states();
            ss.a.view_mut((k, k), (ni, ni)).copy_from(&s.a);
            ss.b.view_mut((k, j), (ni, 1)).copy_from(&s.b);
            ss.c.view_mut((i, k), (1, ni)).copy_from(&s.c);
            ss.d[(i, j)] = s.d[(0, 0)];
            k += ni;
        }
        ss
    }

    /// A minimal realization: the controllable part by an orthogonal block-Arnoldi
    /// (staircase) reduction, then the observable part of that by duality.
    ///
    /// The rank decisions are scale-invariant: `A` is balanced first (an exact diagonal
    /// similarity), each column of `B` (each row of `C` in the dual pass) is normalized
    /// before the first Krylov block is ranked (scaling an input or output does not change
    /// the controllable or observable subspace), and later blocks `A·V` (`V` orthonormal)
    /// are ranked relative to `‖A‖`. A direction with a singular value below `tol` times
    /// that reference counts as absent. So a plant scaled by `10^k` keeps its states for
    /// any finite `k` (a small output gain no longer makes every state "unobservable").
    pub fn minimal(&self, tol: f64) -> Self {
        let sys = if self.states() > 0 {
            self.balanced()
        } else {
            self.clone()
        };
        let c = sys.controllable_part(tol);
        let dual = StateSpace {
            a: c.a.transpose(),
            b: c.c.transpose(),
            c: c.b.transpose(),
            d: c.d.transpose(),
        }
        .controllable_part(tol);
        StateSpace {
            a: dual.a.transpose(),
            b: dual.c.transpose(),
            c: dual.b.transpose(),
            d: dual.d.transpose(),
        }
    }

    fn controllable_part(&self, tol: f64) -> Self {
        let n = self.states();
        if n == 0 {
            return self.clone();
        }
        let a_scale = self.a.norm();
        // Each input direction normalized: the controllable subspace is that of B·S for
        // any invertible diagonal S, so B's own size must not decide its rank.
        let mut block = self.b.clone();
        for mut col in block.column_iter_mut() {
            let nrm = col.norm();
            if nrm > 0.0 && nrm.is_finite() {
                col.unscale_mut(nrm);
            }
        }
        let mut basis: Vec<nalgebra::DVector<f64>> = Vec::new();
        let mut first = true;
        for _ in 0..=n {
            // Orthogonalize twice against the basis (classical Gram–Schmidt, repeated).
            for _ in 0..2 {
                for v in &basis {
                    let proj = v.transpose() * &block;
                    block -= v * proj;
                }
            }
            let svd = block.clone().svd(true, false);
            let u = svd.u.expect("svd u");
            // The first block has unit columns; later ones are A times orthonormal columns.
            let reference = if first { 1.0 } else { a_scale };
            first = false;
            let mut added = Vec::new();
            for (k, s) in svd.singular_values.iter().enumerate() {
                if *s > tol * reference && basis.len() + added.len() < n {
                    added.push(u.column(k).into_owned());
                }
            }
            if added.is_empty() {
                break;
            }
            let next = DMatrix::from_columns(&added);
            block = &self.a * &next;
            basis.extend(added);
        }
        if basis.len() == n {
            return self.clone();
        }
        if basis.is_empty() {
            return StateSpace {
                a: DMatrix::zeros(0, 0),
                b: DMatrix::zeros(0, self.b.ncols()),
                c: DMatrix::zeros(self.c.nrows(), 0),
                d: self.d.clone(),
            };
        }
        let v = DMatrix::from_columns(&basis);
        StateSpace {
            a: v.transpose() * &self.a * &v,
            b: v.transpose() * &self.b,
            c: &self.c * &v,
            d: self.d.clone(),
        }
    }

    /// Balanced truncation to `order` states (square-root method): Gramians from two
    /// Lyapunov equations, Hankel singular values from the SVD of the product of their
    /// square-root factors. Returns the reduced model and all Hankel singular values; the
    /// H∞ error is at most `2·Σ_{i>order} σᵢ` (Glover 1984). Needs a stable `A`.
    pub fn balanced_truncation(&self, order: usize) -> Result<(StateSpace, Vec<f64>)> {
        let n = self.states();
        if order == 0 || order > n {
            return Err(Error::Invalid(format!(
                "balanced truncation to {order} states: choose 1 ≤ order ≤ {n}"
            )));
        }
        // AP + PAᵀ + BBᵀ = 0 and AᵀQ + QA + CᵀC = 0.
        let p = lyapunov(
            &self.a.transpose(),
            &(&self.b * self.b.transpose()),
            "controllability Gramian (is A stable?)",
        )?;
        let q = lyapunov(
            &self.a,
            &(self.c.transpose() * &self.c),
            "observability Gramian (is A stable?)",
        )?;
        let lp = psd_sqrt(&p);
        let lq = psd_sqrt(&q);
        let svd = (lq.transpose() * &lp).svd(true, true);
        let (u, vt) = (svd.u.expect("u"), svd.v_t.expect("v_t"));
        let hsv: Vec<f64> = svd.singular_values.iter().copied().collect();
        let mut idx: Vec<usize> = (0..hsv.len()).collect();
        idx.sort_by(|a, b| hsv[*b].total_cmp(&hsv[*a]));
        let keep = &idx[..order];
        if hsv[keep[order - 1]].is_nan() || hsv[keep[order - 1]] <= 0.0 {
            return Err(Error::Invalid(format!(
                "balanced truncation: Hankel singular value {order} is zero; choose a smaller order"
            )));
        }
        let mut t = DMatrix::zeros(n, order);
        let mut ti = DMatrix::zeros(order, n);
        for (k, &i) in keep.iter().enumerate() {
            let s = hsv[i].powf(-0.5);
            t.set_column(k, &(&lp * vt.row(i).transpose() * s));
            ti.set_row(k, &(u.column(i).transpose() * lq.transpose() * s));
        }
        let mut sorted = hsv.clone();
        sorted.sort_by(|a, b| b.total_cmp(a));
        Ok((
            StateSpace {
                a: &ti * &self.a * &t,
                b: &ti * &self.b,
                c: &self.c * &t,
                d: self.d.clone(),
            },
            sorted,
        ))
    }
}

/// A square-root factor `L` with `L·Lᵀ = P` of a symmetric positive semidefinite matrix
/// (negative round-off eigenvalues are set to zero).
fn psd_sqrt(p: &DMatrix<f64>) -> DMatrix<f64> {
    let sym = (p + p.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let mut l = eig.eigenvectors.clone();
    for (k, lam) in eig.eigenvalues.iter().enumerate() {
        let s = lam.max(0.0).sqrt();
        l.column_mut(k).scale_mut(s);
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::system::TransferFunction;

    #[test]
    fn shared_pole_is_realized_once() {
        // [1/(s−1)  2/(s−1)] has McMillan degree 1.
        let g = TfMatrix::from_rows(vec![vec![
            TransferFunction::new(vec![1.0], vec![1.0, -1.0]),
            TransferFunction::new(vec![2.0], vec![1.0, -1.0]),
        ]])
        .unwrap();
        let full = StateSpace::from_tf_matrix(&g);
        assert_eq!(full.states(), 2);
        let min = full.minimal(1e-10);
        assert_eq!(min.states(), 1);
        for w in [0.1, 1.0, 10.0] {
            assert!((full.freq(w).unwrap() - min.freq(w).unwrap()).norm() < 1e-12);
        }
        assert!((min.a[(0, 0)] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn validate_names_the_bad_entry() {
        let mut ss = StateSpace {
            a: DMatrix::zeros(2, 2),
            b: DMatrix::zeros(2, 1),
            c: DMatrix::zeros(1, 2),
            d: DMatrix::zeros(1, 1),
        };
        assert!(ss.validate("m").is_ok());
        ss.a[(1, 0)] = f64::NAN;
        assert!(ss
            .validate("m")
            .unwrap_err()
            .to_string()
            .contains("A[2][1]"));
        ss.a[(1, 0)] = 0.0;
        ss.b = DMatrix::zeros(3, 1);
        assert!(ss
            .validate("m")
            .unwrap_err()
            .to_string()
            .contains("B must be 2×1"));
    }
}

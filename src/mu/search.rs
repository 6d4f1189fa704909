//! The search over `t = ln d` for the D-scaled upper bound and its lower-bound witnesses
//! (see the parent module for the theory).

use super::{lower_of, MuSettings};
use nalgebra::{DMatrix, DVector, SVD};
use num_complex::Complex64;

/// One evaluation of the search at `t = ln d`.
pub(super) struct Eval {
    pub(super) sigma: f64,
    pub(super) h: f64,
    /// `d²(ln σ̄²)/dt²` (NaN when `σ̄` is repeated or zero).
    pub(super) curv: f64,
}

/// The matrix `M` of a search: given, or built on first use from a structured description
/// (a search that stays on the O(n) low-rank path never forms the dense `(n+2)×(n+1)` matrix).
pub(super) struct Dense<'a> {
    given: Option<&'a DMatrix<Complex64>>,
    make: Option<&'a dyn Fn() -> DMatrix<Complex64>>,
    built: std::cell::OnceCell<DMatrix<Complex64>>,
}

impl<'a> Dense<'a> {
    pub(super) fn given(m: &'a DMatrix<Complex64>) -> Self {
        Self {
            given: Some(m),
            make: None,
            built: std::cell::OnceCell::new(),
        }
    }

    pub(super) fn lazy(make: &'a dyn Fn() -> DMatrix<Complex64>) -> Self {
        Self {
            given: None,
            make: Some(make),
            built: std::cell::OnceCell::new(),
        }
    }

    /// `M` itself (built now if it was not given).
    pub(super) fn get(&self) -> &DMatrix<Complex64> {
        match (self.given, self.make) {
            (Some(m), _) => m,
            (None, Some(make)) => self.built.get_or_init(make),
            (None, None) => unreachable!("a Dense is built given or lazy"),
        }
    }
}

pub(super) struct Search<'a> {
    pub(super) m: Dense<'a>,
    pub(super) q: usize,
    pub(super) k: usize,
    pub(super) settings: &'a MuSettings,
    pub(super) evals: usize,
    pub(super) upper: f64,
    pub(super) t_upper: f64,
    /// `‖y₁‖²` of the top left singular vector at `t_upper`.
    pub(super) share_upper: f64,
    pub(super) lower: f64,
    pub(super) witness: Option<DVector<Complex64>>,
    pub(super) svd_failed: bool,
    /// `M = E + a·bᴴ` when the caller knows it ([`super::low_rank`]): O(n) evaluations.
    pub(super) low_rank: Option<&'a super::LowRank>,
}

impl<'a> Search<'a> {
    pub(super) fn new(
        m: Dense<'a>,
        q: usize,
        k: usize,
        settings: &'a MuSettings,
        low_rank: Option<&'a super::LowRank>,
    ) -> Self {
        Self {
            m,
            q,
            k,
            settings,
            evals: 0,
            upper: f64::INFINITY,
            t_upper: f64::NAN,
            share_upper: f64::NAN,
            lower: 0.0,
            witness: None,
            svd_failed: false,
            low_rank,
        }
    }

    pub(super) fn scaled(&self, t: f64) -> DMatrix<Complex64> {
        let (d, (q, k)) = (t.exp(), (self.q, self.k));
        let mut md = self.m.get().clone();
        for j in 0..q {
            md[(k, j)] *= d;
        }
        for i in 0..k {
            md[(i, q)] /= d;
        }
        md
    }

    pub(super) fn svd(&mut self, t: f64) -> Option<SVD<Complex64, nalgebra::Dyn, nalgebra::Dyn>> {
        self.evals += 1;
        let svd = SVD::try_new_unordered(
            self.scaled(t),
            true,
            true,
            5.0 * f64::EPSILON,
            self.settings.svd_max_iter,
        );
        if svd.is_none() {
            self.svd_failed = true;
        }
        svd
    }

    /// Offers the unscaled vector `x` (columns of `M`) as a lower-bound witness.
    pub(super) fn offer(&mut self, x: DVector<Complex64>) {
        // With a low-rank description (checked against `m` to rounding) the product is O(n).
        let z = match self.low_rank {
            Some(lr) => lr.times(&x),
            None => self.m.get() * &x,
        };
        let lb = lower_of(&x, &z, self.q, self.k);
        if lb > self.lower {
            self.lower = lb;
            self.witness = Some(x);
        }
    }

    pub(super) fn gap_ok(&self) -> bool {
        self.upper - self.lower <= self.settings.rel_gap * self.upper
    }

    /// Evaluates `σ̄(M_d)` and `h(t)` at `t = ln d`, updating both bounds.
    ///
    /// The top right singular pair comes from the Hermitian eigenproblem of the Gram matrix
    /// `M_dᴴM_d` (about half the cost of a complex SVD at these sizes): `σ̄ = √λ_max` (the
    /// largest eigenvalue is computed to `O(ε)‖M_d‖²`, i.e. `σ̄` to `O(ε)` relative), `x` its
    /// eigenvector and `y = M_d x/σ̄`.  The lower bound uses `x` through the exact formula of
    /// [`lower_of`], so an inexact `x` can only weaken it, never invalidate it.
    pub(super) fn eval(&mut self, t: f64) -> Option<Eval> {
        if let Some(e) = self.low_rank.and_then(|lr| self.eval_low_rank(lr, t)) {
            return Some(e);
        }
        self.evals += 1;
        let (q, k) = (self.q, self.k);
        let md = self.scaled(t);
        let gram = md.adjoint() * &md;
        let Some(eig) = gram.try_symmetric_eigen(f64::EPSILON, self.settings.svd_max_iter) else {
            self.svd_failed = true;
            return None;
        };
        let (imax, &lambda) = eig
            .eigenvalues
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))?;
        let sigma = lambda.max(0.0).sqrt();
        let xs = eig.eigenvectors.column(imax);
        let ys = &md * xs;
        // h = |y_k|² − |x_q|² = ‖x₁‖² − ‖y₁‖² (unit x, y): use the form built from the
        // smaller parts, which avoids cancellation when one block carries almost everything.
        let h = if sigma == 0.0 {
            0.0
        } else if xs[q].norm_sqr() > 0.5 {
            xs.rows(0, q).norm_squared() - ys.rows(0, k).norm_squared() / (sigma * sigma)
        } else {
            ys[k].norm_sqr() / (sigma * sigma) - xs[q].norm_sqr()
        };
        let curv = curvature(&md, &eig.eigenvalues, &eig.eigenvectors, imax, ys[k], q, k);
        if sigma < self.upper {
            self.upper = sigma;
            self.t_upper = t;
            self.share_upper = if sigma > 0.0 {
                ys.rows(0, k).norm_squared() / (sigma * sigma)
            } else {
                f64::NAN
            };
        }
        // Unscale by D_r⁻¹.
        let mut x = xs.into_owned();
        x[q] /= t.exp();
        self.offer(x);
        Some(Eval { sigma, h, curv })
    }

    /// [`Search::eval`] for `M = E + a·bᴴ` in O(n) ([`super::low_rank::top_pair`]); the
    /// curvature is the difference quotient of `h` over a step of `1e-6` in `t` (a second
    /// structured evaluation).  `None` (nothing counted or offered) sends the caller to the
    /// dense eigenproblem.
    fn eval_low_rank(&mut self, lr: &super::LowRank, t: f64) -> Option<Eval> {
        let (q, k) = (self.q, self.k);
        let hs = |tp: &super::low_rank::TopPair| {
            let s2 = tp.lambda;
            if tp.x[q].norm_sqr() > 0.5 {
                tp.x.rows(0, q).norm_squared() - tp.y.rows(0, k).norm_squared() / s2
            } else {
                tp.y[k].norm_sqr() / s2 - tp.x[q].norm_sqr()
            }
        };
        let tp = super::low_rank::top_pair(lr, q, k, t)?;
        let step = 1e-6 * t.abs().max(1.0);
        let curv = super::low_rank::top_pair(lr, q, k, t + step)
            .map_or(f64::NAN, |tp2| 2.0 * (hs(&tp2) - hs(&tp)) / step);
        self.evals += 1;
        let sigma = tp.lambda.sqrt();
        let h = hs(&tp);
        if sigma < self.upper {
            self.upper = sigma;
            self.t_upper = t;
            self.share_upper = tp.y.rows(0, k).norm_squared() / tp.lambda;
        }
        let mut x = tp.x;
        x[q] /= t.exp();
        self.offer(x);
        Some(Eval { sigma, h, curv })
    }

    /// Rebalancing of the witness `x = (x₁, x₂)`: at the precision limit of the search the
    /// two ratios of [`lower_of`] differ slightly (most when one part of `x` is tiny, which
    /// amplifies rounding in `h`).  Rescaling `x₂` by a real `α` moves them in opposite
    /// directions; bisection on `ln α ∈ [−0.1, 0.1]` for the sign of `r₁ − r₂` equalizes them.
    pub(super) fn balance_candidate(&mut self) {
        let Some(x0) = self.witness.clone() else {
            return;
        };
        let q = self.q;
        if x0.rows(0, q).norm() == 0.0 || x0[q].norm() == 0.0 {
            return;
        }
        let at = |s: f64| {
            let mut x = x0.clone();
            x[q] *= s.exp();
            x
        };
        let diff = |x: &DVector<Complex64>| {
            let z = self.m.get() * x;
            z.rows(0, self.k).norm() / x.rows(0, q).norm() - z[self.k].norm() / x[q].norm()
        };
        let (mut lo, mut hi) = (-0.1, 0.1);
        let (dlo, dhi) = (diff(&at(lo)), diff(&at(hi)));
        if dlo.signum() == dhi.signum() {
            return;
        }
        let rising = dhi > dlo;
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if (diff(&at(mid)) > 0.0) == rising {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        self.offer(at(lo));
        self.offer(at(hi));
    }

    /// Repeated-`σ̄` candidate at the best `t`: combines the top two right singular vectors
    /// `x = c₁a + c₂b` so that the Hermitian form `|y_last|² − |x_last|²` vanishes.
    pub(super) fn kink_candidate(&mut self) {
        let t = self.t_upper;
        let Some(svd) = self.svd(t) else { return };
        let (Some(u), Some(vt)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
            return;
        };
        let mut idx: Vec<usize> = (0..svd.singular_values.len()).collect();
        idx.sort_by(|a, b| svd.singular_values[*b].total_cmp(&svd.singular_values[*a]));
        if idx.len() < 2 {
            return;
        }
        let (q, k) = (self.q, self.k);
        let (ia, ib) = (idx[0], idx[1]);
        let ya = [u[(k, ia)], u[(k, ib)]];
        let xa = [vt[(ia, q)].conj(), vt[(ib, q)].conj()];
        // H_ij = conj(y_i) y_j − conj(x_i) x_j (2×2 Hermitian).
        let h = |i: usize, j: usize| ya[i].conj() * ya[j] - xa[i].conj() * xa[j];
        let (a, b, c) = (h(0, 0).re, h(1, 1).re, h(0, 1));
        let mean = 0.5 * (a + b);
        let rad = (0.25 * (a - b) * (a - b) + c.norm_sqr()).sqrt();
        let (lp, lm) = (mean + rad, mean - rad);
        if !(lp >= 0.0 && lm <= 0.0) || lp - lm <= 0.0 {
            return;
        }
        // Eigenvectors of [[a, c], [c̄, b]]: (c, l − a) or (l − b, c̄), whichever is longer
        // (the other can cancel catastrophically).
        let ev = |l: f64| -> [Complex64; 2] {
            let v1 = [c, Complex64::new(l - a, 0.0)];
            let v2 = [Complex64::new(l - b, 0.0), c.conj()];
            let n1 = v1[0].norm_sqr() + v1[1].norm_sqr();
            let n2 = v2[0].norm_sqr() + v2[1].norm_sqr();
            let (v, n) = if n1 >= n2 { (v1, n1) } else { (v2, n2) };
            let n = n.sqrt();
            [v[0] / n, v[1] / n]
        };
        let (ep, em) = (ev(lp), ev(lm));
        let cos = (-lm / (lp - lm)).sqrt();
        let sin = (lp / (lp - lm)).sqrt();
        let coef = [cos * ep[0] + sin * em[0], cos * ep[1] + sin * em[1]];
        let d = t.exp();
        let x = DVector::from_fn(q + 1, |j, _| {
            let v = coef[0] * vt[(ia, j)].conj() + coef[1] * vt[(ib, j)].conj();
            if j == q {
                v / d
            } else {
                v
            }
        });
        self.offer(x);
    }
}

/// Second derivative of `f(t) = ln λ₁(t)`, `λ₁ = σ̄²(M_d)`, `M_d = A(t)`, from the full
/// eigen-decomposition of `G = AᴴA` (`A' = PA − AQ`, `A'' = PA − 2PAQ + AQ`, `P`, `Q` the
/// projectors on the last row and the last column):
/// `λ₁'' = v₁ᴴG''v₁ + 2Σ_{j≠1}|v_jᴴG'v₁|²/(λ₁ − λ_j)`, with `w_j = Av_j`,
/// `v₁ᴴG''v₁ = 2Re(w₁ᴴA''v₁) + 2‖A'v₁‖²`, `v_jᴴG'v₁ = 2·conj(w_jk)w₁k − (λ_j + λ₁)conj(v_jq)v₁q`;
/// then `f'' = λ₁''/λ₁ − (λ₁'/λ₁)²` with `λ₁' = 2(|w₁k|² − λ₁|v₁q|²)`.
fn curvature(
    a: &DMatrix<Complex64>,
    lam: &DVector<f64>,
    vecs: &DMatrix<Complex64>,
    i1: usize,
    w1k: Complex64,
    q: usize,
    k: usize,
) -> f64 {
    let l1 = lam[i1];
    if l1.is_nan() || l1 <= 0.0 {
        return f64::NAN;
    }
    let v1q = vecs[(q, i1)];
    let akq = a[(k, q)];
    let colq = a.column(q).norm_squared();
    let cross = w1k.conj() * akq * v1q;
    let wa = w1k.norm_sqr() - 2.0 * cross.re + l1 * v1q.norm_sqr();
    let apv = w1k.norm_sqr() - 2.0 * cross.re + colq * v1q.norm_sqr();
    let mut l2 = 2.0 * wa + 2.0 * apv;
    for j in 0..lam.len() {
        if j == i1 {
            continue;
        }
        let sep = l1 - lam[j];
        if sep.is_nan() || sep <= 1e-12 * l1 {
            return f64::NAN;
        }
        let wjk: Complex64 = (0..a.ncols()).map(|c| a[(k, c)] * vecs[(c, j)]).sum();
        let g = 2.0 * wjk.conj() * w1k - (lam[j] + l1) * vecs[(q, j)].conj() * v1q;
        l2 += 2.0 * g.norm_sqr() / sep;
    }
    let d1 = 2.0 * (w1k.norm_sqr() - l1 * v1q.norm_sqr()) / l1;
    l2 / l1 - d1 * d1
}

/// Safeguarded Newton search for the minimum of `ln σ̄(M_d)` over `t = ln d`, i.e. the root of
/// `h(t)` (`d ln σ̄²/dt = 2h`), stopping as soon as the gap closes.  `h` changes sign once
/// because `σ̄(M_d)` is convex in `t`; every evaluation narrows the bracket `[lo, hi]`
/// (`h(lo) < 0 < h(hi)`).  A Newton step is taken when the curvature is positive and the
/// step stays inside the bracket (and below 2 in length); otherwise the bracket is bisected,
/// or, while it is still open on one side, grown by doubling steps within `±log_d_range`.
pub(super) fn newton_search(s: &mut Search, t0: f64) {
    let cap = s.settings.max_evals;
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut t = t0;
    let mut grow = 0.5;
    while s.evals < cap {
        let Some(e) = s.eval(t) else { return };
        if s.gap_ok() || e.h == 0.0 || e.sigma == 0.0 {
            return;
        }
        if e.h > 0.0 {
            hi = hi.min(t);
        } else {
            lo = lo.max(t);
        }
        if hi - lo <= 4.0 * f64::EPSILON * t.abs().max(1.0) {
            return;
        }
        let newton = t - 2.0 * e.h / e.curv;
        t = if e.curv > 0.0 && newton > lo && newton < hi && (newton - t).abs() <= 2.0 {
            newton
        } else if lo.is_finite() && hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            let next = if e.h > 0.0 { t - grow } else { t + grow };
            grow *= 2.0;
            if (next - t0).abs() > s.settings.log_d_range {
                return;
            }
            next
        };
    }
}

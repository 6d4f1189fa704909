//! The loop of Fig. 1 of Boulet & Francis (1998) around any factorization
//! `G = C·M̃⁻¹·Ñ·J` (eq. (1)): the realization the perturbation `Δ = [Δ_N  −Δ_M]` sees,
//! the Theorem 1 system `T`, and `T(jω)` straight from the factor values.
//!
//! With the modal signal `ξ` of `M̃_p·ξ = Ñ_p·J·u`, `y = C·ξ`, the perturbation enters as
//! `M̃·ξ = Ñ·J·u + w`, `w = Δ·z`, `z = [J·u; ξ]`. Closing `u = −K·y` gives
//!
//! `T : w ↦ z = [−J·K·C; I_n]·(M̃ + Ñ·J·K·C)⁻¹`,
//!
//! the matrix of condition 2 of Theorem 1 (the paper writes it for `u = +K·y` as
//! `[JKC; I](I − M̃⁻¹ÑJKC)⁻¹M̃⁻¹`; the norm is the same). For the standard factorization
//! (`C = I`, `J = I`) this is `[−K; I](I + GK)⁻¹M̃⁻¹`; for the special factorization of a
//! flexible structure `ξ` holds one entry per mode and `T` has `m + n` rows and `n` columns.

use crate::error::{Error, Result};
use crate::model::Factorization;
use crate::system::freq_eval::FreqEvaluator;
use crate::system::interconnect::negative_feedback;
use crate::system::{StateSpace, TfMatrix, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// A realization of `M̃⁻¹·[Ñ·J  I_n]`: inputs `[u; w]`, output the modal signal `ξ`.
///
/// For normalized state-space factors (a `[plant]`) it is `[G  M̃⁻¹]` sharing the plant's
/// states. For factors typed as transfer functions it is the cascade `M̃⁻¹·[Ñ·J  I]`, whose
/// hidden modes are poles of the (stable) factors `Ñ`, `J` and zeros of `M̃`; the latter
/// are poles of the modal system itself, so the closed-loop eigenvalues decide the
/// internal stability of the loop of Fig. 1 (modes that `C` does not see included).
pub fn modal_system(f: &Factorization) -> Result<StateSpace> {
    if let Some(ncf) = &f.realization {
        return Ok(ncf.plant_and_m_inverse());
    }
    if f.states() >= CASCADE_ROWS_FROM && f.m.is_diagonal() {
        // `J` once for all rows (its poles once, as in the whole-matrix cascade).
        return Ok(modal_rows(f, Rows::Cascade)?.series(&j_and_identity(f)));
    }
    modal_cascade(f)
}

/// From this many modal coordinates on, [`modal_system`] of a diagonal `M̃` realizes the
/// cascade one row at a time (`M̃ᵢᵢ⁻¹·[Ñᵢ  1]`, stacked): the same poles (hidden modes of the
/// factors included), without the staircase reduction of a system with `n + m` inputs and
/// `2n` states (1000 modes: minutes, issue 34). Below it, the whole-matrix cascade (the
/// figures of small models unchanged to the last digit).
pub const CASCADE_ROWS_FROM: usize = 50;

/// The cascade `M̃⁻¹·[Ñ·J  I]` of the whole matrices, made minimal factor by factor: what
/// [`modal_system`] is below [`CASCADE_ROWS_FROM`] modal coordinates (or for a
/// non-diagonal `M̃`), and the dense route its row-by-row realization is checked against.
pub fn modal_cascade(f: &Factorization) -> Result<StateSpace> {
    let (n, m) = (f.states(), f.inputs());
    let rows: Vec<Vec<TransferFunction>> = (0..n)
        .map(|i| {
            let mut row: Vec<TransferFunction> =
                (0..m).map(|j| f.n.entry(i, j).mul(&f.j[j])).collect();
            row.extend((0..n).map(|k| TransferFunction::gain(if i == k { 1.0 } else { 0.0 })));
            row
        })
        .collect();
    let nj_i = TfMatrix::from_rows(rows).expect("rectangular");
    let s = StateSpace::from_tf_matrix(&nj_i).minimal(1e-12);
    let mm = StateSpace::from_tf_matrix(&f.m).minimal(1e-12);
    Ok(mm.inverse("M̃")?.series(&s))
}

/// `M̃⁻¹·[Ñ  I_n]` for a diagonal `M̃` (every `[physical]` model), one modal coordinate at a
/// time: row `i` is `M̃ᵢᵢ⁻¹·[Ñᵢ  1]`, realized and made minimal on its own (a few states,
/// balanced), and the rows are stacked block-diagonally. When `Ñᵢ` has the denominator of
/// `M̃ᵢᵢ` (a mode: `Ñᵢ = b·s^k/q`, `M̃ᵢᵢ = d/q`), `q` is cancelled exactly and the row is
/// `[b·s^k  q]/d`: 2 states per mode.
///
/// Why: in the cascade of the whole matrices the poles `q(s)` of `Ñ` cancel the zeros of
/// `M̃⁻¹` only to rounding; on 20 or more lightly damped modes (10..1e4 rad/s) the minimal
/// realization of that cascade kept all 4 states per mode (the hidden ones nearly
/// uncontrollable and unobservable), and the filter Riccati equation of the plant did not
/// converge (`synthesize` failed, issue 34 item 9).
///
/// With [`Rows::Cascade`] each row is instead the cascade `M̃ᵢᵢ⁻¹·[Ñᵢ  1]` without the
/// cancellation (4 states per mode, its hidden modes kept): the realization of
/// [`modal_system`] for a large diagonal `M̃`, block by block.
pub(crate) fn modal_rows(f: &Factorization, how: Rows) -> Result<StateSpace> {
    let (n, m) = (f.states(), f.inputs());
    let mut blocks = Vec::with_capacity(n);
    for i in 0..n {
        let mii = f.m.entry(i, i);
        let nrow: Vec<&TransferFunction> = (0..m).map(|j| f.n.entry(i, j)).collect();
        if how == Rows::Cascade {
            let row: Vec<TransferFunction> = nrow
                .iter()
                .map(|t| (*t).clone())
                .chain(std::iter::once(TransferFunction::gain(1.0)))
                .collect();
            let s = StateSpace::from_tf_matrix(&TfMatrix::from_rows(vec![row]).expect("one row"))
                .minimal(1e-12);
            let mi =
                StateSpace::from_tf_matrix(&TfMatrix::diagonal(vec![mii.clone()])).minimal(1e-12);
            blocks.push(mi.inverse("M̃")?.series(&s));
            continue;
        }
        if nrow.iter().all(|t| t.den == mii.den) {
            // The common case (a [physical] mode: Ñᵢ = b·s^k/q, M̃ᵢᵢ = d/q): cancel q exactly,
            // `M̃ᵢᵢ⁻¹·[Ñᵢ  1] = [b·s^k  q]/d`, and realize that row of one denominator.
            let mut row: Vec<TransferFunction> = nrow
                .iter()
                .map(|t| TransferFunction {
                    num: t.num.clone(),
                    den: mii.num.clone(),
                })
                .collect();
            row.push(TransferFunction {
                num: mii.den.clone(),
                den: mii.num.clone(),
            });
            let tf = TfMatrix::from_rows(vec![row]).expect("one row");
            blocks.push(StateSpace::from_tf_matrix(&tf).minimal(1e-12).balanced());
            continue;
        }
        let mut row: Vec<TransferFunction> = nrow.into_iter().cloned().collect();
        row.push(TransferFunction::gain(1.0));
        let s = StateSpace::from_tf_matrix(&TfMatrix::from_rows(vec![row]).expect("one row"))
            .minimal(1e-12);
        let mi = StateSpace::from_tf_matrix(&TfMatrix::diagonal(vec![mii.clone()])).minimal(1e-12);
        blocks.push(mi.inverse("M̃")?.series(&s).minimal(1e-12).balanced());
    }
    Ok(stack_rows(&blocks, m))
}

/// How [`modal_rows`] realizes a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Rows {
    /// `q` cancelled exactly where `Ñᵢ` has the denominator of `M̃ᵢᵢ` (2 states per mode):
    /// the same transfer function, the factors' hidden modes left out.
    Cancelled,
    /// The cascade `M̃ᵢᵢ⁻¹·[Ñᵢ  1]` (the hidden modes kept): the poles of the loop.
    Cascade,
}

/// The rows `M̃ᵢᵢ⁻¹·[Ñᵢ(·J)  1]` (inputs `[u; wᵢ]`, output `ξᵢ`) stacked into one system with
/// inputs `[u; w]`, block-diagonal `A`.
fn stack_rows(blocks: &[StateSpace], m: usize) -> StateSpace {
    let n = blocks.len();
    let total: usize = blocks.iter().map(StateSpace::states).sum();
    let mut a = DMatrix::zeros(total, total);
    let mut b = DMatrix::zeros(total, m + n);
    let mut c = DMatrix::zeros(n, total);
    let mut d = DMatrix::zeros(n, m + n);
    let mut at = 0;
    for (i, blk) in blocks.iter().enumerate() {
        let k = blk.states();
        a.view_mut((at, at), (k, k)).copy_from(&blk.a);
        b.view_mut((at, 0), (k, m)).copy_from(&blk.b.columns(0, m));
        b.view_mut((at, m + i), (k, 1)).copy_from(&blk.b.column(m));
        c.view_mut((i, at), (1, k)).copy_from(&blk.c);
        d.view_mut((i, 0), (1, m)).copy_from(&blk.d.columns(0, m));
        d[(i, m + i)] = blk.d[(0, m)];
        at += k;
    }
    StateSpace { a, b, c, d }
}

/// `K·C`: the controller reading the modal signal through the output matrix `C`.
fn controller_on_modes(f: &Factorization, k: &StateSpace) -> StateSpace {
    StateSpace {
        a: k.a.clone(),
        b: &k.b * &f.c,
        c: k.c.clone(),
        d: &k.d * &f.c,
    }
}

/// `diag(J, I_n)` as a state-space system (no states when `J` is constant).
fn j_and_identity(f: &Factorization) -> StateSpace {
    let mut diag = f.j.clone();
    diag.extend((0..f.states()).map(|_| TransferFunction::gain(1.0)));
    StateSpace::from_tf_matrix(&TfMatrix::diagonal(diag))
}

/// The Theorem 1 system `w ↦ [J·u; ξ]`, `T = [−J·K·C; I](M̃ + Ñ·J·K·C)⁻¹`, for `u = −K·y`
/// (module docs). States: the modal system, then `K`, then `J`.
pub fn theorem1_system(f: &Factorization, k: &StateSpace) -> Result<StateSpace> {
    if k.d.shape() != (f.inputs(), f.outputs()) {
        return Err(Error::Invalid(format!(
            "the controller must be {}×{} (plant inputs × plant outputs), got {}×{}",
            f.inputs(),
            f.outputs(),
            k.d.nrows(),
            k.d.ncols()
        )));
    }
    let closed = negative_feedback(&modal_system(f)?, &controller_on_modes(f, k), f.inputs())?;
    Ok(j_and_identity(f).series(&closed))
}

/// The loop size (states of [`theorem1_system`]) from which [`theorem1_norm_system`] drops
/// the factors' hidden modes; below it the norms keep the loop of the poles (the figures of
/// small models unchanged to the last digit).
pub const ROW_NORMS_FROM: usize = 200;

/// The same transfer function `T` as [`theorem1_system`], realized for its H∞ norm: for a
/// diagonal `M̃` (factors typed as transfer functions) and a loop of [`ROW_NORMS_FROM`]
/// states or more, the modal system row by row (`modal_rows`, 2 states per mode instead of
/// the cascade's 4), else `full` itself. The hidden modes it leaves out (poles of `Ñ`, `J`)
/// do not change `T`, only its realization; they are in `full`, whose eigenvalues decide
/// internal stability. Why: the Hamiltonian of each norm step is twice the states, and a
/// dense Schur form costs the cube (200 modes: 1600 → 800 + controller, about 8× less).
pub fn theorem1_norm_system(
    f: &Factorization,
    k: &StateSpace,
    full: &StateSpace,
) -> Result<StateSpace> {
    if full.states() < ROW_NORMS_FROM || f.realization.is_some() || !f.m.is_diagonal() {
        return Ok(full.clone());
    }
    row_loop(f, k)
}

/// The Theorem 1 loop on the rows `M̃ᵢᵢ⁻¹·[Ñᵢ  1]` with `q` cancelled (`modal_rows`,
/// [`Rows::Cancelled`]), for a diagonal `M̃`: the same `T` as [`theorem1_system`] without the
/// factors' hidden modes (see [`theorem1_norm_system`] and `loop_poles`).
pub(crate) fn row_loop(f: &Factorization, k: &StateSpace) -> Result<StateSpace> {
    let ms = modal_rows(f, Rows::Cancelled)?.series(&j_and_identity(f));
    let closed = negative_feedback(&ms, &controller_on_modes(f, k), f.inputs())?;
    Ok(j_and_identity(f).series(&closed))
}

/// A realization of the plant `G = C·M̃⁻¹·Ñ·J` (input `u`, output `y`): for a diagonal `M̃`
/// row by row (`modal_rows`: 2 states per mode, what `synthesize` needs), else from the
/// modal system. The Theorem 1 loop keeps [`modal_system`] (its hidden modes included).
pub fn plant_system(f: &Factorization) -> Result<StateSpace> {
    let ms = if f.realization.is_none() && f.m.is_diagonal() {
        modal_rows(f, Rows::Cancelled)?.series(&j_and_identity(f))
    } else {
        modal_system(f)?
    };
    let m = f.inputs();
    Ok(StateSpace {
        a: ms.a.clone(),
        b: ms.b.columns(0, m).into_owned(),
        c: &f.c * &ms.c,
        d: &f.c * ms.d.columns(0, m),
    })
}

/// The system `[d₁; d₂] ↦ [u; y]` of `y = G(u + d₂) + d₁`, `u = −K·y`, i.e.
/// `[−K; I](I + GK)⁻¹[I  G]`, whose H∞ norm is `1/b(G, K)`.
pub fn gang_of_four(f: &Factorization, k: &StateSpace) -> Result<StateSpace> {
    let g = plant_system(f)?;
    let m = f.inputs();
    let p = f.outputs();
    let n = g.states();
    let mut b = DMatrix::zeros(n, m + p + m);
    b.view_mut((0, 0), (n, m)).copy_from(&g.b);
    b.view_mut((0, m + p), (n, m)).copy_from(&g.b);
    let mut d = DMatrix::zeros(p, m + p + m);
    d.view_mut((0, 0), (p, m)).copy_from(&g.d);
    d.view_mut((0, m), (p, p))
        .copy_from(&DMatrix::identity(p, p));
    d.view_mut((0, m + p), (p, m)).copy_from(&g.d);
    let plant = StateSpace {
        a: g.a.clone(),
        b,
        c: g.c.clone(),
        d,
    };
    negative_feedback(&plant, k, m)
}

/// `σ_max` of the gang of four `[−K; I](I + GK)⁻¹[I  G]` at `jω` ([`gang_of_four`], whose
/// H∞ norm is `1/b(G,K)`) from the factor values: `G = C·M̃⁻¹·Ñ·J` with a diagonal `M̃`
/// divided entry by entry (`O(n·m)`, no dense `n × n` solve), else by [`Factorization::plant`].
/// `None` where `M̃` or `I + GK` is singular or `K` has a pole at `jω`. For the start and the
/// local polish of `b(G,K)`'s Hamiltonian iteration on a large loop (an exact value at
/// rounding: it never exceeds the norm but by rounding).
pub fn gang_sigma_max(f: &Factorization, k: &FreqEvaluator, omega: f64) -> Option<f64> {
    let kw = k.freq(omega)?;
    let g = if f.realization.is_none() && f.m.is_diagonal() {
        let n = f.states();
        let mut u = f.n.freq(omega);
        for i in 0..n {
            let d = f.m.entry(i, i).freq(omega);
            if d.norm() == 0.0 || !(d.re.is_finite() && d.im.is_finite()) {
                return None;
            }
            let mut row = u.row_mut(i);
            row /= d;
        }
        for (j, t) in f.j.iter().enumerate() {
            let jj = t.freq(omega);
            let mut col = u.column_mut(j);
            col *= jj;
        }
        f.c.map(|x| Complex64::new(x, 0.0)) * u
    } else {
        f.plant(omega)?
    };
    let (p, m) = g.shape();
    let s = (DMatrix::identity(p, p) + &g * &kw)
        .lu()
        .solve(&DMatrix::identity(p, p))?;
    // [−K; I]·S·[I  G]
    let left = {
        let mut l = DMatrix::zeros(m + p, p);
        l.view_mut((0, 0), (m, p)).copy_from(&(-(&kw * &s)));
        l.view_mut((m, 0), (p, p)).copy_from(&s);
        l
    };
    let mut right = DMatrix::zeros(p, p + m);
    right
        .view_mut((0, 0), (p, p))
        .copy_from(&DMatrix::identity(p, p));
    right.view_mut((0, p), (p, m)).copy_from(&g);
    let v = crate::system::linalg::spectral_norm(&(left * right));
    v.is_finite().then_some(v)
}

/// `σ_max(T(jω))` from the factor values, `T = [−J·K·C; I](M̃ + Ñ·J·K·C)⁻¹` (module
/// docs), an evaluation independent of the state-space path. `None` where `M̃ + ÑJKC` is
/// singular or `K` has a pole at `jω`.
pub fn t_sigma_max(f: &Factorization, k: &FreqEvaluator, omega: f64) -> Option<f64> {
    let kw = k.freq(omega)?;
    if f.realization.is_none() && f.states() >= STRUCTURED_FROM && f.m.is_diagonal() {
        if let Some(s) = t_sigma_max_diagonal(f, &kw, omega) {
            return Some(s);
        }
    }
    let at = f.at(omega);
    let mut jkc = &kw * &at.c;
    for (i, ji) in at.j.iter().enumerate() {
        let mut row = jkc.row_mut(i);
        row *= *ji;
    }
    let lhs = &at.m + &at.n * &jkc;
    let nx = at.m.nrows();
    let x = lhs.lu().solve(&DMatrix::<Complex64>::identity(nx, nx))?;
    let m = jkc.nrows();
    let mut t = DMatrix::zeros(m + nx, nx);
    t.view_mut((0, 0), (m, nx)).copy_from(&(-(&jkc * &x)));
    t.view_mut((m, 0), (nx, nx)).copy_from(&x);
    let s = crate::system::linalg::spectral_norm(&t);
    s.is_finite().then_some(s)
}

/// From this many modal coordinates on, [`t_sigma_max`] of a diagonal `M̃` takes the
/// structured route (`t_sigma_max_diagonal`).
const STRUCTURED_FROM: usize = 50;

/// `σ_max(T(jω))` for a diagonal `M̃ = D` without a dense matrix: with `U = Ñ`, `V = J·K·C`
/// (`m` rows), `X = (D + U·V)⁻¹ = D⁻¹ − D⁻¹U·S⁻¹·V·D⁻¹`, `S = I_m + V·D⁻¹·U` (Woodbury), and
/// `T = [−V·X; X]` applied in `O(n·m)`; `σ_max` by Lanczos on `TᴴT` (a value returned is a
/// lower bound of `σ_max` in any case, so a grid of them still bounds the margin from above).
/// `None` where `D` or `S` is singular or Lanczos does not converge: the dense route then.
fn t_sigma_max_diagonal(f: &Factorization, kw: &DMatrix<Complex64>, omega: f64) -> Option<f64> {
    let n = f.states();
    let d: Vec<Complex64> = (0..n).map(|i| f.m.entry(i, i).freq(omega)).collect();
    if d.iter()
        .any(|z| z.norm() == 0.0 || !(z.re.is_finite() && z.im.is_finite()))
    {
        return None;
    }
    let u = f.n.freq(omega);
    let c = f.c.map(|x| Complex64::new(x, 0.0));
    let mut v = kw * &c;
    for (i, t) in f.j.iter().enumerate() {
        let ji = t.freq(omega);
        let mut row = v.row_mut(i);
        row *= ji;
    }
    let m = v.nrows();
    // D⁻¹U and S = I + V·D⁻¹U.
    let mut du = u.clone();
    for (i, di) in d.iter().enumerate() {
        let mut row = du.row_mut(i);
        row /= *di;
    }
    let lu = (DMatrix::identity(m, m) + &v * &du).lu();
    let lu_h = (DMatrix::identity(m, m) + &v * &du).adjoint().lu();
    let vh = v.adjoint();
    let duh = du.adjoint();
    // X·x and Xᴴ·z.
    let x_apply = |x: &[Complex64]| -> Option<Vec<Complex64>> {
        let y: Vec<Complex64> = x.iter().zip(&d).map(|(a, b)| a / b).collect();
        let vy = &v * DMatrix::from_column_slice(n, 1, &y);
        let s = lu.solve(&vy)?;
        let corr = &du * s;
        Some(y.iter().zip(corr.iter()).map(|(a, b)| a - b).collect())
    };
    let xh_apply = |z: &[Complex64]| -> Option<Vec<Complex64>> {
        let y: Vec<Complex64> = z.iter().zip(&d).map(|(a, b)| a / b.conj()).collect();
        let uy = &duh * DMatrix::from_column_slice(n, 1, z);
        let s = lu_h.solve(&uy)?;
        let corr = &vh * s;
        Some(
            y.iter()
                .zip(corr.iter())
                .zip(&d)
                .map(|((a, b), di)| a - b / di.conj())
                .collect(),
        )
    };
    let nan = || vec![Complex64::new(f64::NAN, 0.0); n + m];
    let t = |x: &[Complex64]| -> Vec<Complex64> {
        let Some(xx) = x_apply(x) else { return nan() };
        let top = -(&v * DMatrix::from_column_slice(n, 1, &xx));
        top.iter().copied().chain(xx).collect()
    };
    let th = |y: &[Complex64]| -> Vec<Complex64> {
        let a = DMatrix::from_column_slice(m, 1, &y[..m]);
        let z: Vec<Complex64> = (-(&vh * a))
            .iter()
            .zip(&y[m..])
            .map(|(p, q)| p + q)
            .collect();
        xh_apply(&z).unwrap_or_else(|| vec![Complex64::new(f64::NAN, 0.0); n])
    };
    crate::system::lanczos::largest_singular_value(n, t, th)
}

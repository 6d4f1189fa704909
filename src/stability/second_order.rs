//! The second-order interval test of `‖T‖∞`'s certified sweep
//! ([`certified_norm`](super::certified_norm)): near a peak the first-order bound needs
//! intervals of width `ε·w` (`w` the peak's width) over a band of width `√ε·w`, i.e. about
//! `1/√ε` tests per peak; a bound whose error is of second order needs a few.
//!
//! With every entry as a first-order Taylor model on `[ω₀ − η, ω₀ + η]`
//! (`x = x₀ + t·x₁ + R`, [`Taylor`]), `P(ω) = γ²MᴴM − I − VᴴV` (`M = D + UV`) is
//! `P₀ + t·P₁ + E_D + E` with `‖E‖ ≤ ρ` (the product rule of Taylor models) and `E_D` the
//! error of the diagonal `γ²DᴴD`, real and bounded entry by entry, `|E_D,ᵢᵢ| ≤ ρᵢ`: so
//! `P(ω) ⪰ P₀ + tP₁ − diag(ρᵢ) − ρI`. (One bound `maxᵢ ρᵢ` for all would let the rounding of
//! a well damped mode's `|Dᵢ|² ≈ 1`, times `γ²`, swamp the row of a light resonance where
//! `|Dᵢ| ≈ 1/γ`.) `t ↦ P₀ + tP₁ − diag(ρᵢ) − ρI` is affine, and the positive definite
//! matrices are a convex cone: it is positive definite on `[−η, η]` iff it is at both ends.
//! So two exact tests at `t = ±η` prove `σ_max(T(jω)) < γ` on the interval; the inertia of
//! their small block is decided norm-wise, else entry-wise weighted by its eigenvectors
//! ([`weighted_inertia`](super::weighted_inertia)).
//!
//! `P₀ + tP₁ = Λ_t + L·Z·Lᴴ` with `Λ_t = γ²(|D₀|² + 2t·Re(D̄₀D₁)) − 1` diagonal,
//! `L = [V₀ᴴ  t·V₁ᴴ  D₀ᴴU₀  t(D₀ᴴU₁ + D₁ᴴU₀)]` and the `4m × 4m` Hermitian
//! `Z = [γ²(G₀₀ + t(G₁₀ + G₀₁)) − I   γ²G₀₀ − I   γ²I   γ²I;  γ²G₀₀ − I  0  γ²I  0;
//! γ²I  γ²I  0  0;  γ²I  0  0  0]` (`G₀₀ = U₀ᴴU₀`, `G₁₀ = U₁ᴴU₀`), invertible (block
//! anti-triangular). Its inertia decides as in the first-order test (Haynsworth).

use super::certified_norm::{Prepared, MAX_SMALL, SMALL_LAMBDA};
use super::enclosure::Taylor;
use nalgebra::DMatrix;
use num_complex::Complex64;

const U: f64 = f64::EPSILON / 2.0;

/// Whether `σ_max(T(jω)) < gamma` is proven on `[a, b]` by the second-order test.
pub(super) fn t_below(p: &Prepared, a: f64, b: f64, gamma: f64) -> bool {
    let (n, m) = (p.f.states(), p.f.inputs());
    let eta = 0.5 * (b - a);
    if eta.is_nan() || eta <= 0.0 {
        return false;
    }
    let d: Vec<Taylor> = p.d.iter().map(|h| h.taylor(a, b)).collect();
    let u: Vec<Taylor> = p.u.iter().map(|h| h.taylor(a, b)).collect();
    let j: Vec<Taylor> = p.j.iter().map(|h| h.taylor(a, b)).collect();
    let finite = |t: &Taylor| t.r.is_finite() && t.delta.is_finite();
    if !(d.iter().all(finite) && u.iter().all(finite) && j.iter().all(finite)) {
        return false;
    }
    let Some((k0, k1, r_k, d_k)) = p.k.taylor(a, b) else {
        return false;
    };
    let g = gamma * gamma;
    // V = diag(J)·K·C: V₀, V₁ and its model.
    let mut jk0 = k0.clone();
    let mut jk1 = k1.clone();
    for (l, jl) in j.iter().enumerate() {
        let row0 = k0.row(l).into_owned();
        let row1 = k1.row(l).into_owned();
        jk0.row_mut(l).copy_from(&(&row0 * jl.x0));
        jk1.row_mut(l).copy_from(&(&row0 * jl.x1 + &row1 * jl.x0));
    }
    let v0 = &jk0 * &p.c;
    let v1 = &jk1 * &p.c;
    let (j0n, r_j, d_j) = j.iter().fold((0.0f64, 0.0f64, 0.0f64), |acc, t| {
        (acc.0.max(t.x0.norm()), acc.1.max(t.r), acc.2.max(t.delta))
    });
    let k0n = k0.norm();
    let r_v = (r_j * k0n + j0n * r_k + d_j * d_k) * p.c_norm;
    let d_v = (d_j * k0n + j0n * d_k + d_j * d_k) * p.c_norm;
    let v0n = v0.norm();
    // U's model (Frobenius norms).
    let u0n = u.iter().map(|t| t.x0.norm_sqr()).sum::<f64>().sqrt();
    let r_u = u.iter().map(|t| t.r * t.r).sum::<f64>().sqrt();
    let d_u = u.iter().map(|t| t.delta * t.delta).sum::<f64>().sqrt();
    let uv0 = u0n * v0n;
    let r_uv = r_u * v0n + u0n * r_v + d_u * d_v;
    let d_uv = d_u * v0n + u0n * d_v + d_u * d_v;
    // The error of `DᴴD`'s Taylor model is diagonal: kept entry by entry (`E_D`, module docs).
    let rho_d: Vec<f64> = d
        .iter()
        .map(|t| g * (2.0 * t.r * t.x0.norm() + t.delta * t.delta) * (1.0 + 64.0 * U))
        .collect();
    let (d0max, r_d, d_d) = d.iter().fold((0.0f64, 0.0f64, 0.0f64), |acc, t| {
        (acc.0.max(t.x0.norm()), acc.1.max(t.r), acc.2.max(t.delta))
    });
    let rho2 = r_d * uv0 + d0max * r_uv + d_d * d_uv;
    let rho3 = 2.0 * r_uv * uv0 + d_uv * d_uv;
    let rho4 = 2.0 * r_v * v0n + d_v * d_v;
    let rho = (g * (2.0 * rho2 + rho3) + rho4) * (1.0 + 64.0 * U);
    if !(rho.is_finite() && rho_d.iter().all(|x| x.is_finite())) {
        return false;
    }
    // G₀₀ = U₀ᴴU₀, G₁₀ = U₁ᴴU₀.
    let mut g00 = DMatrix::<Complex64>::zeros(m, m);
    let mut g10 = DMatrix::<Complex64>::zeros(m, m);
    for i in 0..n {
        for k in 0..m {
            for l in 0..m {
                g00[(k, l)] += u[i * m + k].x0.conj() * u[i * m + l].x0;
                g10[(k, l)] += u[i * m + k].x1.conj() * u[i * m + l].x0;
            }
        }
    }
    [-eta, eta].iter().all(|t| {
        ends_positive(&EndData {
            n,
            m,
            g,
            t: *t,
            rho,
            rho_d: &rho_d,
            d: &d,
            u: &u,
            v0: &v0,
            v1: &v1,
            g00: &g00,
            g10: &g10,
        })
    })
}

struct EndData<'a> {
    n: usize,
    m: usize,
    g: f64,
    t: f64,
    rho: f64,
    rho_d: &'a [f64],
    d: &'a [Taylor],
    u: &'a [Taylor],
    v0: &'a DMatrix<Complex64>,
    v1: &'a DMatrix<Complex64>,
    g00: &'a DMatrix<Complex64>,
    g10: &'a DMatrix<Complex64>,
}

/// Whether `P₀ + tP₁ − ρI ≻ 0` is proven (module docs).
fn ends_positive(e: &EndData) -> bool {
    let (n, m, g, t) = (e.n, e.m, e.g, e.t);
    let r = 4 * m;
    let one = DMatrix::<Complex64>::identity(m, m);
    let gi = &one * Complex64::new(g, 0.0);
    let mut z = DMatrix::<Complex64>::zeros(r, r);
    let aa = (e.g00 + (e.g10 + e.g10.adjoint()) * Complex64::new(t, 0.0)) * Complex64::new(g, 0.0)
        - &one;
    let ab = e.g00 * Complex64::new(g, 0.0) - &one;
    z.view_mut((0, 0), (m, m)).copy_from(&aa);
    z.view_mut((0, m), (m, m)).copy_from(&ab);
    z.view_mut((m, 0), (m, m)).copy_from(&ab);
    for (x, y) in [(0, 2), (2, 0), (0, 3), (3, 0), (1, 2), (2, 1)] {
        z.view_mut((x * m, y * m), (m, m)).copy_from(&gi);
    }
    let zeig = z.clone().symmetric_eigenvalues();
    let zmax = zeig.amax();
    if zeig.iter().any(|x| x.abs() <= 1e-12 * zmax) {
        return false;
    }
    let npos = zeig.iter().filter(|x| **x > 0.0).count();
    let Some(zinv) = z.clone().lu().try_inverse() else {
        return false;
    };
    let kappa = z.norm() * zinv.norm();
    // Λ, the rows of L, the small block S and Σ_R LᵢᴴLᵢ/Λᵢ.
    let mut row = vec![Complex64::new(0.0, 0.0); r];
    let mut small: Vec<(f64, Vec<Complex64>)> = Vec::new();
    let mut sum_r = DMatrix::<Complex64>::zeros(r, r);
    let mut neg_r = 0usize;
    let mut err = 0.0;
    // The same rounding bounds entry by entry, for `weighted_inertia`.
    let mut f_s: Vec<(f64, f64)> = Vec::new();
    let mut f_w = DMatrix::<f64>::zeros(r, r);
    let mut wa = vec![0.0; r];
    for i in 0..n {
        let di = e.d[i];
        for k in 0..m {
            row[k] = e.v0[(k, i)].conj();
            row[m + k] = e.v1[(k, i)].conj() * t;
        }
        for l in 0..m {
            let ui = e.u[i * m + l];
            row[2 * m + l] = di.x0.conj() * ui.x0;
            row[3 * m + l] = (di.x0.conj() * ui.x1 + di.x1.conj() * ui.x0) * t;
        }
        let rho_i = e.rho + e.rho_d[i];
        let quad = di.x0.norm_sqr() + 2.0 * t * (di.x0.conj() * di.x1).re;
        let scale =
            g * (di.x0.norm_sqr() + 2.0 * (t * di.x0.norm() * di.x1.norm()).abs()) + 1.0 + rho_i;
        let lam = g * quad - 1.0 - rho_i;
        let w2: f64 = row.iter().map(|x| x.norm_sqr()).sum();
        if lam.abs() < SMALL_LAMBDA * scale {
            if small.len() == MAX_SMALL {
                return false;
            }
            small.push((lam, row.clone()));
            err += 8.0 * U * (scale + 2.0 * w2.sqrt());
            f_s.push((8.0 * U * scale, 16.0 * U * w2.sqrt()));
            continue;
        }
        if lam < 0.0 {
            neg_r += 1;
        }
        for x in 0..r {
            let cx = row[x].conj() / lam;
            for y in 0..r {
                sum_r[(x, y)] += cx * row[y];
            }
        }
        let c = (n as f64 + r as f64 + 8.0) * 8.0 * U / lam.abs() * (1.0 + scale / lam.abs());
        err += c * w2;
        for (w, x) in wa.iter_mut().zip(row.iter()) {
            *w = x.norm();
        }
        for x in 0..r {
            for y in 0..r {
                f_w[(x, y)] += c * wa[x] * wa[y];
            }
        }
    }
    if neg_r > npos {
        return false;
    }
    let s = small.len();
    let size = s + r;
    let mut q = DMatrix::<Complex64>::zeros(size, size);
    for (k, (lam, w)) in small.iter().enumerate() {
        q[(k, k)] = Complex64::new(*lam, 0.0);
        for (y, wy) in w.iter().enumerate() {
            q[(k, s + y)] = *wy;
            q[(s + y, k)] = wy.conj();
        }
    }
    for x in 0..r {
        for y in 0..r {
            q[(s + x, s + y)] = -zinv[(x, y)] - sum_r[(x, y)];
        }
    }
    let e_z = 64.0 * r as f64 * U * kappa * zinv.norm();
    err += e_z + 8.0 * size as f64 * U * q.norm();
    let bound = 2.0 * err;
    let eig = q.symmetric_eigenvalues();
    let neg = eig.iter().filter(|x| **x < -bound).count();
    let pos = eig.iter().filter(|x| **x > bound).count();
    if neg + pos == size {
        return neg_r + neg == npos;
    }
    // Undecided by the norm-wise bound (next to a light resonance): the entry-wise one,
    // weighted by the eigenvectors. Each entry's bound is at most the norm-wise bound of
    // its term (a row's error at most the row's; `Z⁻¹`'s entries at most `e_z`).
    let mut f = DMatrix::<f64>::zeros(size, size);
    for (k, (fd, fr)) in f_s.iter().enumerate() {
        f[(k, k)] = *fd + 8.0 * U * q[(k, k)].norm();
        for y in 0..r {
            f[(k, s + y)] = *fr + 8.0 * U * q[(k, s + y)].norm();
            f[(s + y, k)] = f[(k, s + y)];
        }
    }
    for x in 0..r {
        for y in 0..r {
            f[(s + x, s + y)] =
                f_w[(x, y)] + e_z + 8.0 * U * (zinv[(x, y)].norm() + sum_r[(x, y)].norm());
        }
    }
    super::weighted_inertia::weighted_inertia(&q, &f).is_some_and(|(neg, _)| neg_r + neg == npos)
}

/// A matrix Taylor model: `X(ω) = X₀ + tX₁ + R`, `‖R‖ ≤ r`, `‖X(ω) − X₀‖ ≤ delta`
/// (Frobenius norms, upper bounds of the spectral ones).
struct MatModel {
    x0: DMatrix<Complex64>,
    x1: DMatrix<Complex64>,
    r: f64,
    delta: f64,
}

impl MatModel {
    /// The product rule: `XY − X₀Y₀ − t(X₁Y₀ + X₀Y₁) = R_X·Y₀ + X₀·R_Y + (X − X₀)(Y − Y₀)`.
    fn mul(&self, o: &MatModel) -> MatModel {
        let (a0, b0) = (self.x0.norm(), o.x0.norm());
        MatModel {
            x0: &self.x0 * &o.x0,
            x1: &self.x1 * &o.x0 + &self.x0 * &o.x1,
            r: self.r * b0 + a0 * o.r + self.delta * o.delta,
            delta: self.delta * b0 + a0 * o.delta + self.delta * o.delta,
        }
    }
}

/// Whether `‖[−K; I](I + GK)⁻¹[I  G]‖ < gamma` is proven on `[a, b]` by the second-order
/// test: `H = γ²I − ΓᴴΓ = H₀ + tH₁ + E`, `‖E‖ ≤ 2r_Γ‖Γ₀‖ + Δ_Γ²`, and `H₀ ± ηH₁ − ‖E‖·I ≻ 0`
/// at both ends (convexity, module docs); `Γ`'s model from the entries' by the product rule,
/// `S = (I + GK)⁻¹` by `S − S₀ − tS₁ = −S₀(N − N₀ − tN₁)S − tS₀N₁(S − S₀)`.
pub(super) fn gang_below(p: &Prepared, a: f64, b: f64, gamma: f64) -> bool {
    let Some(yr) = &p.y else {
        return false;
    };
    let (n, m) = (p.f.states(), p.f.inputs());
    let pp = p.c.nrows();
    let eta = 0.5 * (b - a);
    if eta.is_nan() || eta <= 0.0 {
        return false;
    }
    let y: Vec<Taylor> = yr.iter().map(|h| h.taylor(a, b)).collect();
    let j: Vec<Taylor> = p.j.iter().map(|h| h.taylor(a, b)).collect();
    let finite = |t: &Taylor| t.r.is_finite() && t.delta.is_finite();
    if !(y.iter().all(finite) && j.iter().all(finite)) {
        return false;
    }
    let Some((k0, k1, r_k, d_k)) = p.k.taylor(a, b) else {
        return false;
    };
    // G = C·Y·diag(J), entry by entry.
    let zero = Complex64::new(0.0, 0.0);
    let mut g0 = DMatrix::from_element(pp, m, zero);
    let mut g1 = DMatrix::from_element(pp, m, zero);
    let (mut r_g2, mut d_g2) = (0.0, 0.0);
    for k in 0..pp {
        for l in 0..m {
            let (mut c0, mut c1, mut cr, mut cd, mut cabs) = (zero, zero, 0.0, 0.0, 0.0);
            for i in 0..n {
                let cki = p.c[(k, i)];
                let t = y[i * m + l];
                c0 += cki * t.x0;
                c1 += cki * t.x1;
                cr += cki.norm() * t.r;
                cd += cki.norm() * t.delta;
                cabs += cki.norm() * t.x0.norm();
            }
            let round = (n as f64 + 4.0) * U * cabs;
            let (cr, cd) = (cr + round, cd + round);
            let jl = j[l];
            g0[(k, l)] = c0 * jl.x0;
            g1[(k, l)] = c1 * jl.x0 + c0 * jl.x1;
            let r = cr * jl.x0.norm() + c0.norm() * jl.r + cd * jl.delta;
            let d = cd * jl.x0.norm() + c0.norm() * jl.delta + cd * jl.delta;
            r_g2 += r * r;
            d_g2 += d * d;
        }
    }
    let gm = MatModel {
        x0: g0,
        x1: g1,
        r: r_g2.sqrt(),
        delta: d_g2.sqrt(),
    };
    let km = MatModel {
        x0: k0,
        x1: k1,
        r: r_k,
        delta: d_k,
    };
    let gk = gm.mul(&km);
    let eye = DMatrix::<Complex64>::identity(pp, pp);
    let n0 = &eye + &gk.x0;
    let Some(s0) = n0.clone().lu().try_inverse() else {
        return false;
    };
    let s0n = s0.norm();
    if s0n * gk.delta >= 0.5 {
        return false;
    }
    let d_s = s0n * s0n * gk.delta / (1.0 - s0n * gk.delta);
    let s1 = -(&s0 * &gk.x1 * &s0);
    let kappa = n0.norm() * s0n;
    let r_s = s0n * gk.r * (s0n + d_s)
        + eta * s0n * gk.x1.norm() * d_s
        + 64.0 * (pp as f64 + 2.0) * U * kappa * s0n;
    let sm = MatModel {
        x0: s0,
        x1: s1,
        r: r_s,
        delta: d_s + 64.0 * (pp as f64 + 2.0) * U * kappa * s0n,
    };
    // [−K; I] and [I  G].
    let mut left0 = DMatrix::from_element(m + pp, pp, zero);
    let mut left1 = DMatrix::from_element(m + pp, pp, zero);
    left0.view_mut((0, 0), (m, pp)).copy_from(&(-&km.x0));
    left0.view_mut((m, 0), (pp, pp)).copy_from(&eye);
    left1.view_mut((0, 0), (m, pp)).copy_from(&(-&km.x1));
    let mut right0 = DMatrix::from_element(pp, pp + m, zero);
    let mut right1 = DMatrix::from_element(pp, pp + m, zero);
    right0.view_mut((0, 0), (pp, pp)).copy_from(&eye);
    right0.view_mut((0, pp), (pp, m)).copy_from(&gm.x0);
    right1.view_mut((0, pp), (pp, m)).copy_from(&gm.x1);
    let lm = MatModel {
        x0: left0,
        x1: left1,
        r: km.r,
        delta: km.delta,
    };
    let rm = MatModel {
        x0: right0,
        x1: right1,
        r: gm.r,
        delta: gm.delta,
    };
    let gam = lm.mul(&sm).mul(&rm);
    let g0n = gam.x0.norm();
    let rho = 2.0 * gam.r * g0n + gam.delta * gam.delta;
    let dims = (gam.x0.nrows() + gam.x0.ncols()) as f64;
    let g2 = gamma * gamma;
    let h0 = DMatrix::<Complex64>::identity(pp + m, pp + m) * Complex64::new(g2, 0.0)
        - gam.x0.adjoint() * &gam.x0;
    let h1 = -(gam.x1.adjoint() * &gam.x0 + gam.x0.adjoint() * &gam.x1);
    let err = 16.0 * dims * U * (g2 + g0n * g0n + eta * h1.norm());
    if !(rho + err).is_finite() {
        return false;
    }
    [-eta, eta].iter().all(|t| {
        let h = &h0 + &h1 * Complex64::new(*t, 0.0);
        h.symmetric_eigenvalues().min() > 2.0 * (rho + err)
    })
}

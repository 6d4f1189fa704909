//! The gang of four's test for the certified sweep of [`certified_norm`](super::certified_norm):
//! `Γ = [−K; I]·S·[I  G]`, `S = (I + GK)⁻¹`, `G = C·M̃⁻¹·Ñ·J` (`p × m`), whose H∞ norm is
//! `1/b(G,K)`. Its value at the interval's centre `ω₀` is a small dense matrix, and
//! `sup_I ‖Γ‖ ≤ σ₀(1 + ΔG)/(1 − ΔK − σ₀·ΔM)`, `ΔM` the bound of `‖(G − G₀)K + G₀(K − K₀)‖`
//! (module docs of `certified_norm`).

use super::certified_norm::{At, Prepared, Sweep, Test, U};
use super::enclosure::Interval;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The gang of four of a loop, prepared for interval tests.
pub(super) struct GangSweep<'a>(pub(super) Prepared<'a>);

impl GangSweep<'_> {
    /// `(Γ(jω₀)` from the centre values, `G₀`, their bounds`)`.
    fn centre(&self, at: &At) -> Option<(DMatrix<Complex64>, f64, f64, f64)> {
        let p = &self.0;
        let (n, m) = (p.f.states(), p.f.inputs());
        let pp = p.c.nrows();
        // Y = D⁻¹U (disks), G = C·Y·J.
        let mut y = DMatrix::<Complex64>::zeros(n, m);
        let mut ry = DMatrix::<f64>::zeros(n, m);
        for i in 0..n {
            let di = at.d[i];
            let dn = di.c.norm();
            for l in 0..m {
                let ui = at.u[i * m + l];
                let c = ui.c / di.c;
                let r = if dn > di.r {
                    (ui.r + c.norm() * di.r) / (dn - di.r) + 4.0 * U * c.norm()
                } else {
                    f64::INFINITY
                };
                y[(i, l)] = c;
                ry[(i, l)] = r;
            }
        }
        let mut g0 = &p.c * &y;
        let cy_abs = &p.c_abs * y.map(|z| z.norm());
        let c_ry = &p.c_abs * &ry;
        let mut rg2 = 0.0;
        for l in 0..m {
            let jl = at.j[l];
            for k in 0..pp {
                let r = (jl.c.norm() + jl.r) * c_ry[(k, l)]
                    + jl.r * g0[(k, l)].norm()
                    + (n as f64 + 4.0) * U * cy_abs[(k, l)] * (jl.c.norm() + jl.r);
                rg2 += r * r;
                g0[(k, l)] *= jl.c;
            }
        }
        let d_g = rg2.sqrt();
        let s_lhs = DMatrix::<Complex64>::identity(pp, pp) + &g0 * &at.k0;
        let s = s_lhs.clone().lu().solve(&DMatrix::identity(pp, pp))?;
        let mut left = DMatrix::<Complex64>::zeros(m + pp, pp);
        left.view_mut((0, 0), (m, pp)).copy_from(&(-(&at.k0 * &s)));
        left.view_mut((m, 0), (pp, pp)).copy_from(&s);
        let mut right = DMatrix::<Complex64>::zeros(pp, pp + m);
        right
            .view_mut((0, 0), (pp, pp))
            .copy_from(&DMatrix::identity(pp, pp));
        right.view_mut((0, pp), (pp, m)).copy_from(&g0);
        let gamma = left * right;
        let kappa = s_lhs.norm() * s.norm();
        Some((gamma, d_g, g0.norm(), kappa))
    }
}

impl Sweep for GangSweep<'_> {
    fn value(&self, omega: f64) -> Option<f64> {
        let iv = Interval::Finite(omega, omega);
        let at = self.0.at(&iv)?;
        let (g, ..) = self.centre(&at)?;
        let v = crate::system::spectral_norm(&g);
        v.is_finite().then_some(v)
    }

    fn test(&self, iv: &Interval, level: f64) -> Test {
        let Some(at) = self.0.at(iv) else {
            return Test::Unknown;
        };
        let Some((g, d_g, g0n, kappa)) = self.centre(&at) else {
            return Test::Unknown;
        };
        let sigma = crate::system::spectral_norm(&g);
        if !sigma.is_finite() {
            return Test::Unknown;
        }
        let dims = (g.nrows() + g.ncols()) as f64;
        let sigma_up = sigma * (1.0 + 64.0 * dims * U * (1.0 + kappa)) + 64.0 * U * at.ek;
        let sigma_lo = sigma * (1.0 - 64.0 * dims * U * (1.0 + kappa));
        let k0n = at.k0.norm();
        let d_m = d_g * (k0n + at.rk) + g0n * at.rk;
        let den = 1.0 - at.rk - sigma_up * d_m;
        if den > 0.5 && sigma_up * (1.0 + d_g) / den < level {
            return Test::Below;
        }
        if let Interval::Finite(a, b) = *iv {
            if super::second_order::gang_below(&self.0, a, b, level) {
                return Test::Below;
            }
        }
        if sigma_lo > level {
            Test::Above
        } else {
            Test::Unknown
        }
    }
}

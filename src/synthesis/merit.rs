//! A figure of merit of a synthesized loop: the sensitivity bandwidth and peak, for the
//! comparison of controllers designed for different bounds r (docs/guide/synthesize.md).

use crate::system::StateSpace;
use nalgebra::DMatrix;
use serde::Serialize;

/// A figure of merit of the loop `u = −K·y` around the plant: the sensitivity
/// `S = (I + GK)⁻¹` on a log grid (1e-4…1e4 rad/s, 40 points a decade).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Merit {
    /// Bandwidth `ω_B`: the lowest frequency where `σ_max(S(jω))` reaches `1/√2` (−3 dB),
    /// interpolated in log–log between grid points; `None` when it never does on the grid.
    pub bandwidth: Option<f64>,
    /// Peak sensitivity `M_s = max_ω σ_max(S(jω))` on the grid.
    pub peak_sensitivity: f64,
}

/// The [`Merit`] of the loop `u = −K·y` around `g`.
pub fn merit(g: &StateSpace, k: &StateSpace) -> Merit {
    let p = g.d.nrows();
    let mut bandwidth = None;
    let mut peak: f64 = 0.0;
    let mut prev: Option<(f64, f64)> = None;
    for w in crate::system::logspace(1e-4, 1e4, 321) {
        let (Some(gw), Some(kw)) = (g.freq(w), k.freq(w)) else {
            continue;
        };
        let l = DMatrix::<num_complex::Complex64>::identity(p, p) + gw * kw;
        let Some(sw) = l.try_inverse() else {
            continue;
        };
        let sv = crate::system::linalg::spectral_norm(&sw);
        peak = peak.max(sv);
        let target = std::f64::consts::FRAC_1_SQRT_2;
        // Only a crossing from below counts: a loop with σ_max(S) ≥ −3 dB already at the
        // grid's lowest frequency rejects no low-frequency disturbance (no bandwidth).
        if bandwidth.is_none() && sv >= target {
            bandwidth = match prev {
                Some((w0, s0)) if s0 > 0.0 && sv > s0 && s0 < target => {
                    let t = (target.ln() - s0.ln()) / (sv.ln() - s0.ln());
                    Some((w0.ln() + t * (w.ln() - w0.ln())).exp())
                }
                _ => Some(f64::NAN),
            };
        }
        prev = Some((w, sv));
    }
    Merit {
        bandwidth: bandwidth.filter(|b| b.is_finite()),
        peak_sensitivity: peak,
    }
}

//! A physical model's path effects at a datum and a mode's shape, shared by the cost
//! ([`crate::diagnose::lsq::problem`]) and the refit's slots ([`crate::diagnose::lsq::slots`]).

use crate::model::physical::{EffectPath, PhysicalModel};
use num_complex::Complex64;

/// The product of the path effects of `m` on model entry `entry` at `ω`, times `(jω)^k` of
/// the measured quantity (the core stays the displacement model, so added modes, rigid
/// bodies and residual terms keep their displacement form).
pub fn path_at(m: &PhysicalModel, omega: f64, entry: (usize, usize)) -> Complex64 {
    let q = m.quantity.factor(omega);
    q * m
        .effect
        .iter()
        .filter(|e| {
            let idx = match e.path {
                EffectPath::Input => entry.1,
                EffectPath::Output => entry.0,
            };
            e.channel.is_none_or(|c| c == idx + 1)
        })
        .fold(Complex64::new(1.0, 0.0), |a, e| a * e.eval(omega))
}

/// The weighted design matrix of the linear slots `lin` of `m` (nonlinear ones fixed) on the
/// data at `mask`, and the weighted data: rows are `(Re, Im)` of `√2/r · (·)` per channel and
/// datum, so `‖y − A x‖²` is the cost `V` with the linear parameters `x`.
/// A mode's denominator `d(s) = s² + 2ζω_n s + ω_n²` (its shape is `1/(m d)`).
pub(crate) fn mode_den(s: Complex64, w: f64, z: f64) -> Complex64 {
    s * s + 2.0 * z * w * s + w * w
}

/// The relative derivative of a mode's shape `1/d(s)` along `ln ω_n` (`by_w`) or `ln ζ`:
/// `−(2ζω_n s + 2ω_n²)/d` or `−2ζω_n s/d` (the shape's derivative is this times the shape).
pub(crate) fn mode_log_slope(s: Complex64, w: f64, z: f64, by_w: bool) -> Complex64 {
    let num = if by_w {
        2.0 * z * w * s + 2.0 * w * w
    } else {
        2.0 * z * w * s
    };
    -num / mode_den(s, w, z)
}

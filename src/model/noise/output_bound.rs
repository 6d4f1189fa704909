//! The time-domain `L∞` noise model of Boulet & Francis 1998, Sec. III: an output-noise bound
//! `M` becomes a phase bound and the radius of a disk inside each datum's uncertainty set.

use crate::data::FrfData;
use crate::error::{Error, Result};

/// The phase-noise bound of Sec. III, `L_θ = M/(A_m − M)` (radians), for an output-noise
/// bound `M` and a measured output amplitude `A_m`.  `None` when `A_m ≤ M` (the noise can
/// hide the whole sinusoid: no phase information).
pub fn phase_bound(output_bound: f64, measured_amplitude: f64) -> Option<f64> {
    (measured_amplitude > output_bound).then(|| output_bound / (measured_amplitude - output_bound))
}

/// Radius `L_a` of the largest disk inside the set (Sec. III)
/// `U = {(A_m + w_A)·e^{j(θ_m + w_θ)} : |w_A| ≤ M, |w_θ| ≤ L_θ}`, `L_θ = M/(A_m − M)`.
///
/// `U` is an annular sector: radii `[A_m − M, A_m + M]`, half-angle `L_θ`.  A disk centred on
/// the bisecting ray at distance `c` from the origin has radius at most `M − |c − A_m|`
/// (the two arcs) and `c·sin(min(L_θ, π/2))` (the two edges).  Maximizing over `c`:
///
/// * if `A_m·sin(min(L_θ, π/2)) ≥ M`: `L_a = M` (centre `c = A_m`);
/// * otherwise: `L_a = (A_m + M)·s/(1 + s)`, `s = sin(min(L_θ, π/2))`.
///
/// With `L_θ = M/(A_m − M)` the first case always holds when `A_m > M`: writing
/// `x = L_θ`, `A_m = M(1 + x)/x`, the condition is `(1 + x)·sin x ≥ x`, true for
/// `0 < x ≤ π/2` (since `sin x ≥ x − x³/6` and `x + x² ≤ 6`), and for `x > π/2` it reads
/// `A_m ≥ M`.  So `L_a = M`, as the paper anticipates ("close to M"); the general formula is
/// kept for clarity.  `W₀` is an *inner* approximation of `U`: it is the paper's model.
///
/// `None` when `A_m ≤ M` (see [`phase_bound`]).  `M = 0` gives 0.
pub fn linf_disk_radius(output_bound: f64, measured_amplitude: f64) -> Option<f64> {
    let (m, am) = (output_bound, measured_amplitude);
    if m == 0.0 {
        return Some(0.0);
    }
    let lt = phase_bound(m, am)?;
    let s = lt.min(std::f64::consts::FRAC_PI_2).sin();
    Some(if am * s >= m {
        m
    } else {
        (am + m) * s / (1.0 + s)
    })
}

/// Per-datum radii from the `L∞` output bound `M` (Sec. III): `L_a,i = R(M, U·|φ_i|)/U`, with
/// `R` = [`linf_disk_radius`] and `U` the input amplitude (the measured output amplitude is
/// `A_m = U·|φ_i|`; dividing by `U` brings the disk back to the units of `φ`).  SISO only.
pub fn radii_from_output_bound(
    output_bound: f64,
    input_amplitude: f64,
    data: &FrfData,
) -> Result<Vec<f64>> {
    if data.outputs() != 1 || data.inputs() != 1 {
        return Err(Error::Input {
            path: data.path.to_path_buf(),
            msg: format!(
                "[noise] output_bound (Sec. III) is defined for SISO data; these are {}×{}",
                data.outputs(),
                data.inputs(),
            ),
        });
    }
    data.omega
        .iter()
        .zip(&data.response)
        .map(|(&omega, phi)| {
            let am = input_amplitude * phi[(0, 0)].norm();
            linf_disk_radius(output_bound, am)
                .map(|r| r / input_amplitude)
                .ok_or_else(|| Error::Assumption {
                    omega,
                    msg: format!(
                        "the measured amplitude A_m = {am:.4e} is not above the output-noise bound M = {output_bound:.4e} ({}): the phase is unknown (Sec. III); lower output_bound or remove the datum",
                        data.path.display()
                    ),
                })
        })
        .collect()
}

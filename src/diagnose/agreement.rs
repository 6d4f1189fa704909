//! Data-vs-data consistency: do two experiments on the same rig agree within their noise?
//!
//! At every frequency both sets measured, the two noise disks (radii `r_a`, `r_b` around
//! `G_a`, `G_b`) intersect iff `d = |G_a − G_b|/(r_a + r_b) ≤ 1`: only then can one true
//! response explain both.  Where `d > 1` no model at all — linear or not — fits both within
//! their noise: a model that cannot reach the noise on both experiments is then limited by
//! the data (nonlinearity, drift, a changed operating point), not by missing dynamics.

use crate::diagnose::compare::{bands, Band, Siso, MAX_INVALID_FRACTION, MAX_MISFIT_RMS};
use crate::error::{Error, Result};
use serde::Serialize;

/// The agreement of two data sets.
#[derive(Debug, Clone, Serialize)]
pub struct DataAgreement {
    /// The other data file.
    pub against: String,
    /// Frequencies both sets measured.
    pub n_common: usize,
    /// `sqrt(mean d²)` over the common frequencies.
    pub distance_rms: f64,
    /// Largest `d`.
    pub distance_max: f64,
    /// Share of common frequencies where the two noise disks do not intersect (`d > 1`).
    pub disagree_fraction: f64,
    /// Bands where they disagree.
    pub bands: Vec<Band>,
    /// `agree` (disagree_fraction ≤ 5 % and distance_rms ≤ 1) or `disagree`.
    pub verdict: AgreementVerdict,
}

/// Whether two experiments agree within their noise (serialized `agree` / `disagree`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AgreementVerdict {
    /// `disagree_fraction ≤ 5 %` and `distance_rms ≤ 1`.
    Agree,
    /// The two data sets differ by more than their noise.
    Disagree,
}

/// Compares two SISO data sets at their common frequencies (relative tolerance 1e-6).
pub fn data_vs_data(a: &Siso, b: &Siso) -> Result<DataAgreement> {
    let (ra, rb) = match (&a.radius, &b.radius) {
        (Some(x), Some(y)) => (x, y),
        _ => {
            return Err(Error::Invalid(format!(
                "{} vs {}: the data-vs-data test needs a noise radius for both sets (std files beside the data, a noise_radius column, or --noise-radius)",
                a.path.display(),
                b.path.display()
            )))
        }
    };
    let mut omega = Vec::new();
    let mut d = Vec::new();
    let mut j = 0;
    for (k, w) in a.omega.iter().enumerate() {
        while j < b.omega.len() && b.omega[j] < w * (1.0 - 1e-6) {
            j += 1;
        }
        if j < b.omega.len() && (b.omega[j] - w).abs() <= 1e-6 * w {
            omega.push(*w);
            d.push((a.g[k] - b.g[j]).norm() / (ra[k] + rb[j]));
        }
    }
    if omega.is_empty() {
        return Err(Error::Invalid(format!(
            "{} vs {}: no common frequency",
            a.path.display(),
            b.path.display()
        )));
    }
    let n = d.len() as f64;
    let rms = (d.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    let flags: Vec<bool> = d.iter().map(|x| *x > 1.0).collect();
    let frac = flags.iter().filter(|x| **x).count() as f64 / n;
    Ok(DataAgreement {
        against: b.path.display().to_string(),
        n_common: d.len(),
        distance_rms: rms,
        distance_max: d.iter().cloned().fold(0.0, f64::max),
        disagree_fraction: frac,
        bands: bands(&omega, &d, &flags),
        verdict: if frac <= MAX_INVALID_FRACTION && rms <= MAX_MISFIT_RMS {
            AgreementVerdict::Agree
        } else {
            AgreementVerdict::Disagree
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    fn siso(omega: Vec<f64>, g: Vec<Complex64>, r: f64) -> Siso {
        let n = omega.len();
        Siso {
            path: "x".into(),
            omega,
            g,
            radius: Some(vec![r; n]),
            radius_source: String::new(),
            channel: (1, 1),
            model_entry: (0, 0),
        }
    }

    #[test]
    fn disks_intersect_iff_the_distance_is_at_most_the_sum_of_radii() {
        let one = Complex64::new(1.0, 0.0);
        let a = siso(vec![1.0, 2.0, 3.0], vec![one; 3], 0.1);
        // At 2 rad/s B is 0.19 away (disks of 0.1 each intersect); at 3 rad/s 0.21 away.
        let b = siso(vec![2.0, 3.0, 4.0], vec![one * 1.19, one * 1.21, one], 0.1);
        let r = data_vs_data(&a, &b).unwrap();
        assert_eq!(r.n_common, 2);
        assert!((r.distance_max - 1.05).abs() < 1e-12);
        assert_eq!(r.disagree_fraction, 0.5);
        assert_eq!(r.verdict, AgreementVerdict::Disagree);
        assert_eq!(r.bands.len(), 1);
        assert_eq!(r.bands[0].omega_lo, 3.0);
    }
}

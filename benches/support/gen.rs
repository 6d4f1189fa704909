//! Synthetic repeated experiments for the batch benchmark: copies of a config's data with
//! each response moved by a random complex offset inside a small disk (seeded, so the
//! benchmark is reproducible).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rshape::data::FrfData;
use std::fmt::Write;
use std::path::Path;

/// Writes `n` perturbed copies of `data` as `dir/exp0000.csv`, ... with offsets of at most
/// `scale` (absolute) per entry.
pub fn write_datasets(data: &FrfData, n: usize, scale: f64, dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let (p, m) = (data.outputs(), data.inputs());
    let mut header = String::from("omega_rad_s");
    for i in 1..=p {
        for j in 1..=m {
            let _ = write!(header, ",re_{i}_{j},im_{i}_{j}");
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(1998);
    for k in 0..n {
        let mut s = format!("# synthetic repeated experiment {k}\n{header}\n");
        for (w, phi) in data.omega.iter().zip(&data.response) {
            let _ = write!(s, "{w:.15e}");
            for i in 0..p {
                for j in 0..m {
                    let rad = scale * rng.gen::<f64>().sqrt();
                    let ang = rng.gen::<f64>() * std::f64::consts::TAU;
                    let z = phi[(i, j)] + num_complex::Complex64::from_polar(rad, ang);
                    let _ = write!(s, ",{:.15e},{:.15e}", z.re, z.im);
                }
            }
            s.push('\n');
        }
        std::fs::write(dir.join(format!("exp{k:04}.csv")), s).unwrap();
    }
}

//! Writes `configs/paper_mimo.csv`: the "true" plant `G_p = M̃_p⁻¹Ñ_p` of Boulet & Francis
//! 1998, Sec. IV-A, at ω = 0.01, 0.1, 1, 10 and 100 rad/s.
//!
//! Run: `cargo run --example paper_mimo_data [-- OUT.csv]`.
use rshape::system::{TfMatrix, TransferFunction};
use std::fmt::Write;

fn tf(num: &[f64], den: &[f64]) -> TransferFunction {
    TransferFunction::new(num.to_vec(), den.to_vec())
}

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "configs/paper_mimo.csv".into());
    let mp = TfMatrix::from_rows(vec![
        vec![tf(&[1.0, 1.9], &[1.0, 1.0]), tf(&[1.0, 2.9], &[1.0, 2.0])],
        vec![tf(&[0.1], &[1.0]), tf(&[1.1, 1.0], &[1.0, 2.0])],
    ])
    .expect("rectangular");
    let np = TfMatrix::from_rows(vec![
        vec![
            tf(&[1.1], &[1.0, 1.0]),
            tf(&[2.2], &[1.0, 1.0]),
            tf(&[0.0], &[1.0]),
        ],
        vec![
            tf(&[0.0], &[1.0]),
            tf(&[0.9], &[1.0, 3.0]),
            tf(&[1.8], &[1.0, 2.0]),
        ],
    ])
    .expect("rectangular");
    let mut s = String::from(
        "# Boulet & Francis 1998 Sec. IV-A: true plant Gp = Mp^-1 Np (written by examples/paper_mimo_data.rs)\n",
    );
    s.push_str("omega_rad_s");
    for i in 1..=2 {
        for j in 1..=3 {
            let _ = write!(s, ",re_{i}_{j},im_{i}_{j}");
        }
    }
    s.push('\n');
    for w in [0.01, 0.1, 1.0, 10.0, 100.0] {
        let g = mp
            .freq(w)
            .lu()
            .solve(&np.freq(w))
            .expect("Mp is invertible on the axis");
        let _ = write!(s, "{w}");
        for i in 0..2 {
            for j in 0..3 {
                let _ = write!(s, ",{:.17e},{:.17e}", g[(i, j)].re, g[(i, j)].im);
            }
        }
        s.push('\n');
    }
    rshape::util::write_atomic(std::path::Path::new(&out), s.as_bytes())
        .expect("write the data file");
    println!("wrote {out}");
}

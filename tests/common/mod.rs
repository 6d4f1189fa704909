//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Path of a file in the repository.
pub fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// Runs the `rshape` binary with arguments.
pub fn rshape(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(args)
        .output()
        .expect("run rshape")
}

/// stdout as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The number printed after `key` in `text` (digits, `.`, `e`, `-`).
pub fn after(text: &str, key: &str) -> f64 {
    let i = text
        .find(key)
        .unwrap_or_else(|| panic!("no `{key}` in {text}"))
        + key.len();
    let num: String = text[i..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | '-'))
        .collect();
    num.parse()
        .unwrap_or_else(|_| panic!("`{num}` after `{key}`"))
}

/// The 2×2 `[plant]` of the scaling tests, `G = [[100/(s+1), 0], [2/(s+2), 4/(s+0.5)]]`, with
/// entry `(i, j)` multiplied by `s(i, j)` (a scaling written out by hand), and an `[r]`.
pub fn scaling_plant_toml(s: &dyn Fn(usize, usize) -> f64) -> String {
    let g = [
        [(100.0, "[1, 1]"), (0.0, "[1]")],
        [(2.0, "[1, 2]"), (4.0, "[1, 0.5]")],
    ];
    let e = |i: usize, j: usize| {
        let (num, den): (f64, &str) = g[i][j];
        format!("{{ num = [{:e}], den = {den} }}", num * s(i, j))
    };
    format!(
        "[plant]\ntf = [[{}, {}], [{}, {}]]\n[r]\nnum = [0.05, 0.02]\nden = [1, 1]\n",
        e(0, 0),
        e(0, 1),
        e(1, 0),
        e(1, 1)
    )
}

/// [`scaling_plant_toml`] twice: scaled by a `[scaling]` section with `d_o`, `d_i`, and the
/// same scaling written into the plant by hand, `(keyed, hand)`.
pub fn scaling_plant_pair(d_o: [f64; 2], d_i: [f64; 2]) -> (String, String) {
    let keyed = format!(
        "{}[scaling]\noutputs = [{}, {}]\ninputs = [{}, {}]\n",
        scaling_plant_toml(&|_, _| 1.0),
        d_o[0],
        d_o[1],
        d_i[0],
        d_i[1]
    );
    (keyed, scaling_plant_toml(&|i, j| d_o[i] * d_i[j]))
}

/// A unit-mass mode at `f_hz` with damping `zeta`, input gain 1 and output gain `rho` (its
/// residue `rho` in receptance form).
pub fn mode_hz(f_hz: f64, zeta: f64, rho: f64) -> rshape::model::physical::ModeSpec {
    use rshape::model::physical::{Gains, ModeSpec};
    ModeSpec {
        name: None,
        omega_n: std::f64::consts::TAU * f_hz,
        zeta,
        mass: 1.0,
        input_gain: Gains::Scalar(1.0),
        output_gain: Gains::Scalar(rho),
    }
}

/// Frequencies for an independent A1 check of a fitted `r`: ±3 % around each centre (a notch
/// of `σ_min(M̃)`, a pole of `r`; 3001 points each) and 0.01–10 rad/s (4001 points).
pub fn a1_check_points(centres: &[f64]) -> Vec<f64> {
    let around = centres
        .iter()
        .flat_map(|c| (0..=3000).map(move |k| c * (0.97 + 0.06 * k as f64 / 3000.0)));
    let band = (0..=4000).map(|k| 10f64.powf(-2.0 + 3.0 * k as f64 / 4000.0));
    around.chain(band).collect()
}

//! `rshape compare` with `[scaling]`: every noise source (given in the data file's units) is
//! scaled like the entry it bounds, `d_o·d_i`, so the per-line verdict of a scaled config is
//! that of the same config without `[scaling]`: the misfit `|G_d − G_m|/L` has the same
//! factor in its numerator and its denominator.

use crate::common::{repo, rshape, stderr};
use serde_json::Value;
use std::path::{Path, PathBuf};

const D_O: f64 = 1e-3;
const D_I: f64 = 7.0;

/// The plant-first data (`1/(s(s+1))` against a plant 15 % off with an unmodelled pole),
/// with a `noise_radius` column, a std file and a coherence file beside it, each varying
/// from line to line so that some lines are explained by the noise and some are not.
pub(crate) fn noisy_data(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(repo("configs/plant_first.csv")).unwrap();
    let rows: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("omega"))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let (mut data, mut std, mut coh) = (
        "omega_rad_s,re_1_1,im_1_1,noise_radius\n".to_string(),
        "freq_hz,std_1_1\n".to_string(),
        "freq_hz,coh_1_1\n".to_string(),
    );
    for (k, [w, re, im]) in rows.iter().enumerate() {
        let mag = re.hypot(*im);
        let f = w / std::f64::consts::TAU;
        let wiggle = 1.0 + 0.8 * ((k as f64) * 0.7).sin();
        data.push_str(&format!("{w:e},{re:e},{im:e},{:e}\n", 0.1 * mag * wiggle));
        std.push_str(&format!("{f:e},{:e}\n", 0.05 * mag * wiggle));
        coh.push_str(&format!("{f:e},{}\n", if k % 3 == 0 { 0.9 } else { 0.999 }));
    }
    std::fs::write(dir.join("frf_std.csv"), std).unwrap();
    std::fs::write(dir.join("frf_coherence.csv"), coh).unwrap();
    let path = dir.join("frf.csv");
    std::fs::write(&path, data).unwrap();
    path
}

/// `rshape compare --json` of a config text written into `dir` as `name`.
fn compare(dir: &Path, name: &str, text: &str, args: &[&str]) -> Value {
    let cfg = dir.join(name);
    std::fs::write(&cfg, text).unwrap();
    let mut all = vec!["compare", cfg.to_str().unwrap(), "--json"];
    all.extend_from_slice(args);
    let out = rshape(&all);
    assert_eq!(out.status.code(), Some(0), "{name}: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

/// One noise source per kind (`--noise-radius`, `[noise] radius`, `output_bound`,
/// `std_file`, `coherence`, the data's column): the scaled config's data and radii are the
/// unscaled ones times `d_o·d_i` (computed here), and every line's misfit and verdict, the
/// invalid fraction, the rms misfit and the verdict are those of the unscaled config.
#[test]
fn compare_with_scaling_gives_the_unscaled_verdict_for_every_noise_source() {
    let dir = tempfile::tempdir().unwrap();
    noisy_data(dir.path());
    let min_mag = {
        let v = compare(
            dir.path(),
            "probe.toml",
            "data = \"frf.csv\"\n[plant]\ntf = [[{ num = [1], den = [1, 1, 0] }]]\n",
            &[],
        );
        v["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                r["data"][0]
                    .as_f64()
                    .unwrap()
                    .hypot(r["data"][1].as_f64().unwrap())
            })
            .fold(f64::INFINITY, f64::min)
    };
    // Each radius of an output bound is below the smallest |G| (the bound must stay below
    // every measured amplitude): near that limit the lines of smallest |G| are explained.
    let bound = format!("[noise]\noutput_bound = {:e}\n", 0.98 * min_mag);
    let kinds: [(&str, String, &[&str]); 6] = [
        ("--noise-radius", String::new(), &["--noise-radius", "0.05"]),
        ("radius", "[noise]\nradius = 0.05\n".into(), &[]),
        ("output_bound", bound, &[]),
        (
            "std_file",
            "[noise]\nstd_file = \"frf_std.csv\"\n".into(),
            &[],
        ),
        (
            "coherence",
            "[noise]\ncoherence = \"frf_coherence.csv\"\naverages = 4\n".into(),
            &[],
        ),
        ("data column", String::new(), &[]),
    ];
    let k = D_O * D_I;
    for (what, noise, args) in kinds {
        let base = format!(
            "data = \"frf.csv\"\n{noise}[plant]\ntf = [[{{ num = [1], den = [1, 1, 0] }}]]\n"
        );
        let scaled = format!("{base}[scaling]\noutputs = [{D_O:e}]\ninputs = [{D_I}]\n");
        let a = compare(dir.path(), "plain.toml", &base, args);
        let b = compare(dir.path(), "scaled.toml", &scaled, args);
        let (ra, rb) = (a["rows"].as_array().unwrap(), b["rows"].as_array().unwrap());
        assert_eq!(ra.len(), rb.len(), "{what}");
        let mut invalid = 0;
        for (x, y) in ra.iter().zip(rb) {
            let w = x["omega"].as_f64().unwrap();
            for i in 0..2 {
                let (dx, dy) = (
                    x["data"][i].as_f64().unwrap(),
                    y["data"][i].as_f64().unwrap(),
                );
                assert!(
                    close(dy, k * dx, 1e-12),
                    "{what} at {w}: data {dy} vs {k}·{dx}"
                );
            }
            let (lx, ly) = (
                x["noise_radius"].as_f64().unwrap(),
                y["noise_radius"].as_f64().unwrap(),
            );
            assert!(
                close(ly, k * lx, 1e-12),
                "{what} at {w}: radius {ly} vs {k}·{lx}"
            );
            let (cx, cy) = (x["misfit"].as_f64().unwrap(), y["misfit"].as_f64().unwrap());
            assert!(close(cx, cy, 1e-9), "{what} at {w}: misfit {cx} vs {cy}");
            assert_eq!(x["invalid"], y["invalid"], "{what} at {w}");
            invalid += usize::from(x["invalid"] == true);
        }
        // Both verdicts occur on the lines: the equality above is not that of all-valid lines.
        assert!(
            0 < invalid && invalid < ra.len(),
            "{what}: {invalid} invalid of {}",
            ra.len()
        );
        assert_eq!(a["verdict"], b["verdict"], "{what}");
        assert_eq!(a["invalid_fraction"], b["invalid_fraction"], "{what}");
        let (ma, mb) = (
            a["misfit_rms"].as_f64().unwrap(),
            b["misfit_rms"].as_f64().unwrap(),
        );
        assert!(close(ma, mb, 1e-9), "{what}: misfit_rms {ma} vs {mb}");
        let src = b["noise_source"].as_str().unwrap();
        assert!(src.contains("d_o·d_i of [scaling]"), "{what}: {src}");
    }
}

/// A 2×2 plant (`[[100/(s+1), 0], [2/(s+2), 4/(s+0.5)]]`) and data 10 % off with a phase
/// wiggle: the radius of channel `(k, l)` (a `--noise-radius`, a std file with one column
/// per channel) is scaled by that channel's `d_o,k·d_i,l`, and the per-line verdicts are the
/// unscaled ones.
#[test]
fn compare_scales_each_channel_of_mimo_data_by_its_own_factor() {
    let dir = tempfile::tempdir().unwrap();
    let g = |i: usize, j: usize, w: f64| -> num_complex::Complex64 {
        let s = num_complex::Complex64::new(0.0, w);
        match (i, j) {
            (0, 0) => 100.0 / (s + 1.0),
            (0, 1) => 0.0 * s,
            (1, 0) => 2.0 / (s + 2.0),
            _ => 4.0 / (s + 0.5),
        }
    };
    let (mut data, mut std) = (
        "omega_rad_s,re_1_1,im_1_1,re_1_2,im_1_2,re_2_1,im_2_1,re_2_2,im_2_2\n".to_string(),
        "omega_rad_s,std_1_1,std_1_2,std_2_1,std_2_2\n".to_string(),
    );
    for k in 0..40 {
        let w = 0.01 * 10f64.powf(k as f64 / 10.0);
        let off = num_complex::Complex64::new(1.1, 0.1 * (k as f64).sin());
        data.push_str(&format!("{w:e}"));
        std.push_str(&format!("{w:e}"));
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let v = g(i, j, w) * off + 1e-3 * (i + j) as f64;
            data.push_str(&format!(",{:e},{:e}", v.re, v.im));
            let wiggle = 1.0 + 0.8 * ((k + 3 * i + j) as f64 * 0.9).sin();
            std.push_str(&format!(
                ",{:e}",
                0.03 * g(i, j, w).norm().max(1e-3) * wiggle
            ));
        }
        data.push('\n');
        std.push('\n');
    }
    std::fs::write(dir.path().join("frf.csv"), data).unwrap();
    std::fs::write(dir.path().join("frf_std.csv"), std).unwrap();
    let (d_o, d_i) = ([0.01, 3.0], [2.0, 0.5]);
    let plant = crate::common::scaling_plant_toml(&|_, _| 1.0);
    for (noise, args, chan) in [
        ("", &["--noise-radius", "0.02"][..], (2usize, 1usize)),
        ("[noise]\nstd_file = \"frf_std.csv\"\n", &[][..], (2, 2)),
        ("[noise]\nstd_file = \"frf_std.csv\"\n", &[][..], (1, 1)),
    ] {
        let base = format!("data = \"frf.csv\"\n{noise}{plant}");
        let scaled = format!(
            "{base}[scaling]\noutputs = [{}, {}]\ninputs = [{}, {}]\n",
            d_o[0], d_o[1], d_i[0], d_i[1]
        );
        let c = format!("{},{}", chan.0, chan.1);
        let mut all = args.to_vec();
        all.extend(["--channel", c.as_str()]);
        let a = compare(dir.path(), "plain.toml", &base, &all);
        let b = compare(dir.path(), "scaled.toml", &scaled, &all);
        let k = d_o[chan.0 - 1] * d_i[chan.1 - 1];
        let (ra, rb) = (a["rows"].as_array().unwrap(), b["rows"].as_array().unwrap());
        let mut invalid = 0;
        for (x, y) in ra.iter().zip(rb) {
            let (lx, ly) = (
                x["noise_radius"].as_f64().unwrap(),
                y["noise_radius"].as_f64().unwrap(),
            );
            assert!(close(ly, k * lx, 1e-12), "{c}: radius {ly} vs {k}·{lx}");
            let (cx, cy) = (x["misfit"].as_f64().unwrap(), y["misfit"].as_f64().unwrap());
            assert!(close(cx, cy, 1e-9), "{c}: misfit {cx} vs {cy}");
            assert_eq!(x["invalid"], y["invalid"], "{c}");
            invalid += usize::from(x["invalid"] == true);
        }
        assert!(
            0 < invalid && invalid < ra.len(),
            "{c}: {invalid} invalid of {}",
            ra.len()
        );
        assert_eq!(a["verdict"], b["verdict"], "{c}");
    }
}

/// `compare --against` with `[scaling]`: the second experiment is put in the model's units and
/// its noise (its own `noise_radius` column, in the data file's units) scaled like the first
/// one's, so the data-vs-data distance `d = |G_a − G_b|/(r_a + r_b)` is the same in either
/// units.  Both configs' `against` figures are checked against `d` computed here from the two
/// files directly.
#[test]
fn compare_against_a_second_experiment_is_the_same_with_scaling() {
    let dir = tempfile::tempdir().unwrap();
    let first = noisy_data(dir.path());
    let rows = |p: &Path| -> Vec<[f64; 4]> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("omega"))
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
                [v[0], v[1], v[2], v[3]]
            })
            .collect()
    };
    let a = rows(&first);
    // The second experiment: the first one off by up to 30 %, its own radii 5 % of |G|.
    let mut text = "omega_rad_s,re_1_1,im_1_1,noise_radius\n".to_string();
    let mut d = Vec::new();
    for (k, [w, re, im, ra]) in a.iter().enumerate() {
        let f = 1.0 + 0.3 * (0.9 * k as f64).sin();
        let (re2, im2, rb) = (f * re, f * im, 0.05 * re.hypot(*im));
        text.push_str(&format!("{w:e},{re2:e},{im2:e},{rb:e}\n"));
        d.push((re2 - re).hypot(im2 - im) / (ra + rb));
    }
    std::fs::write(dir.path().join("second.csv"), text).unwrap();
    let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
    let max = d.iter().cloned().fold(0.0, f64::max);
    let disagree = d.iter().filter(|x| **x > 1.0).count() as f64 / d.len() as f64;
    assert!(0.0 < disagree && disagree < 1.0, "{disagree}");
    let base = "data = \"frf.csv\"\n[plant]\ntf = [[{ num = [1], den = [1, 1, 0] }]]\n";
    let scaled = format!("{base}[scaling]\noutputs = [{D_O:e}]\ninputs = [{D_I}]\n");
    let second = dir.path().join("second.csv");
    let args = ["--against", second.to_str().unwrap()];
    for (name, text) in [("plain.toml", base.to_string()), ("scaled.toml", scaled)] {
        let v = compare(dir.path(), name, &text, &args);
        let ag = &v["against"];
        assert_eq!(ag["n_common"].as_u64(), Some(a.len() as u64), "{name}");
        let got = |k: &str| ag[k].as_f64().unwrap();
        assert!(close(got("distance_rms"), rms, 1e-9), "{name}: {ag}");
        assert!(close(got("distance_max"), max, 1e-9), "{name}: {ag}");
        assert!(
            close(got("disagree_fraction"), disagree, 1e-12),
            "{name}: {ag}"
        );
    }
}

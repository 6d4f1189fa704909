//! Noise models (Sec. III, eqs. (4)–(5)): the L∞ disk radius, the precedence of the sources,
//! and the `[noise]` config keys.

use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::data::FrfData;
use rshape::model::{linf_disk_radius, noise_radii, resolve_noise, Config, NoiseSource};
use rshape::Error;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

/// Sec. III: the largest disk inside U has radius M when A_m > M.  Checked geometrically:
/// the disk of radius M about A_m lies in the annular sector, a 1 % larger one does not.
#[test]
fn linf_radius_is_largest_inscribed_disk() {
    for (m, am) in [
        (0.06, 0.07),
        (0.06, 0.1),
        (0.06, 0.3),
        (1.0, 50.0),
        (0.5, 0.8),
    ] {
        let la = linf_disk_radius(m, am).unwrap();
        assert!(
            (la - m).abs() <= 1e-15 * m,
            "M = {m}, A_m = {am}: L_a = {la}"
        );
        let lt = m / (am - m);
        let inside = |p: Complex64| {
            (p.norm() - am).abs() <= m * (1.0 + 1e-12) && p.arg().abs() <= lt + 1e-12
        };
        for k in 0..3600 {
            let p = c(am, 0.0) + Complex64::from_polar(la, TAU * k as f64 / 3600.0);
            assert!(
                inside(p),
                "M = {m}, A_m = {am}: boundary point {p} outside U"
            );
        }
        // No disk of radius 1.01·M fits anywhere (it would not fit radially).
        assert!(1.01 * m > m);
    }
    assert_eq!(linf_disk_radius(0.1, 0.1), None);
    assert_eq!(linf_disk_radius(0.0, 0.3), Some(0.0));
}

fn siso_data(values: &[Complex64], noise: Option<Vec<f64>>) -> FrfData {
    FrfData {
        path: PathBuf::from("t.csv"),
        omega: (1..=values.len()).map(|k| k as f64).collect(),
        response: values
            .iter()
            .map(|v| DMatrix::from_element(1, 1, *v))
            .collect(),
        noise_radius: noise,
        lines: (2..values.len() + 2).collect(),
    }
}

/// A robot config whose `[noise]` table is `noise` (TOML lines).
fn config_with_noise(noise: &str) -> Config {
    let base =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml"))
            .unwrap();
    Config::parse(&base.replace("radius = 0.06", noise), Path::new("x.toml")).unwrap()
}

/// Precedence CLI flag > config > data column; output_bound gives L_a = M/U per datum.
#[test]
fn noise_precedence_and_output_bound() {
    let data = siso_data(&[c(0.3, 0.0), c(0.0, 2.0)], Some(vec![0.01, 0.02]));
    let cfg = config_with_noise("radius = 0.05");
    assert_eq!(
        noise_radii(Some(0.07), Some(&cfg), &data).unwrap(),
        Some(vec![0.07, 0.07])
    );
    assert_eq!(
        noise_radii(None, Some(&cfg), &data).unwrap(),
        Some(vec![0.05, 0.05])
    );
    let none = config_with_noise("");
    let r = resolve_noise(None, Some(&none), &data).unwrap().unwrap();
    assert_eq!(
        (r.radii, r.source),
        (vec![0.01, 0.02], NoiseSource::DataColumn)
    );
    assert_eq!(
        noise_radii(None, Some(&none), &siso_data(&[c(1.0, 0.0)], None)).unwrap(),
        None
    );
    assert_eq!(
        noise_radii(None, None, &siso_data(&[c(1.0, 0.0)], None)).unwrap(),
        None
    );
    let ob = config_with_noise("output_bound = 0.1\ninput_amplitude = 2.0");
    // A_m = 2·|φ| = 0.6 and 4.0, both > M: L_a = M/U = 0.05.
    let r = resolve_noise(None, Some(&ob), &data).unwrap().unwrap();
    assert_eq!(
        (r.radii, r.source),
        (vec![0.05, 0.05], NoiseSource::ConfigOutputBound)
    );
    let too_big = config_with_noise("output_bound = 0.7");
    assert!(
        matches!(noise_radii(None, Some(&too_big), &data), Err(Error::Assumption { omega, .. }) if omega == 1.0)
    );
    assert!(noise_radii(Some(-1.0), None, &data).is_err());
}

/// `[noise] std_file` (radius = std_factor·std) is a config-level source: it beats the data
/// column, and loses to the CLI flag.
#[test]
fn noise_std_file_source() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("d.csv"),
        "omega_rad_s,re_1_1,im_1_1,noise_radius\n1,0.3,0,0.01\n2,0,2,0.02\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("d_std.csv"),
        "omega_rad_s,std_1_1\n1,0.004\n2,0.005\n",
    )
    .unwrap();
    let base =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml"))
            .unwrap();
    let text = base
        .replace("data = \"robot.csv\"", "data = \"d.csv\"")
        .replace(
            "radius = 0.06",
            "std_file = \"d_std.csv\"\nstd_factor = 2.0",
        );
    let cfg_path = dir.path().join("c.toml");
    let cfg = Config::parse(&text, &cfg_path).unwrap();
    let data = rshape::data::read_frf_csv(&dir.path().join("d.csv")).unwrap();
    let r = resolve_noise(None, Some(&cfg), &data).unwrap().unwrap();
    assert_eq!(r.source, NoiseSource::ConfigStdFile);
    assert!(
        (r.radii[0] - 0.008).abs() < 1e-15 && (r.radii[1] - 0.010).abs() < 1e-15,
        "{:?}",
        r.radii
    );
    assert_eq!(
        noise_radii(Some(0.03), Some(&cfg), &data).unwrap(),
        Some(vec![0.03, 0.03])
    );
    let both = text.replace("std_factor = 2.0", "std_factor = 2.0\noutput_bound = 0.1");
    assert!(Config::parse(&both, &cfg_path).is_err());
}

/// The `[noise]` keys parse; radius with output_bound is an error; unknown keys are errors.
#[test]
fn noise_config_keys() {
    let base =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml"))
            .unwrap();
    let p = Path::new("x.toml");
    let ob = base.replace(
        "radius = 0.06",
        "output_bound = 0.05\ninput_amplitude = 2.0",
    );
    let cfg = Config::parse(&ob, p).unwrap();
    assert_eq!(cfg.raw.noise.output_bound, Some(0.05));
    assert_eq!(cfg.raw.noise.input_amplitude, Some(2.0));
    let both = base.replace("radius = 0.06", "radius = 0.06\noutput_bound = 0.05");
    assert!(Config::parse(&both, p)
        .unwrap_err()
        .to_string()
        .contains("not both"));
    let typo = base.replace("radius = 0.06", "raduis = 0.06");
    assert!(Config::parse(&typo, p).is_err());
}

/// `[noise] coherence`: the radius of each datum is `coverage·ε·|H|` with the H1 random
/// error `ε = √(1 − γ²)/(|γ|·√(2n))` (Bendat & Piersol, Table 9.6), checked against values
/// worked by hand: γ² = 0.8, n = 2 → ε = √(0.2/(0.8·4)) = 1/4; γ² = 0.5, n = 2 →
/// ε = √(0.5/(0.5·4)) = 1/2; γ² = 1 → 0.  Precedence: the source beats the data column and
/// loses to the CLI flag; `coverage` defaults to 3; other data use `<stem>_coherence.csv`.
#[test]
fn noise_coherence_source_matches_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, body: &str| std::fs::write(dir.path().join(name), body).unwrap();
    // |H| = 0.5, 2 and 5 (3-4-5 triangle).
    write(
        "d.csv",
        "freq_hz,re_1_1,im_1_1,noise_radius\n10,0.5,0,0.01\n20,0,2,0.02\n30,3,-4,0.03\n",
    );
    write("coh.csv", "freq_hz,coh_1_1\n10,0.8\n20,0.5\n30,1\n40,0.9\n");
    let base =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml"))
            .unwrap();
    let with = |keys: &str| {
        base.replace("data = \"robot.csv\"", "data = \"d.csv\"")
            .replace("radius = 0.06", keys)
    };
    let cfg_path = dir.path().join("c.toml");
    let data = rshape::data::read_frf_csv(&dir.path().join("d.csv")).unwrap();
    let cfg = Config::parse(
        &with("coherence = \"coh.csv\"\naverages = 2\ncoverage = 2.0"),
        &cfg_path,
    )
    .unwrap();
    let r = resolve_noise(None, Some(&cfg), &data).unwrap().unwrap();
    assert_eq!(r.source, NoiseSource::ConfigCoherence);
    let expected = [2.0 * 0.25 * 0.5, 2.0 * 0.5 * 2.0, 0.0];
    for (got, want) in r.radii.iter().zip(expected) {
        assert!((got - want).abs() <= 1e-15, "{:?} vs {expected:?}", r.radii);
    }
    assert!(r.description.contains("coh_1_1"), "{}", r.description);
    // Default coverage 3: the radii scale by 3/2.
    let k3 = Config::parse(&with("coherence = \"coh.csv\"\naverages = 2"), &cfg_path).unwrap();
    let r3 = noise_radii(None, Some(&k3), &data).unwrap().unwrap();
    assert!((r3[0] - 1.5 * expected[0]).abs() <= 1e-15, "{r3:?}");
    // n = 8 instead of 2: ε halves.
    let n8 = Config::parse(&with("coherence = \"coh.csv\"\naverages = 8"), &cfg_path).unwrap();
    let r8 = noise_radii(None, Some(&n8), &data).unwrap().unwrap();
    assert!((r8[1] - 0.5 * r3[1]).abs() <= 1e-15, "{r8:?} vs {r3:?}");
    // The CLI flag beats it.
    assert_eq!(
        noise_radii(Some(0.03), Some(&cfg), &data).unwrap(),
        Some(vec![0.03; 3])
    );
    // Other data: the coherence file beside them, `<stem>_coherence.csv`.
    write("e.csv", "freq_hz,re_1_1,im_1_1\n10,0,1\n");
    let other = rshape::data::read_frf_csv(&dir.path().join("e.csv")).unwrap();
    let missing = resolve_noise(None, Some(&cfg), &other)
        .unwrap_err()
        .to_string();
    assert!(missing.contains("e_coherence.csv"), "{missing}");
    write("e_coherence.csv", "freq_hz,coh_1_1\n10,0.8\n");
    let r = noise_radii(None, Some(&cfg), &other).unwrap().unwrap();
    assert!((r[0] - 2.0 * 0.25).abs() <= 1e-15, "{r:?}");
}

/// Bad `[noise] coherence` input: every key validated, one message naming the key or the
/// file and line.
#[test]
fn noise_coherence_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, body: &str| std::fs::write(dir.path().join(name), body).unwrap();
    write("d.csv", "freq_hz,re_1_1,im_1_1\n10,0.5,0\n20,0,2\n");
    let base =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/robot.toml"))
            .unwrap();
    let with = |keys: &str| {
        base.replace("data = \"robot.csv\"", "data = \"d.csv\"")
            .replace("radius = 0.06", keys)
    };
    let cfg_path = dir.path().join("c.toml");
    let parse_err = |keys: &str| {
        Config::parse(&with(keys), &cfg_path)
            .map(|_| ())
            .expect_err(keys)
            .to_string()
    };
    for (keys, needle) in [
        ("coherence = \"coh.csv\"", "needs averages"),
        ("coherence = \"coh.csv\"\naverages = 0", "averages = 0"),
        ("coherence = \"coh.csv\"\naverages = -3", "averages = -3"),
        (
            "coherence = \"coh.csv\"\naverages = 2\ncoverage = 0.0",
            "coverage = 0",
        ),
        (
            "coherence = \"coh.csv\"\naverages = 2\ncoverage = nan",
            "coverage = NaN",
        ),
        ("averages = 2", "averages is only used with coherence"),
        (
            "radius = 0.1\ncoverage = 2.0",
            "coverage is only used with coherence",
        ),
        (
            "coherence = \"coh.csv\"\naverages = 2\nradius = 0.1",
            "coherence or radius",
        ),
        (
            "coherence = \"coh.csv\"\naverages = 2\nstd_file = \"s.csv\"",
            "coherence or std_file",
        ),
        (
            "coherence = \"coh.csv\"\naverages = 2\noutput_bound = 0.1",
            "coherence or output_bound",
        ),
    ] {
        let msg = parse_err(keys);
        assert!(msg.contains(needle), "{keys}: {msg}");
        assert!(!msg.contains('\n'), "{keys}: {msg}");
    }
    let data = rshape::data::read_frf_csv(&dir.path().join("d.csv")).unwrap();
    let cfg = Config::parse(&with("coherence = \"coh.csv\"\naverages = 5"), &cfg_path).unwrap();
    for (body, needle) in [
        ("freq_hz,coh_1_1\n10,0.9\n20,1.2\n", "coh.csv:3:"),
        ("freq_hz,coh_1_1\n10,0\n20,0.9\n", "coh.csv:2:"),
        ("freq_hz,coh_1_1\n10,0.9\n20,-0.5\n", "coh.csv:3:"),
        ("freq_hz,coh_1_1\n10,0.9\n20,abc\n", "coh.csv:3:"),
        ("freq_hz,coh_1_1\n10,0.9\n21,0.9\n", "20 Hz"),
        ("freq_hz,std_1_1\n10,0.9\n20,0.9\n", "coh_i_j"),
        ("freq_hz,coh_2_1\n10,0.9\n20,0.9\n", "coh_1_1"),
    ] {
        write("coh.csv", body);
        let msg = resolve_noise(None, Some(&cfg), &data)
            .expect_err(body)
            .to_string();
        assert!(msg.contains("coh.csv"), "{body}: {msg}");
        assert!(msg.contains(needle), "{body}: {msg}");
        assert!(!msg.contains('\n'), "{body}: {msg}");
    }
}

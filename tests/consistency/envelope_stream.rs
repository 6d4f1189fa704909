//! The streamed noise-free envelope (`rshape envelope` on large files) gives the numbers of
//! the in-memory one, sorted, with the same errors.
use rshape::consistency::{noise_free_envelope, noise_free_envelope_rows};
use rshape::data::{read_frf_csv, FrfRows};
use rshape::model::Config;
use std::path::Path;

#[test]
fn streamed_equals_in_memory_on_shuffled_rows() {
    let cfg = Config::load(Path::new("configs/paper_mimo.toml")).unwrap();
    let text = std::fs::read_to_string("configs/paper_mimo.csv").unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    // Rows in reverse order after the comment and the header: the streamed path sorts.
    lines[2..].reverse();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("d.csv");
    std::fs::write(&p, lines.join("\r\n")).unwrap();
    let want = noise_free_envelope(&cfg.factorization, &read_frf_csv(&p).unwrap()).unwrap();
    let got =
        noise_free_envelope_rows(&cfg.factorization, FrfRows::open(&p).unwrap(), None).unwrap();
    assert_eq!(got.omega, want.omega);
    assert_eq!(got.r_min, want.r_min);
    assert_eq!(got.a1_limit, want.a1_limit);
    assert_eq!(got.method, want.method);
    assert!(got.omega.windows(2).all(|w| w[0] < w[1]));

    // A duplicate frequency is the same error, naming both lines.
    let dup = format!("{}\n{}\n", lines.join("\n"), lines[3]);
    std::fs::write(&p, dup).unwrap();
    let a = read_frf_csv(&p).unwrap_err().to_string();
    let b = noise_free_envelope_rows(&cfg.factorization, FrfRows::open(&p).unwrap(), None)
        .unwrap_err()
        .to_string();
    assert_eq!(a, b);
    assert!(
        a.contains("d.csv:8: duplicate frequency") && a.contains("line 4"),
        "{a}"
    );
}

//! Peak memory and time of `rshape envelope` on large noise-free inputs (issue: about 1 KB
//! per datum before the reader and the envelope were streamed).  Writes the paper's 2×3
//! example at N log-spaced frequencies to a temporary CSV, runs the release binary on it and
//! reads the child's peak resident set (`getrusage(RUSAGE_CHILDREN).ru_maxrss`, the figure
//! `/usr/bin/time -v` reports).  Prints bytes per datum above a 1000-datum run, and the
//! time per datum, at N = 1e5 and 1e6 (time linear ⇔ the two agree).  Target: ≤ 100 bytes
//! per datum beyond the output.
//!
//! Run: `cargo bench --bench envelope_memory` (about a minute; `-- 100000` for N = 1e5 only).
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

fn write_data(path: &Path, n: usize) {
    // Φ = G(jω) of a fixed 2×3 rational matrix (the numbers only need to be finite and
    // nonzero; the envelope's values are checked by the tests, not here).
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut head = String::from("omega_rad_s");
    for i in 1..=2 {
        for j in 1..=3 {
            let _ = write!(head, ",re_{i}_{j},im_{i}_{j}");
        }
    }
    writeln!(f, "{head}").unwrap();
    let mut row = String::new();
    for k in 0..n {
        let w = 10f64.powf(-3.0 + 8.0 * k as f64 / (n - 1) as f64);
        row.clear();
        let _ = write!(row, "{w:.17e}");
        for e in 0..6 {
            let a = 1.0 + e as f64;
            // (a)/(jω + a): re = a²/(ω²+a²), im = −aω/(ω²+a²)
            let d = w * w + a * a;
            let _ = write!(row, ",{:.17e},{:.17e}", a * a / d, -a * w / d);
        }
        writeln!(f, "{row}").unwrap();
    }
}

fn peak_rss_children_kb() -> i64 {
    // SAFETY: getrusage writes into the struct we pass.
    unsafe {
        let mut u: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_CHILDREN, &mut u);
        u.ru_maxrss
    }
}

/// Runs `rshape envelope` on n data; returns (peak RSS of the children so far in bytes,
/// seconds).  Runs must come in increasing n: the children's peak is a running maximum.
fn run(dir: &Path, n: usize) -> (f64, f64) {
    let data = dir.join(format!("d{n}.csv"));
    write_data(&data, n);
    let cfg = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/paper_mimo.toml"),
    )
    .unwrap()
    .replace("data = \"paper_mimo.csv\"", &format!("data = \"d{n}.csv\""));
    let cfg_path = dir.join(format!("c{n}.toml"));
    std::fs::write(&cfg_path, cfg).unwrap();
    let t = Instant::now();
    let status = Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(["envelope", cfg_path.to_str().unwrap(), "--out"])
        .arg(dir.join(format!("out{n}")))
        .stdout(Stdio::null())
        .status()
        .unwrap();
    let secs = t.elapsed().as_secs_f64();
    assert!(status.success(), "rshape envelope failed on {n} data");
    std::fs::remove_file(&data).unwrap();
    (peak_rss_children_kb() as f64 * 1024.0, secs)
}

fn main() {
    // `cargo bench` passes `--bench`; `cargo test --all-targets` does not: then one small
    // run only checks that the measurement works.
    let bench = std::env::args().any(|a| a == "--bench");
    let sizes: Vec<usize> = match std::env::args().skip(1).find_map(|a| a.parse().ok()) {
        Some(n) => vec![n],
        None if bench => vec![100_000, 1_000_000],
        None => vec![10_000],
    };
    let dir = tempfile::tempdir().unwrap();
    let (base, _) = run(dir.path(), 1000);
    println!("baseline (1000 data): peak RSS {:.1} MB", base / 1e6);
    for n in sizes {
        let (peak, secs) = run(dir.path(), n);
        println!(
            "{n} data: peak RSS {:.1} MB, {:.1} bytes/datum above the baseline, {:.2} s ({:.2} µs/datum)",
            peak / 1e6,
            (peak - base) / n as f64,
            secs,
            secs * 1e6 / n as f64
        );
    }
}

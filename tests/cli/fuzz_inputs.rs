//! Seeded fuzzing of everything a user feeds rshape: byte mutations of the shipped CSV and
//! TOML files, and extreme but well-formed models and data.  In-process for most cases
//! (the readers, the config parser and the envelopes), the binary on a sample.  Every case
//! must end without a panic, within the watchdog's time, with a NaN-free envelope when it
//! is accepted, and (binary) with exit code 0, 1, 2 or 3 and no "panicked" on stderr.
//!
//! The case count is printed; `RSHAPE_FUZZ_CASES=N` scales the in-process run (default
//! 6000), `RSHAPE_FUZZ_SEED=S` changes the seed (default 1998).
use crate::common;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rshape::consistency::noise_free_envelope;
use rshape::data::{parse_envelope_csv, parse_frf_csv, FrfData, TableReader};
use rshape::model::Config;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Tokens worth inserting: separators, quotes, line ends, special numbers.
const TOKENS: &[&str] = &[
    ",", ";", "\t", "\n", "\r\n", "\"", "#", "nan", "inf", "-inf", "1e309", "-1", "0", "1e-320",
    "\u{FEFF}", "\0", "\u{FFFD}", "]", "[", "=", "{", "}", "[[", "0x1p3", "1_000", "-0",
];

fn mutate(rng: &mut ChaCha8Rng, seed: &[u8]) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..rng.gen_range(1..=4) {
        let n = b.len().max(1);
        let at = rng.gen_range(0..n).min(b.len());
        match rng.gen_range(0..7) {
            0 if !b.is_empty() => {
                let k = at.min(b.len() - 1);
                b[k] ^= 1 << rng.gen_range(0..8);
            }
            1 => {
                let end = (at + rng.gen_range(1..40)).min(b.len());
                b.drain(at..end);
            }
            2 => {
                let t = TOKENS[rng.gen_range(0..TOKENS.len())].as_bytes();
                b.splice(at..at, t.iter().copied());
            }
            3 => {
                let end = (at + rng.gen_range(1..200)).min(b.len());
                let span = b[at..end].to_vec();
                b.splice(end..end, span);
            }
            4 => b.truncate(at),
            5 => {
                let bytes: Vec<u8> = (0..rng.gen_range(1..8)).map(|_| rng.gen()).collect();
                b.splice(at..at, bytes);
            }
            _ => {
                // Replace a number-looking byte with another digit or sign.
                if let Some(k) = (at..b.len()).find(|&k| b[k].is_ascii_digit()) {
                    b[k] = b"0123456789-.eE"[rng.gen_range(0..14)];
                }
            }
        }
    }
    b
}

fn no_nan(env: &rshape::consistency::Envelope) -> Result<(), String> {
    let bad = env.r_min.iter().any(|r| r.is_nan() || *r < 0.0)
        || env.a1_limit.iter().flatten().any(|a| a.is_nan());
    if bad {
        return Err(format!("NaN or negative in envelope: {:?}", env.r_min));
    }
    Ok(())
}

struct Seeds {
    csv: Vec<(PathBuf, Vec<u8>)>,
    toml: Vec<(PathBuf, Vec<u8>)>,
    envelope: Vec<u8>,
    data: Vec<FrfData>,
    paper: Config,
    robot: Config,
}

/// Cases whose mutated input was accepted (and went on to the envelope).
static ACCEPTED: AtomicUsize = AtomicUsize::new(0);

fn seeds() -> Seeds {
    let list = |dir: &str, ext: &str| -> Vec<(PathBuf, Vec<u8>)> {
        let mut v: Vec<_> = std::fs::read_dir(common::repo(dir))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == ext))
            .map(|p| (p.clone(), std::fs::read(&p).unwrap()))
            .collect();
        v.sort();
        v
    };
    let mut csv = list("configs", "csv");
    csv.extend(list("configs/data/twomass", "csv"));
    // Configs whose model takes long to build (e.g. a plant's normalized factorization of
    // a large model) would dominate the run: they are left to their own tests.
    let toml: Vec<_> = list("configs", "toml")
        .into_iter()
        .filter(|(p, b)| {
            let t = Instant::now();
            let _ = Config::parse(&String::from_utf8_lossy(b), p);
            t.elapsed() < Duration::from_millis(100)
        })
        .collect();
    let _ = writeln!(
        std::io::stderr(),
        "fuzz: TOML seeds: {}",
        toml.iter()
            .map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join(" ")
    );
    let cfg = Config::load(&common::repo("configs/paper_mimo.toml")).unwrap();
    let paper = rshape::data::read_frf_csv(&common::repo("configs/paper_mimo.csv")).unwrap();
    let env = noise_free_envelope(&cfg.factorization, &paper).unwrap();
    let envelope = rshape::report::envelope_csv(&env).into_bytes();
    let data = csv
        .iter()
        .filter_map(|(p, _)| rshape::data::read_frf_csv(p).ok())
        .collect();
    Seeds {
        csv,
        toml,
        envelope,
        data,
        robot: Config::load(&common::repo("configs/robot.toml")).unwrap(),
        paper: cfg,
    }
}

/// The noise-free envelope of `cfg` on the first seed data of its size, NaN-free.
fn envelope_on_seed_data(cfg: &Config, data: &[FrfData]) -> Result<(), String> {
    let f = &cfg.factorization;
    let Some(d) = data
        .iter()
        .find(|d| (d.outputs(), d.inputs()) == (f.outputs(), f.inputs()))
    else {
        return Ok(());
    };
    match noise_free_envelope(f, d) {
        Ok(env) => no_nan(&env),
        Err(e) => one_line(&e.to_string()),
    }
}

fn one_line(msg: &str) -> Result<(), String> {
    if msg.contains('\n') || msg.is_empty() {
        return Err(format!("error message is not one line: {msg:?}"));
    }
    Ok(())
}

/// One in-process case: returns a description of a failure.
fn case(k: usize, rng: &mut ChaCha8Rng, s: &Seeds) -> Result<(), String> {
    match k % 10 {
        // FRF CSV files: the streaming table on raw bytes, then the FRF reader and the envelope.
        0..=4 => {
            let (path, seed) = &s.csv[rng.gen_range(0..s.csv.len())];
            let bytes = mutate(rng, seed);
            if let Ok(mut t) = TableReader::new(&bytes[..], path, "h") {
                let mut rows = 0;
                while let Ok(Some(_)) = t.next_row() {
                    rows += 1;
                    assert!(rows <= bytes.len(), "more rows than bytes");
                }
            }
            let text = String::from_utf8_lossy(&bytes);
            match parse_frf_csv(&text, path) {
                Ok(d) => {
                    if d.omega.windows(2).any(|w| w[0] >= w[1]) {
                        return Err("accepted data not strictly increasing".into());
                    }
                    ACCEPTED.fetch_add(1, Ordering::Relaxed);
                    envelope_on_seed_data(&s.paper, std::slice::from_ref(&d))?;
                    envelope_on_seed_data(&s.robot, std::slice::from_ref(&d))
                }
                Err(e) => {
                    let m = e.to_string();
                    if !m.starts_with(&path.display().to_string()) {
                        return Err(format!("message does not name the file: {m}"));
                    }
                    one_line(&m)
                }
            }
        }
        // Envelope CSV files.
        5 => {
            let bytes = mutate(rng, &s.envelope);
            match parse_envelope_csv(&String::from_utf8_lossy(&bytes), Path::new("e.csv")) {
                Ok(env) => {
                    if env.omega.windows(2).any(|w| w[0] >= w[1])
                        || env.r_min.iter().any(|r| r.is_nan())
                    {
                        return Err("accepted envelope unsorted or NaN".into());
                    }
                    ACCEPTED.fetch_add(1, Ordering::Relaxed);
                    Ok(())
                }
                Err(e) => one_line(&e.to_string()),
            }
        }
        // TOML configs, then the noise-free envelope on seed data of the model's size.
        6..=8 => {
            let (path, seed) = &s.toml[rng.gen_range(0..s.toml.len())];
            let bytes = mutate(rng, seed);
            match Config::parse(&String::from_utf8_lossy(&bytes), path) {
                Ok(cfg) => {
                    ACCEPTED.fetch_add(1, Ordering::Relaxed);
                    envelope_on_seed_data(&cfg, &s.data)
                }
                Err(e) => one_line(&e.to_string()),
            }
        }
        // Extreme but well-formed SISO models and data.
        _ => extreme(rng),
    }
}

/// A SISO standard factorization with a lightly damped (ζ down to 1e-4) mode and
/// coefficients over 12 decades, and data over 12 decades of frequency and magnitude.
fn extreme(rng: &mut ChaCha8Rng) -> Result<(), String> {
    let lg = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| 10f64.powf(rng.gen_range(lo..hi));
    let (w, z, p, k) = (
        lg(rng, -6.0, 6.0),
        lg(rng, -4.0, 0.0),
        lg(rng, -6.0, 6.0),
        lg(rng, -6.0, 6.0) * if rng.gen() { 1.0 } else { -1.0 },
    );
    let toml = format!(
        "[model]\nfactorization = \"standard\"\nm = [[{{ num = [1, {}, {}], den = [1, {}, {}] }}]]\nn = [[{{ num = [{}], den = [1, {}] }}]]\n",
        2.0 * z * w,
        w * w,
        2.0 * p,
        p * p,
        k,
        p
    );
    let cfg = match Config::parse(&toml, Path::new("extreme.toml")) {
        Ok(c) => c,
        Err(e) => return one_line(&e.to_string()),
    };
    let n = rng.gen_range(1..60);
    let mut omega: Vec<f64> = (0..n).map(|_| lg(rng, -6.0, 6.0)).collect();
    omega.sort_by(f64::total_cmp);
    omega.dedup_by(|a, b| *a <= *b * (1.0 + 1e-9));
    let response = omega
        .iter()
        .map(|_| {
            let (m, ph) = (lg(rng, -6.0, 6.0), rng.gen_range(-180.0..180.0f64));
            nalgebra::DMatrix::from_element(
                1,
                1,
                num_complex::Complex64::from_polar(m, ph.to_radians()),
            )
        })
        .collect();
    let data = FrfData {
        path: PathBuf::from("extreme.csv"),
        lines: (1..=omega.len()).collect(),
        omega,
        response,
        noise_radius: None,
    };
    match noise_free_envelope(&cfg.factorization, &data) {
        Ok(env) => {
            ACCEPTED.fetch_add(1, Ordering::Relaxed);
            no_nan(&env)
        }
        Err(e) => one_line(&e.to_string()),
    }
}

/// Runs `f` on another thread; panics if it takes longer than `limit` (a hang).
fn with_watchdog<T: Send + 'static>(
    limit: Duration,
    progress: Arc<AtomicUsize>,
    f: impl FnOnce() -> T + Send + 'static,
) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(limit) {
        Ok(v) => v,
        Err(_) => panic!(
            "watchdog: no answer within {limit:?}, stuck at case {}",
            progress.load(Ordering::SeqCst)
        ),
    }
}

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
fn mutated_and_extreme_inputs_in_process() {
    let cases = env_usize("RSHAPE_FUZZ_CASES", 6000);
    let seed = env_usize("RSHAPE_FUZZ_SEED", 1998) as u64;
    let progress = Arc::new(AtomicUsize::new(0));
    let p = progress.clone();
    let t = Instant::now();
    let failures = with_watchdog(Duration::from_secs(240), progress, move || {
        let s = seeds();
        let mut failures = Vec::new();
        for k in 0..cases {
            p.store(k, Ordering::SeqCst);
            // One generator per case: a failure is replayed from (seed, k) alone.
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (k as u64).wrapping_mul(0x9E37_79B9));
            let r =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| case(k, &mut rng, &s)));
            match r {
                Ok(Ok(())) => {}
                Ok(Err(e)) => failures.push(format!("case {k}: {e}")),
                Err(_) => failures.push(format!("case {k}: panic")),
            }
        }
        failures
    });
    let _ = writeln!(
        std::io::stderr(),
        "fuzz: {cases} in-process cases (seed {seed}) in {:.1} s, {} accepted and processed, {} failures",
        t.elapsed().as_secs_f64(),
        ACCEPTED.load(Ordering::Relaxed),
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Runs the binary with a time limit; returns (exit code, stderr).
fn run_limited(args: &[&str], limit: Duration) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rshape"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            let o = child.wait_with_output().unwrap();
            return (
                o.status.code(),
                String::from_utf8_lossy(&o.stderr).into_owned(),
            );
        }
        if t.elapsed() > limit {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("watchdog: rshape {args:?} still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn mutated_inputs_through_the_binary() {
    let cases = env_usize("RSHAPE_FUZZ_CASES", 6000) / 100;
    let seed = env_usize("RSHAPE_FUZZ_SEED", 1998) as u64;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let csv = std::fs::read(common::repo("configs/paper_mimo.csv")).unwrap();
    let toml = std::fs::read_to_string(common::repo("configs/paper_mimo.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut failures = Vec::new();
    let mut codes = [0usize; 4];
    for k in 0..cases {
        let (cfg, data) = if k % 2 == 0 {
            (toml.clone().into_bytes(), mutate(&mut rng, &csv))
        } else {
            (mutate(&mut rng, toml.as_bytes()), csv.clone())
        };
        std::fs::write(d.join("paper_mimo.toml"), &cfg).unwrap();
        std::fs::write(d.join("paper_mimo.csv"), &data).unwrap();
        let c = d.join("paper_mimo.toml");
        let out = d.join(format!("out{k}"));
        let args: Vec<&str> = match k % 4 {
            0 | 1 => vec![
                "envelope",
                c.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            _ => vec!["check", c.to_str().unwrap()],
        };
        let (code, err) = run_limited(&args, Duration::from_secs(60));
        match code {
            Some(x @ 0..=3) => codes[x as usize] += 1,
            other => failures.push(format!("case {k}: exit {other:?}: {err}")),
        }
        if err.contains("panicked") {
            failures.push(format!("case {k}: panic: {err}"));
        }
        if code == Some(2) && (err.trim_end().lines().count() != 1 || !err.starts_with("error: ")) {
            failures.push(format!("case {k}: not a one-line error: {err}"));
        }
    }
    let _ = writeln!(
        std::io::stderr(),
        "fuzz: {cases} binary cases, exit codes 0/1/2/3: {codes:?}"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

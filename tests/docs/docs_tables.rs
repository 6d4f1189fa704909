//! The figures tables of the user guide are rerun and compared: docs/guide/synthesize.md's
//! "What a tighter r buys" tables (marked `<!-- table: NAME -->`), each cell against what
//! `rshape synthesize` prints now, to the digits the table shows.  The cheap rows run in every
//! `cargo test`; the robot's configured row and the fitted-r table (a fit each, about 75 s in a
//! debug build) in the ignored test.
use crate::common::{repo, rshape, stdout};

/// The rows of the table that follows `<!-- table: NAME -->` in `doc`: cells without the
/// leading/trailing pipes, header and separator skipped.
fn table(doc: &str, name: &str) -> Vec<Vec<String>> {
    let marker = format!("<!-- table: {name} -->");
    let start = doc.find(&marker).unwrap_or_else(|| panic!("no {marker}"));
    doc[start + marker.len()..]
        .lines()
        .skip_while(|l| l.trim().is_empty())
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim()
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

/// What one `synthesize` run printed: the value after `key = ` on the line that has it.
fn after(out: &str, key: &str) -> Option<f64> {
    let i = out.find(key)? + key.len();
    let tail = out[i..].trim_start();
    let end = tail
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | 'e' | '-' | '+')))
        .unwrap_or(tail.len());
    tail[..end].parse().ok()
}

/// α* in the proof's row `label` (its first number).
fn alpha_row(out: &str, label: &str) -> Option<f64> {
    // Other lines start with the same word ("configured r is frequency dependent: …").
    out.lines()
        .filter(|l| l.split_whitespace().next() == Some(label))
        .find_map(|l| l.split_whitespace().nth(1)?.parse().ok())
}

/// Bandwidth from the `closed loop:` line (None where it prints `none`).
fn bandwidth(out: &str) -> Option<f64> {
    let l = out
        .lines()
        .find(|l| l.starts_with("closed loop: bandwidth"))?;
    let rest = &l[l.find(" dB) ")? + 5..];
    if rest.starts_with("none") {
        None
    } else {
        rest.split_whitespace().next()?.parse().ok()
    }
}

/// The doc's cell agrees with the measured value to the digits it shows (`–` = none).
fn agrees(cell: &str, got: Option<f64>) -> bool {
    match (cell, got) {
        ("–", None) => true,
        ("–", Some(_)) | (_, None) => false,
        (c, Some(v)) => {
            let Ok(doc) = c.parse::<f64>() else {
                return false;
            };
            // Half a unit in the last digit shown (mantissa digits after the point).
            let mantissa = c.split(['e', 'E']).next().unwrap();
            let decimals = mantissa.split('.').nth(1).map_or(0, str::len) as i32;
            let exp10: i32 = c.split(['e', 'E']).nth(1).map_or(0, |e| e.parse().unwrap());
            (v - doc).abs() <= 0.5 * 10f64.powi(exp10 - decimals) * (1.0 + 1e-9)
        }
    }
}

fn synthesize(config: &str, extra: &[&str]) -> String {
    let out = tempfile::tempdir().unwrap();
    let cfg = repo(&format!("configs/{config}"));
    let mut args = vec![
        "synthesize",
        cfg.to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = rshape(&args);
    let text = stdout(&o);
    assert!(
        matches!(o.status.code(), Some(0) | Some(1)),
        "synthesize {config} {extra:?} failed: {}{}",
        text,
        String::from_utf8_lossy(&o.stderr)
    );
    text
}

fn config_of(cell: &str) -> String {
    cell.trim_matches('`').to_string()
}

/// The cells of `row` that disagree with `got`, each as a line naming table, row and column.
fn stale_cells(what: &str, row: &[String], got: &[Option<f64>]) -> Vec<String> {
    eprintln!("table {what}, {}: measured {got:?}", row[0]);
    row[1..]
        .iter()
        .zip(got)
        .enumerate()
        .filter(|(_, (cell, g))| !agrees(cell, **g))
        .map(|(k, (cell, g))| {
            format!(
                "docs/guide/synthesize.md, table {what}, row {}, column {}: the doc says {cell}, synthesize now gives {g:?}",
                row[0],
                k + 2
            )
        })
        .collect()
}

fn assert_current(stale: &[String]) {
    assert!(stale.is_empty(), "stale figures:\n{}", stale.join("\n"));
}

fn configured_row(row: &[String]) -> Vec<String> {
    let config = config_of(&row[0]);
    let gm = synthesize(&config, &[]);
    let hinf = synthesize(&config, &["--method", "hinf"]);
    let got = [
        alpha_row(&gm, "configured"),
        bandwidth(&gm),
        after(&gm, "Ms ="),
        after(&hinf, "alpha_opt ="),
        alpha_row(&hinf, "configured"),
        bandwidth(&hinf),
        after(&hinf, "Ms ="),
    ];
    stale_cells("configured", row, &got)
}

fn doc() -> String {
    std::fs::read_to_string(repo("docs/guide/synthesize.md")).unwrap()
}

#[test]
fn parser_reads_the_digits_shown() {
    assert!(agrees("2.734", Some(2.7344)));
    assert!(!agrees("2.734", Some(2.7346)));
    assert!(agrees("0.000575", Some(5.7503e-4)));
    assert!(agrees("–", None));
    assert!(!agrees("–", Some(1.0)));
    assert!(!agrees("1.0", None));
    let out = "configured r is frequency dependent: …\nclosed loop: bandwidth (sigma_max(S) = -3 dB) 0.447428 rad/s, peak sensitivity Ms = 1.295371\nconfigured       2.090673       2.097509     2.090673      yes\n";
    assert_eq!(bandwidth(out), Some(0.447428));
    assert_eq!(after(out, "Ms ="), Some(1.295371));
    assert_eq!(alpha_row(out, "configured"), Some(2.090673));
}

#[test]
fn synthesize_configured_table_is_current() {
    let rows = table(&doc(), "configured");
    assert_eq!(
        rows.len(),
        3,
        "the configured table has the three examples with an r"
    );
    let stale: Vec<String> = rows
        .iter()
        .filter(|r| !r[0].contains("robot"))
        .flat_map(|r| configured_row(r))
        .collect();
    assert_current(&stale);
}

#[test]
#[ignore = "about 75 s in a debug build: the robot's proofs and four fits"]
fn synthesize_robot_and_fitted_tables_are_current() {
    let d = doc();
    let mut stale: Vec<String> = table(&d, "configured")
        .iter()
        .filter(|r| r[0].contains("robot"))
        .flat_map(|r| configured_row(r))
        .collect();
    let rows = table(&d, "fitted");
    assert_eq!(rows.len(), 4);
    for row in &rows {
        let config = config_of(&row[0]);
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().to_str().unwrap();
        let cfg = repo(&format!("configs/{config}"));
        let o = rshape(&[
            "synthesize",
            cfg.to_str().unwrap(),
            "--fit",
            "--method",
            "hinf",
            "--out",
            out,
        ]);
        let hinf = stdout(&o);
        let r_json = dir.path().join("r.json");
        let gm = synthesize(&config, &["--r-json", r_json.to_str().unwrap()]);
        let got = [
            after(&hinf, "alpha_opt ="),
            alpha_row(&hinf, "fitted"),
            alpha_row(&hinf, "configured"),
            bandwidth(&hinf),
            after(&hinf, "Ms ="),
            alpha_row(&gm, "fitted"),
        ];
        stale.extend(stale_cells("fitted", row, &got));
    }
    assert_current(&stale);
}

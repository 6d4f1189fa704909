//! Long work and long lists stay readable (issue 24): `compare` summarizes many failing
//! bands on the terminal (the worst few and a count) while `--json` keeps the full list;
//! `batch` reports progress on a non-terminal stdout with periodic lines.
use crate::common;

use common::{repo, rshape, stdout};

#[test]
fn compare_summarizes_many_failing_bands_and_json_keeps_them_all() {
    let cfg = repo("configs/twomass_rev3.toml");
    let o = rshape(&["compare", cfg.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0));
    let j: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let bands = j["bands"].as_array().unwrap();
    assert!(
        bands.len() > 10,
        "the example must have many bands: {}",
        bands.len()
    );
    let total: u64 = bands.iter().map(|b| b["count"].as_u64().unwrap()).sum();

    let o = rshape(&["compare", cfg.to_str().unwrap()]);
    let t = stdout(&o);
    let line = t
        .lines()
        .find(|l| l.starts_with("fails (noise only):"))
        .unwrap();
    assert!(
        line.chars().count() < 600,
        "{} chars: {line}",
        line.chars().count()
    );
    assert!(
        line.contains(&format!("{} bands, {total} data", bands.len())),
        "{line}"
    );
    // The worst band by peak misfit is among the three shown.
    let worst = bands
        .iter()
        .max_by(|a, b| {
            a["peak_misfit"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["peak_misfit"].as_f64().unwrap())
        })
        .unwrap();
    let hz = worst["omega_peak"].as_f64().unwrap() / std::f64::consts::TAU;
    assert!(line.contains(&format!("at {} Hz", hz.round())), "{line}");
    assert_eq!(line.matches("peak misfit").count(), 3, "{line}");
    assert!(
        line.contains(&format!("{} more bands", bands.len() - 3)),
        "{line}"
    );
}

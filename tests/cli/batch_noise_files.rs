//! `batch --data-dir`: the noise files beside a dataset (`<stem>_std.csv`,
//! `<stem>_coherence.csv`) are not datasets (they used to become failed rows, exit 3, on the
//! DaISy robot arm's folder of an H1 estimate and its coherence).

use crate::common::{repo, rshape, stderr, stdout};

#[test]
fn noise_siblings_are_not_datasets() {
    let d = tempfile::tempdir().unwrap();
    let data = std::fs::read_to_string(repo("configs/plant_first.csv")).unwrap();
    for name in ["a.csv", "b.csv"] {
        std::fs::write(d.path().join(name), &data).unwrap();
    }
    std::fs::write(d.path().join("a_coherence.csv"), "freq_hz,coh_1_1\n1,0.9\n").unwrap();
    std::fs::write(d.path().join("b_std.csv"), "freq_hz,std_1_1\n1,0.1\n").unwrap();
    // Not a sibling: no `c.csv` beside it, so it stays a dataset (and fails, named).
    std::fs::write(d.path().join("c_std.csv"), "freq_hz,std_1_1\n1,0.1\n").unwrap();
    let out = d.path().join("out");
    let cfg = repo("configs/plant_first.toml");
    let o = rshape(&[
        "batch",
        cfg.to_str().unwrap(),
        "--data-dir",
        d.path().to_str().unwrap(),
        "--order",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = stdout(&o);
    assert_eq!(o.status.code(), Some(3), "{text}{}", stderr(&o));
    assert!(
        text.contains("3 of 3 dataset(s) processed, 2 ok, 1 failed"),
        "{text}"
    );
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let names: Vec<&str> = summary
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    assert_eq!(names, ["a", "b", "c_std"], "{summary}");
}

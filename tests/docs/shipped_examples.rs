//! README.md's "Shipped examples" table names every config in `configs/`: a config added
//! without a row (the DaISy and SLICOT sets were) is caught here.  A cell's backticked names
//! are paths from the repository (`configs/x.toml`), names beside such a path in the same cell
//! (`x_controller.toml`, in `configs/`), or globs with one `*` (`configs/closed_loop_*.toml`).
use crate::common::repo;

/// The backticked names of the table under `## Shipped examples`, as paths from the
/// repository root (a bare name is taken to be in `configs/`).
fn listed(readme: &str) -> Vec<String> {
    let start = readme
        .find("## Shipped examples")
        .expect("README.md has a `## Shipped examples` section");
    let section = &readme[start..];
    let end = section[3..].find("\n## ").map_or(section.len(), |i| i + 3);
    section[..end]
        .lines()
        .filter(|l| l.starts_with('|'))
        .filter_map(|l| l.trim_matches('|').split('|').next())
        .flat_map(|cell| cell.split('`').skip(1).step_by(2).map(str::to_string))
        .map(|n| {
            if n.contains('/') {
                n
            } else {
                format!("configs/{n}")
            }
        })
        .collect()
}

/// `name` matches `pattern`, a path with at most one `*`.
fn matches(pattern: &str, name: &str) -> bool {
    match pattern.split_once('*') {
        Some((pre, post)) => {
            name.len() >= pre.len() + post.len() && name.starts_with(pre) && name.ends_with(post)
        }
        None => pattern == name,
    }
}

#[test]
fn the_matcher_reads_globs_and_bare_names() {
    let table = "## Shipped examples\n\n| file | what |\n|---|---|\n| `configs/a_*.toml`, `b_controller.toml` | `configs/not_me.toml` |\n\n## Next\n| `configs/c.toml` | x |\n";
    let got = listed(table);
    assert_eq!(got, ["configs/a_*.toml", "configs/b_controller.toml"]);
    assert!(matches(&got[0], "configs/a_one.toml"));
    assert!(!matches(&got[0], "configs/b_one.toml"));
    assert!(matches(&got[1], "configs/b_controller.toml"));
    assert!(!matches(&got[1], "configs/b.toml"));
}

#[test]
fn every_shipped_config_has_a_row() {
    let readme = std::fs::read_to_string(repo("README.md")).unwrap();
    let patterns = listed(&readme);
    let mut missing = Vec::new();
    for e in std::fs::read_dir(repo("configs")).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        if !name.ends_with(".toml") {
            continue;
        }
        let path = format!("configs/{name}");
        if !patterns.iter().any(|p| matches(p, &path)) {
            missing.push(path);
        }
    }
    missing.sort();
    assert!(
        missing.is_empty(),
        "configs without a row in README.md's Shipped examples: {missing:?}"
    );
    // And no row names a config that is not there.
    for p in patterns
        .iter()
        .filter(|p| !p.contains('*') && p.ends_with(".toml"))
    {
        assert!(
            repo(p).is_file(),
            "README.md lists {p}, which does not exist"
        );
    }
}

//! The library stands without the CLI: no module outside `src/cli` (and `src/main.rs`, which
//! only calls it) refers to `crate::cli` or `rshape::cli`.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src is readable") {
        let p = entry.expect("dir entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Where a line of code matches: `file:line: text`, for every line of the sources under
/// `src` outside the CLI (`src/cli`, `src/main.rs`) unless `with_cli`, up to the first
/// `#[cfg(test)]` of each file when `code_only`, with its comment cut off.
fn offending_lines(with_cli: bool, code_only: bool, matches: impl Fn(&str) -> bool) -> Vec<String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(
        files.len() > 50,
        "expected the whole source tree, got {}",
        files.len()
    );
    let cli_dir = src.join("cli");
    let mut offenders = Vec::new();
    for f in files {
        if !with_cli && (f.starts_with(&cli_dir) || f.ends_with("main.rs")) {
            continue;
        }
        let text = std::fs::read_to_string(&f).expect("source is UTF-8");
        for (i, line) in text.lines().enumerate() {
            // Test code: a `#[cfg(test)]` module at the end of a file, or a whole file that
            // declares itself test-only (`#![cfg(test)]`, a `#[path]` test module).
            let t = line.trim_start();
            if code_only && (t.starts_with("#[cfg(test)]") || t.starts_with("#![cfg(test)]")) {
                break;
            }
            if matches(line.split("//").next().unwrap_or("")) {
                offenders.push(format!("{}:{}: {}", f.display(), i + 1, line.trim()));
            }
        }
    }
    offenders
}

#[test]
fn no_library_module_imports_the_cli() {
    let offenders = offending_lines(false, false, |code| {
        code.contains("crate::cli") || code.contains("rshape::cli") || code.contains("super::cli")
    });
    assert!(
        offenders.is_empty(),
        "library modules import the CLI:\n{}",
        offenders.join("\n")
    );
}

/// The library does not depend on the CLI's crates: clap, indicatif and anyhow are optional
/// dependencies enabled only by the `cli` feature (which the binary requires), and no library
/// source names them.
#[test]
fn the_library_does_not_depend_on_clap_indicatif_or_anyhow() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest: toml::Value = std::fs::read_to_string(root.join("Cargo.toml"))
        .expect("Cargo.toml")
        .parse()
        .expect("Cargo.toml parses");
    let cli_crates = ["clap", "indicatif", "anyhow"];
    for name in cli_crates {
        let dep = &manifest["dependencies"][name];
        assert_eq!(
            dep.get("optional").and_then(|v| v.as_bool()),
            Some(true),
            "{name} must be an optional dependency (feature `cli`)"
        );
    }
    let cli_feature: Vec<&str> = manifest["features"]["cli"]
        .as_array()
        .expect("feature cli")
        .iter()
        .filter_map(|v| v.as_str())
        .collect();
    for name in cli_crates {
        assert!(cli_feature.contains(&format!("dep:{name}").as_str()));
    }
    let bins = manifest["bin"].as_array().expect("[[bin]]");
    assert!(bins.iter().all(|b| b["required-features"]
        .as_array()
        .is_some_and(|f| f.iter().any(|x| x.as_str() == Some("cli")))));

    let offenders = offending_lines(false, false, |code| {
        cli_crates
            .iter()
            .any(|c| code.contains(&format!("{c}::")) || code.contains(&format!("use {c}")))
    });
    assert!(
        offenders.is_empty(),
        "library modules use CLI crates:\n{}",
        offenders.join("\n")
    );
}

/// No control flow in the library is decided by matching message text: fields that hold
/// messages (`origin`, `action`, `msg`, `message`, `reason`, `note`, `verdict`, an error's
/// `to_string()`) are never tested with `starts_with`/`contains`/`==` on a string literal
/// outside test code.  Decisions use enums (issue 25).
#[test]
fn no_decision_matches_message_text() {
    let fields = [
        "origin",
        "action",
        "msg",
        "message",
        "reason",
        "note",
        "verdict",
        "to_string()",
    ];
    let ops = [".starts_with(\"", ".contains(\"", " == \"", ".ends_with(\""];
    let offenders = offending_lines(true, true, |code| {
        fields
            .iter()
            .any(|field| ops.iter().any(|op| code.contains(&format!("{field}{op}"))))
    });
    assert!(
        offenders.is_empty(),
        "decisions on message text:\n{}",
        offenders.join("\n")
    );
}

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

#[test]
fn no_library_module_imports_the_cli() {
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
        if f.starts_with(&cli_dir) || f.ends_with("main.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&f).expect("source is UTF-8");
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if code.contains("crate::cli")
                || code.contains("rshape::cli")
                || code.contains("super::cli")
            {
                offenders.push(format!("{}:{}: {}", f.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "library modules import the CLI:\n{}",
        offenders.join("\n")
    );
}

//! The documentation stays true: every command in a ```` ```console ```` block of README.md
//! and of the user guide (docs/guide/*.md) is executed and its printed output compared with
//! the text under it.
//!
//! Conventions (stated in docs/guide/README.md): a line `$ CMD` is a command, run by `sh -c`
//! from a scratch folder that holds a link to the repository's `configs/`, with the freshly
//! built `rshape` first on `PATH`; the lines up to the next `$ ` are its expected output
//! (stdout, then stderr).  In an expected line `[..]` matches any text (times, for
//! instance); a line `...` matches any number of lines.  A ```` ```toml ```` block whose first
//! line is `# file: PATH` is written to `PATH` in the scratch folder before the commands that
//! follow it.  A ```` ```text output-of: CMD ```` block shows part of what `CMD` prints: `CMD`
//! is run there and the block's lines must appear in its output as one run (with the same
//! `[..]` and `...`).  Each document gets its own scratch folder, so its commands may build on
//! each other in order (the README's tutorial does).  Every other fenced block has a language
//! and shows no `$ ` command line, so no documented command escapes the test.
#![cfg(unix)]
use crate::common;

use common::repo;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One step of a document, in order.
#[derive(Debug)]
enum Step {
    /// Write a file (path relative to the scratch folder, contents).
    File(String, String),
    /// Run a command and compare its output (line of the `$` in the document, command,
    /// expected lines).
    Run(usize, String, Vec<String>),
    /// Run a command and find the lines of an excerpt in its output (line of the block,
    /// command, excerpt).
    Excerpt(usize, String, Vec<String>),
}

/// The command of a ```` ```text output-of: CMD ```` fence.
fn output_of(fence: &str) -> Option<&str> {
    fence
        .strip_prefix("```text output-of:")
        .map(str::trim)
        .filter(|c| !c.is_empty())
}

/// The steps of a Markdown document.
fn steps(text: &str) -> Vec<Step> {
    let mut out = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i].trim_end();
        if let Some(cmd) = output_of(l) {
            let mut body = Vec::new();
            let mut j = i + 1;
            while j < lines.len() && !lines[j].starts_with("```") {
                body.push(lines[j].trim_end().to_string());
                j += 1;
            }
            out.push(Step::Excerpt(i + 1, cmd.to_string(), body));
            i = j;
        } else if l == "```console" || l == "```toml" {
            let mut body = Vec::new();
            let mut j = i + 1;
            while j < lines.len() && !lines[j].starts_with("```") {
                body.push((j + 1, lines[j]));
                j += 1;
            }
            if l == "```toml" {
                if let Some(p) = body.first().and_then(|(_, b)| b.strip_prefix("# file: ")) {
                    let mut contents: String =
                        body[1..].iter().map(|(_, b)| format!("{b}\n")).collect();
                    if contents.is_empty() {
                        contents.push('\n');
                    }
                    out.push(Step::File(p.trim().to_string(), contents));
                }
            } else {
                for (n, b) in body {
                    if let Some(cmd) = b.strip_prefix("$ ") {
                        out.push(Step::Run(n, cmd.to_string(), Vec::new()));
                    } else if let Some(Step::Run(_, _, exp)) = out.last_mut() {
                        exp.push(b.trim_end().to_string());
                    }
                }
            }
            i = j;
        }
        i += 1;
    }
    out
}

/// Does `got` match the expected line `want` (`[..]` = any text)?
fn line_matches(want: &str, got: &str) -> bool {
    let parts: Vec<&str> = want.split("[..]").collect();
    if parts.len() == 1 {
        return want == got;
    }
    let (first, last) = (parts[0], parts[parts.len() - 1]);
    if !got.starts_with(first) || got.len() < first.len() + last.len() || !got.ends_with(last) {
        return false;
    }
    let mut rest = &got[first.len()..got.len() - last.len()];
    for p in &parts[1..parts.len() - 1] {
        match rest.find(p) {
            Some(k) => rest = &rest[k + p.len()..],
            None => return false,
        }
    }
    true
}

/// Do the lines `got` match the expected lines `want` (`...` = any number of lines)?
fn lines_match(want: &[String], got: &[String]) -> bool {
    match want.split_first() {
        None => got.is_empty(),
        Some((w, rest)) if w == "..." => (0..=got.len()).any(|k| lines_match(rest, &got[k..])),
        Some((w, rest)) => {
            !got.is_empty() && line_matches(w, &got[0]) && lines_match(rest, &got[1..])
        }
    }
}

/// Runs the steps of one document in a fresh scratch folder; returns the mismatches.
fn run_document(doc: &Path) -> (usize, Vec<String>) {
    let text = std::fs::read_to_string(doc).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(repo("configs"), dir.path().join("configs")).unwrap();
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_rshape")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let scratch = dir.path().display().to_string();
    let mut failures = Vec::new();
    let mut n = 0;
    for step in steps(&text) {
        let excerpt = matches!(step, Step::Excerpt(..));
        match step {
            Step::File(p, contents) => {
                let f = dir.path().join(&p);
                std::fs::create_dir_all(f.parent().unwrap()).unwrap();
                std::fs::write(&f, contents).unwrap();
            }
            Step::Run(line, cmd, want) | Step::Excerpt(line, cmd, want) => {
                n += 1;
                let o = Command::new("sh")
                    .arg("-c")
                    .arg(&cmd)
                    .current_dir(dir.path())
                    .env("PATH", &path)
                    .output()
                    .unwrap();
                let all = format!(
                    "{}{}",
                    String::from_utf8_lossy(&o.stdout),
                    String::from_utf8_lossy(&o.stderr)
                )
                .replace(&scratch, "DIR");
                let got: Vec<String> = all.lines().map(|l| l.trim_end().to_string()).collect();
                // An excerpt is one run of lines anywhere in the output.
                let pattern = if excerpt {
                    [
                        vec!["...".to_string()],
                        want.clone(),
                        vec!["...".to_string()],
                    ]
                    .concat()
                } else {
                    want.clone()
                };
                if !lines_match(&pattern, &got) {
                    failures.push(format!(
                        "{}:{line}: `{cmd}`\n--- documented\n{}\n--- printed\n{}",
                        doc.display(),
                        want.join("\n"),
                        got.join("\n")
                    ));
                }
            }
        }
    }
    (n, failures)
}

/// README.md and every chapter of the guide.
fn documents() -> Vec<PathBuf> {
    let mut docs = vec![repo("README.md")];
    let mut guide: Vec<PathBuf> = std::fs::read_dir(repo("docs/guide"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    guide.sort();
    docs.extend(guide);
    docs
}

#[test]
fn every_documented_command_prints_what_the_docs_say() {
    let mut failures = Vec::new();
    let mut total = 0;
    for doc in documents() {
        let (n, f) = run_document(&doc);
        total += n;
        failures.extend(f);
    }
    assert!(total >= 10, "only {total} documented commands found");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn the_readme_tutorial_is_executed() {
    // The tutorial's steps are all present as executable blocks (a `text` block would
    // silently escape the test).
    let text = std::fs::read_to_string(repo("README.md")).unwrap();
    let s = steps(&text);
    let cmds: Vec<&str> = s
        .iter()
        .filter_map(|st| match st {
            Step::Run(_, c, _) => Some(c.as_str()),
            _ => None,
        })
        .collect();
    for want in [
        "rshape run configs/paper_mimo.toml --out out/paper",
        "rshape run mine/model.toml --out out/mine",
        "rshape stability mine/model.toml --controller mine/k.toml --r-json out/mine/r.json",
    ] {
        assert!(
            cmds.contains(&want),
            "README lacks `{want}` in a console block"
        );
    }
    let files: Vec<&str> = s
        .iter()
        .filter_map(|st| match st {
            Step::File(p, _) => Some(p.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(files, ["mine/model.toml", "mine/k.toml"]);
}

/// Every fenced block of README.md and the guide has a language, and only `console` blocks
/// show `$ ` command lines: a command with its output in a `text`, `sh` or unlabelled block
/// would escape the test above.
#[test]
fn no_documented_command_escapes_the_test() {
    let mut bad = Vec::new();
    let mut excerpts = 0;
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        let mut fence: Option<(usize, String)> = None;
        for (k, line) in text.lines().enumerate() {
            let l = line.trim_start();
            match (&fence, l.strip_prefix("```")) {
                (None, Some(info)) => {
                    if info.trim().is_empty() {
                        bad.push(format!(
                            "{}:{}: a block without a language",
                            doc.display(),
                            k + 1
                        ));
                    }
                    excerpts += usize::from(output_of(l).is_some());
                    fence = Some((k + 1, info.trim().to_string()));
                }
                (Some(_), Some(_)) => fence = None,
                (Some((start, info)), None) => {
                    if info != "console" && l.starts_with("$ ") {
                        bad.push(format!(
                            "{}:{}: `{l}` in a `{info}` block (line {start}): put it in a console block",
                            doc.display(),
                            k + 1
                        ));
                    }
                }
                (None, None) => {}
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    assert!(excerpts >= 2, "only {excerpts} output-of excerpts found");
}

#[test]
fn the_matcher_rejects_what_it_should() {
    let v = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert!(line_matches("time [..] ms", "time 12.5 ms"));
    assert!(!line_matches("time [..] ms", "time 12.5 s"));
    assert!(!line_matches("a", "ab"));
    assert!(lines_match(
        &v(&["x", "...", "z"]),
        &v(&["x", "1", "2", "z"])
    ));
    assert!(!lines_match(&v(&["x", "...", "z"]), &v(&["x", "1", "2"])));
    assert!(!lines_match(&v(&["x"]), &v(&["x", "extra"])));
}

//! `src/diagnose` is in layers (its `mod.rs` says which): no import cycle between its
//! modules nor between its layers (`effects`, `lsq`, `search`, and each file beside them),
//! and the bottom layers use nothing above them (issue 37).
//!
//! The imports are read from the sources: every `crate::diagnose::a::b…` path (and
//! `super::a` naming a sibling module) in the code of a file, before its `#[cfg(test)]`
//! module, resolves to the longest module path it starts with; the registration list of the
//! effects (`register! { … }`) names each effect's module by a relative path
//! (`delay::Delay`), read as well.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src/diagnose is readable") {
        let p = entry.expect("dir entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `lsq/problem.rs` → `lsq::problem`, `lsq/mod.rs` → `lsq`, `mod.rs` → `` (the root).
fn module_of(rel: &Path) -> String {
    let mut parts: Vec<String> = rel
        .with_extension("")
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|l| l == "mod") {
        parts.pop();
    }
    parts.join("::")
}

/// The identifiers of the path that starts at byte `at` of `code`: `a::b::C` → `[a, b, C]`.
fn path_at(code: &str, at: usize) -> Vec<String> {
    let rest = &code[at..];
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
        .unwrap_or(rest.len());
    rest[..end]
        .split("::")
        .take_while(|s| !s.is_empty())
        .map(str::to_string)
        .collect()
}

/// The longest module path among `modules` that `path` starts with.
fn resolve(path: &[String], modules: &BTreeSet<String>) -> Option<String> {
    (1..=path.len())
        .rev()
        .map(|k| path[..k].join("::"))
        .find(|m| modules.contains(m))
}

/// The first segments of the relative paths (`delay::Delay` → `delay`) in the body of a
/// `register! { … }` invocation of `code` (the effects' registration list).
fn registry_paths(code: &str) -> Vec<String> {
    let Some(start) = code.find("register! {") else {
        return Vec::new();
    };
    let body = &code[start + "register! {".len()..];
    let body = &body[..body.find("\n}").unwrap_or(body.len())];
    let mut out = Vec::new();
    for line in body.lines() {
        let code = line.split("//").next().unwrap_or("");
        for (at, _) in code.match_indices("::") {
            let head = &code[..at];
            let name: String = head
                .chars()
                .rev()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect();
            let before = head[..head.len() - name.len()].chars().last();
            if !name.is_empty() && !matches!(before, Some(':') | Some('$')) {
                out.push(name);
            }
        }
    }
    out
}

/// Module → the diagnose modules its code names, and the lines that name diagnose in a form
/// the reader cannot resolve (`crate::diagnose::{…}`).
fn imports() -> (BTreeMap<String, BTreeSet<String>>, Vec<String>) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/diagnose");
    let mut files = Vec::new();
    rust_files(&dir, &mut files);
    let modules: BTreeSet<String> = files
        .iter()
        .map(|f| module_of(f.strip_prefix(&dir).expect("under src/diagnose")))
        .filter(|m| !m.is_empty())
        .collect();
    let mut graph = BTreeMap::new();
    let mut unreadable = Vec::new();
    for f in &files {
        let me = module_of(f.strip_prefix(&dir).expect("under src/diagnose"));
        if me.is_empty() {
            continue; // the root re-exports every layer: it is the top
        }
        let text = std::fs::read_to_string(f).expect("source is UTF-8");
        if text.contains("#![cfg(test)]") {
            continue; // a test-only file
        }
        let parent: Vec<&str> = me.split("::").collect();
        let parent = parent[..parent.len() - 1].join("::");
        let mut deps = BTreeSet::new();
        for (i, line) in text.lines().enumerate() {
            if line.starts_with("#[cfg(test)]") {
                break;
            }
            let code = line.split("//").next().unwrap_or("");
            for (at, _) in code.match_indices("crate::diagnose::") {
                let start = at + "crate::diagnose::".len();
                if code[start..].starts_with('{') {
                    unreadable.push(format!("{}:{}: {}", f.display(), i + 1, line.trim()));
                }
                if let Some(m) = resolve(&path_at(code, start), &modules) {
                    deps.insert(m);
                }
            }
            for (at, _) in code.match_indices("super::") {
                if code[..at].ends_with("super::") {
                    continue; // the second `super::` of `super::super::` (test code only)
                }
                let mut path: Vec<String> = parent
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_string)
                    .collect();
                path.extend(path_at(code, at + "super::".len()));
                if let Some(m) = resolve(&path, &modules) {
                    deps.insert(m);
                }
            }
        }
        // The registry (`register! { … }` in effects/mod.rs) names each effect's module by a
        // path relative to the file (`delay::Delay`): the module depends on each.
        for name in registry_paths(&text) {
            let child = if me.is_empty() {
                name
            } else {
                format!("{me}::{name}")
            };
            if modules.contains(&child) {
                deps.insert(child);
            }
        }
        deps.remove(&me);
        graph.insert(me, deps);
    }
    (graph, unreadable)
}

/// A cycle of `graph` as `a → b → … → a`, if it has one (depth-first search).
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        v: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(v.to_string(), 1);
        stack.push(v.to_string());
        for w in graph.get(v).into_iter().flatten() {
            match state.get(w.as_str()).copied().unwrap_or(0) {
                1 => {
                    let from = stack.iter().position(|s| s == w).expect("on the stack");
                    let mut c = stack[from..].to_vec();
                    c.push(w.clone());
                    return Some(c);
                }
                0 => {
                    if let Some(c) = visit(w, graph, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(v.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for v in graph.keys() {
        if state.get(v.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(v, graph, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

fn layer(module: &str) -> &str {
    module.split("::").next().unwrap_or(module)
}

fn layers(graph: &BTreeMap<String, BTreeSet<String>>) -> BTreeMap<String, BTreeSet<String>> {
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (m, deps) in graph {
        let entry = out.entry(layer(m).to_string()).or_default();
        entry.extend(
            deps.iter()
                .map(|d| layer(d).to_string())
                .filter(|d| d != layer(m)),
        );
    }
    out
}

#[test]
fn the_cycle_finder_finds_a_cycle_and_only_a_cycle() {
    let g = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    assert_eq!(cycle(&g(&[("a", "b"), ("b", "c"), ("a", "c")])), None);
    let c = cycle(&g(&[("a", "b"), ("b", "c"), ("c", "d"), ("d", "b")])).expect("a cycle");
    assert_eq!(c.first(), c.last());
    let mut inner = c[..3].to_vec();
    inner.sort();
    assert_eq!(inner, ["b", "c", "d"]);
    // Layers: modules of one folder collapse into one node.
    let l = layers(&g(&[
        ("lsq::a", "effects::b"),
        ("effects::b", "effects::c"),
    ]));
    assert_eq!(l["lsq"], BTreeSet::from(["effects".to_string()]));
    assert!(l["effects"].is_empty());
}

#[test]
fn diagnose_has_no_import_cycle_between_modules_or_layers() {
    let (graph, unreadable) = imports();
    assert!(
        unreadable.is_empty(),
        "name one diagnose module per path (`use crate::diagnose::lsq::problem::Problem;`), \
         so that this test can read the layering:\n{}",
        unreadable.join("\n")
    );
    // The reader sees the imports it must: a few known edges.
    for (from, to) in [
        ("lsq::problem", "effects::candidates"),
        // Read from the registry's relative paths.
        ("effects", "effects::delay"),
        ("effects", "effects::damping"),
        ("search::beam", "lsq::retune"),
        ("engine", "search::beam"),
        ("lsq::channels", "lsq::measures"),
    ] {
        assert!(
            graph.get(from).is_some_and(|d| d.contains(to)),
            "expected {from} to import {to}; the reader found {:?}",
            graph.get(from)
        );
    }
    assert!(
        graph.len() > 30,
        "expected every module, got {}",
        graph.len()
    );
    if let Some(c) = cycle(&graph) {
        panic!("import cycle between diagnose's modules: {}", c.join(" → "));
    }
    let layered = layers(&graph);
    if let Some(c) = cycle(&layered) {
        panic!("import cycle between diagnose's layers: {}", c.join(" → "));
    }
    // The bottom layers: the catalogue uses nothing of diagnose; the least squares only the
    // catalogue and the leaf `compare`.
    assert!(
        layered["effects"].is_empty(),
        "effects/ imports {:?}",
        layered["effects"]
    );
    let lsq_allowed = BTreeSet::from(["effects".to_string(), "compare".to_string()]);
    assert!(
        layered["lsq"].is_subset(&lsq_allowed),
        "lsq/ imports {:?}",
        layered["lsq"]
    );
    assert!(
        !layered["search"].contains("engine") && !layered["search"].contains("revision"),
        "search/ imports the engine: {:?}",
        layered["search"]
    );
}

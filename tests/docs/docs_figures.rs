//! The documentation's figures are current: `examples/docs_figures.rs` redraws every figure of
//! `docs/figures/` from the shipped configs into a scratch folder, and each committed SVG must
//! have the same structure as the fresh one — the same texts in the same order (titles, axis
//! labels, tick labels, legend entries, among them the fitted `r`) and the same number of
//! each kind of element (paths, polylines, circles, …).  Coordinates are not compared, so
//! the check does not depend on the last bit of a plotted value.  After a change that alters
//! a figure, regenerate them with `cargo run --release --example docs_figures`.
use crate::common;

#[allow(dead_code)]
#[path = "../../examples/docs_figures.rs"]
mod example;

use std::collections::BTreeMap;
use std::path::Path;

/// What is compared of an SVG: its texts in document order, its element counts by name
/// (polylines apart: a dashed curve is one polyline per dash, so their number follows the
/// curve's length in pixels) and the colours of its lines (which curves are drawn).
#[derive(Debug, PartialEq)]
struct Structure {
    texts: Vec<String>,
    elements: BTreeMap<String, usize>,
    line_colours: std::collections::BTreeSet<String>,
}

fn structure(path: &Path) -> Structure {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let doc = roxmltree::Document::parse(&text)
        .unwrap_or_else(|e| panic!("{}: not an SVG document: {e}", path.display()));
    let mut texts = Vec::new();
    let mut elements = BTreeMap::new();
    let mut line_colours = std::collections::BTreeSet::new();
    for node in doc.descendants().filter(|n| n.is_element()) {
        let name = node.tag_name().name();
        if name == "polyline" {
            line_colours.insert(node.attribute("stroke").unwrap_or("").to_string());
        } else {
            *elements.entry(name.to_string()).or_insert(0) += 1;
        }
        if node.tag_name().name() == "text" {
            let t: String = node
                .descendants()
                .filter(|n| n.is_text())
                .filter_map(|n| n.text())
                .collect();
            texts.push(t.trim().to_string());
        }
    }
    Structure {
        texts,
        elements,
        line_colours,
    }
}

#[test]
fn the_committed_figures_are_current() {
    let dir = tempfile::tempdir().unwrap();
    // The figures name their configs as `configs/…`: cargo runs tests from the package root.
    // (No `set_current_dir`: the working folder is process-global and this binary's other
    // tests run in parallel with this one.)
    assert_eq!(
        std::env::current_dir().unwrap().canonicalize().unwrap(),
        common::repo("").canonicalize().unwrap(),
        "run from the repository's root (as `cargo test` does)"
    );
    let fresh = example::regenerate(dir.path()).unwrap();
    let expected: usize = example::FIGURES.iter().map(|(_, _, f)| f.len()).sum();
    assert_eq!(fresh.len(), expected, "figures drawn: {fresh:?}");
    let mut stale = Vec::new();
    for f in &fresh {
        let name = f.file_name().unwrap();
        let committed = common::repo("docs/figures").join(name);
        let (got, want) = (structure(f), structure(&committed));
        if got != want {
            let texts: Vec<String> = want
                .texts
                .iter()
                .zip(&got.texts)
                .filter(|(a, b)| a != b)
                .map(|(a, b)| format!("    committed `{a}`, now `{b}`"))
                .take(5)
                .collect();
            stale.push(format!(
                "docs/figures/{}: texts {} → {}, elements {:?} → {:?}, curves {:?} → {:?}\n{}",
                name.to_string_lossy(),
                want.texts.len(),
                got.texts.len(),
                want.elements,
                got.elements,
                want.line_colours,
                got.line_colours,
                texts.join("\n")
            ));
        }
    }
    assert!(
        stale.is_empty(),
        "stale figures (regenerate with `cargo run --release --example docs_figures`):\n{}",
        stale.join("\n")
    );
    // Every committed figure is one the example draws (none is left unmaintained).
    let mut committed: Vec<String> = std::fs::read_dir(common::repo("docs/figures"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".svg"))
        .collect();
    committed.sort();
    let mut drawn: Vec<String> = fresh
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    drawn.sort();
    assert_eq!(committed, drawn);
}

/// The comparison sees a changed title and a missing element.
#[test]
fn the_structure_comparison_sees_a_change() {
    let dir = tempfile::tempdir().unwrap();
    let svg = |title: &str, circles: usize| {
        let c = "<circle cx=\"1\" cy=\"1\" r=\"1\"/>".repeat(circles);
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\"><text x=\"1\">\n{title}\n</text>{c}</svg>"
        )
    };
    let write = |name: &str, text: String| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let a = structure(&write("a.svg", svg("r vs Δ — robot", 3)));
    assert_eq!(a, structure(&write("b.svg", svg("r vs Δ — robot", 3))));
    assert_eq!(a.texts, ["r vs Δ — robot"]);
    assert_ne!(a, structure(&write("c.svg", svg("r vs Δ — paper", 3))));
    assert_ne!(a, structure(&write("d.svg", svg("r vs Δ — robot", 2))));
    let blue = svg("r vs Δ — robot", 3).replace("</svg>", "<polyline stroke=\"#1F77B4\"/></svg>");
    assert_ne!(a, structure(&write("e.svg", blue)));
}

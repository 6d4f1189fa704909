//! The Rust snippet of the user guide compiles: the `rust` block under "Library API" in
//! docs/guide/run-check-fit.md is `examples/library_api.rs` verbatim, and that example is
//! built by `cargo test --all-targets` (issue 25: the documented library snippet compiled).

use crate::common;

#[test]
fn the_guide_library_snippet_is_the_compiled_example() {
    let guide = std::fs::read_to_string(common::repo("docs/guide/run-check-fit.md")).unwrap();
    let example = std::fs::read_to_string(common::repo("examples/library_api.rs")).unwrap();
    let start = guide
        .find("### Library API")
        .and_then(|i| {
            guide[i..]
                .find("```rust\n")
                .map(|j| i + j + "```rust\n".len())
        })
        .expect("a ```rust block under ### Library API");
    let end = start + guide[start..].find("```\n").expect("the block ends");
    assert_eq!(
        &guide[start..end],
        example,
        "docs/guide/run-check-fit.md's Library API block differs from examples/library_api.rs"
    );
}

//! Test binary `docs` (tests/README.md says which binary a new test joins).
//!
//! The documentation and the repository stay true: README/guide console blocks, figures,
//! snippets, and the library/CLI layering.

#[path = "../common/mod.rs"]
mod common;

mod architecture;
mod diagnose_layers;
mod docs_commands;
mod docs_figures;
mod docs_snippets;
mod docs_tables;
mod shipped_examples;

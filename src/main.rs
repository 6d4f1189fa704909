//! The `rshape` binary: a thin wrapper over [`rshape::cli`].
fn main() {
    std::process::exit(rshape::cli::main());
}

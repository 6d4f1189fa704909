//! The `rshape` binary: the command-line interface ([`cli`]) over the `rshape` library.
//!
//! The CLI parses arguments, calls one library function per subcommand and prints; it is a
//! module of the binary only, so the library does not depend on clap, indicatif or anyhow.

mod cli;

// The CLI names library items as `crate::fit`, `crate::model`, …: the library's modules are
// brought into the binary's root under their own names.
#[allow(unused_imports)]
use rshape::{
    batch, consistency, data, diagnose, error, fit, model, mu, pipeline, plot, report, settings,
    stability, synthesis, system, util,
};

fn main() {
    // Restore the default SIGPIPE action so `rshape ... | head` ends quietly instead of
    // panicking on a closed stdout.
    #[cfg(unix)]
    // SAFETY: setting a signal disposition to SIG_DFL before any thread starts is sound.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    std::process::exit(cli::main());
}

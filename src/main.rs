//! The `rshape` binary: a thin wrapper over [`rshape::cli`].
fn main() {
    // Restore the default SIGPIPE action so `rshape ... | head` ends quietly instead of
    // panicking on a closed stdout.
    #[cfg(unix)]
    // SAFETY: setting a signal disposition to SIG_DFL before any thread starts is sound.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    std::process::exit(rshape::cli::main());
}

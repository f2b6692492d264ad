//! Signals end the command without leaving temporary files behind, and a closed pipe ends it
//! quietly.

/// Makes Ctrl-C, SIGTERM and SIGHUP remove pending temporary files and exit with status 130. Without
/// it the rename never happens, so the target is safe anyway, but a stray `.tmp` would remain.
pub fn remove_temporaries_on_interrupt() {
    // Failing to install the handler only loses the clean-up, never correctness: ignore it.
    let _ = ctrlc::set_handler(|| {
        sc_io::atomic::remove_pending();
        eprintln!("interrupted");
        std::process::exit(130);
    });
}

/// Restores the default action for SIGPIPE, which Rust programs ignore: `skelclimb info f | head`
/// then ends the command silently when `head` stops reading, as `cat` or `grep` do, instead of a
/// panic in `println!`.
pub fn exit_quietly_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to SIG_DFL at start-up, before any thread exists,
    // installs no handler code and touches no Rust state.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

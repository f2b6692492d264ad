//! Signals end the command without leaving temporary files behind.

/// Makes Ctrl-C (and SIGTERM) remove pending temporary files and exit with status 130. Without
/// it the rename never happens, so the target is safe anyway, but a stray `.tmp` would remain.
pub fn remove_temporaries_on_interrupt() {
    // Failing to install the handler only loses the clean-up, never correctness: ignore it.
    let _ = ctrlc::set_handler(|| {
        sc_io::atomic::remove_pending();
        eprintln!("interrupted");
        std::process::exit(130);
    });
}

//! Signals end the command without leaving temporary files behind, and a closed pipe ends it
//! quietly.
//!
//! What a signal means depends on when it lands, and the exit status always agrees with what is
//! on disk: before the outputs are put in place it interrupts the run (temporary files removed,
//! "interrupted", status 130, every target as it was); once they are being put in place it
//! changes nothing, and the run ends as it would have (status 0, the outputs complete). The two
//! cannot interleave: the handler decides and exits while holding the lock that [`finish`]
//! holds while it renames.

use std::sync::{Mutex, MutexGuard, PoisonError};

/// Whether the outputs are being, or have been, put in place.
static FINISHING: Mutex<bool> = Mutex::new(false);

fn finishing() -> MutexGuard<'static, bool> {
    FINISHING.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Makes Ctrl-C, SIGTERM and SIGHUP remove pending temporary files and exit with status 130,
/// unless the outputs are already being put in place ([`finish`]). Without it the rename never
/// happens, so the target is safe anyway, but a stray `.tmp` would remain.
pub fn remove_temporaries_on_interrupt() {
    // Failing to install the handler only loses the clean-up, never correctness: ignore it.
    let _ = ctrlc::set_handler(|| {
        let finishing = finishing();
        if *finishing {
            // The outputs are in place (or will be once the lock is free): the run is done.
            return;
        }
        sc_io::atomic::remove_pending();
        eprintln!("interrupted");
        // Exiting with the lock held: no rename can start after the decision to interrupt.
        std::process::exit(130);
    });
}

/// Runs `renames`, which put the run's complete outputs in place, as one step no signal can
/// split; from then on a signal leaves the run to end as it would have. A failed rename is still
/// reported as an error, as without a signal.
pub fn finish<T>(renames: impl FnOnce() -> sc_io::Result<T>) -> sc_io::Result<T> {
    let mut finishing = finishing();
    *finishing = true;
    let result = renames();
    drop(finishing);
    test_hook_pause();
    result
}

/// Test hook, for the test that signals a run whose outputs are in place: with
/// `SKELCLIMB_TEST_PAUSE_AFTER_RENAME_MS` set, the run waits that long once its outputs are
/// renamed, so that a signal lands there every time. Not documented for users; a mistaken
/// setting only delays the end of a successful run.
fn test_hook_pause() {
    if let Some(ms) = std::env::var_os("SKELCLIMB_TEST_PAUSE_AFTER_RENAME_MS")
        .and_then(|v| v.to_str()?.parse::<u64>().ok())
    {
        std::thread::sleep(std::time::Duration::from_millis(ms.min(60_000)));
    }
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

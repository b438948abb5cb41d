//! Ctrl-C during `animate`: the first interrupt asks the run to stop after
//! the frame being drawn (which is then written whole), so the command can
//! say which frames are complete; a second one ends the process at once
//! (still leaving no half-written frame: frames are written to a temporary
//! file and renamed).

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Whether an interrupt asked the run to stop.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

#[cfg(unix)]
extern "C" fn on_sigint(_: libc::c_int) {
    if REQUESTED.swap(true, Ordering::SeqCst) {
        // Second interrupt: the default action (async-signal-safe calls only).
        // SAFETY: signal() and raise() are async-signal-safe.
        unsafe {
            libc::signal(libc::SIGINT, libc::SIG_DFL);
            libc::raise(libc::SIGINT);
        }
    }
}

/// Installs the handler (unix; elsewhere Ctrl-C keeps its default action).
pub fn install() {
    #[cfg(unix)]
    // SAFETY: the handler only touches an atomic and calls
    // async-signal-safe functions.
    unsafe {
        libc::signal(
            libc::SIGINT,
            on_sigint as extern "C" fn(libc::c_int) as libc::sighandler_t,
        );
    }
}

//! The `zoovr` command line: a thin shell that turns a `Result` into an exit
//! code (0 success, 1 error with the message on stderr, 2 usage).

mod cli;

fn main() {
    // Like other Unix tools, stop quietly when the reader of our output goes
    // away (`zoovr info f.vtu | head`) instead of failing to print.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread
    // starts; no handler is installed.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    quiet_mesa_runtime_dir();
    std::process::exit(cli::run());
}

/// Mesa's software Vulkan driver (lavapipe) prints "XDG_RUNTIME_DIR is
/// invalid or not set" on every start when the variable is missing (headless
/// machines, CI, containers). Point it at a private directory of ours so a
/// render's stderr holds only zoovr's own messages. A user's own value is
/// kept. Runs before any thread starts.
fn quiet_mesa_runtime_dir() {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt};
        let set =
            std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
        if set {
            return;
        }
        // SAFETY: getuid has no preconditions and cannot fail.
        let uid = unsafe { libc::getuid() };
        let dir = std::env::temp_dir().join(format!("zoovr-runtime-{uid}"));
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        // Only a directory that is ours and private is used.
        let ok = std::fs::symlink_metadata(&dir)
            .is_ok_and(|m| m.is_dir() && m.uid() == uid && m.mode() & 0o077 == 0);
        if ok {
            std::env::set_var("XDG_RUNTIME_DIR", &dir);
        }
    }
}

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
    std::process::exit(cli::run());
}

//! The `zoovr` command line: a thin shell that turns a `Result` into an exit
//! code (0 success, 1 error with the message on stderr, 2 usage).

mod cli;

fn main() {
    std::process::exit(cli::run());
}

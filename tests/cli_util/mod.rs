//! Running the `zoovr` binary from the CLI tests.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Runs `zoovr ARGS...` (with a runtime directory, so that Mesa's drivers
/// do not complain).
pub fn zoovr(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_zoovr"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run zoovr")
}

/// The run's standard error.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `zoovr render FILE -o OUT ARGS...`.
pub fn render(file: &Path, out: &Path, args: &[&str]) -> Output {
    let mut all = vec![
        "render",
        file.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend(args);
    zoovr(&all)
}

/// Whether a render failed only for want of a GPU adapter (a GPU mode is
/// then skipped).
pub fn no_adapter(o: &Output) -> bool {
    !o.status.success() && stderr(o).contains("adapter")
}

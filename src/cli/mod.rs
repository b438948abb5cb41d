//! Command-line parsing and dispatch. Each command lives in its own file;
//! `anyhow` is used only here, at the edge.

mod args;
mod compare;
mod info;
mod render;

use clap::error::ErrorKind;
use clap::{CommandFactory, Parser, Subcommand};

/// zoovr: exact volume rendering of unstructured and curvilinear zoo-cell grids.
#[derive(Parser, Debug)]
#[command(name = "zoovr", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print what a file holds: cells by kind, points, bounds, arrays, time
    /// steps, topology and cell-quality counts.
    Info(info::InfoArgs),
    /// Render one image of a dataset (exact mode through wgpu, or the CPU
    /// reference ray caster).
    Render(Box<render::RenderArgs>),
    /// Compare two images: max absolute, RMS and PSNR over pixels and
    /// channels (float values for two EXR files, else PNG display values).
    Compare(compare::CompareArgs),
}

/// Parses the arguments, runs the command and returns the exit code.
pub fn run() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    if let Command::Render(args) = &cli.command {
        if let Some(msg) = args.view.usage_error() {
            let mut cmd = Cli::command();
            // Built, so that the subcommand's usage line reads `zoovr render`.
            cmd.build();
            let e = match cmd.find_subcommand_mut("render") {
                Some(render) => render.error(ErrorKind::ArgumentConflict, msg),
                None => cmd.error(ErrorKind::ArgumentConflict, msg),
            };
            let _ = e.print();
            return 2;
        }
    }
    let result = match cli.command {
        Command::Info(args) => info::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Compare(args) => compare::run(&args),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("zoovr: error: {}", error_chain(&e));
            1
        }
    }
}

/// The error and its causes joined by ": ", leaving out a cause whose text
/// the message already holds (library errors name their source in their
/// own message, e.g. "FILE: cannot open: No such file or directory").
fn error_chain(e: &anyhow::Error) -> String {
    let mut msg = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    msg
}

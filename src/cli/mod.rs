//! Command-line parsing and dispatch. Each command lives in its own file;
//! `anyhow` is used only here, at the edge.

mod animate;
mod args;
mod assemble;
mod bench;
mod compare;
mod info;
mod interrupt;
mod legend;
mod render;
mod scene;

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
    /// Render the steps of a time series (or a turntable of one dataset) to
    /// numbered PNG frames, and optionally a GIF or an MP4, reusing the
    /// topology, sort, projected regions and GPU state across frames where
    /// the steps allow.
    Animate(Box<animate::AnimateArgs>),
    /// Time every mode against its error: each mode at the settings that
    /// trade time for error, at several sizes and views, against the ray
    /// caster on the same field and on the native field; a table, CSV,
    /// JSON and a log-log plot, with VTK's mappers as external points.
    Bench(Box<bench::BenchArgs>),
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
    let (name, view) = match &cli.command {
        Command::Render(args) => ("render", Some(&args.view)),
        Command::Animate(args) => ("animate", Some(&args.view)),
        Command::Bench(_) => ("bench", None),
        _ => ("", None),
    };
    if let Some(msg) = view.and_then(|v| v.usage_error()) {
        return usage(name, msg);
    }
    let result = match cli.command {
        Command::Info(args) => info::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Animate(args) => animate::run(&args),
        Command::Bench(args) => bench::run(&args),
        Command::Compare(args) => compare::run(&args),
    };
    match result {
        Ok(()) => 0,
        Err(e) => match e.downcast_ref::<UsageError>() {
            Some(UsageError(msg)) => usage(name, msg.clone()),
            None => {
                eprintln!("zoovr: error: {}", error_chain(&e));
                1
            }
        },
    }
}

/// A usage error found after parsing (a flag combination, or one that
/// depends on the input, e.g. `--frames` beyond the series): exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Prints a usage error of subcommand `name` the way clap does; returns 2.
fn usage(name: &str, msg: String) -> i32 {
    let mut cmd = Cli::command();
    // Built, so that the subcommand's usage line reads `zoovr NAME`.
    cmd.build();
    let e = match cmd.find_subcommand_mut(name) {
        Some(sub) => sub.error(ErrorKind::ArgumentConflict, msg),
        None => cmd.error(ErrorKind::ArgumentConflict, msg),
    };
    let _ = e.print();
    2
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

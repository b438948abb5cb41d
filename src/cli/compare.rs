//! `zoovr compare A B [--diff out.png]`: image error statistics.
//!
//! Two EXR files are compared on their float values (linear premultiplied
//! RGBA); anything else on PNG display values (RGB over black in [0, 1],
//! docs/conventions.md "Images"). Prints the maximum absolute difference (and where),
//! the RMS over pixels and channels and the PSNR for a peak of 1.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;

use zoovr::image::{compare_display, compare_float, Image};

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// First image (PNG or EXR).
    pub a: PathBuf,
    /// Second image (PNG or EXR).
    pub b: PathBuf,
    /// Write the per-channel absolute difference as a PNG.
    #[arg(long)]
    pub diff: Option<PathBuf>,
}

fn is_exr(p: &Path) -> bool {
    p.extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("exr"))
}

pub fn run(args: &CompareArgs) -> Result<()> {
    let a = Image::read(&args.a)?;
    let b = Image::read(&args.b)?;
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "images differ in size: '{}' is {}x{}, '{}' is {}x{}",
            args.a.display(),
            a.width,
            a.height,
            args.b.display(),
            b.width,
            b.height
        );
    }
    let float = is_exr(&args.a) && is_exr(&args.b);
    let (d, diff) = if float {
        compare_float(&a, &b)?
    } else {
        compare_display(&a, &b, [0.0; 3])?
    };
    println!(
        "values:  {}",
        if float { "float RGBA" } else { "display RGB" }
    );
    println!(
        "max_abs: {:.6e} at pixel ({}, {})",
        d.max_abs, d.worst.0, d.worst.1
    );
    println!("rms:     {:.6e}", d.rms);
    println!("psnr:    {:.2} dB", d.psnr);
    if let Some(path) = &args.diff {
        diff.write_png(path, [0.0; 3], false)
            .with_context(|| format!("writing the difference image '{}'", path.display()))?;
    }
    Ok(())
}

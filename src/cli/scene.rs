//! The scene flags every command that renders shares (`render`,
//! `animate`, `bench`): which field, which transfer function, which cells,
//! and the PLOT3D solution; and loading a file with them.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use clap::Args;

use zoovr::io::{self, ReadOptions};
use zoovr::render::{Geometry, SceneSpec, Shading};

use super::args::parse_range;

/// Field, transfer function and cells of a scene.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Field to render: NAME, point:NAME or cell:NAME, with :mag, :x, :y, :z or
    /// :N for vectors. Default: the docs/conventions.md default-field rule.
    #[arg(long)]
    pub field: Option<String>,
    /// Transfer-function file: zoovr JSON or a ParaView colour map (absolute
    /// scalar values).
    #[arg(long, conflicts_with = "preset")]
    pub tf: Option<PathBuf>,
    /// Colour-map preset normalised onto the range, opacity ramp 0 -> 1.
    #[arg(long)]
    pub preset: Option<String>,
    /// Scalar range LO,HI for presets and the default transfer function.
    #[arg(long, value_parser = parse_range, allow_hyphen_values = true)]
    pub range: Option<(f64, f64)>,
    /// Average cell data to points.
    #[arg(long)]
    pub cell_to_point: bool,
    /// Draw the cells that the file's `vtkGhostType` cell array flags hidden
    /// (32) or duplicate (1). By default they are left out, as ParaView does
    /// (and the default range is over the cells drawn); point flags never
    /// remove cells.
    #[arg(long)]
    pub show_hidden: bool,
    /// PLOT3D solution file for a PLOT3D grid.
    #[arg(long)]
    pub q: Option<PathBuf>,
}

impl SceneArgs {
    /// The scene specification.
    pub fn spec(&self) -> SceneSpec {
        SceneSpec {
            field: self.field.clone(),
            tf_file: self.tf.clone(),
            preset: self.preset.clone(),
            range: self.range,
            cell_to_point: self.cell_to_point,
            show_hidden: self.show_hidden,
        }
    }

    /// How files are read.
    pub fn read_options(&self) -> ReadOptions {
        ReadOptions {
            q_file: self.q.clone(),
        }
    }

    /// Reads `file` and builds its geometry and shading.
    pub fn load(&self, file: &Path) -> Result<(Geometry, Shading)> {
        let mesh = io::read(file, &self.read_options())?;
        // What the reader repaired or left out (arrays missing from some
        // pieces, blocks without 3D cells, quadratic cells read by their
        // corners): said once, on stderr.
        for n in &mesh.source.notes {
            eprintln!("zoovr: note: {}: {n}", file.display());
        }
        let spec = self.spec();
        let geometry = Geometry::build(mesh, spec.show_hidden)
            .with_context(|| format!("{}", file.display()))?;
        let shading =
            Shading::build(&geometry, &spec).with_context(|| format!("{}", file.display()))?;
        Ok((geometry, shading))
    }
}

//! What one render is asked to do: the camera, the mode, the GPU, and the
//! typed options of each kind of mode. Each kind's options print as one
//! line (`Display`) and serialise (serde) for reports and `bench`.

use std::fmt;

use serde::Serialize;

use crate::camera::CameraParams;
use crate::gpu::{AccumFormat, DrawKind, GpuOptions};
use crate::raycast::{FieldModel, Traversal};

use super::iso::IsoOptions;
use super::Mode;

/// Per-render options.
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    pub camera: CameraParams,
    pub mode: Mode,
    pub gpu: GpuOptions,
    pub accum: AccumFormat,
    /// Options of the projected-cell modes ([`super::driver`]).
    pub projected: ProjectedOptions,
    /// Options of the reference ray caster.
    pub reference: ReferenceOptions,
    /// Options of the pre-integrated table modes (`preint3d`, `preint2d`,
    /// `preint2d-cyl`).
    pub tables: TableOptions,
    /// Isosurfaces (`--iso`, `--shading`): drawn by `--mode iso`, mixed
    /// with the volume by the segment modes and the ray caster.
    pub iso: IsoOptions,
}

/// How the pre-integration tables are built (`--table-build`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum TableBuild {
    /// The GPU compute build when drawing on a GPU (hardware or software:
    /// on lavapipe it builds the 128^3 3D table in about 40 ms against
    /// 0.3-0.37 s for the exact `f64` CPU build, and the other tables 1.3-1.6
    /// times as fast), the exact CPU build when drawing on the CPU.
    #[default]
    Auto,
    /// The exact integrals in `f64` on the CPU (all cores).
    Exact,
    /// Integral functions on the CPU (EKE 3.5): exact opacity,
    /// approximate colour, fastest on the CPU.
    Fast,
    /// The exact integrals in `f32` by a wgpu compute pass.
    Gpu,
}

impl TableBuild {
    /// The name `--table-build` takes.
    pub fn name(self) -> &'static str {
        match self {
            TableBuild::Auto => "auto",
            TableBuild::Exact => "exact",
            TableBuild::Fast => "fast",
            TableBuild::Gpu => "gpu",
        }
    }
}

/// Options of the pre-integrated table modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct TableOptions {
    /// `--table N`: samples along each table axis (`None`: the mode's
    /// default, [`super::modes::preint_tables::TableKind::default_size`]).
    pub size: Option<u32>,
    /// `--table-build`.
    pub build: TableBuild,
}

impl fmt::Display for TableOptions {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.size {
            Some(n) => write!(f, "table size {n}")?,
            None => write!(f, "default table size")?,
        }
        write!(f, ", build {}", self.build.name())
    }
}

/// Where a projected-cell mode's triangles are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Compositor {
    /// wgpu ([`crate::gpu::Frame`]).
    #[default]
    Gpu,
    /// The CPU twin of the GPU stage ([`crate::gpu::cpu::CpuFrame`]).
    Cpu,
}

/// Options of the projected-cell modes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ProjectedOptions {
    /// `--split all`: every cell drawn as its consistent tets.
    pub split_all: bool,
    /// Leave out region triangles that contain no pixel centre
    /// ([`crate::projection::coverage`]; on by default). The image is the
    /// same either way; off only to check that.
    pub cull_to_pixels: bool,
    /// Where the triangles are rasterised and composited: the GPU, or its
    /// CPU twin ([`crate::gpu::cpu`]; no adapter needed).
    pub compositor: Compositor,
    /// Composite, or count coverage (tests and diagnostics).
    pub draw: DrawKind,
    /// On the CPU twin: the pixel whose fragments are listed in
    /// [`super::ProjectedStats::watched`].
    pub watch: Option<(u32, u32)>,
    /// Leave out pieces whose scalar range maps to zero extinction (and
    /// zero emission) and holds no isosurface: they neither emit nor
    /// absorb, so the image is the same (on by default; off only to
    /// measure what it saves).
    pub skip_invisible: bool,
    /// The exact mode's colour refinement tolerance (`--refine-tol`;
    /// [`crate::numeric::tolerance::COLOR_REFINE_TOL`] by default): lower
    /// refines more region triangles, for less colour interpolation error.
    pub refine_tol: f64,
    /// Decide the pixel centres next to each part's outline on the exact
    /// geometry ([`super::ties`]; on by default). Off only to measure what
    /// the decisions cost: centres within the snap of an outline are then
    /// left to the rasteriser's rounding, which can miss or double them.
    pub exact_ties: bool,
    /// Leave out pieces hidden behind opaque ones ([`super::occlusion`]):
    /// what can change no channel by more than this (by default
    /// [`crate::numeric::tolerance::OCCLUSION_TRANSMITTANCE`]); `None`
    /// draws them, to check the image and measure what the pass saves.
    pub occlusion: Option<f64>,
    /// Let the occlusion pass hide whole nodes of the geometry's min/max
    /// tree ([`super::cell_tree`]) behind opaque pixels, before testing
    /// pieces one by one (on by default). The same pieces are hidden
    /// either way; off only to measure what the tree saves.
    pub occlusion_tree: bool,
    /// Sort and draw only the cells that are not dark when at least
    /// [`super::visible::DARK_SUBSET_MIN`] of them are ([`super::visible`];
    /// on by default, and only with [`Self::skip_invisible`]). Off to
    /// measure what leaving them out of the sort saves.
    pub dark_subset: bool,
    /// Keep the frame's triangles, so that the next frame that differs
    /// only in the transfer function's colours draws them again without
    /// sorting or projecting (modes on the segment payload: exact-frag and
    /// the table modes; [`super::driver::kept`] says when it applies). Off
    /// by default: a kept frame holds its vertices (tens of bytes each,
    /// at most [`super::driver::kept::KEEP_MAX_BYTES`]). For interactive
    /// colour editing through the library. Whole-piece quads (exact-frag's
    /// and the table modes') are not kept: which pieces go whole depends on
    /// the rates.
    pub keep_projection: bool,
    /// Keep each part's regions (the winged-edge subdivision of its
    /// projection) for the next frame with the same camera whose values
    /// change and nothing else, which gives them its values instead of
    /// projecting again ([`super::driver::regions`]; `zoovr animate` turns
    /// it on for a fixed camera). Off by default: kept regions take about
    /// 2 KB per hex, at most
    /// [`super::driver::regions::KEEP_REGIONS_MAX_BYTES`].
    pub keep_regions: bool,
    /// How exact-frag and the table modes draw a piece (`--piece-draw`):
    /// projected into regions on the CPU, or whole, as one polygon whose
    /// fragments find their own segment ([`super::modes::piece_quad`],
    /// [`super::modes::preint_quads`]).
    pub piece_draw: PieceDraw,
}

/// How exact-frag and the table modes draw their pieces (`--piece-draw`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum PieceDraw {
    /// `quads` on a hardware GPU (the CPU then only sorts and packs
    /// pieces), `regions` on a software adapter (llvmpipe, lavapipe: their
    /// triangle setup dearer than the quads' fragment loop) and on the CPU
    /// twin.
    #[default]
    Auto,
    /// Each piece projected into regions on the CPU (winged-edge
    /// subdivision), the segment payload at their corners.
    Regions,
    /// Each piece drawn whole as one polygon over its outline (the convex
    /// hull of its projected points, widened a little, or, for small
    /// pieces, the quad over its pixel bounding box); every fragment
    /// intersects its ray with the piece's boundary triangles (view-independent cell projection). Pieces that `f32`
    /// cannot settle (near plane, faces seen nearly edge-on, optically
    /// thick, more than 8 points) are projected as with `regions`.
    Quads,
}

impl PieceDraw {
    /// The name `--piece-draw` takes.
    pub fn name(self) -> &'static str {
        match self {
            PieceDraw::Auto => "auto",
            PieceDraw::Regions => "regions",
            PieceDraw::Quads => "quads",
        }
    }
}

impl Default for ProjectedOptions {
    fn default() -> Self {
        ProjectedOptions {
            split_all: false,
            cull_to_pixels: true,
            compositor: Compositor::Gpu,
            draw: DrawKind::Composite,
            watch: None,
            skip_invisible: true,
            refine_tol: crate::numeric::tolerance::COLOR_REFINE_TOL,
            exact_ties: true,
            occlusion: Some(crate::numeric::tolerance::OCCLUSION_TRANSMITTANCE),
            occlusion_tree: true,
            dark_subset: true,
            keep_projection: false,
            keep_regions: false,
            piece_draw: PieceDraw::Auto,
        }
    }
}

impl fmt::Display for ProjectedOptions {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}, coverage culling {}, compositor {:?}, draw {:?}",
            if self.split_all {
                "every cell as its tets"
            } else {
                "whole cells"
            },
            if self.cull_to_pixels { "on" } else { "off" },
            self.compositor,
            self.draw
        )?;
        if let Some((i, j)) = self.watch {
            write!(f, ", watching pixel ({i}, {j})")?;
        }
        Ok(())
    }
}

/// Options of the reference ray caster.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct ReferenceOptions {
    /// Field model of the ray caster.
    pub model: FieldModel,
    /// How the ray caster finds the pieces along a ray (walk by adjacency,
    /// or brute force: `faces` and `tets` only).
    pub traversal: Traversal,
    /// Stop a ray once its transmittance falls below
    /// [`crate::numeric::tolerance::RAY_TERMINATION_TRANSMITTANCE`] (on by
    /// default; the colour it leaves out is at most that fraction of the
    /// brightest glow). Off only to measure what it saves.
    pub early_termination: bool,
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        ReferenceOptions {
            model: FieldModel::default(),
            traversal: Traversal::default(),
            early_termination: true,
        }
    }
}

impl fmt::Display for ReferenceOptions {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "model {}, traversal {}",
            self.model.name(),
            self.traversal.name()
        )
    }
}

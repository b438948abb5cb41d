//! The rendering modes and their registry.
//!
//! [`Mode`] is what `--mode` takes; [`Mode::info`] is the registry: for each
//! mode, what it needs (a GPU or not), which emission models it can draw,
//! whether it slices pieces at TF breakpoints, its stage (shader) and the
//! bounds the comparison harness holds it to against the reference ray
//! caster. [`crate::render::Renderer::render`] dispatches a render to the
//! mode.
//!
//! How to add a projected-cell mode:
//! 1. `shaders/NAME.wgsl` with `vs_main`, `fs_main` and `fs_count` (the
//!    functions of `shaders/common.wgsl` are in scope);
//! 2. `src/render/modes/NAME.rs`: the vertex type (a
//!    [`crate::gpu::GpuVertex`] mirroring `VertexIn`), its `StageDesc`,
//!    the CPU twin `fn fs_main` with the stage's bindings on the CPU (a
//!    [`crate::gpu::cpu::CpuStage`]) and an implementation of
//!    [`super::driver::ProjectedMode`] (split points, payload, vertex,
//!    binding the stage), or of [`segment::SegmentMode`] for a mode on the
//!    segment payload;
//! 3. a variant of [`Mode`], its [`ModeInfo`] in [`Mode::info`], and its arm
//!    in `Renderer::render_with_camera` (src/render/mod.rs);
//! 4. its file in [`SHADERS`] and its twins in [`twins::stage_twins`].
//!    `tests/modes.rs` then compares it with the reference at its bounds,
//!    on the CPU twin and on the GPU, and checks that every function of its
//!    shader has a twin of the same name ([`twins`] gives the scheme).

pub mod exact;
pub mod exact_frag;
pub mod integral;
pub mod iso;
pub mod iso_levels;
pub mod iso_seams;
pub mod iso_split;
pub mod iso_stages;
pub mod iso_walk;
pub mod piece_quad;
pub mod preint;
pub mod preint2d;
pub mod preint2d_cyl;
pub mod preint3d;
pub mod preint_quads;
pub mod preint_tables;
pub mod raycast;
pub mod segment;
pub mod segment_view;
pub mod table_build;
pub mod twins;

pub use exact::exptable;

use clap::ValueEnum;
use serde::Serialize;

use crate::gpu::layer::LAYER_STAGE;
use crate::gpu::StageDesc;
use crate::raycast::FieldModel;
use crate::tf::EmissionModel;

/// The rendering modes that exist (`--mode`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    /// Projection of convex pieces with exact vertex integrals, composited
    /// by wgpu.
    #[default]
    Exact,
    /// Projection of convex pieces, the exact ray integral evaluated per
    /// fragment by wgpu.
    ExactFrag,
    /// Projection of convex pieces, a 3D pre-integrated table looked up per
    /// fragment by wgpu.
    Preint3d,
    /// Projection of convex pieces, a 2D pre-integrated table at the mean
    /// cell thickness, scaled per fragment.
    Preint2d,
    /// Projection of convex pieces, the 3D table re-mapped into cylindrical
    /// 2D planes.
    Preint2dCyl,
    /// Isosurfaces alone (`--iso`), found per fragment between the
    /// segment's end scalars, in the exact order.
    Iso,
    /// The CPU reference ray caster.
    Raycast,
}

/// How closely a mode must match the reference ray caster over every pixel
/// of the comparison harness's scenes (display values, f32 accumulation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The ray caster's field model the mode integrates for whole cells.
    pub reference: FieldModel,
    /// `--split all` against `--model tets` (the same field): the largest
    /// difference of any channel of any pixel.
    pub split_max: f64,
    /// Whole cells against `reference`: the largest difference, which may
    /// hold the model difference inside cells the mode splits into tets
    /// (problem cells, cells holding a breakpoint), where it integrates the
    /// `tets` field.
    pub whole_max: f64,
    /// Pixels of one harness image (96 x 80) allowed beyond `split_max`,
    /// for a named reason the mode's entry states (0 for the volume modes:
    /// the bound holds over every pixel).
    pub split_outliers: usize,
    /// The same beyond `whole_max` (where the model difference inside the
    /// cells the mode splits moves a surface, not only a colour).
    pub whole_outliers: usize,
}

/// What the registry knows of a mode.
#[derive(Debug)]
pub struct ModeInfo {
    pub name: &'static str,
    /// One line for `--help`.
    pub summary: &'static str,
    /// Whether it draws with wgpu (else it runs on the CPU alone).
    pub gpu: bool,
    /// The emission models it can draw.
    pub emission: &'static [EmissionModel],
    /// Whether pieces are sliced at TF breakpoints.
    pub slices_at_breakpoints: bool,
    /// Whether it can draw its pieces whole (`--piece-draw quads`,
    /// [`piece_quad`], [`preint_quads`]).
    pub draws_pieces_whole: bool,
    /// Its stage (shader), for a GPU mode.
    pub stage: Option<&'static StageDesc>,
    /// Its bounds against the reference (`None`: it is the reference).
    pub bounds: Option<Bounds>,
}

impl Mode {
    /// Every mode.
    pub const ALL: &'static [Mode] = &[
        Mode::Exact,
        Mode::ExactFrag,
        Mode::Preint3d,
        Mode::Preint2d,
        Mode::Preint2dCyl,
        Mode::Iso,
        Mode::Raycast,
    ];

    /// The registry entry of the mode.
    pub fn info(self) -> &'static ModeInfo {
        match self {
            Mode::Exact => &exact::INFO,
            Mode::ExactFrag => &exact_frag::INFO,
            Mode::Preint3d => &preint3d::INFO,
            Mode::Preint2d => &preint2d::INFO,
            Mode::Preint2dCyl => &preint2d_cyl::INFO,
            Mode::Iso => &iso::INFO,
            Mode::Raycast => &raycast::INFO,
        }
    }

    /// The CLI name.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// The names `--mode` takes.
    pub fn names() -> Vec<&'static str> {
        Mode::ALL.iter().map(|m| m.name()).collect()
    }
}

impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Mode {
    type Err = String;
    fn from_str(s: &str) -> Result<Mode, String> {
        Mode::ALL
            .iter()
            .copied()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown mode '{s}' (available: {})",
                    Mode::names().join(", ")
                )
            })
    }
}

/// Every shader file under `shaders/`, by name, with its source (without
/// `shaders/common.wgsl`, which [`crate::gpu::stage::stage_source`] puts in
/// front of each).
pub const SHADERS: &[(&str, &str)] = &[
    ("common.wgsl", crate::gpu::stage::COMMON_WGSL),
    ("exact.wgsl", include_str!("../../../shaders/exact.wgsl")),
    (
        "exptable.wgsl",
        include_str!("../../../shaders/exptable.wgsl"),
    ),
    (
        "exact_frag.wgsl",
        include_str!("../../../shaders/exact_frag.wgsl"),
    ),
    (
        "integral.wgsl",
        include_str!("../../../shaders/integral.wgsl"),
    ),
    ("iso.wgsl", include_str!("../../../shaders/iso.wgsl")),
    (
        "iso_split.wgsl",
        include_str!("../../../shaders/iso_split.wgsl"),
    ),
    (
        "iso_walk.wgsl",
        include_str!("../../../shaders/iso_walk.wgsl"),
    ),
    (
        "iso_vertex.wgsl",
        include_str!("../../../shaders/iso_vertex.wgsl"),
    ),
    ("layer.wgsl", LAYER_STAGE.wgsl),
    ("preint.wgsl", include_str!("../../../shaders/preint.wgsl")),
    (
        "preint2d.wgsl",
        include_str!("../../../shaders/preint2d.wgsl"),
    ),
    (
        "preint2d_cyl.wgsl",
        include_str!("../../../shaders/preint2d_cyl.wgsl"),
    ),
    (
        "preint3d.wgsl",
        include_str!("../../../shaders/preint3d.wgsl"),
    ),
    (
        "segment.wgsl",
        include_str!("../../../shaders/segment.wgsl"),
    ),
    (
        "segment_view.wgsl",
        include_str!("../../../shaders/segment_view.wgsl"),
    ),
    (
        "piece_quad.wgsl",
        include_str!("../../../shaders/piece_quad.wgsl"),
    ),
    (
        "segment_vertex.wgsl",
        include_str!("../../../shaders/segment_vertex.wgsl"),
    ),
    (
        "table_build.wgsl",
        include_str!("../../../shaders/table_build.wgsl"),
    ),
];

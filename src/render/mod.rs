//! Rendering a scene in one of the modes, the same way for every caller
//! (CLI `render`, `animate`, `bench`, tests).
//!
//! [`Scene`] holds what does not depend on the view; [`Renderer`] holds what
//! is reused between views of one scene (the visibility sorter with its
//! planes and subdivisions, the GPU context); [`Renderer::render`] makes one
//! image. Modes:
//! - [`Mode::Exact`]: projection of convex pieces with exact vertex integrals,
//!   composited by wgpu ([`exact`]);
//! - [`Mode::Raycast`]: the CPU reference ray caster ([`crate::raycast`]),
//!   walking by adjacency or, with [`Traversal::Brute`], testing every
//!   piece ([`crate::raycast::brute`]).

pub mod exact;
mod group;
pub mod scene;

use std::time::Instant;

use thiserror::Error;

use crate::camera::{Camera, CameraParams};
use crate::gpu::{AccumFormat, Context, DrawKind, GpuError, GpuOptions, PendingContext};
use crate::image::Image;
use crate::raycast::brute::{Brute, BruteStats};
use crate::raycast::{self, FieldModel, RaycastOptions, Raycaster, Traversal};
use crate::visibility::{Sorter, VisibilityError};

pub use exact::ExactStats;
pub use scene::{ScalarsRef, Scene, SceneSpec};

/// The rendering modes that exist.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Exact,
    Raycast,
}

impl Mode {
    /// Names as the CLI spells them.
    pub const NAMES: &'static [&'static str] = &["exact", "raycast"];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Exact => "exact",
            Mode::Raycast => "raycast",
        }
    }
}

impl std::str::FromStr for Mode {
    type Err = String;
    fn from_str(s: &str) -> Result<Mode, String> {
        match s {
            "exact" => Ok(Mode::Exact),
            "raycast" => Ok(Mode::Raycast),
            _ => Err(format!(
                "unknown mode '{s}' (available: {})",
                Mode::NAMES.join(", ")
            )),
        }
    }
}

/// Errors of a render.
#[derive(Debug, Error)]
pub enum RenderError {
    #[error("the mesh has no 3D cells to render")]
    NoCells,
    #[error(
        "all {0} cells are flagged hidden or duplicate in 'vtkGhostType'; --show-hidden draws them"
    )]
    AllCellsHidden(usize),
    #[error(transparent)]
    Ghost(#[from] crate::mesh::ghost::GhostError),
    #[error(transparent)]
    Field(#[from] crate::field::FieldError),
    #[error("{path}: {msg}")]
    Tf { path: String, msg: String },
    #[error(transparent)]
    Visibility(#[from] VisibilityError),
    #[error("projection failed: {0}")]
    Projection(String),
    #[error("the view draws more than {0} pieces, more than one frame can number")]
    TooManyPieces(u32),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Raycast(#[from] raycast::RaycastError),
    #[error("the {0} mode cannot represent independent emission (its per-pixel colour is glow x opacity); use --mode raycast")]
    Unsupported(&'static str),
}

/// Per-render options (camera, mode, field model, GPU).
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub camera: CameraParams,
    pub mode: Mode,
    /// Field model of the ray caster.
    pub model: FieldModel,
    /// How the ray caster finds the pieces along a ray (walk by adjacency,
    /// or brute force: `faces` and `tets` only).
    pub traversal: Traversal,
    /// `--split all`: every cell drawn as its consistent tets.
    pub split_all: bool,
    pub gpu: GpuOptions,
    pub accum: AccumFormat,
    /// Exact mode: leave out region triangles that contain no pixel centre
    /// ([`crate::projection::coverage`]; on by default). The image is the
    /// same either way; off only to check that.
    pub cull_to_pixels: bool,
    /// Exact mode: where the triangles are rasterised and composited: the
    /// GPU, or its CPU twin ([`crate::gpu::cpu`]; no adapter needed).
    pub compositor: Compositor,
    /// Exact mode: composite, or count coverage (tests and diagnostics).
    pub draw: DrawKind,
    /// Exact mode on the CPU twin: the pixel whose fragments are listed in
    /// [`ExactStats::watched`].
    pub watch: Option<(u32, u32)>,
}

/// Where the exact mode's triangles are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compositor {
    /// wgpu ([`crate::gpu::Frame`]).
    #[default]
    Gpu,
    /// The CPU twin of the GPU stage ([`crate::gpu::cpu::CpuFrame`]).
    Cpu,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            camera: CameraParams::default(),
            mode: Mode::Exact,
            model: FieldModel::Faces,
            traversal: Traversal::Walk,
            split_all: false,
            gpu: GpuOptions::default(),
            accum: AccumFormat::Auto,
            cull_to_pixels: true,
            compositor: Compositor::Gpu,
            draw: DrawKind::Composite,
            watch: None,
        }
    }
}

/// What one render did (seconds of wall time).
#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    pub mode: Option<Mode>,
    pub total_s: f64,
    pub setup_s: f64,
    pub exact: Option<ExactStats>,
    pub raycast: Option<RaycastStats>,
    pub gpu_adapter: Option<String>,
}

/// What a ray-cast render used.
#[derive(Clone, Copy, Debug)]
pub struct RaycastStats {
    pub model: FieldModel,
    pub traversal: Traversal,
    /// Rays stop once their transmittance falls below this (0: never), so
    /// a pixel's opacity may fall short of the full integral by at most it.
    pub termination_transmittance: f64,
    /// Native model: intervals integrated and what fell back from the
    /// exact method during this render (zero for other models).
    pub native: crate::raycast::native::NativeStats,
    /// Brute-force traversal: pieces tested, segments, and segments that
    /// overlapped another piece's (zero for the walk).
    pub brute: BruteStats,
}

/// Reusable state for rendering many views of one scene.
pub struct Renderer<'s> {
    scene: &'s Scene,
    sorter: Option<Sorter>,
    gpu: Option<Context>,
    pending_gpu: Option<PendingContext>,
    raycaster: Option<(FieldModel, Raycaster<'s>)>,
    brute: Option<(FieldModel, Brute<'s>)>,
}

impl<'s> Renderer<'s> {
    /// A renderer for `scene` (nothing is built until the first render).
    pub fn new(scene: &'s Scene) -> Renderer<'s> {
        Renderer {
            scene,
            sorter: None,
            gpu: None,
            pending_gpu: None,
            raycaster: None,
            brute: None,
        }
    }

    /// Hands over a GPU context that is still opening ([`Context::spawn`]);
    /// the exact mode waits for it after sorting, when its options are the
    /// render's (otherwise it opens its own).
    pub fn set_pending_gpu(&mut self, pending: PendingContext) {
        if self.gpu.is_none() {
            self.pending_gpu = Some(pending);
        }
    }

    /// The visibility sorter of the exact mode (made on first use), e.g. to
    /// change its options ([`Sorter::plane_split`], [`Sorter::nonconvex`]).
    pub fn sorter(&mut self) -> &mut Sorter {
        let scene = self.scene;
        self.sorter
            .get_or_insert_with(|| Sorter::new(&scene.mesh, &scene.topology))
    }

    /// Renders one image with the camera of `opts.camera` (fitted to the
    /// mesh bounds, docs/conventions.md Conventions).
    pub fn render(
        &mut self,
        opts: &RenderOptions,
        progress: impl FnMut(usize, usize),
    ) -> Result<(Image, RenderStats), RenderError> {
        let camera = Camera::fit(self.scene.mesh.bounds(), &opts.camera);
        self.render_with_camera(opts, &camera, progress)
    }

    /// Renders one image from an explicit camera (e.g. an eye moved inside
    /// the mesh); `opts.camera` is not used.
    pub fn render_with_camera(
        &mut self,
        opts: &RenderOptions,
        camera: &Camera,
        progress: impl FnMut(usize, usize),
    ) -> Result<(Image, RenderStats), RenderError> {
        let t0 = Instant::now();
        let scene = self.scene;
        let camera = *camera;
        let mut stats = RenderStats {
            mode: Some(opts.mode),
            ..Default::default()
        };
        let image = match opts.mode {
            Mode::Exact => {
                if scene.tf.model() == crate::tf::EmissionModel::Independent {
                    return Err(RenderError::Unsupported("exact"));
                }
                let mut sorter = self
                    .sorter
                    .take()
                    .unwrap_or_else(|| Sorter::new(&scene.mesh, &scene.topology));
                let sorter_s = t0.elapsed().as_secs_f64();
                let result = exact::render_exact(
                    scene,
                    &mut sorter,
                    &mut self.gpu,
                    &mut self.pending_gpu,
                    opts,
                    &camera,
                    progress,
                );
                self.sorter = Some(sorter);
                stats.gpu_adapter = self.gpu.as_ref().map(|g| g.info().to_string());
                let (img, es) = result?;
                stats.setup_s = sorter_s + es.gpu_open_s;
                stats.exact = Some(es);
                img
            }
            Mode::Raycast => {
                let scalars = match scene.scalars() {
                    ScalarsRef::Point(v) => raycast::Scalars::Point(v),
                    ScalarsRef::Cell(v) => raycast::Scalars::Cell(v),
                    ScalarsRef::Constant(c) => raycast::Scalars::Constant(c),
                };
                let rs = raycast::Scene {
                    mesh: &scene.mesh,
                    topology: &scene.topology,
                    scalars,
                };
                let ro = RaycastOptions {
                    model: opts.model,
                    traversal: opts.traversal,
                    ..Default::default()
                };
                let mut rstats = RaycastStats {
                    model: opts.model,
                    traversal: opts.traversal,
                    termination_transmittance: ro.early_termination,
                    native: Default::default(),
                    brute: Default::default(),
                };
                let img = match opts.traversal {
                    Traversal::Walk => {
                        let rc = match self.raycaster.take() {
                            Some((m, rc)) if m == opts.model => rc,
                            _ => Raycaster::new(rs, opts.model)?,
                        };
                        stats.setup_s = t0.elapsed().as_secs_f64();
                        let before = rc.native_stats();
                        let img = rc.render_with_progress(&scene.tf, &camera, &ro, progress);
                        rstats.native = rc.native_stats().since(&before);
                        self.raycaster = Some((opts.model, rc));
                        img
                    }
                    Traversal::Brute => {
                        let b = match self.brute.take() {
                            Some((m, b)) if m == opts.model => b,
                            _ => Brute::new(rs, opts.model)?,
                        };
                        stats.setup_s = t0.elapsed().as_secs_f64();
                        let before = b.stats();
                        let img = b.render_with_progress(&scene.tf, &camera, &ro, progress);
                        rstats.brute = b.stats().since(&before);
                        self.brute = Some((opts.model, b));
                        img
                    }
                };
                stats.raycast = Some(rstats);
                img
            }
        };
        stats.total_s = t0.elapsed().as_secs_f64();
        Ok((image, stats))
    }
}

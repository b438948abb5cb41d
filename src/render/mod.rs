//! Rendering a scene in one of the modes, the same way for every caller
//! (CLI `render`, `animate`, `bench`, tests).
//!
//! [`Scene`] holds what does not depend on the view; [`Renderer`] holds what
//! is reused between views of one scene (the visibility sorter with its
//! planes and subdivisions, the GPU context, the ray caster's structures);
//! [`Renderer::render`] makes one image with the mode of
//! [`RenderOptions::mode`]. The modes and their registry are in [`modes`];
//! every projected-cell mode runs on one driver ([`driver`]), which turns
//! pieces into polyhedra through [`pieces`] and draws cycle groups
//! ([`group`]) through the mode-independent layer stage.

pub mod breakpoints;
pub mod driver;
mod group;
pub mod modes;
mod options;
pub mod pieces;
pub mod scene;
pub mod stats;
mod workers;

use std::time::Instant;

use thiserror::Error;

use crate::camera::Camera;
use crate::gpu::{Context, GpuError, PendingContext};
use crate::image::Image;
use crate::raycast::brute::Brute;
use crate::raycast::{self, FieldModel, Raycaster};
use crate::visibility::{Sorter, VisibilityError};

pub use breakpoints::split_points;
pub use modes::{Bounds, Mode, ModeInfo};
pub use options::{
    Compositor, ProjectedOptions, ReferenceOptions, RenderOptions, TableBuild, TableOptions,
};
pub use pieces::PieceError;
pub use scene::{ScalarsRef, Scene, SceneSpec};
pub use stats::{ModeStats, ProjectedStats, RaycastStats, RenderStats};

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
    Piece(#[from] PieceError),
    #[error("the view draws more than {0} pieces, more than one frame can number")]
    TooManyPieces(u32),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Raycast(#[from] raycast::RaycastError),
    #[error(transparent)]
    TableSize(#[from] modes::preint_tables::TableSizeError),
    #[error("the {mode} mode cannot draw {model:?} emission (it supports {supported}); use --mode raycast")]
    Unsupported {
        mode: &'static str,
        model: crate::tf::EmissionModel,
        supported: String,
    },
}

/// Reusable state for rendering many views of one scene.
pub struct Renderer<'s> {
    pub(crate) scene: &'s Scene,
    sorter: Option<Sorter>,
    gpu: Option<Context>,
    pending_gpu: Option<PendingContext>,
    pub(crate) raycaster: Option<(FieldModel, Raycaster<'s>)>,
    pub(crate) brute: Option<(FieldModel, Brute<'s>)>,
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
            .get_or_insert_with(|| Sorter::shared(scene.mesh.clone(), scene.topology.clone()))
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
        let info = opts.mode.info();
        let model = scene.tf.model();
        if !info.emission.contains(&model) {
            return Err(RenderError::Unsupported {
                mode: info.name,
                model,
                supported: format!("{:?}", info.emission),
            });
        }
        let (image, detail, setup_s) = match opts.mode {
            Mode::Exact => self.projected(&modes::exact::ExactMode, opts, camera, progress)?,
            Mode::ExactFrag => {
                self.projected(&modes::exact_frag::ExactFragMode, opts, camera, progress)?
            }
            Mode::Preint3d | Mode::Preint2d | Mode::Preint2dCyl => {
                let mode = modes::preint::PreintMode::for_mode(opts.mode, opts)?;
                let (img, mut detail, setup) = self.projected(&mode, opts, camera, progress)?;
                if let ModeStats::Projected(s) = &mut detail {
                    s.table = mode.take_stats();
                }
                (img, detail, setup)
            }
            Mode::Raycast => {
                let (img, s, setup) = modes::raycast::render(self, opts, camera, progress)?;
                (img, ModeStats::Raycast(s), setup)
            }
        };
        let stats = RenderStats {
            mode: opts.mode,
            total_s: t0.elapsed().as_secs_f64(),
            setup_s,
            gpu_adapter: info
                .gpu
                .then(|| self.gpu.as_ref().map(|g| g.info().to_string()))
                .flatten(),
            detail,
        };
        Ok((image, stats))
    }

    /// Renders with a projected-cell mode on the shared driver.
    fn projected<M: driver::ProjectedMode>(
        &mut self,
        mode: &M,
        opts: &RenderOptions,
        camera: &Camera,
        progress: impl FnMut(usize, usize),
    ) -> Result<(Image, ModeStats, f64), RenderError> {
        let t0 = Instant::now();
        let scene = self.scene;
        let mut sorter = self
            .sorter
            .take()
            .unwrap_or_else(|| Sorter::shared(scene.mesh.clone(), scene.topology.clone()));
        let sorter_s = t0.elapsed().as_secs_f64();
        let result = driver::render_projected(
            mode,
            scene,
            &mut sorter,
            &mut self.gpu,
            &mut self.pending_gpu,
            opts,
            camera,
            progress,
        );
        self.sorter = Some(sorter);
        let (img, stats) = result?;
        let setup_s = sorter_s + stats.gpu_open_s;
        Ok((img, ModeStats::Projected(Box::new(stats)), setup_s))
    }
}

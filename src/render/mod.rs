//! Rendering a scene in one of the modes, the same way for every caller
//! (CLI `render`, `animate`, `bench`, tests).
//!
//! A [`Renderer`] is built once from a [`Geometry`] (points, cells, face
//! adjacency) and owns what is reused between frames: the geometry, the
//! visibility sorter with its planes and subdivisions, and the GPU context
//! once one is opened. [`Renderer::render`] makes one image of a
//! [`Shading`] (field, range, transfer function) with the mode of
//! [`RenderOptions::mode`]; the shading may change from frame to frame (the
//! steps of a time series with fixed topology) without rebuilding the
//! topology or the sorter. The ray caster's structures are built per frame
//! (they hold the frame's scalars). [`Scene`] is a geometry and one shading
//! together, for one-off renders and tests. The modes and their registry are in [`modes`];
//! every projected-cell mode runs on one driver ([`driver`]), which turns
//! pieces into polyhedra through [`pieces`] and draws cycle groups
//! ([`group`]) through the mode-independent layer stage.

pub mod breakpoints;
pub mod cell_tree;
pub mod driver;
pub mod gradients;
mod group;
pub mod iso;
pub mod marching;
pub mod modes;
pub mod occlusion;
mod options;
mod order_cache;
pub mod origin;
pub mod pieces;
mod projected_mode;
pub mod scene;
pub mod stats;
pub mod steps;
pub mod ties;
pub mod visible;
mod workers;

use std::time::Instant;

use thiserror::Error;

use crate::camera::Camera;
use crate::gpu::{Context, GpuError, PendingContext};
use crate::image::Image;
use crate::raycast;
use crate::visibility::{Sorter, VisibilityError};

pub use breakpoints::split_points;
pub use modes::{Bounds, Mode, ModeInfo};
pub use options::{
    Compositor, PieceDraw, ProjectedOptions, ReferenceOptions, RenderOptions, TableBuild,
    TableOptions,
};
pub use pieces::PieceError;
pub use scene::{Geometry, ScalarsRef, Scene, SceneSpec, Shading};
pub use stats::{ModeStats, ProjectedStats, RaycastStats, RenderStats};
pub use steps::StepChange;

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
    #[error("field '{name}' has {got} values, but the geometry has {want} {per}")]
    FieldLength {
        name: String,
        got: usize,
        want: usize,
        per: &'static str,
    },
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
    #[error(transparent)]
    Iso(#[from] iso::IsoError),
    #[error("--mode iso draws isosurfaces only: give them with --iso V,V,...")]
    IsoMissing,
    #[error("the {mode} mode cannot draw {model:?} emission (it supports {supported}); modes that can: --mode {alternatives}")]
    Unsupported {
        mode: &'static str,
        model: crate::tf::EmissionModel,
        supported: String,
        alternatives: String,
    },
}

/// The isosurface mode of a render with `--iso` (or `--mode iso`): the
/// surfaces resolved against the scene's transfer function, over the
/// volume of `opts.mode`, with the points' gradients for smooth light.
fn iso_mode(scene: &Scene, opts: &RenderOptions) -> Result<modes::iso::IsoMode, RenderError> {
    use modes::iso::{IsoMode, Volume};
    let ScalarsRef::Point(values) = scene.scalars() else {
        return Err(iso::IsoError::CellData.into());
    };
    let set = iso::IsoSet::new(&opts.iso, &scene.tf);
    let volume = match opts.mode {
        _ if opts.iso.alone => Volume::None,
        Mode::Iso => Volume::None,
        // The exact mode's vertex integrals cannot hold a crossing inside
        // a segment: with surfaces its frame integrates per fragment, the
        // same closed form, on whole cells (module docs of `modes::iso`).
        Mode::Exact | Mode::ExactFrag => Volume::Integral,
        m => Volume::Table(modes::preint::PreintMode::for_mode(m, opts)?),
    };
    let smooth = set.lighting == iso::Lighting::Smooth;
    let mode = IsoMode::new(volume, set, None);
    Ok(if smooth {
        mode.with_surface_gradients(&scene.tf, &scene.mesh, values)
    } else {
        mode
    })
}

/// State reused across frames of one geometry: the geometry itself, the
/// visibility sorter (made on first use) and the GPU context (opened on
/// first use, or handed over with [`Renderer::set_pending_gpu`]).
pub struct Renderer {
    geometry: Geometry,
    sorter: Option<Sorter>,
    /// The last order, reused by a frame that asks for the same one.
    orders: order_cache::OrderCache,
    /// The cells that are not dark, sorted without the rest when most
    /// are ([`visible`]).
    visible: visible::VisibleCache,
    /// Whether the last projected-cell render sorted the visible subset.
    last_visible: bool,
    gpu: Option<Context>,
    pending_gpu: Option<PendingContext>,
    /// The last frame's triangles, with `keep_projection`
    /// ([`driver::kept`]).
    kept: Option<driver::kept::KeptProjection>,
    /// Each part's regions, with `keep_regions` ([`driver::regions`]).
    regions: driver::regions::RegionStore,
    /// The last field moved to its origin ([`origin`]).
    moved: origin::MovedField,
}

impl Renderer {
    /// A renderer for `geometry` (nothing is built until the first render).
    pub fn new(geometry: Geometry) -> Renderer {
        Renderer {
            geometry,
            sorter: None,
            orders: Default::default(),
            visible: Default::default(),
            last_visible: false,
            gpu: None,
            pending_gpu: None,
            kept: None,
            regions: Default::default(),
            moved: Default::default(),
        }
    }

    /// The geometry it renders.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// Moves on to the geometry of another step of the series
    /// ([`Geometry::next_step`]), keeping what `change` allows: with
    /// [`StepChange::Values`] (or `None`) the visibility sorter (its planes,
    /// splits and scratch) stays, otherwise it is rebuilt on first use (on
    /// the shared topology for [`StepChange::Points`]), and so do the
    /// views' sorts ([`order_cache`]: a values-only step splices its values
    /// into the last sort of the view) and the parts' kept regions
    /// ([`driver::regions`]); the GPU context always stays.
    pub fn set_geometry(&mut self, geometry: Geometry, change: StepChange) {
        if !matches!(change, StepChange::None | StepChange::Values) {
            self.sorter = None;
            self.orders.clear();
            self.regions.clear();
        }
        self.visible.clear();
        self.geometry = geometry;
    }

    /// The adapter of the GPU device, once one is open.
    pub fn gpu_info(&self) -> Option<String> {
        self.gpu.as_ref().map(|g| g.info().to_string())
    }

    /// Hands over a GPU context that is still opening ([`Context::spawn`]);
    /// the exact mode waits for it after sorting, when its options are the
    /// render's (otherwise it opens its own).
    pub fn set_pending_gpu(&mut self, pending: PendingContext) {
        if self.gpu.is_none() {
            self.pending_gpu = Some(pending);
        }
    }

    /// The GPU context of `opts`, opened now (or the pending one waited
    /// for) if none is open yet.
    fn open_gpu(&mut self, opts: &RenderOptions) -> Result<&Context, RenderError> {
        if self.gpu.is_none() {
            self.gpu = Some(match self.pending_gpu.take() {
                Some(p) if p.options() == &opts.gpu => p.wait()?,
                _ => Context::new(&opts.gpu)?,
            });
        }
        match self.gpu.as_ref() {
            Some(g) => Ok(g),
            None => unreachable!("opened above"),
        }
    }

    /// How the modes that can draw pieces whole
    /// ([`modes::ModeInfo::draws_pieces_whole`]) draw them for `opts`:
    /// `auto` is whole-piece quads on a hardware GPU (the CPU then only
    /// sorts and packs pieces) and regions on a software adapter (its
    /// triangle setup dearer than the quads' fragments) and on the CPU twin.
    fn piece_draw(&mut self, opts: &RenderOptions) -> Result<PieceDraw, RenderError> {
        Ok(match opts.projected.piece_draw {
            PieceDraw::Auto => {
                let hardware = opts.projected.compositor == Compositor::Gpu
                    && !self.open_gpu(opts)?.info().is_software();
                if hardware {
                    PieceDraw::Quads
                } else {
                    PieceDraw::Regions
                }
            }
            d => d,
        })
    }

    /// The visibility sorter of the projected-cell modes (made on first
    /// use), e.g. to change its options ([`Sorter::plane_split`],
    /// [`Sorter::nonconvex`]).
    pub fn sorter(&mut self) -> &mut Sorter {
        let g = &self.geometry;
        self.sorter
            .get_or_insert_with(|| Sorter::new(g.mesh.clone(), g.topology.clone()))
    }

    /// The visibility order the last projected-cell render drew (kept for
    /// the next render of the same view), e.g. to see which cells it drew
    /// as tets ([`crate::visibility::Piece`]).
    /// With the geometry's cell ids also when the render sorted the visible
    /// subset ([`visible`]).
    pub fn last_order(&self) -> Option<std::sync::Arc<crate::visibility::Order>> {
        if self.last_visible {
            let subset = self.visible.current()?;
            let order = subset.orders.last()?;
            return Some(std::sync::Arc::new(subset.whole_order(order)));
        }
        self.orders.last().cloned()
    }

    /// Renders one image of `shading` with the camera of `opts.camera`
    /// (fitted to the mesh bounds, docs/conventions.md Conventions).
    pub fn render(
        &mut self,
        shading: &Shading,
        opts: &RenderOptions,
        progress: impl FnMut(usize, usize),
    ) -> Result<(Image, RenderStats), RenderError> {
        let camera = Camera::fit(self.geometry.mesh.bounds(), &opts.camera);
        self.render_with_camera(shading, opts, &camera, progress)
    }

    /// Renders one image of `shading` from an explicit camera (e.g. an eye
    /// moved inside the mesh); `opts.camera` is not used.
    pub fn render_with_camera(
        &mut self,
        shading: &Shading,
        opts: &RenderOptions,
        camera: &Camera,
        progress: impl FnMut(usize, usize),
    ) -> Result<(Image, RenderStats), RenderError> {
        let t0 = Instant::now();
        let info = opts.mode.info();
        let model = shading.tf.model();
        if !info.emission.contains(&model) {
            return Err(RenderError::Unsupported {
                mode: info.name,
                model,
                supported: format!("{:?}", info.emission),
                alternatives: Mode::ALL
                    .iter()
                    .filter(|m| m.info().emission.contains(&model))
                    .map(|m| m.name())
                    .collect::<Vec<_>>()
                    .join(", --mode "),
            });
        }
        shading.check(&self.geometry)?;
        // A field far from zero next to its span is rendered from offsets.
        let moved = self.moved.frame(shading, opts);
        let (shading, opts) = match &moved {
            Some((s, o)) => (s, o),
            None => (shading, opts),
        };
        // The frame's scene: the geometry and the field shared, not copied.
        let scene = Scene::new(self.geometry.clone(), shading.clone());
        let (image, detail, setup_s) = match opts.mode {
            Mode::Iso if !opts.iso.any() => return Err(RenderError::IsoMissing),
            Mode::Iso
            | Mode::Exact
            | Mode::ExactFrag
            | Mode::Preint3d
            | Mode::Preint2d
            | Mode::Preint2dCyl
                if opts.iso.any() =>
            {
                let mode = iso_mode(&scene, opts)?;
                let (img, mut detail, setup) =
                    self.projected(&mode, &scene, opts, camera, progress)?;
                if let ModeStats::Projected(s) = &mut detail {
                    s.table = mode.take_stats();
                }
                (img, detail, setup)
            }
            Mode::Exact => {
                let mode = modes::exact::ExactMode {
                    refine_tol: opts.projected.refine_tol,
                };
                self.projected(&mode, &scene, opts, camera, progress)?
            }
            Mode::ExactFrag if self.piece_draw(opts)? == PieceDraw::Quads => self.projected(
                &modes::piece_quad::ExactFragQuads,
                &scene,
                opts,
                camera,
                progress,
            )?,
            Mode::ExactFrag => self.projected(
                &modes::exact_frag::ExactFragMode,
                &scene,
                opts,
                camera,
                progress,
            )?,
            Mode::Preint3d | Mode::Preint2d | Mode::Preint2dCyl => {
                let mode = modes::preint::PreintMode::for_mode(opts.mode, opts)?;
                let (img, mut detail, setup) = if self.piece_draw(opts)? == PieceDraw::Quads {
                    let quads = modes::preint_quads::PreintQuads(&mode);
                    self.projected(&quads, &scene, opts, camera, progress)?
                } else {
                    self.projected(&mode, &scene, opts, camera, progress)?
                };
                if let ModeStats::Projected(s) = &mut detail {
                    s.table = mode.take_stats();
                }
                (img, detail, setup)
            }
            Mode::Iso => return Err(RenderError::IsoMissing),
            Mode::Raycast => {
                let (img, s, setup) = modes::raycast::render(&scene, opts, camera, progress)?;
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
        scene: &Scene,
        opts: &RenderOptions,
        camera: &Camera,
        progress: impl FnMut(usize, usize),
    ) -> Result<(Image, ModeStats, f64), RenderError> {
        let t0 = Instant::now();
        let Renderer {
            geometry: g,
            sorter,
            orders,
            visible,
            last_visible,
            gpu,
            pending_gpu,
            kept,
            regions,
            moved: _,
        } = self;
        // The min/max tree, for the occlusion pass where it may hide
        // something (the visible subset builds it anyway).
        let occluding = opts.projected.occlusion.is_some_and(|t| {
            opts.projected.occlusion_tree
                && opts.projected.draw == crate::gpu::DrawKind::Composite
                && occlusion::may_hide(
                    &scene.tf,
                    mode.isosurfaces(),
                    mode.draws_volume(),
                    g.mesh.diagonal(),
                    t,
                )
        });
        let (tree, tree_s) = if occluding {
            let (t, s) = visible.tree(&g.mesh);
            (Some(t), s)
        } else {
            (None, 0.0)
        };
        let (subset, dark_cells, checked_s, classified) =
            if opts.projected.skip_invisible && opts.projected.dark_subset {
                visible.prepare(scene, mode.isosurfaces(), mode.draws_volume())
            } else {
                (None, 0, 0.0, Default::default())
            };
        *last_visible = subset.is_some();
        // The visible subset's scene, sorter and order cache, or the
        // geometry's; one driver call either way.
        let sub_scene;
        let (drawn, sorter, orders, sorter_s, ids) = match subset {
            Some(sub) => {
                if let Some(s) = sorter.as_ref() {
                    sub.sorter.copy_options(s);
                }
                sub_scene = sub.scene_of(scene);
                let ids = Some(&sub.cells[..]);
                (&sub_scene, &mut sub.sorter, &mut sub.orders, checked_s, ids)
            }
            None => {
                let sorter =
                    sorter.get_or_insert_with(|| Sorter::new(g.mesh.clone(), g.topology.clone()));
                (scene, sorter, orders, t0.elapsed().as_secs_f64(), None)
            }
        };
        let (img, mut stats) = driver::render_projected(
            mode,
            drawn,
            sorter,
            gpu,
            pending_gpu,
            orders,
            opts,
            camera,
            &scene.mesh,
            tree.as_deref().map(|tree| occlusion::TreeView {
                tree,
                geometry_ids: ids,
            }),
            kept,
            (regions, ids),
            progress,
        )?;
        stats.dark_cells_left_out = dark_cells;
        stats.visible_subset_s = checked_s;
        stats.dark_nodes_visited = classified.nodes_visited;
        stats.dark_cells_tested = classified.cells_tested;
        stats.tree_nodes = classified.nodes;
        let setup_s = sorter_s + stats.gpu_open_s + tree_s;
        Ok((img, ModeStats::Projected(Box::new(stats)), setup_s))
    }
}

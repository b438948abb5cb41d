//! What a render did: the typed statistics of each kind of mode, printable
//! (`Display`, the lines of `zoovr render --stats`) and machine-readable
//! (serde, `--stats --json` and `bench`).

use std::fmt;

use serde::Serialize;

use crate::gpu::FrameStats;
use crate::raycast::brute::BruteStats;
use crate::raycast::native::NativeStats;
use crate::raycast::{FieldModel, Traversal};
use crate::visibility::OrderStats;

use super::Mode;

/// What a projected-cell mode did ([`super::driver`]), with times in
/// seconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ProjectedStats {
    pub pieces: usize,
    pub culled_pieces: usize,
    pub slabs: usize,
    pub triangles: usize,
    pub refined_triangles: usize,
    /// Pixel centres next to a part's outline that snapping would have put
    /// on the wrong side, decided by a pixel triangle ([`super::ties`]).
    pub tie_pixels: usize,
    /// Parts whose outline and slivers were left to the rasteriser as
    /// optically thin ([`super::ties::thin_outline`]).
    pub thin_outlines: usize,
    /// Triangles steep enough that the snap of their corners would shift
    /// the optical depth, drawn with the exact triangle's values at the
    /// snapped corners ([`super::ties::snap_is_steep`]).
    pub steep_triangles: usize,
    /// Parts drawn whole as one quad (exact-frag `--piece-draw quads`,
    /// [`super::modes::piece_quad`]); the others were projected.
    pub whole_pieces: usize,
    /// Of those, the parts drawn as their outline's widened hull rather
    /// than their pixel bounding box ([`super::driver`]'s `whole`).
    pub whole_hulls: usize,
    /// Parts whose regions were kept from an earlier frame with other
    /// values ([`super::ProjectedOptions::keep_regions`]): not projected
    /// again, only given the new values; and what the kept regions hold,
    /// bytes.
    pub regions_reused: usize,
    pub regions_kept_bytes: usize,
    /// Pieces left out as hidden behind opaque ones
    /// ([`super::occlusion`]), and the time the pass took.
    pub hidden_pieces: usize,
    pub occlusion_s: f64,
    /// Nodes of the min/max tree ([`super::cell_tree`]) the occlusion
    /// pass found hidden whole, and the hidden pieces it left out through
    /// them without testing each.
    pub occlusion_nodes_hidden: usize,
    pub hidden_by_nodes: usize,
    /// Pixels of the per-pixel layers of cycle groups
    /// ([`super::group`]).
    pub group_pixels: usize,
    pub sort_s: f64,
    /// Dark cells left out of the sort ([`super::visible`]: the visible
    /// subset was sorted and drawn), and the time spent building the
    /// subset this frame (0 when it was reused).
    pub dark_cells_left_out: usize,
    pub visible_subset_s: f64,
    /// What finding the dark cells looked at when the subset was built
    /// this frame ([`super::cell_tree`]): nodes of the min/max tree and
    /// cells tested one by one, of all (zeros when reused or not built).
    pub dark_nodes_visited: usize,
    pub dark_cells_tested: usize,
    pub tree_nodes: usize,
    /// The frame took the renderer's last order, made for the same camera,
    /// split policy, scalars and sorter options, without sorting again
    /// (`order` then holds the statistics of the sort that made it).
    pub order_reused: bool,
    /// The frame took the sort of the same view (the geometry's order,
    /// [`crate::visibility::Sorter::base_order`]) and only spliced its
    /// values in: a time step or a transfer function that changed only the
    /// values' splits.
    pub sort_reused: bool,
    /// The frame drew the triangles the renderer kept from its last frame,
    /// which differed only in the transfer function's colours
    /// ([`super::ProjectedOptions::keep_projection`]): no sort, no
    /// projection.
    pub projection_reused: bool,
    /// Time spent opening (or waiting for) the GPU context.
    pub gpu_open_s: f64,
    /// Projection, payloads and the draw calls, which overlap (workers
    /// project later chunks while this thread uploads and draws finished
    /// ones).
    pub project_s: f64,
    pub gpu: FrameStats,
    /// What the GPU had left after the last draw call: finishing and
    /// reading the image back.
    pub gpu_total_s: f64,
    pub order: OrderStats,
    /// The table of a pre-integrated table mode: its size, how it was
    /// built and what that cost this frame.
    pub table: Option<crate::render::modes::preint_tables::TableStats>,
    /// CPU twin with [`super::ProjectedOptions::watch`]: the fragments drawn
    /// at the watched pixel, in drawing order.
    #[serde(skip)]
    pub watched: Vec<crate::gpu::cpu::Fragment>,
}

impl fmt::Display for ProjectedStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (e, o) = (self, &self.order);
        writeln!(
            f,
            "sort         {:.3} s{}  ({} pieces, {} cells outside the view, {} split cells, {} dark cells left whole, {} problem cells, {} cycles, {} cut by planes into {} fragments, {} cycle groups of {} pieces over {} pixels)",
            e.sort_s,
            if e.order_reused {
                ", order reused"
            } else if e.sort_reused {
                ", sort reused, values spliced"
            } else {
                ""
            },
            e.pieces,
            o.frustum_culled,
            o.split_cells,
            o.dark_unsplit,
            o.problem_cells,
            o.cycles_found,
            o.cycles_resolved_by_planes,
            o.fragments,
            o.cycle_groups,
            o.pieces_in_groups,
            e.group_pixels
        )?;
        writeln!(
            f,
            "             (classify faces {:.3}, non-convex constraints {:.3}, splits {:.3}, topological sort {:.3}, values spliced {:.3})",
            o.time_classify.as_secs_f64(),
            o.time_nonconvex.as_secs_f64(),
            o.time_split.as_secs_f64(),
            o.time_sort.as_secs_f64(),
            o.time_splice.as_secs_f64()
        )?;
        if e.dark_cells_left_out > 0 {
            writeln!(
                f,
                "visible      {:.3} s  ({} dark cells left out of the sort{})",
                e.visible_subset_s,
                e.dark_cells_left_out,
                if e.dark_nodes_visited > 0 {
                    format!(
                        "; min/max tree: {} of {} nodes visited, {} cells tested",
                        e.dark_nodes_visited, e.tree_nodes, e.dark_cells_tested
                    )
                } else {
                    String::new()
                }
            )?;
        }
        writeln!(
            f,
            "occlusion    {:.3} s  ({} pieces hidden behind opaque ones{})",
            e.occlusion_s,
            e.hidden_pieces,
            if e.occlusion_nodes_hidden > 0 {
                format!(
                    "; min/max tree: {} nodes hidden whole, {} of the pieces through them",
                    e.occlusion_nodes_hidden, e.hidden_by_nodes
                )
            } else {
                String::new()
            }
        )?;
        writeln!(
            f,
            "project+draw {:.3} s{}  ({} triangles, {} culled pieces, {} slab pieces, {} refined triangles, {} tie pixels ({} parts thin at their outline), {} steep triangles{})",
            e.project_s,
            if e.projection_reused {
                ", kept triangles drawn again"
            } else {
                ""
            },
            e.triangles,
            e.culled_pieces,
            e.slabs,
            e.refined_triangles,
            e.tie_pixels,
            e.thin_outlines,
            e.steep_triangles,
            if e.whole_pieces > 0 {
                format!(
                    ", {} pieces drawn whole ({} as hulls)",
                    e.whole_pieces, e.whole_hulls
                )
            } else {
                String::new()
            }
        )?;
        if e.regions_kept_bytes > 0 {
            writeln!(
                f,
                "kept regions {} parts' regions from an earlier frame given the new values ({:.1} MiB kept)",
                e.regions_reused,
                e.regions_kept_bytes as f64 / (1u64 << 20) as f64
            )?;
        }
        if let Some(t) = &e.table {
            writeln!(
                f,
                "table        {:.3} s  ({:?} {}x{}x{}, build {}, {} texels built, length {:.4e})",
                t.build_s,
                t.kind,
                t.size[0],
                t.size[1],
                t.size[2],
                t.build.name(),
                t.texels_built,
                t.l_table
            )?;
        }
        write!(
            f,
            "gpu finish   {:.3} s  (upload {:.3}, wait {:.3}, readback {:.3}, {} batches)",
            e.gpu_total_s, e.gpu.upload_s, e.gpu.gpu_wait_s, e.gpu.readback_s, e.gpu.batches
        )
    }
}

/// What a ray-cast render used.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RaycastStats {
    pub model: FieldModel,
    pub traversal: Traversal,
    /// Rays stop once their transmittance falls below this (0: never), so
    /// a pixel's opacity may fall short of the full integral by at most it.
    pub termination_transmittance: f64,
    /// Rays that stopped there (their optical depth reached
    /// `-ln(termination_transmittance)`): the work the early termination
    /// saved lies behind them.
    pub terminated_rays: u64,
    /// Native model: intervals integrated and what fell back from the
    /// exact method during this render (zero for other models).
    pub native: NativeStats,
    /// Brute-force traversal: pieces tested, segments, and segments that
    /// overlapped another piece's (zero for the walk).
    pub brute: BruteStats,
}

impl fmt::Display for RaycastStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = self;
        write!(
            f,
            "raycast      model {}, traversal {}, early ray termination below transmittance {:e} \
             ({} rays stopped there)",
            r.model.name(),
            r.traversal.name(),
            r.termination_transmittance,
            r.terminated_rays
        )?;
        if r.traversal == Traversal::Brute {
            let b = &r.brute;
            write!(
                f,
                "\nbrute        {} cells tested, {} segments, {} of them overlapping another \
                 piece's in depth",
                b.cells_tested, b.segments, b.overlapping_segments
            )?;
        }
        if r.model == FieldModel::Native {
            let n = &r.native;
            write!(
                f,
                "\nnative       {} intervals, {} extra cells (bilinear faces), {} Newton failures, \
                 {} linear fallbacks, {} parity-classified, {} depth-limited brackets",
                n.intervals,
                n.extra_cells,
                n.newton_failures,
                n.fallback_intervals,
                n.parity_classified,
                n.bracket_depth_limited
            )?;
        }
        Ok(())
    }
}

/// The statistics of the mode that rendered.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum ModeStats {
    /// A projected-cell mode ([`super::driver`]).
    Projected(Box<ProjectedStats>),
    /// The reference ray caster.
    Raycast(RaycastStats),
}

impl fmt::Display for ModeStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModeStats::Projected(s) => s.fmt(f),
            ModeStats::Raycast(s) => s.fmt(f),
        }
    }
}

/// What one render did (seconds of wall time).
#[derive(Clone, Debug, Serialize)]
pub struct RenderStats {
    pub mode: Mode,
    pub total_s: f64,
    /// Building what the mode reuses between views (the sorter's geometry,
    /// the ray caster's acceleration structures) and opening the GPU.
    pub setup_s: f64,
    pub gpu_adapter: Option<String>,
    pub detail: ModeStats,
}

impl RenderStats {
    /// The projected-cell statistics, when a projected-cell mode rendered.
    pub fn projected(&self) -> Option<&ProjectedStats> {
        match &self.detail {
            ModeStats::Projected(s) => Some(s.as_ref()),
            _ => None,
        }
    }

    /// The ray caster's statistics, when it rendered.
    pub fn raycast(&self) -> Option<&RaycastStats> {
        match &self.detail {
            ModeStats::Raycast(s) => Some(s),
            _ => None,
        }
    }
}

impl fmt::Display for RenderStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.detail {
            ModeStats::Projected(e) => writeln!(
                f,
                "setup        {:.3} s  (visibility geometry {:.3}, waiting for the GPU device {:.3})",
                self.setup_s,
                self.setup_s - e.gpu_open_s,
                e.gpu_open_s
            )?,
            _ => writeln!(f, "setup        {:.3} s", self.setup_s)?,
        }
        if let Some(a) = &self.gpu_adapter {
            writeln!(f, "adapter      {a}")?;
        }
        writeln!(f, "{}", self.detail)?;
        write!(f, "render total {:.3} s", self.total_s)
    }
}

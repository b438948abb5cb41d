//! The reference mode: the CPU ray caster ([`crate::raycast`]), walking by
//! adjacency or, with [`Traversal::Brute`], testing every piece
//! ([`crate::raycast::brute`]). Its acceleration structures are kept in the
//! [`Renderer`] between views.

use std::time::Instant;

use crate::camera::Camera;
use crate::image::Image;
use crate::raycast::brute::Brute;
use crate::raycast::{self, RaycastOptions, Raycaster, Traversal};
use crate::render::scene::ScalarsRef;
use crate::render::stats::RaycastStats;
use crate::render::{RenderError, RenderOptions, Renderer};
use crate::tf::EmissionModel;

use super::ModeInfo;

/// The registry entry of the ray caster.
pub static INFO: ModeInfo = ModeInfo {
    name: "raycast",
    summary: "the CPU reference ray caster (--model, --traversal)",
    gpu: false,
    emission: &[EmissionModel::Glow, EmissionModel::Independent],
    slices_at_breakpoints: false,
    stage: None,
    bounds: None,
};

/// Renders one image with the ray caster; returns it with its statistics
/// and the seconds spent building the ray caster.
pub(crate) fn render(
    r: &mut Renderer,
    opts: &RenderOptions,
    camera: &Camera,
    progress: impl FnMut(usize, usize),
) -> Result<(Image, RaycastStats, f64), RenderError> {
    let t0 = Instant::now();
    let scene = r.scene;
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
        model: opts.reference.model,
        traversal: opts.reference.traversal,
        ..Default::default()
    };
    let mut stats = RaycastStats {
        model: opts.reference.model,
        traversal: opts.reference.traversal,
        termination_transmittance: ro.early_termination,
        native: Default::default(),
        brute: Default::default(),
    };
    let setup_s;
    let img = match opts.reference.traversal {
        Traversal::Walk => {
            let rc = match r.raycaster.take() {
                Some((m, rc)) if m == opts.reference.model => rc,
                _ => Raycaster::new(rs, opts.reference.model)?,
            };
            setup_s = t0.elapsed().as_secs_f64();
            let before = rc.native_stats();
            let img = rc.render_with_progress(&scene.tf, camera, &ro, progress);
            stats.native = rc.native_stats().since(&before);
            r.raycaster = Some((opts.reference.model, rc));
            img
        }
        Traversal::Brute => {
            let b = match r.brute.take() {
                Some((m, b)) if m == opts.reference.model => b,
                _ => Brute::new(rs, opts.reference.model)?,
            };
            setup_s = t0.elapsed().as_secs_f64();
            let before = b.stats();
            let img = b.render_with_progress(&scene.tf, camera, &ro, progress);
            stats.brute = b.stats().since(&before);
            r.brute = Some((opts.reference.model, b));
            img
        }
    };
    Ok((img, stats, setup_s))
}

//! The reference mode: the CPU ray caster ([`crate::raycast`]), walking by
//! adjacency or, with [`Traversal::Brute`], testing every piece
//! ([`crate::raycast::brute`]). Its acceleration structures (the walk's
//! boundary and bounding-volume hierarchy, or the brute force's pieces) are
//! built per frame: they hold the frame's scalars.

use std::time::Instant;

use crate::camera::Camera;
use crate::image::Image;
use crate::raycast::brute::Brute;
use crate::raycast::iso::{BruteIsoReference, Empty, IsoReference};
use crate::raycast::{self, RayTracer, RaycastOptions, Raycaster, Traversal};
use crate::render::gradients::point_gradients;
use crate::render::iso::{IsoError, IsoSet, Lighting};
use crate::render::scene::{ScalarsRef, Scene};
use crate::render::stats::RaycastStats;
use crate::render::{RenderError, RenderOptions};
use crate::tf::EmissionModel;

use super::ModeInfo;

/// The registry entry of the ray caster.
pub static INFO: ModeInfo = ModeInfo {
    name: "raycast",
    summary: "the CPU reference ray caster (--model, --traversal)",
    gpu: false,
    emission: &[EmissionModel::Glow, EmissionModel::Independent],
    slices_at_breakpoints: false,
    draws_pieces_whole: false,
    stage: None,
    bounds: None,
};

/// Renders one image with the ray caster; returns it with its statistics
/// and the seconds spent building the ray caster. With `opts.iso`, the
/// isosurfaces are mixed with the volume ([`render_iso`]).
pub(crate) fn render(
    scene: &Scene,
    opts: &RenderOptions,
    camera: &Camera,
    progress: impl FnMut(usize, usize),
) -> Result<(Image, RaycastStats, f64), RenderError> {
    if opts.iso.any() {
        return render_iso(scene, opts, camera, !opts.iso.alone, progress);
    }
    let t0 = Instant::now();
    let rs = scene.ray_scene();
    let ro = RaycastOptions {
        model: opts.reference.model,
        traversal: opts.reference.traversal,
        early_termination: if opts.reference.early_termination {
            crate::numeric::tolerance::RAY_TERMINATION_TRANSMITTANCE
        } else {
            0.0
        },
        ..Default::default()
    };
    let mut stats = RaycastStats {
        model: opts.reference.model,
        traversal: opts.reference.traversal,
        termination_transmittance: ro.early_termination,
        terminated_rays: 0,
        native: Default::default(),
        brute: Default::default(),
    };
    let setup_s;
    let img = match opts.reference.traversal {
        Traversal::Walk => {
            let rc = Raycaster::new(rs, opts.reference.model)?;
            setup_s = t0.elapsed().as_secs_f64();
            let before = rc.native_stats();
            let (img, n) = rc.render_counting(&scene.tf, camera, &ro, progress);
            stats.native = rc.native_stats().since(&before);
            stats.terminated_rays = n;
            img
        }
        Traversal::Brute => {
            let b = Brute::new(rs, opts.reference.model)?;
            setup_s = t0.elapsed().as_secs_f64();
            let before = b.stats();
            let (img, n) = b.render_counting(&scene.tf, camera, &ro, progress);
            stats.brute = b.stats().since(&before);
            stats.terminated_rays = n;
            img
        }
    };
    Ok((img, stats, setup_s))
}

/// The reference with the isosurfaces of `opts.iso`, over the volume
/// (`volume`) or alone (the reference of `--mode iso`): the walk (any
/// field model) or the brute-force traversal (`faces`, `tets`), see
/// [`crate::raycast::iso`].
pub fn render_iso(
    scene: &Scene,
    opts: &RenderOptions,
    camera: &Camera,
    volume: bool,
    progress: impl FnMut(usize, usize),
) -> Result<(Image, RaycastStats, f64), RenderError> {
    let t0 = Instant::now();
    let ScalarsRef::Point(values) = scene.scalars() else {
        return Err(IsoError::CellData.into());
    };
    let rs = raycast::Scene {
        mesh: &scene.mesh,
        topology: &scene.topology,
        scalars: raycast::Scalars::Point(values),
    };
    let ro = RaycastOptions {
        model: opts.reference.model,
        traversal: opts.reference.traversal,
        early_termination: if opts.reference.early_termination {
            crate::numeric::tolerance::RAY_TERMINATION_TRANSMITTANCE
        } else {
            0.0
        },
        ..Default::default()
    };
    let set = IsoSet::new(&opts.iso, &scene.tf);
    let grads = (set.lighting == Lighting::Smooth).then(|| point_gradients(&scene.mesh, values));
    let mut native = Default::default();
    let mut brute = Default::default();
    let (setup_s, (img, terminated_rays)) = match opts.reference.traversal {
        Traversal::Walk => {
            let rc = Raycaster::new(rs, opts.reference.model)?;
            let iso = IsoReference::new(&rc, &set, camera.forward, grads.as_deref(), values);
            let setup_s = t0.elapsed().as_secs_f64();
            let before = rc.native_stats();
            let out = if volume {
                iso.render_counting(&scene.tf, camera, &ro, progress)
            } else {
                iso.render_counting(&Empty, camera, &ro, progress)
            };
            native = rc.native_stats().since(&before);
            (setup_s, out)
        }
        Traversal::Brute => {
            let b = Brute::new(rs, opts.reference.model)?;
            let iso = BruteIsoReference::new(&b, &set, camera.forward, grads.as_deref(), values);
            let setup_s = t0.elapsed().as_secs_f64();
            let before = b.stats();
            let out = if volume {
                iso.render_counting(&scene.tf, camera, &ro, progress)
            } else {
                iso.render_counting(&Empty, camera, &ro, progress)
            };
            brute = b.stats().since(&before);
            (setup_s, out)
        }
    };
    let stats = RaycastStats {
        model: opts.reference.model,
        traversal: opts.reference.traversal,
        termination_transmittance: ro.early_termination,
        terminated_rays,
        native,
        brute,
    };
    Ok((img, stats, setup_s))
}

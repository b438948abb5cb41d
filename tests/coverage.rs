//! Pixel-centre coverage, pixel by pixel: every pixel centre inside a
//! piece's projected silhouette is coloured by exactly one of its
//! triangles.
//!
//! The exact mode draws with `DrawKind::CountPieces` (each fragment adds 1,
//! at most once per piece: the depth test on the piece key) and
//! `DrawKind::CountTriangles` (every fragment adds 1). The counts are
//! compared with:
//! - the CPU twin of the rasteriser (`gpu::cpu`), which must give the
//!   GPU's counts exactly (same snapped positions, same top-left rule);
//! - the number of pieces the reference ray crosses for a positive length,
//!   from the ray caster's brute force (`raycast::brute`: every tet tested
//!   on its own, no adjacency): with `--split all` and a transfer function
//!   without breakpoints every piece is one tet of the consistent
//!   tetrahedralisation. **Zero mismatches**, in every view.
//!
//! Why zero, by construction: a centre far from a piece's projected
//! outline is inside the snapped piece exactly when it is inside the exact
//! one; a centre near it (within the snap of 1/256 px) is decided by
//! `render::ties` with the ray caster's own predicate on the ray caster's
//! own numbers (the same world-space ray, far point, perturbation and
//! points), so a centre on a projected edge, a vertex, or a face seen
//! edge-on goes to the side the ray caster gives it, and a ray that meets
//! a piece for no length (through a vertex or along an edge) takes no
//! segment there, as in the brute force.
//!
//! The adjacency walk (`raycast::walk`, the default traversal) chains each
//! tet's entry depth to the previous tet's exit, so where the ray passes
//! through a vertex it reports tets crossed for no length, or for a
//! rounding error's length, that the brute force (and the renderer) leave
//! out. Every other segment is the brute force's: checked here, segments
//! longer than [`NOISE_LEN`] counted per pixel.

mod render_util;
use render_util::gpu_available;

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::gpu::DrawKind;
use zoovr::image::Image;
use zoovr::io::{self, ReadOptions};
use zoovr::mesh::tetra::tetrahedralize_cell;
use zoovr::mesh::Mesh;
use zoovr::raycast::brute::Brute;
use zoovr::raycast::{self, FieldModel, Raycaster};
use zoovr::render::{
    Compositor, Mode, ModeStats, PieceDraw, ProjectedOptions, RenderOptions, Renderer, Scene,
    SceneSpec, Shading,
};
use zoovr::testdata::{mesh_file, shared_file};
use zoovr::tf::{EmissionModel, TransferFunction};

/// Segments of the walk and the brute force at most this long relative to
/// the mesh's size are rounding (a ray through a vertex); longer ones are
/// the same in both.
const NOISE_LEN: f64 = 1e-12;

/// Constant extinction and colour: no breakpoint (every tet is one piece)
/// and no piece skipped for zero extinction.
fn flat_tf(range: (f64, f64)) -> TransferFunction {
    let (lo, hi) = (range.0, range.1.max(range.0 + 1.0));
    TransferFunction::from_channels(
        &[(lo, [1.0]), (hi, [1.0])],
        &[(lo, [0.5, 0.5, 0.5]), (hi, [0.5, 0.5, 0.5])],
        None,
        EmissionModel::Glow,
    )
    .unwrap()
}

fn counts(
    renderer: &mut Renderer,
    shading: &Shading,
    camera: &Camera,
    kind: DrawKind,
    compositor: Compositor,
) -> Image {
    counts_with(
        renderer,
        shading,
        camera,
        kind,
        compositor,
        PieceDraw::Regions,
    )
    .0
}

/// [`counts`] of the exact mode (`Regions`) or of exact-frag's whole-piece
/// quads (`Quads`), with the number of parts drawn whole and, of them, as
/// their outline's hull.
fn counts_with(
    renderer: &mut Renderer,
    shading: &Shading,
    camera: &Camera,
    kind: DrawKind,
    compositor: Compositor,
    draw: PieceDraw,
) -> (Image, usize, usize) {
    let opts = RenderOptions {
        mode: if draw == PieceDraw::Quads {
            Mode::ExactFrag
        } else {
            Mode::Exact
        },
        projected: ProjectedOptions {
            split_all: true,
            draw: kind,
            compositor,
            piece_draw: draw,
            ..Default::default()
        },
        ..Default::default()
    };
    let (img, stats) = renderer
        .render_with_camera(shading, &opts, camera, |_, _| {})
        .unwrap();
    let (whole, hulls) = match stats.detail {
        ModeStats::Projected(p) => {
            // A counting draw counts every centre: no outline is left to
            // the rasteriser as optically thin.
            assert_eq!(p.thin_outlines, 0, "{kind:?}");
            (p.whole_pieces, p.whole_hulls)
        }
        _ => (0, 0),
    };
    (img, whole, hulls)
}

/// The reference: the ray caster's brute force over the `tets`, built once
/// per scene for all its views.
fn reference(scene: &Scene) -> Brute<'_> {
    Brute::new(scene.ray_scene(), FieldModel::Tets).unwrap()
}

/// The `tets` walk of `scene`.
fn walk(scene: &Scene) -> Raycaster<'_> {
    Raycaster::new(scene.ray_scene(), FieldModel::Tets).unwrap()
}

/// Tets each pixel's reference ray crosses for a positive length.
fn reference_counts(rc: &Brute, camera: &Camera) -> Vec<usize> {
    let t_near = if camera.ortho { 0.0 } else { camera.near };
    let mut out = Vec::new();
    for j in 0..camera.height {
        for i in 0..camera.width {
            out.push(rc.segments(&camera.pixel_ray(i, j), t_near).len());
        }
    }
    out
}

/// The walk gives the brute force's segments but for rounding-length ones
/// (see the module docs): the counts of segments longer than
/// [`NOISE_LEN`] times the mesh's diagonal agree at every pixel.
fn check_walk(scene: &Scene, brute: &Brute, camera: &Camera, tag: &str) {
    let b = scene.mesh.bounds();
    let diag = glam::DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length();
    let t_near = if camera.ortho { 0.0 } else { camera.near };
    let long = |s: &raycast::Segment| s.t_out - s.t_in > NOISE_LEN * diag;
    let walk = walk(scene);
    for j in 0..camera.height {
        for i in 0..camera.width {
            let ray = camera.pixel_ray(i, j);
            let w = walk.segments(&ray, t_near);
            let r = brute.segments(&ray, t_near);
            let (nw, nr) = (
                w.iter().filter(|s| long(s)).count(),
                r.iter().filter(|s| long(s)).count(),
            );
            assert_eq!(
                nw, nr,
                "{tag}: pixel ({i}, {j}): walk {w:?}, brute force {r:?}"
            );
        }
    }
}

/// The tet edges of `mesh` projected into the image of `camera` (both ends
/// in front of the camera), in pixels.
fn projected_edges(mesh: &Mesh, camera: &Camera) -> Vec<(glam::DVec2, glam::DVec2)> {
    let mut edges = Vec::new();
    let mut tets = Vec::new();
    for cell in 0..mesh.cells.len() {
        tets.clear();
        tetrahedralize_cell(&mesh.cells, cell, &mut tets);
        for t in &tets {
            let p: Vec<Option<glam::DVec2>> = t
                .iter()
                .map(|&n| {
                    let v = camera.to_view(mesh.points[n as usize]);
                    camera
                        .view_to_pixel(v)
                        .map(|(x, y, _)| glam::DVec2::new(x, y))
                })
                .collect();
            for a in 0..4 {
                for b in a + 1..4 {
                    if let (Some(pa), Some(pb)) = (p[a], p[b]) {
                        edges.push((pa, pb));
                    }
                }
            }
        }
    }
    edges
}

/// Distance in pixels from centre `(i, j)` to the nearest of `edges`
/// ([`projected_edges`]).
fn distance_to_edges(edges: &[(glam::DVec2, glam::DVec2)], i: u32, j: u32) -> f64 {
    let c = glam::DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
    let mut best = f64::INFINITY;
    for &(pa, pb) in edges {
        let d = pb - pa;
        let s = ((c - pa).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
        best = best.min((pa + d * s - c).length());
    }
    best
}

/// Every centre's piece count is the ray's tet count; the first that is
/// not is reported with its distance to the nearest projected tet edge.
fn check_counts(scene: &Scene, camera: &Camera, pieces: &[usize], want: &[usize], tag: &str) {
    check_counts_outside(scene, camera, pieces, want, &vec![false; want.len()], tag);
}

/// [`check_counts`] at the centres not in `skip`.
fn check_counts_outside(
    scene: &Scene,
    camera: &Camera,
    pieces: &[usize],
    want: &[usize],
    skip: &[bool],
    tag: &str,
) {
    let bad: Vec<usize> = (0..want.len())
        .filter(|&k| !skip[k] && want[k] != pieces[k])
        .collect();
    if let Some(&k) = bad.first() {
        let (i, j) = (k as u32 % camera.width, k as u32 / camera.width);
        let d = distance_to_edges(&projected_edges(&scene.mesh, camera), i, j);
        panic!(
            "{tag}: {} mismatches; first: pixel ({i}, {j}) drawn by {} pieces, the ray \
             crosses {} tets, {d:.2e} px from the nearest projected edge",
            bad.len(),
            pieces[k],
            want[k]
        );
    }
}

fn red(img: &Image) -> Vec<usize> {
    img.pixels.iter().map(|p| p[0].round() as usize).collect()
}

/// GPU counts equal the CPU twin's, both kinds; returns the twin's piece
/// counts and the number of centres covered by more than one triangle of
/// a piece (folds the depth test resolves).
fn check_twin(
    renderer: &mut Renderer,
    shading: &Shading,
    camera: &Camera,
    gpu: bool,
    tag: &str,
) -> (Vec<usize>, usize) {
    let pieces = red(&counts(
        renderer,
        shading,
        camera,
        DrawKind::CountPieces,
        Compositor::Cpu,
    ));
    let tris = red(&counts(
        renderer,
        shading,
        camera,
        DrawKind::CountTriangles,
        Compositor::Cpu,
    ));
    if gpu {
        for (kind, twin) in [
            (DrawKind::CountPieces, &pieces),
            (DrawKind::CountTriangles, &tris),
        ] {
            let got = red(&counts(renderer, shading, camera, kind, Compositor::Gpu));
            let bad: Vec<usize> = (0..got.len()).filter(|&k| got[k] != twin[k]).collect();
            assert!(
                bad.is_empty(),
                "{tag} {kind:?}: GPU and CPU twin counts differ at {} pixels, first {:?}: gpu {} twin {}",
                bad.len(),
                bad.first().map(|&k| (k as u32 % camera.width, k as u32 / camera.width)),
                bad.first().map_or(0, |&k| got[k]),
                bad.first().map_or(0, |&k| twin[k]),
            );
        }
    }
    let folds = (0..pieces.len()).filter(|&k| tris[k] > pieces[k]).count();
    (pieces, folds)
}

/// A grid of `n^3` hexes with spacing 2 px whose vertices project onto
/// pixel centres of a 64 x 64 orthographic view down -z (optionally
/// sheared so that faces are not edge-on), and that camera.
fn on_grid(n: usize, shear: f64) -> (Mesh, Camera) {
    on_grid_scaled(n, shear, 1)
}

/// [`on_grid`] with its points `scale` times as far from the image's
/// centre (odd, so that they still project onto pixel centres; the camera
/// is unchanged, so every coordinate stays exact in binary).
fn on_grid_scaled(n: usize, shear: f64, scale: u32) -> (Mesh, Camera) {
    let mut mesh = warped_hex_grid(
        n,
        &Warp {
            amplitude: 0.0,
            seed: 1,
        },
    );
    let k = 2.0 * n as f64;
    for p in &mut mesh.points {
        let (x, y, z) = (p.x * k, p.y * k, (p.z * k).round());
        *p = DVec3::new(x - n as f64 + 0.5 + shear * z, y - n as f64 + 0.5, z) * scale as f64;
    }
    let params = CameraParams {
        width: 64,
        height: 64,
        ortho: true,
        ..Default::default()
    };
    let mut camera = Camera::fit([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0], &params);
    camera.position = DVec3::new(0.0, 0.0, 1000.0);
    camera.focal_point = DVec3::ZERO;
    camera.parallel_scale = 32.0;
    (mesh, camera)
}

#[test]
fn on_grid_meshes_are_covered_exactly_once() {
    let gpu = gpu_available();
    for shear in [0.0, 1.0, -2.0] {
        let (mesh, camera) = on_grid(6, shear);
        let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        scene.tf = flat_tf(scene.range);
        let mut renderer = Renderer::new(scene.geometry());
        let tag = format!("on-grid shear {shear}");
        let (pieces, folds) = check_twin(&mut renderer, &scene.shading(), &camera, gpu, &tag);
        let brute = reference(&scene);
        let want = reference_counts(&brute, &camera);
        check_counts(&scene, &camera, &pieces, &want, &tag);
        check_walk(&scene, &brute, &camera, &tag);
        assert!(want.iter().any(|&c| c > 0), "{tag}: nothing covered");
        let edges = projected_edges(&scene.mesh, &camera);
        let on_edges = (0..want.len())
            .filter(|&k| {
                let (i, j) = (k as u32 % camera.width, k as u32 / camera.width);
                distance_to_edges(&edges, i, j) == 0.0
            })
            .count();
        // Folds here are blockers: centres on a vertex the rasteriser
        // gives to a tet that the ray meets there for no length.
        eprintln!("{tag}: {on_edges} centres on projected edges, all decided alike, {folds} folds");
    }
}

/// The project's zoo_3x3x3 and ring_hole meshes, and the shared datasets
/// `rel` that are present.
fn project_and_shared(rel: &[&str]) -> Vec<std::path::PathBuf> {
    let mut files = vec![mesh_file("zoo_3x3x3.vtu"), mesh_file("ring_hole.vtu")];
    files.extend(rel.iter().filter_map(|r| shared_file(r)));
    files
}

/// Real meshes in seeded random views: the GPU counts equal the twin's and
/// the ray's tet counts at every centre.
#[test]
fn datasets_are_covered_exactly_once_in_random_views() {
    let files = project_and_shared(&[
        "tets_small/CylinderLinear.vtk",
        "tets_small/tetraMesh.vtk",
        "prisms_zoo/PentaHexa.vtk",
        "prisms_zoo/uGridEx.vtk",
        "angular_sector/AngularSector.vtk",
        "synthetic/mixed.vtk",
    ]);
    random_views(files, 0x9e37_79b9_7f4a_7c15);
}

/// The rest of the shared collection, eight random views each (skipped
/// without it).
#[test]
fn every_shared_dataset_is_covered_exactly_once_in_random_views() {
    let mut files = Vec::new();
    for rel in [
        "bluntfin/bluntfin_converted.vts",
        "can_crush/can.vtu",
        "disk_out_ref/disk_out_ref_converted.vtu",
        "fea_bracket_qtet/kiefer_bracket.vtu",
        "fire_room/fire_ug.vtu",
        "notch/notch_disp.vtu",
        "office_kitchen/office.binary.vtk",
        "office_kitchen/kitchen.vtk",
        "prisms_zoo/hexa.vtk",
        "su2_sphere_hybrid/sphere_hybrid_converted.vtu",
        "synthetic/hex_shell_zlib.vtu",
    ] {
        files.extend(shared_file(rel));
    }
    random_views(files, 0x2545_f491_4f6c_dd1d);
}

/// Eight seeded random views of each file: the GPU counts equal the
/// twin's, the twin's equal the brute force's at every centre, and the
/// walk's segments longer than rounding are the brute force's (except on
/// can_crush, whose overlapping pieces the walk legitimately sees once:
/// README, "The ray caster").
fn random_views(files: Vec<std::path::PathBuf>, seed: u64) {
    let gpu = gpu_available();
    let mut seed = seed;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for path in files {
        let mesh = io::read(&path, &ReadOptions::default()).unwrap();
        let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        scene.tf = flat_tf(scene.range);
        let mut renderer = Renderer::new(scene.geometry());
        let rc = reference(&scene);
        let overlapping = path.ends_with("can.vtu");
        for view in 0..8 {
            let params = CameraParams {
                width: 48 + (next() * 48.0) as u32,
                height: 48 + (next() * 48.0) as u32,
                azimuth: next() * 360.0,
                elevation: next() * 180.0 - 90.0,
                zoom: 0.8 + next(),
                ortho: view % 2 == 0,
                ..Default::default()
            };
            let camera = Camera::fit(scene.mesh.bounds(), &params);
            let tag = format!("{} view {view} {params:?}", path.display());
            let (pieces, folds) = check_twin(&mut renderer, &scene.shading(), &camera, gpu, &tag);
            let want = reference_counts(&rc, &camera);
            // Unresolved visibility cycles (can_crush's overlapping
            // pieces) are composited per pixel into one layer, drawn as one
            // piece: their pixels are left out, and counted.
            let groups = group_mask(&renderer, &rc, &scene, &camera);
            check_counts_outside(&scene, &camera, &pieces, &want, &groups, &tag);
            let in_groups = groups.iter().filter(|&&g| g).count();
            assert!(overlapping || in_groups == 0, "{tag}: cycle groups");
            if !overlapping {
                check_walk(&scene, &rc, &camera, &tag);
            }
            eprintln!("{tag}: all right, {folds} fold pixels, {in_groups} pixels of cycle groups");
        }
    }
}

/// The centres whose reference ray crosses a cell that has a piece in a
/// cycle group of the last render's order.
fn group_mask(renderer: &Renderer, rc: &Brute, scene: &Scene, camera: &Camera) -> Vec<bool> {
    use zoovr::visibility::Piece;
    let order = renderer.last_order().expect("a projected render");
    let mut cells = vec![false; scene.mesh.cells.len()];
    for g in &order.groups {
        for p in &order.pieces[g.clone()] {
            let c = match *p {
                Piece::Cell(c) => c,
                Piece::Tet { cell, .. } | Piece::Slab { cell, .. } | Piece::Frag { cell, .. } => {
                    cell
                }
            };
            cells[c as usize] = true;
        }
    }
    let t_near = if camera.ortho { 0.0 } else { camera.near };
    let mut mask = Vec::new();
    for j in 0..camera.height {
        for i in 0..camera.width {
            let segs = rc.segments(&camera.pixel_ray(i, j), t_near);
            mask.push(segs.iter().any(|s| cells[s.cell as usize]));
        }
    }
    mask
}

/// Colour refinement (`--refine-tol`) splits region triangles inside a
/// part at edge midpoints, conforming (`projection::refine`: the split is
/// decided per edge, so both triangles on an edge take the same midpoint,
/// no T-junction; a silhouette edge, zero thickness along it, is not
/// split, and the exact decisions of `render::ties` hold the outline's
/// centres anyway). So refinement changes no centre's coverage: the piece
/// counts are the same at the default tolerance and at a fine one, which
/// refines several times more triangles.
#[test]
fn refinement_changes_no_coverage() {
    let files = project_and_shared(&[
        "prisms_zoo/PentaHexa.vtk",
        "angular_sector/AngularSector.vtk",
        "bluntfin/bluntfin_converted.vts",
    ]);
    for path in files {
        let mesh = io::read(&path, &ReadOptions::default()).unwrap();
        let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let mut renderer = Renderer::new(scene.geometry());
        for (view, ortho) in [(0, false), (1, true)] {
            let params = CameraParams {
                width: 72,
                height: 64,
                azimuth: 30.0 + 50.0 * view as f64,
                elevation: 25.0 - 40.0 * view as f64,
                zoom: 1.3,
                ortho,
                ..Default::default()
            };
            let camera = Camera::fit(scene.mesh.bounds(), &params);
            let mut refined = Vec::new();
            let tag = format!("{} view {view}", path.display());
            let mut first = None;
            for tol in [zoovr::numeric::tolerance::COLOR_REFINE_TOL, 1e-3] {
                let opts = RenderOptions {
                    projected: ProjectedOptions {
                        split_all: true,
                        draw: DrawKind::CountPieces,
                        compositor: Compositor::Cpu,
                        refine_tol: tol,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let (img, stats) = renderer
                    .render_with_camera(&scene.shading(), &opts, &camera, |_, _| {})
                    .unwrap();
                refined.push(stats.projected().unwrap().refined_triangles);
                let counts = red(&img);
                let first = first.get_or_insert_with(|| counts.clone());
                let bad = (0..counts.len()).find(|&p| counts[p] != first[p]);
                assert!(
                    bad.is_none(),
                    "{tag}: piece count at pixel {:?} is {} unrefined, {} at tolerance {tol}",
                    bad.map(|p| (p as u32 % camera.width, p as u32 / camera.width)),
                    bad.map_or(0, |p| first[p]),
                    bad.map_or(0, |p| counts[p]),
                );
            }
            eprintln!("{tag}: refined triangles {refined:?}, counts unchanged");
            assert!(refined[1] > refined[0], "{tag}: {refined:?}");
        }
    }
}

/// Exact-frag's whole-piece quads cover what their rays meet: the quad
/// stage's counting fragment counts where the pixel's ray meets the piece
/// (`shaders/piece_quad.wgsl`: its sheared edge functions, from each
/// edge's lower-numbered point), which must equal the number of tets the
/// brute-force ray crosses for a positive length at every centre, with the
/// GPU equal to the twin. The on-grid meshes are sheared along both axes
/// so that no face is edge-on (pieces with one are projected as regions,
/// checked above) while every vertex still projects onto a pixel centre:
/// centres on shared edges and vertices by the thousand.
#[test]
fn whole_piece_quads_cover_what_their_rays_meet() {
    let gpu = gpu_available();
    let mut cases = Vec::new();
    for (sx, sy) in [(1.0, 1.0), (-2.0, 1.0)] {
        let (mut mesh, camera) = on_grid(6, sx);
        for p in &mut mesh.points {
            p.y += sy * p.z;
        }
        cases.push((format!("on-grid shear {sx}, {sy}"), mesh, vec![camera]));
    }
    // Pieces tens of pixels wide, drawn as their outlines' hulls, with
    // points on pixel centres.
    for (sx, sy) in [(0.5, 0.25), (-1.0, 0.5)] {
        let (mut mesh, camera) = on_grid_scaled(3, sx, 5);
        for p in &mut mesh.points {
            p.y += sy * p.z;
        }
        cases.push((format!("on-grid x5 shear {sx}, {sy}"), mesh, vec![camera]));
    }
    for path in project_and_shared(&[
        "tets_small/CylinderLinear.vtk",
        "prisms_zoo/PentaHexa.vtk",
        "angular_sector/AngularSector.vtk",
    ]) {
        let mesh = io::read(&path, &ReadOptions::default()).unwrap();
        let b = mesh.bounds();
        let cams = (0..4)
            .map(|v| {
                let params = CameraParams {
                    width: 64,
                    height: 56,
                    azimuth: 30.0 + 77.0 * v as f64,
                    elevation: 20.0 - 23.0 * v as f64,
                    zoom: 1.1,
                    ortho: v % 2 == 0,
                    ..Default::default()
                };
                Camera::fit(b, &params)
            })
            .collect();
        cases.push((path.display().to_string(), mesh, cams));
    }
    let mut all_hulls = 0;
    for (name, mesh, cams) in cases {
        let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        scene.tf = flat_tf(scene.range);
        let mut renderer = Renderer::new(scene.geometry());
        let brute = reference(&scene);
        for (v, camera) in cams.iter().enumerate() {
            let tag = format!("{name} view {v} quads");
            let shading = scene.shading();
            let count = |r: &mut Renderer, c| {
                counts_with(
                    r,
                    &shading,
                    camera,
                    DrawKind::CountPieces,
                    c,
                    PieceDraw::Quads,
                )
            };
            let (twin, whole, hulls) = count(&mut renderer, Compositor::Cpu);
            all_hulls += hulls;
            let twin = red(&twin);
            if gpu {
                let got = red(&count(&mut renderer, Compositor::Gpu).0);
                let bad = (0..got.len()).filter(|&k| got[k] != twin[k]).count();
                assert_eq!(bad, 0, "{tag}: GPU and twin counts differ at {bad} pixels");
            }
            let want = reference_counts(&brute, camera);
            check_counts(&scene, camera, &twin, &want, &tag);
            let pieces = scene.mesh.cells.len();
            eprintln!(
                "{tag}: all right, {whole} tets drawn whole ({hulls} as hulls) of {pieces} cells"
            );
            assert!(whole > 0, "{tag}: no piece drawn whole");
        }
    }
    assert!(all_hulls > 0, "no part drawn as its outline's hull");
}

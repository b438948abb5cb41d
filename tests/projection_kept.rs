//! Kept regions ([`zoovr::projection::KeptRegions`]) given new scalars give
//! the projection a fresh projection gives, bit for bit: random cells of
//! every kind, orthographic and perspective views, close-ups clipped to the
//! image, eyes inside cells (near-plane clip), the fast and the general
//! path, with and without culling and perspective refinement.

mod projection_util;

use glam::DVec3;
use projection_util::*;
use zoovr::camera::{Camera, CameraParams};
use zoovr::projection::{Polyhedron, Projected, Projector};

/// The projector settings a renderer uses, or the plain ones, on the fast
/// or the general path.
fn projector(renderer: bool, fast: bool, refine: bool) -> Projector {
    let mut p = Projector::new();
    p.clip_to_image = renderer;
    p.cull_to_pixels = renderer;
    p.fast_path = fast;
    p.perspective_refine = refine;
    p
}

/// A camera of one of four kinds: orthographic, perspective, a perspective
/// close-up reaching past the image, or an eye inside the cell.
fn camera(rng: &mut Rng, pts: &[DVec3], kind: u32) -> Camera {
    match kind {
        0 => random_camera(rng, bounds(pts), true),
        1 => random_camera(rng, bounds(pts), false),
        2 => {
            let p = CameraParams {
                width: 97,
                height: 61,
                azimuth: rng.range(-180.0, 180.0),
                elevation: rng.range(-80.0, 80.0),
                zoom: rng.range(3.0, 8.0),
                view_angle: 50.0,
                ..Default::default()
            };
            Camera::fit(bounds(pts), &p)
        }
        _ => {
            let mut cam = random_camera(rng, bounds(pts), false);
            cam.position = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
            cam
        }
    }
}

#[test]
fn kept_regions_with_new_scalars_equal_a_fresh_projection() {
    let mut rng = Rng(0x5eed_cafe_f00d_0001);
    let (mut restored, mut with_regions, mut clipped_near) = (0, 0, 0);
    let (mut fresh, mut kept_out) = (Projected::default(), Projected::default());
    for kind in KINDS {
        for n in 0..48u32 {
            let (pts, cells, s1) = random_cell(kind, &mut rng);
            // The second frame's scalars: new values, with some repeated
            // and some far off (crossings, constants, large ranges).
            let s2: Vec<f64> = s1
                .iter()
                .enumerate()
                .map(|(i, &s)| match (n + i as u32) % 5 {
                    0 => s,
                    1 => -3.0 * s + 0.25,
                    2 => 1.0,
                    3 => s * 1e6,
                    _ => rng.range(-2.0, 2.0),
                })
                .collect();
            let cam = camera(&mut rng, &pts, n % 4);
            let renderer = n % 3 != 2;
            let fast = n % 7 != 3;
            let refine = n % 2 == 0;
            let poly = |s: &[f64]| {
                Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam).unwrap()
            };
            let (p1, p2) = (poly(&s1), poly(&s2));
            let mut first = projector(renderer, fast, refine);
            let kept = first
                .project_with(&p1, &cam, None, true, &mut Projected::default())
                .unwrap();
            let Some(kept) = kept else {
                // Wholly behind the near plane, or no regions: nothing to keep.
                continue;
            };
            assert!(kept.holds(&p2) && kept.bytes() > 0);
            let mut again = projector(renderer, fast, refine);
            again.project(&p2, &cam, &mut fresh).unwrap();
            let mut reuse = projector(renderer, fast, refine);
            let none = reuse
                .project_with(&p2, &cam, Some(&kept), true, &mut kept_out)
                .unwrap();
            assert!(none.is_none(), "a restored projection is not kept again");
            assert_eq!(
                format!("{fresh:?}"),
                format!("{kept_out:?}"),
                "{kind:?} #{n}: camera kind {}, renderer {renderer}, fast {fast}, refine {refine}",
                n % 4
            );
            assert_eq!(
                std::ptr::eq(reuse.projected_piece(&p2), &p2),
                std::ptr::eq(again.projected_piece(&p2), &p2)
            );
            restored += 1;
            with_regions += !fresh.regions.is_empty() as usize;
            clipped_near += !std::ptr::eq(again.projected_piece(&p2), &p2) as usize;
        }
    }
    println!("{restored} restored, {with_regions} with regions, {clipped_near} near-clipped");
    assert!(
        with_regions > 200 && clipped_near > 20,
        "{with_regions} {clipped_near}"
    );
}

#[test]
fn kept_regions_hold_only_their_own_piece() {
    let mut rng = Rng(42);
    let (pts, cells, s) = random_cell(zoovr::mesh::CellKind::Hexahedron, &mut rng);
    let cam = random_camera(&mut rng, bounds(&pts), false);
    let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam).unwrap();
    let kept = projector(true, true, true)
        .project_with(&poly, &cam, None, true, &mut Projected::default())
        .unwrap()
        .expect("kept");
    assert!(kept.holds(&poly));
    let mut moved = poly.clone();
    moved.points[3].x = f64::from_bits(moved.points[3].x.to_bits() + 1);
    assert!(!kept.holds(&moved), "one ulp moved");
    let mut other = poly.clone();
    other.triangles.swap(0, 1);
    assert!(!kept.holds(&other), "triangles reordered");
    // Another camera sees other view-space points.
    let cam2 = random_camera(&mut rng, bounds(&pts), false);
    let seen = Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam2).unwrap();
    assert!(!kept.holds(&seen));
}

//! Tests of the fast path: its vertex kinds and known first steps agree
//! with a plain trace, its topology cache follows the triangle lists, and
//! its regions equal those of the general path (the arrangement) on random
//! pieces of every cell kind.

use glam::{DMat3, DVec3};

use crate::camera::{Camera, CameraParams};
use crate::mesh::{CellKind, Cells};
use crate::projection::{Polyhedron, Projected, Projector};
use crate::testdata::Rng;

const KINDS: [CellKind; 6] = CellKind::FIXED;

/// Case `i` of the tests' mix: ortho every other case, the reference
/// cell axis-aligned every 7th and nearly axis-aligned (slivers of faces
/// seen nearly edge-on) every 7th + 3; and whether the view is exactly
/// axis-aligned and orthographic.
fn case(kind: CellKind, rng: &mut Rng, i: usize) -> (Polyhedron, Camera, bool) {
    let (ortho, axis) = (i % 2 == 0, i % 7 == 0 || i % 7 == 3);
    let tilt = if i % 7 == 3 {
        10f64.powf(-rng.range(3.0, 13.0))
    } else {
        0.0
    };
    let (poly, cam) = piece(kind, rng, ortho, axis, tilt);
    (poly, cam, axis && ortho && tilt == 0.0)
}

/// A random affine image of `kind`'s reference cell (or the reference
/// itself, axis-aligned views then see faces edge-on, or nearly: tilted
/// by `tilt` degrees) and a camera.
fn piece(
    kind: CellKind,
    rng: &mut Rng,
    ortho: bool,
    axis: bool,
    tilt: f64,
) -> (Polyhedron, Camera) {
    let r = kind.reference_corners();
    let m = if axis {
        DMat3::IDENTITY
    } else {
        loop {
            let m = DMat3::from_cols_array(&std::array::from_fn(|_| rng.range(-1.0, 1.0)));
            if m.determinant().abs() > 0.15 {
                break m;
            }
        }
    };
    let pts: Vec<DVec3> = r.iter().map(|&p| m * p).collect();
    let mut cells = Cells::default();
    cells.push(kind, &(0..r.len() as u32).collect::<Vec<_>>());
    let near = rng.f64() < 0.2;
    let e = if near { 0.6 } else { rng.range(1.0, 30.0) };
    let c = DVec3::splat(0.5);
    let cam = Camera::fit(
        [c.x - e, c.x + e, c.y - e, c.y + e, c.z - e, c.z + e],
        &CameraParams {
            width: 64,
            height: 48,
            azimuth: if axis {
                90.0 * (rng.f64() * 4.0).floor() + tilt
            } else {
                rng.range(-180.0, 180.0)
            },
            elevation: if axis {
                tilt * rng.range(-1.0, 1.0)
            } else {
                rng.range(-80.0, 80.0)
            },
            zoom: if near { 4.0 } else { 1.0 },
            ortho,
            ..Default::default()
        },
    );
    let s: Vec<f64> = (0..r.len()).map(|_| rng.f64()).collect();
    let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam).unwrap();
    (poly, cam)
}

fn area(out: &Projected, r: usize) -> f64 {
    let reg = &out.regions[r];
    let o = out.vertices[reg[0] as usize].pos();
    let mut a = 0.0;
    for k in 1..reg.len() {
        let p = out.vertices[reg[k] as usize].pos() - o;
        let q = out.vertices[reg[(k + 1) % reg.len()] as usize].pos() - o;
        a += p.perp_dot(q);
    }
    0.5 * a
}

/// Asserts that two projections are the same, bit for bit.
fn assert_same(a: &Projected, b: &Projected, what: &str) {
    let bits = |o: &Projected| -> Vec<u64> {
        o.vertices
            .iter()
            .flat_map(|v| {
                [v.px, v.py, v.z_front, v.z_back, v.l, v.s_front, v.s_back]
                    .map(f64::to_bits)
                    .into_iter()
                    .chain([v.profile as u64])
            })
            .collect()
    };
    assert_eq!(bits(a), bits(b), "{what}");
    assert_eq!(a.regions, b.regions, "{what}");
    assert_eq!(a.triangles, b.triangles, "{what}");
    assert_eq!(a.triangle_region, b.triangle_region, "{what}");
    assert_eq!(a.region_faces, b.region_faces, "{what}");
}

/// Fast-path vertices get the same bits from their `VertexKind` as from
/// the search among the regions around them (the same front and back
/// triangles, ties included), in every output.
#[test]
fn vertex_kinds_match_search() {
    let mut direct = Projector::new();
    let mut search = Projector::new();
    search.vertex_faces_by_search = true;
    let fast = agree(&mut direct, &mut search, 0x5eed_f00d_fa57_0001, 300, true);
    assert!(fast > 2000, "fast path taken {fast} times");
}

/// The first steps a walk takes over from the walk that queued it are
/// the steps it would trace: the same regions, vertices and triangles,
/// bit for bit, as when every step is traced.
#[test]
fn known_first_steps_match_tracing() {
    let mut fast = Projector::new();
    let mut traced = Projector::new();
    traced.overlay.retrace = true;
    let taken = agree(&mut fast, &mut traced, 0x5ca1_ab1e_0000_0007, 400, false);
    assert!(taken > 1500, "fast path taken {taken} times");
}

/// Projects `n` cases of every kind (seeded by `seed`; each also clipped
/// to the image with `clip`) with both projectors, asserts that they take
/// the same path to the same output, bit for bit, and returns how often
/// `a` took the fast path.
fn agree(a_pr: &mut Projector, b_pr: &mut Projector, seed: u64, n: usize, clip: bool) -> usize {
    let mut rng = Rng(seed);
    let (mut a, mut b) = (Projected::default(), Projected::default());
    let mut fast = 0;
    for kind in KINDS {
        for i in 0..n {
            let (poly, cam, _) = case(kind, &mut rng, i);
            for clip in [false, true].into_iter().take(1 + clip as usize) {
                a_pr.clip_to_image = clip;
                b_pr.clip_to_image = clip;
                a_pr.project(&poly, &cam, &mut a).unwrap();
                b_pr.project(&poly, &cam, &mut b).unwrap();
                fast += a_pr.took_fast_path as usize;
                assert_eq!(a_pr.took_fast_path, b_pr.took_fast_path, "{kind:?} {i}");
                assert_same(&a, &b, &format!("{kind:?} {i}"));
            }
        }
    }
    fast
}

/// The cached topology follows the triangle list: pieces of every kind,
/// with their faces split along varying diagonals (the corners' global
/// ids shuffled) and repeated or alternating, project with one
/// projector exactly as with a fresh one each.
#[test]
fn topology_cache_follows_the_triangles() {
    let mut rng = Rng(0x70b0_1099_cace_0001);
    let mut shared = Projector::new();
    let (mut a, mut b) = (Projected::default(), Projected::default());
    let mut fast = 0;
    let mut last: Option<(Polyhedron, Camera)> = None;
    for i in 0..600 {
        let kind = KINDS[rng.below(KINDS.len())];
        let (poly, cam) = if i % 3 == 2 && last.is_some() {
            // The same triangles again, in another view.
            let (p, _) = last.clone().unwrap();
            let (_, cam) = piece(kind, &mut rng, i % 2 == 0, false, 0.0);
            (p, cam)
        } else {
            let r = kind.reference_corners();
            let mut ids: Vec<u32> = (0..r.len() as u32).collect();
            for k in (1..ids.len()).rev() {
                ids.swap(k, rng.below(k + 1));
            }
            let (_, cam) = piece(kind, &mut rng, i % 2 == 0, false, 0.0);
            let m = loop {
                let m = DMat3::from_cols_array(&std::array::from_fn(|_| rng.range(-1.0, 1.0)));
                if m.determinant().abs() > 0.15 {
                    break m;
                }
            };
            // Corner k of the cell is world point ids[k].
            let mut world = vec![DVec3::ZERO; r.len()];
            for (k, &id) in ids.iter().enumerate() {
                world[id as usize] = m * r[k];
            }
            let mut cells = Cells::default();
            cells.push(kind, &ids);
            let s: Vec<f64> = (0..r.len()).map(|_| rng.f64()).collect();
            let p = Polyhedron::from_cell(&cells, 0, &world, |i| s[i as usize], &cam);
            match p {
                Ok(p) => (p, cam),
                Err(_) => continue,
            }
        };
        let _ = shared.project(&poly, &cam, &mut a);
        let mut fresh = Projector::new();
        let _ = fresh.project(&poly, &cam, &mut b);
        fast += shared.took_fast_path as usize;
        assert_eq!(shared.took_fast_path, fresh.took_fast_path, "{kind:?} {i}");
        assert_same(&a, &b, &format!("{kind:?} {i}"));
        last = Some((poly, cam));
    }
    assert!(fast > 300, "fast path taken {fast} times");
}

/// The fast path gives the general path's regions: the same front and
/// back triangles, areas and vertex values (crossings may round
/// differently), and is taken for pieces in general position.
#[test]
fn fast_path_matches_general_path() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut fast = Projector::new();
    let mut general = Projector::new();
    general.fast_path = false;
    let (mut a, mut b) = (Projected::default(), Projected::default());
    let (mut taken, mut total, mut axis_fast, mut axis_total) = (0, 0, 0, 0);
    for kind in KINDS {
        for i in 0..400 {
            let (poly, cam, axis_ortho) = case(kind, &mut rng, i);
            fast.project(&poly, &cam, &mut a).unwrap();
            general.project(&poly, &cam, &mut b).unwrap();
            total += 1;
            taken += fast.took_fast_path as usize;
            assert!(!general.took_fast_path);
            if axis_ortho {
                axis_fast += fast.took_fast_path as usize;
                axis_total += 1;
            }
            assert_eq!(a.regions.len(), b.regions.len(), "{kind:?} {i}");
            let hull: f64 = (0..b.regions.len()).map(|r| area(&b, r)).sum();
            let tol = 1e-9 * hull.max(1e-300);
            // Crossings of nearly parallel edges (of faces seen nearly
            // edge-on) are ill-conditioned: either path's rounding may
            // put them anywhere along the edges' overlap (and values
            // follow). Positions are compared where every face is wide.
            let well_conditioned = a
                .region_faces
                .iter()
                .all(|f| f.iter().all(|&t| a.faces[t as usize].width() > 0.5));
            for ra in 0..a.regions.len() {
                // (Rounded crossings may leave slivers of zero area.)
                assert!(area(&a, ra) >= -tol, "{kind:?} {i}");
                let rb = (0..b.regions.len())
                    .find(|&rb| b.region_faces[rb] == a.region_faces[ra])
                    .unwrap_or_else(|| panic!("{kind:?} {i}: region {ra} not found"));
                assert!((area(&a, ra) - area(&b, rb)).abs() <= tol, "{kind:?} {i}");
                if area(&a, ra) > 1e-6 * hull {
                    assert_eq!(a.regions[ra].len(), b.regions[rb].len(), "{kind:?} {i}");
                }
                for &va in &a.regions[ra] {
                    let va = a.vertices[va as usize];
                    let vb = b.regions[rb]
                        .iter()
                        .map(|&v| b.vertices[v as usize])
                        .min_by(|x, y| {
                            let dx = (x.pos() - va.pos()).length();
                            let dy = (y.pos() - va.pos()).length();
                            dx.total_cmp(&dy)
                        })
                        .unwrap();
                    let d = (vb.pos() - va.pos()).length();
                    if well_conditioned {
                        assert!(d <= 1e-9 * (1.0 + va.pos().length()), "{kind:?} {i}: {d}");
                    }
                    // Values where the position names one vertex (a
                    // rounded crossing may land on another vertex).
                    let unique = |o: &Projected| {
                        o.vertices.iter().filter(|v| v.pos() == va.pos()).count() == 1
                    };
                    if d == 0.0 && unique(&a) && unique(&b) {
                        assert_eq!(va.profile, vb.profile);
                        let e = (va.l - vb.l)
                            .abs()
                            .max((va.s_front - vb.s_front).abs())
                            .max((va.s_back - vb.s_back).abs());
                        // (Elsewhere slivers' values are rounding noise,
                        // and widest-triangle ties may break otherwise.)
                        if well_conditioned {
                            assert!(e <= 1e-9, "{kind:?} {i}: {e} {va:?} {vb:?}");
                        }
                    }
                }
            }
            // Fans may start at other vertices (and refine differently).
            let (ta, tb) = (a.triangle_area(), b.triangle_area());
            assert!((ta - tb).abs() <= tol, "{kind:?} {i}: {ta} {tb}");
        }
    }
    assert!(taken * 10 > total * 7, "fast path taken {taken} of {total}");
    // Faces seen edge-on in axis-aligned orthographic views (or nearly,
    // by rounding: those may take either path).
    assert!(axis_fast * 2 < axis_total, "{axis_fast} of {axis_total}");
    eprintln!("fast path: {taken} of {total}; axis-aligned {axis_fast} of {axis_total}");
}

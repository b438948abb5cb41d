//! Bookkeeping and input handling of the visibility sorter: subdivisions kept
//! and restored across views, breakpoint splits, typed errors on bad input.

use std::sync::Arc;

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::topology::Topology;
use zoovr::mesh::{CellKind, Mesh};
use zoovr::visibility::synth::{grid, GridSpec};
use zoovr::visibility::{Piece, Sorter, SplitPolicy, VisibilityError, NO_LEVEL};

fn warped() -> Mesh {
    grid(
        &GridSpec {
            dims: [6, 6, 6],
            jitter: 0.22,
            seed: 4,
            planar_boundary: false,
        },
        |_, _, _| true,
    )
}

fn cam(mesh: &Mesh, az: f64, el: f64, ortho: bool) -> Camera {
    let p = CameraParams {
        width: 32,
        height: 32,
        azimuth: az,
        elevation: el,
        ortho,
        ..Default::default()
    };
    Camera::fit(mesh.bounds(), &p)
}

#[test]
fn splits_are_kept_restored_and_history_free() {
    let mesh = Arc::new(warped());
    let topo = Arc::new(Topology::build(&mesh.cells));
    let mut s = Sorter::new(mesh.clone(), topo.clone());
    let pol = SplitPolicy::default();
    let a = cam(&mesh, 30.0, 20.0, false);
    let b = cam(&mesh, 200.0, -50.0, true);
    let o1 = s.order(&a, &pol).unwrap();
    assert!(o1.stats.split_cells > 0);
    assert_eq!(o1.stats.newly_split, o1.stats.split_cells);
    let o2 = s.order(&b, &pol).unwrap();
    s.sanity_check().unwrap();
    assert!(o2.stats.restored > 0, "{:?}", o2.stats);
    assert_eq!(
        o2.stats.split_cells,
        o1.stats.split_cells - o2.stats.restored + o2.stats.newly_split
    );
    // The same view again: the same order, whatever the pool went through.
    let o3 = s.order(&a, &pol).unwrap();
    s.sanity_check().unwrap();
    assert_eq!(o3.pieces, o1.pieces);
    // Same view twice in a row: nothing new to split.
    let o4 = s.order(&a, &pol).unwrap();
    assert_eq!((o4.stats.newly_split, o4.stats.restored), (0, 0));
}

#[test]
fn breakpoint_cells_match_brute_force() {
    let mesh = Arc::new(warped());
    let topo = Arc::new(Topology::build(&mesh.cells));
    let mut s = Sorter::new(mesh.clone(), topo.clone());
    let scalars: Vec<f64> = mesh.points.iter().map(|p| p.x + p.y * p.z).collect();
    let bps = [0.3, 0.75];
    let want = (0..mesh.cells.len())
        .filter(|&c| {
            let v: Vec<f64> = mesh
                .cells
                .nodes(c)
                .iter()
                .map(|&i| scalars[i as usize])
                .collect();
            let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            bps.iter().any(|&b| lo < b && b < hi)
        })
        .count();
    let pol = SplitPolicy {
        all: false,
        breakpoints: &bps,
        point_scalars: Some(&scalars),
        dark: None,
    };
    let o = s.order(&cam(&mesh, 10.0, 10.0, false), &pol).unwrap();
    assert_eq!(o.stats.breakpoint_cells, want);
    assert!(want > 0);
    let tet_cells: std::collections::HashSet<u32> = o
        .pieces
        .iter()
        .filter_map(|p| match p {
            Piece::Tet { cell, .. } | Piece::Slab { cell, .. } => Some(*cell),
            _ => None,
        })
        .collect();
    assert!(tet_cells.len() >= want);
    assert_eq!(tet_cells.len(), o.stats.split_cells);
}

/// Entry and exit parameters of the line `o + t d` through tet `q`.
fn clip_tet(q: [DVec3; 4], o: DVec3, d: DVec3) -> Option<(f64, f64)> {
    let centre = (q[0] + q[1] + q[2] + q[3]) / 4.0;
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for f in [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]] {
        let [a, b, c] = f.map(|i| q[i]);
        let mut n = (b - a).cross(c - a);
        if n.dot(centre - a) > 0.0 {
            n = -n;
        }
        let (num, den) = (n.dot(a - o), n.dot(d));
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else if den < 0.0 {
            t0 = t0.max(num / den);
        } else {
            t1 = t1.min(num / den);
        }
    }
    (t0 < t1).then_some((t0, t1))
}

/// Tets holding a breakpoint are listed as their slabs: consecutive, the
/// bands chained from open end to open end, and back to front along the
/// ray through the tet's centroid (brute force: the scalar at the ray's
/// entry and exit says which bands it meets, front to back).
#[test]
fn slabs_are_listed_back_to_front() {
    let mesh = Arc::new(warped());
    let topo = Arc::new(Topology::build(&mesh.cells));
    let mut s = Sorter::new(mesh.clone(), topo.clone());
    let scalars: Vec<f64> = mesh.points.iter().map(|p| p.x + p.y * p.z).collect();
    let bps = [0.75, 0.3, 0.5];
    let pol = SplitPolicy {
        all: false,
        breakpoints: &bps,
        point_scalars: Some(&scalars),
        dark: None,
    };
    let mut checked = 0;
    for (az, el, ortho) in [
        (10.0, 10.0, false),
        (200.0, -30.0, true),
        (95.0, 60.0, false),
    ] {
        let camera = cam(&mesh, az, el, ortho);
        let o = s.order(&camera, &pol).unwrap();
        assert_eq!(o.levels, vec![0.3, 0.5, 0.75]);
        assert!(
            o.stats.slabs > 0 && o.stats.sliced_tets > 0,
            "{:?}",
            o.stats
        );
        let level = |k: u32, open: f64| {
            if k == NO_LEVEL {
                open
            } else {
                o.levels[k as usize]
            }
        };
        let mut k = 0;
        while k < o.pieces.len() {
            let range = |t: [u32; 4]| {
                let v = t.map(|i| scalars[i as usize]);
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (lo, hi)
            };
            match o.pieces[k] {
                Piece::Tet { tet, .. } => {
                    let (lo, hi) = range(tet);
                    assert!(!bps.iter().any(|&b| lo < b && b < hi), "unsliced {tet:?}");
                    k += 1;
                }
                Piece::Slab { tet, .. } => {
                    let run: Vec<(f64, f64)> = o.pieces[k..]
                        .iter()
                        .take_while(|p| matches!(p, Piece::Slab { tet: t, .. } if *t == tet))
                        .map(|p| match *p {
                            Piece::Slab { lo, hi, .. } => {
                                (level(lo, f64::NEG_INFINITY), level(hi, f64::INFINITY))
                            }
                            _ => unreachable!(),
                        })
                        .collect();
                    // The bands chain from -inf to +inf through the levels
                    // inside the tet's range.
                    let (lo, hi) = range(tet);
                    let mut sorted = run.clone();
                    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
                    let inner: Vec<f64> = o
                        .levels
                        .iter()
                        .copied()
                        .filter(|&b| lo < b && b < hi)
                        .collect();
                    assert_eq!(sorted.len(), inner.len() + 1, "{tet:?}");
                    assert_eq!(sorted[0].0, f64::NEG_INFINITY);
                    assert_eq!(sorted[sorted.len() - 1].1, f64::INFINITY);
                    for w in sorted.windows(2) {
                        assert_eq!(w[0].1, w[1].0);
                    }
                    // Back to front along the centroid ray.
                    let q = tet.map(|i| mesh.points[i as usize]);
                    let sv = tet.map(|i| scalars[i as usize]);
                    let c = (q[0] + q[1] + q[2] + q[3]) / 4.0;
                    let (orig, dir) = if camera.ortho {
                        (c - camera.forward * 100.0, camera.forward)
                    } else {
                        (camera.position, (c - camera.position).normalize())
                    };
                    let (t0, t1) = clip_tet(q, orig, dir).expect("the ray meets the tet");
                    // Scalar at a point of the tet (barycentric).
                    let m = glam::DMat3::from_cols(q[1] - q[0], q[2] - q[0], q[3] - q[0]);
                    let at = |x: DVec3| {
                        let w = m.inverse() * (x - q[0]);
                        sv[0]
                            + w.x * (sv[1] - sv[0])
                            + w.y * (sv[2] - sv[0])
                            + w.z * (sv[3] - sv[0])
                    };
                    let (s_front, s_back) = (at(orig + dir * t0), at(orig + dir * t1));
                    let met: Vec<usize> = run
                        .iter()
                        .enumerate()
                        .filter(|(_, &(a, b))| a < s_front.max(s_back) && b > s_front.min(s_back))
                        .map(|(i, _)| i)
                        .collect();
                    // Drawn first = nearest to s_back.
                    for w in met.windows(2) {
                        let (a, b) = (run[w[0]], run[w[1]]);
                        if s_back > s_front {
                            assert!(a.0 > b.0, "{tet:?}: {run:?} s {s_front}..{s_back}");
                        } else {
                            assert!(a.0 < b.0, "{tet:?}: {run:?} s {s_front}..{s_back}");
                        }
                        checked += 1;
                    }
                    k += run.len();
                }
                Piece::Cell(_) | Piece::Frag { .. } => k += 1,
            }
        }
    }
    assert!(checked > 50, "{checked} slab pairs checked");
}

#[test]
fn bad_input_is_a_typed_error() {
    let mesh = Arc::new(warped());
    let topo = Arc::new(Topology::build(&mesh.cells));
    let c = cam(&mesh, 0.0, 0.0, false);
    // Point id out of range.
    let mut bad = Mesh {
        points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        ..Default::default()
    };
    bad.cells.push(CellKind::Tetra, &[0, 1, 2, 7]);
    let bt = Arc::new(Topology::build(&bad.cells));
    let err = Sorter::new(bad, bt.clone()).order(&c, &SplitPolicy::default());
    assert!(matches!(
        err,
        Err(VisibilityError::PointOutOfRange { point: 7, .. })
    ));
    // Non-finite point.
    let mut nan = (*mesh).clone();
    nan.points[5].y = f64::NAN;
    let err = Sorter::new(nan, topo.clone()).order(&c, &SplitPolicy::default());
    assert_eq!(err.unwrap_err(), VisibilityError::NonFinitePoint(5));
    // Topology of another mesh.
    let err = Sorter::new(mesh.clone(), bt).order(&c, &SplitPolicy::default());
    assert!(matches!(err, Err(VisibilityError::TopologyMismatch { .. })));
    // Too few scalars; empty image.
    let mut s = Sorter::new(mesh.clone(), topo.clone());
    let short = [1.0, 2.0];
    let pol = SplitPolicy {
        all: false,
        breakpoints: &[1.5],
        point_scalars: Some(&short),
        dark: None,
    };
    assert!(matches!(
        s.order(&c, &pol),
        Err(VisibilityError::ScalarCount { got: 2, .. })
    ));
    let mut empty = c;
    empty.width = 0;
    assert!(matches!(
        s.order(&empty, &SplitPolicy::default()),
        Err(VisibilityError::BadCamera(_))
    ));
    // An empty mesh sorts to nothing.
    let none = Mesh::default();
    let nt = Topology::build(&none.cells);
    let o = Sorter::new(none, nt)
        .order(&c, &SplitPolicy::default())
        .unwrap();
    assert!(o.pieces.is_empty());
}

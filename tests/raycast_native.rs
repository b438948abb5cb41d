//! The `native` model on curved cells against an independent brute force:
//! fine sampling of the ray, point-in-cell by Newton inversion of the
//! iso-parametric map (own shape functions, finite-difference Jacobian),
//! cell boundaries found by bisecting the membership indicator, and the
//! Williams-Max integral by a fine midpoint rule.

mod raycast_util;

use glam::{DMat3, DVec3};
use raycast_util::*;
use zoovr::camera::Ray;
use zoovr::integrate::RayMaterial;
use zoovr::mesh::{CellKind, Cells, Mesh};
use zoovr::raycast::native::{breakpoint_crossings, IsoRay, NativeStats};
use zoovr::raycast::{FieldModel, Raycaster, Scalars, Scene};

fn material() -> TestMaterial {
    TestMaterial {
        s: vec![0.1, 0.35, 0.5, 0.8],
        tau: vec![0.3, 2.5, 0.8, 3.0],
        color: vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.5],
            [0.3, 0.3, 1.0],
            [1.0, 1.0, 0.0],
        ],
    }
}

/// Shape functions of the reference elements (written independently of the
/// crate: VTK node order).
fn shape(kind: CellKind, p: DVec3) -> Vec<f64> {
    let (r, s, t) = (p.x, p.y, p.z);
    match kind {
        CellKind::Hexahedron => vec![
            (1. - r) * (1. - s) * (1. - t),
            r * (1. - s) * (1. - t),
            r * s * (1. - t),
            (1. - r) * s * (1. - t),
            (1. - r) * (1. - s) * t,
            r * (1. - s) * t,
            r * s * t,
            (1. - r) * s * t,
        ],
        CellKind::Wedge => vec![
            (1. - r - s) * (1. - t),
            r * (1. - t),
            s * (1. - t),
            (1. - r - s) * t,
            r * t,
            s * t,
        ],
        CellKind::Pyramid => vec![
            (1. - r) * (1. - s) * (1. - t),
            r * (1. - s) * (1. - t),
            r * s * (1. - t),
            (1. - r) * s * (1. - t),
            t,
        ],
        _ => unreachable!(),
    }
}

fn map(kind: CellKind, x: &[DVec3], p: DVec3) -> DVec3 {
    shape(kind, p).iter().zip(x).map(|(n, q)| *q * *n).sum()
}

/// Parametric coordinates of `y` in the cell, by Newton with a
/// central-difference Jacobian from several starts.
fn invert(kind: CellKind, x: &[DVec3], y: DVec3) -> Option<DVec3> {
    for start in [
        DVec3::new(0.3, 0.3, 0.4),
        DVec3::new(0.7, 0.2, 0.2),
        DVec3::new(0.2, 0.6, 0.7),
    ] {
        let mut p = start;
        for _ in 0..60 {
            let f = map(kind, x, p) - y;
            let h = 1e-6;
            let col = |e: DVec3| (map(kind, x, p + e * h) - map(kind, x, p - e * h)) / (2.0 * h);
            let j = DMat3::from_cols(col(DVec3::X), col(DVec3::Y), col(DVec3::Z));
            let step = j.inverse() * f;
            if !step.is_finite() {
                break;
            }
            p -= step;
            if step.length() < 1e-14 {
                return Some(p);
            }
        }
        let f = map(kind, x, p) - y;
        if f.length() < 1e-12 {
            return Some(p);
        }
    }
    None
}

fn inside(kind: CellKind, p: DVec3) -> bool {
    let e = 1e-12;
    let b = |v: f64| (-e..=1.0 + e).contains(&v);
    match kind {
        CellKind::Wedge => p.x >= -e && p.y >= -e && p.x + p.y <= 1.0 + e && b(p.z),
        _ => b(p.x) && b(p.y) && b(p.z),
    }
}

/// The scalar at `y` if `y` is in some cell of `mesh` (first found).
fn field_at(mesh: &Mesh, s: &[f64], y: DVec3) -> Option<f64> {
    for c in 0..mesh.cells.len() {
        let kind = mesh.cells.kinds[c];
        let nodes = mesh.cells.nodes(c);
        let x: Vec<DVec3> = nodes.iter().map(|&n| mesh.points[n as usize]).collect();
        if let Some(p) = invert(kind, &x, y) {
            if inside(kind, p) {
                let v: f64 = shape(kind, p)
                    .iter()
                    .zip(nodes)
                    .map(|(n, &i)| n * s[i as usize])
                    .sum();
                return Some(v);
            }
        }
    }
    None
}

/// Brute-force Williams-Max integral of `ray` over `[t0, t1]`: membership
/// changes found on a grid of `n` samples and bisected, then a midpoint
/// rule with `m` steps on each inside part. Returns (depth, colour, length
/// inside).
fn brute_force(
    mesh: &Mesh,
    s: &[f64],
    m: &TestMaterial,
    ray: &Ray,
    t0: f64,
    t1: f64,
) -> (f64, [f64; 3], f64) {
    let n = 4000;
    let at = |t: f64| ray.origin + ray.dir * t;
    let is_in = |t: f64| field_at(mesh, s, at(t)).is_some();
    let mut cuts = vec![];
    let mut prev = is_in(t0);
    let h = (t1 - t0) / n as f64;
    for k in 1..=n {
        let t = t0 + h * k as f64;
        let cur = is_in(t);
        if cur != prev {
            let (mut a, mut b) = (t - h, t);
            for _ in 0..60 {
                let mid = 0.5 * (a + b);
                if is_in(mid) == prev {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            cuts.push((0.5 * (a + b), cur));
        }
        prev = cur;
    }
    let mut depth = 0.0;
    let mut color = [0.0; 3];
    let mut len = 0.0;
    for w in cuts.windows(2) {
        let ((a, entering), (b, _)) = (w[0], w[1]);
        if !entering {
            continue;
        }
        len += b - a;
        let steps = 40_000;
        let hh = (b - a) / steps as f64;
        for i in 0..steps {
            let t = a + hh * (i as f64 + 0.5);
            // Just inside a boundary the inversion may fail by rounding:
            // nearest valid value.
            let v = field_at(mesh, s, at(t))
                .or_else(|| field_at(mesh, s, at(t + 1e-9)))
                .or_else(|| field_at(mesh, s, at(t - 1e-9)))
                .expect("inside");
            let mat = m.material(v);
            let e = (-(depth + 0.5 * hh * mat.tau)).exp();
            for (c, g) in color.iter_mut().zip(mat.source) {
                *c += hh * g * e;
            }
            depth += hh * mat.tau;
        }
    }
    (depth, color, len)
}

fn mesh_of(cells: &[(CellKind, Vec<u32>)], pts: &[DVec3]) -> Mesh {
    let mut c = Cells::default();
    for (k, n) in cells {
        c.push(*k, n);
    }
    Mesh {
        points: pts.to_vec(),
        cells: c,
        ..Default::default()
    }
}

/// Rays through the bounding box of `mesh` from several directions, some of
/// them grazing.
fn bounds(mesh: &Mesh) -> (DVec3, DVec3) {
    let b = mesh.bounds();
    (DVec3::new(b[0], b[2], b[4]), DVec3::new(b[1], b[3], b[5]))
}

fn rays_for(mesh: &Mesh, count: usize) -> Vec<Ray> {
    let (lo, hi) = bounds(mesh);
    let c = (lo + hi) * 0.5;
    let ext = (hi - lo).length();
    let mut out = Vec::new();
    for k in 0..count {
        let a = k as f64 * 2.399_963; // golden angle
        let z = 1.0 - 2.0 * (k as f64 + 0.5) / count as f64;
        let r = (1.0 - z * z).sqrt();
        let d = DVec3::new(r * a.cos(), r * a.sin(), z);
        let off = DVec3::new(
            (k as f64 * 0.731).sin(),
            (k as f64 * 1.379).cos(),
            (k as f64 * 0.513).sin(),
        ) * 0.35
            * (hi - lo);
        let target = c + off;
        out.push(ray(target - d * ext * 2.0, d));
    }
    out
}

fn scene_of<'a>(
    mesh: &'a Mesh,
    topo: &'a zoovr::mesh::topology::Topology,
    s: &'a [f64],
) -> Scene<'a> {
    Scene {
        mesh,
        topology: topo,
        scalars: Scalars::Point(s),
    }
}

/// Traces every ray natively and by brute force; returns the largest
/// difference from the faces model (to show the test discriminates).
fn check_against_brute_force(name: &str, mesh: &Mesh, s: &[f64], rays: &[Ray]) -> f64 {
    let topology = topo(mesh);
    let scene = scene_of(mesh, &topology, s);
    let m = material();
    let native = Raycaster::new(scene, FieldModel::Native).unwrap();
    let faces = Raycaster::new(scene, FieldModel::Faces).unwrap();
    let (lo, hi) = bounds(mesh);
    let ext = (hi - lo).length();
    let mut gap = 0.0f64;
    let mut boundary_gap = 0.0f64;
    let mut hit = 0;
    for r in rays {
        let t_mid = (lo + hi - r.origin * 2.0).dot(r.dir) * 0.5;
        let (t0, t1) = (t_mid - ext, t_mid + ext);
        let (depth, color, len) = brute_force(mesh, s, &m, r, t0, t1);
        let acc = trace_one(&native, &m, r, FieldModel::Native);
        let segs = native.native_segments(r, 0.0);
        let nl: f64 = segs.iter().map(|s| s.t_out - s.t_in).sum();
        assert!(
            (nl - len).abs() < 1e-8 * (1.0 + len),
            "{name}: native length {nl} vs brute force {len} for {r:?}"
        );
        assert!(
            (acc.depth - depth).abs() < 1e-6 * (1.0 + depth),
            "{name}: depth {} vs {depth} for {r:?}",
            acc.depth
        );
        for k in 0..3 {
            assert!(
                (acc.color[k] - color[k]).abs() < 1e-6,
                "{name}: colour {:?} vs {color:?}",
                acc.color
            );
        }
        let f = trace_one(&faces, &m, r, FieldModel::Faces);
        gap = gap.max((f.depth - depth).abs());
        hit += (len > 0.0) as usize;
        let wl: f64 = faces
            .segments(r, 0.0)
            .iter()
            .map(|s| s.t_out - s.t_in)
            .sum();
        boundary_gap = boundary_gap.max((wl - len).abs());
    }
    assert!(hit * 2 > rays.len(), "{name}: only {hit} rays hit");
    // The bilinear boundary matters on these rays: the triangulated one
    // gives other chord lengths.
    assert!(boundary_gap > 1e-3, "{name}: boundary gap {boundary_gap}");
    let st = native.native_stats();
    assert_eq!(st.newton_failures, 0, "{name}: {st:?}");
    assert_eq!(st.fallback_intervals, 0, "{name}: {st:?}");
    assert_eq!(st.parity_classified, 0, "{name}: {st:?}");
    assert!(st.intervals > 0);
    gap
}

/// Node values of a non-linear field with an `xyz` term.
fn xyz_field(pts: &[DVec3]) -> Vec<f64> {
    pts.iter()
        .map(|p| {
            0.45 + 0.3 * p.x - 0.2 * p.y + 0.25 * p.z + 1.1 * p.x * p.y * p.z - 0.4 * p.x * p.z
        })
        .collect()
}

fn warped_hex_points() -> Vec<DVec3> {
    [
        [0.0, 0.0, 0.0],
        [1.1, -0.1, 0.15],
        [1.0, 1.0, -0.2],
        [-0.1, 0.9, 0.1],
        [0.1, 0.05, 1.0],
        [1.0, 0.2, 0.8],
        [1.2, 1.1, 1.3],
        [0.0, 1.0, 0.9],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p))
    .collect()
}

#[test]
fn warped_hexahedron_matches_brute_force() {
    let pts = warped_hex_points();
    let mesh = mesh_of(&[(CellKind::Hexahedron, (0..8).collect())], &pts);
    let s = xyz_field(&pts);
    let gap = check_against_brute_force("hex", &mesh, &s, &rays_for(&mesh, 40));
    assert!(gap > 1e-4, "faces vs native gap {gap}");
}

#[test]
fn twisted_wedge_matches_brute_force() {
    let pts: Vec<DVec3> = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.1],
        [0.0, 1.0, -0.1],
        [0.2, -0.1, 1.0],
        [1.1, 0.3, 0.9],
        [-0.2, 1.0, 1.2],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p))
    .collect();
    let mesh = mesh_of(&[(CellKind::Wedge, (0..6).collect())], &pts);
    let s = xyz_field(&pts);
    let gap = check_against_brute_force("wedge", &mesh, &s, &rays_for(&mesh, 40));
    assert!(gap > 1e-5, "faces vs native gap {gap}");
}

#[test]
fn pyramid_with_nonplanar_base_matches_brute_force() {
    let pts: Vec<DVec3> = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.25],
        [1.0, 1.0, -0.1],
        [0.0, 1.0, 0.2],
        [0.4, 0.6, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p))
    .collect();
    let mesh = mesh_of(&[(CellKind::Pyramid, (0..5).collect())], &pts);
    let s = xyz_field(&pts);
    let gap = check_against_brute_force("pyramid", &mesh, &s, &rays_for(&mesh, 40));
    assert!(gap > 1e-5, "faces vs native gap {gap}");
}

#[test]
fn two_cells_sharing_a_bulging_face_equal_their_single_cell_union() {
    // Split the warped hex at r = 1/2: both halves are the trilinear map
    // restricted (the map is linear in r), so the block's field and volume
    // equal the single cell's; their shared face is the bulging bilinear
    // patch r = 1/2.
    let big = warped_hex_points();
    let mid = |a: usize, b: usize| (big[a] + big[b]) * 0.5;
    // New points 8..11: midpoints of the r-edges 0-1, 3-2, 4-5, 7-6.
    let mut pts = big.clone();
    pts.extend([mid(0, 1), mid(3, 2), mid(4, 5), mid(7, 6)]);
    let block = mesh_of(
        &[
            (CellKind::Hexahedron, vec![0, 8, 9, 3, 4, 10, 11, 7]),
            (CellKind::Hexahedron, vec![8, 1, 2, 9, 10, 5, 6, 11]),
        ],
        &pts,
    );
    let single = mesh_of(&[(CellKind::Hexahedron, (0..8).collect())], &big);
    let s_big = xyz_field(&big);
    // Field at the new points from the single cell's trilinear field.
    let mut s = s_big.clone();
    for (a, b) in [(0, 1), (3, 2), (4, 5), (7, 6)] {
        s.push(0.5 * (s_big[a] + s_big[b]));
    }
    // The shared face really bulges: its points are not coplanar.
    let q = [8, 9, 11, 10].map(|i| pts[i]);
    let n = (q[1] - q[0]).cross(q[3] - q[0]);
    assert!((q[2] - q[0]).dot(n).abs() > 1e-2);
    let tb = topo(&block);
    let ts = topo(&single);
    let m = material();
    let nb = Raycaster::new(scene_of(&block, &tb, &s), FieldModel::Native).unwrap();
    let ns = Raycaster::new(scene_of(&single, &ts, &s_big), FieldModel::Native).unwrap();
    let fb = Raycaster::new(scene_of(&block, &tb, &s), FieldModel::Faces).unwrap();
    // Rays grazing the shared patch: nearly tangent to it, through points
    // between the patch and its two triangles, and a general fan.
    let centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
    let pu = (q[1] - q[0] + q[2] - q[3]) * 0.5;
    let pv = (q[3] - q[0] + q[2] - q[1]) * 0.5;
    let normal = pu.cross(pv).normalize();
    let mut rays = rays_for(&block, 30);
    for k in 0..40 {
        let a = k as f64 * 0.37;
        let (x, y) = (0.4 * (k as f64 * 0.71).sin(), 0.4 * (k as f64 * 1.13).cos());
        let p = centre + pu * x + pv * y + normal * (0.01 * (k as f64 * 0.9).sin());
        let d = (pu.normalize() * a.cos()
            + pv.normalize() * a.sin()
            + normal * 0.05 * (k as f64 - 20.0) / 20.0)
            .normalize();
        rays.push(ray(p - d * 5.0, d));
    }
    let mut differ = 0;
    for r in &rays {
        let a = trace_one(&nb, &m, r, FieldModel::Native);
        let b = trace_one(&ns, &m, r, FieldModel::Native);
        assert!(
            (a.depth - b.depth).abs() < 1e-8 * (1.0 + b.depth),
            "block {} vs single {} for {r:?}",
            a.depth,
            b.depth
        );
        for k in 0..3 {
            assert!((a.color[k] - b.color[k]).abs() < 1e-8);
        }
        // Segments: no gap and no overlap at the shared face.
        let segs = nb.native_segments(r, 0.0);
        for w in segs.windows(2) {
            assert!(w[1].t_in >= w[0].t_out, "overlap {segs:?}");
            if w[0].cell != w[1].cell {
                assert_eq!(
                    w[0].t_out, w[1].t_in,
                    "gap/overlap at the shared face {segs:?}"
                );
                assert!((w[0].s_out - w[1].s_in).abs() < 1e-12);
            }
        }
        let lb: f64 = segs.iter().map(|s| s.t_out - s.t_in).sum();
        let ls: f64 = ns
            .native_segments(r, 0.0)
            .iter()
            .map(|s| s.t_out - s.t_in)
            .sum();
        assert!((lb - ls).abs() < 1e-12 * (1.0 + ls), "{lb} vs {ls}");
        let f = trace_one(&fb, &m, r, FieldModel::Faces);
        differ += ((f.depth - b.depth).abs() > 1e-6) as usize;
    }
    assert!(
        differ > 10,
        "the faces model should differ on these rays ({differ})"
    );
    // A few rays also against the brute force over the block.
    for r in rays.iter().skip(30).step_by(8) {
        let t_mid = (centre - r.origin).dot(r.dir);
        let (depth, _, _) = brute_force(&block, &s, &m, r, t_mid - 6.0, t_mid + 6.0);
        let a = trace_one(&nb, &m, r, FieldModel::Native);
        assert!(
            (a.depth - depth).abs() < 1e-6 * (1.0 + depth),
            "{} vs {depth}",
            a.depth
        );
    }
    let st = nb.native_stats();
    assert_eq!(
        st.newton_failures + st.fallback_intervals + st.parity_classified,
        0,
        "{st:?}"
    );
}

#[test]
fn close_breakpoint_crossings_are_all_bracketed() {
    // Unit cube, s = c + k (x - a)(y - b)(z - e): trilinear, and along the
    // near-diagonal ray a cubic with three close roots, so a breakpoint at c
    // is crossed three times within a few hundredths of the chord (the old
    // 9-sample scheme saw one).
    let pts: Vec<DVec3> = [
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p))
    .collect();
    let f = |p: DVec3| 0.5 + 40.0 * (p.x - 0.51) * (p.y - 0.53) * (p.z - 0.55);
    let s: Vec<f64> = pts.iter().map(|&p| f(p)).collect();
    let r = ray(DVec3::new(0.001, 0.0, 0.0), DVec3::new(1.0, 1.0, 1.0));
    let mut field = IsoRay::new(CellKind::Hexahedron, &pts, &s, &r).unwrap();
    let t_out = (1.0 - 0.001) * 3f64.sqrt();
    let mut st = NativeStats::default();
    let cuts = breakpoint_crossings(&mut field, &[0.5], 0.0, t_out, &mut st).unwrap();
    // Brute force: sign changes of s - 0.5 on a fine grid.
    let n = 100_000;
    let mut want = 0;
    let g = |t: f64| f(r.origin + r.dir * t) - 0.5;
    for i in 0..n {
        let (a, b) = (
            t_out * i as f64 / n as f64,
            t_out * (i + 1) as f64 / n as f64,
        );
        want += ((g(a) > 0.0) != (g(b) > 0.0) && g(b) != 0.0) as usize;
    }
    assert_eq!(want, 3);
    assert_eq!(cuts.len(), 3, "{cuts:?}");
    for &t in &cuts {
        assert!(g(t).abs() < 1e-12, "{t}: {}", g(t));
    }
    assert_eq!(st.bracket_depth_limited, 0);
    // And the integral agrees with the brute force through that knot.
    let mesh = mesh_of(&[(CellKind::Hexahedron, (0..8).collect())], &pts);
    let topology = topo(&mesh);
    let scene = scene_of(&mesh, &topology, &s);
    let m = TestMaterial {
        s: vec![0.0, 0.5, 1.0],
        tau: vec![0.1, 30.0, 0.1],
        color: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };
    let rc = Raycaster::new(scene, FieldModel::Native).unwrap();
    let acc = trace_one(&rc, &m, &r, FieldModel::Native);
    let (depth, color, _) = brute_force(&mesh, &s, &m, &r, -0.5, 2.5);
    assert!(
        (acc.depth - depth).abs() < 1e-6 * (1.0 + depth),
        "{} vs {depth}",
        acc.depth
    );
    for (a, b) in acc.color.iter().zip(color) {
        assert!((a - b).abs() < 1e-6);
    }
}

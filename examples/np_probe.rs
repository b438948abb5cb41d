//! Temporary probe: counts nonplanar quad faces under candidate definitions.
use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;
use zoovr::mesh::Mesh;

const FILES: &[(&str, usize)] = &[
    ("bluntfin/bluntfin_converted.vts", 2),
    ("can_crush/can.vtu", 24569),
    ("disk_out_ref/disk_out_ref_converted.vtu", 2316),
    ("angular_sector/AngularSector.vtk", 0),
    ("office_kitchen/office.binary.vtk", 0),
    ("fire_room/fire_ug.vtu", 0),
    ("notch/notch_stress.vtk", 0),
    ("su2_sphere_hybrid/sphere_hybrid_converted.vtu", 0),
    ("blood_vessels_pvtu/blood_vessels/T0000000500.pvtu", 0),
    ("tets_small/CylinderLinear.vtk", 0),
    ("prisms_zoo/PentaHexa.vtk", 0),
];

fn dist(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let n = (b - a).cross(c - a);
    let l = n.length();
    if l == 0.0 || !l.is_finite() {
        return 0.0;
    }
    (n.dot(d - a) / l).abs()
}

fn bbox_diag(p: &[DVec3]) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &q in p {
        lo = lo.min(q);
        hi = hi.max(q);
    }
    (hi - lo).length()
}

/// Numerators for a quad.
fn numerators(q: [DVec3; 4]) -> Vec<(&'static str, f64)> {
    let [a, b, c, d] = q;
    let h4 = dist(a, b, c, d);
    let hs = [dist(b, c, d, a), dist(c, d, a, b), dist(d, a, b, c), h4];
    let hmax = hs.iter().cloned().fold(0.0, f64::max);
    let hmin = hs.iter().cloned().fold(f64::INFINITY, f64::min);
    // Newell normal, plane through centroid
    let mut n = DVec3::ZERO;
    for i in 0..4 {
        let p = q[i];
        let r = q[(i + 1) % 4];
        n.x += (p.y - r.y) * (p.z + r.z);
        n.y += (p.z - r.z) * (p.x + r.x);
        n.z += (p.x - r.x) * (p.y + r.y);
    }
    let cen = (a + b + c + d) / 4.0;
    let newell = if n.length() > 0.0 {
        let nn = n.normalize();
        q.iter()
            .map(|p| (p - cen).dot(nn).abs())
            .fold(0.0, f64::max)
    } else {
        0.0
    };
    // Newell normal, plane through first point (vtkPolygon style: p0)
    let newell0 = if n.length() > 0.0 {
        let nn = n.normalize();
        q.iter().map(|p| (p - a).dot(nn).abs()).fold(0.0, f64::max)
    } else {
        0.0
    };
    // distance between diagonals (skew lines)
    let u = c - a;
    let v = d - b;
    let w = u.cross(v);
    let diagdist = if w.length() > 0.0 {
        ((b - a).dot(w) / w.length()).abs()
    } else {
        0.0
    };
    vec![
        ("h4", h4),
        ("hmax", hmax),
        ("hmin", hmin),
        ("newellC", newell),
        ("newell0", newell0),
        ("diagdist", diagdist),
    ]
}

fn denominators(q: [DVec3; 4], cell: f64, mesh: f64) -> Vec<(&'static str, f64)> {
    let [a, b, c, d] = q;
    let d1 = (c - a).length();
    let d2 = (d - b).length();
    vec![
        ("dmax", d1.max(d2)),
        ("dmin", d1.min(d2)),
        ("d02", d1),
        ("d13", d2),
        ("fbox", bbox_diag(&q)),
        ("cbox", cell),
        ("mesh", mesh),
    ]
}

fn faces(mesh: &Mesh, c: usize) -> Vec<[u32; 4]> {
    let mut out = vec![];
    mesh.cells.for_each_face(c, |_, f| {
        if let [a, b, cc, d] = *f {
            out.push([a, b, cc, d]);
        }
    });
    out
}

fn main() {
    let root = Path::new("/work/shared/data");
    let thr = 1e-3;
    let mut results: Vec<(String, Vec<usize>)> = vec![];
    let mut idx: HashMap<String, usize> = HashMap::new();
    for (fi, (f, _)) in FILES.iter().enumerate() {
        let mesh = zoovr::io::read(&root.join(f), &Default::default()).unwrap();
        let pts = &mesh.points;
        let mdiag = bbox_diag(pts);
        let mut seen: HashMap<[u32; 4], ()> = HashMap::new();
        let mut bump = |key: String, v: usize| {
            let i = *idx.entry(key.clone()).or_insert_with(|| {
                results.push((key, vec![0; FILES.len()]));
                results.len() - 1
            });
            results[i].1[fi] += v;
        };
        for c in 0..mesh.cells.len() {
            let cd = bbox_diag(
                &mesh
                    .cells
                    .nodes(c)
                    .iter()
                    .map(|&i| pts[i as usize])
                    .collect::<Vec<_>>(),
            );
            for qi in faces(&mesh, c) {
                let q = qi.map(|i| pts[i as usize]);
                let mut key = qi;
                key.sort_unstable();
                let first = seen.insert(key, ()).is_none();
                let nums = numerators(q);
                let dens = denominators(q, cd, mdiag);
                for (nn, nv) in &nums {
                    for (dn, dv) in &dens {
                        let r = if *dv > 0.0 { nv / dv } else { 0.0 };
                        let hit = (r > thr) as usize;
                        bump(format!("cell {nn}/{dn}"), hit);
                        if first {
                            bump(format!("uniq {nn}/{dn}"), hit);
                        }
                    }
                }
            }
        }
        eprintln!("done {f}");
    }
    let want: Vec<usize> = FILES.iter().map(|x| x.1).collect();
    println!("{:28} {:?}", "WANT", want);
    for (k, v) in &results {
        let ok = v == &want;
        let err: i64 = v
            .iter()
            .zip(&want)
            .map(|(a, b)| (*a as i64 - *b as i64).abs())
            .sum();
        println!("{}{:27} {:?} err={}", if ok { "*" } else { " " }, k, v, err);
    }
}

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::projection::*;
fn main() {
    let cam = Camera::fit([-2.0, 2.0, -2.0, 2.0, -2.0, 2.0], &CameraParams { width: 100, height: 100, ortho: true, ..Default::default() });
    let c = [(0., 0., 0.),(1., 0., 0.),(1., 1., 0.),(0., 1., 0.),(0., 0., 1.),(1., 0., 1.),(1., 1., 1.),(0., 1., 1.)];
    let mut cells = zoovr::mesh::Cells::default();
    cells.push(zoovr::mesh::CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]);
    let mut p = Polyhedron::default();
    p.points = c.iter().map(|&(x,y,z)| DVec3::new(x-0.5,y-0.5,z+2.0)).collect();
    p.scalars = (0..8).map(|i| i as f64 * 0.25).collect();
    cells.for_each_face(0, |_, f| { zoovr::mesh::tetra::triangulate_face(f, |t| p.triangles.push(t)); });
    p.orient_outward();
    println!("tris {:?}", p.triangles);
    let mut pr = Projector::new();
    pr.check_each_insertion = true;
    let mut out = Projected::default();
    pr.project(&p, &cam, &mut out).unwrap();
    let a = pr.arrangement();
    println!("pieces {:?}", a.pieces); dump(a);
    println!("regions {:?}", out.regions);
    for v in &out.vertices { println!("{v:?}"); }
    println!("area {} tri {}", out.region_area(), out.triangle_area());
}
#[allow(dead_code)]
fn dump(a: &Arrangement) {
    let s = &a.sub;
    for v in 0..s.vertex_count() as u32 {
        let h0 = s.vertex_edge(v);
        if h0 == u32::MAX { continue; }
        let mut h = h0;
        let mut line = format!("v{v} {:?}:", a.pos[v as usize]);
        loop {
            let d = a.pos[s.dest(h) as usize] - a.pos[v as usize];
            line += &format!(" ->{}({:.0}deg)", s.dest(h), d.y.atan2(d.x).to_degrees());
            h = s.cw_next(h);
            if h == h0 { break; }
        }
        println!("{line}");
    }
}

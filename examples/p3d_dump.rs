fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let q = a.get(1).map(std::path::Path::new);
    let t = std::time::Instant::now();
    match zoovr::io::plot3d::read(std::path::Path::new(&a[0]), q) {
        Ok(m) => {
            println!("{:?} pts={} cells={} by_type={:?} ignored={} notes={:?}", t.elapsed(), m.points.len(), m.cells.len(), m.source.cells_by_type, m.source.ignored_cells, m.source.notes);
            for d in &m.point_data { println!("   {:?} comps={} {} {:?}", d.name, d.components, d.vtk_type, d.range(Some(0))); }
        }
        Err(e) => println!("ERROR {e}"),
    }
}

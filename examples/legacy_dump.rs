fn main() {
    for a in std::env::args().skip(1) {
        let t = std::time::Instant::now();
        match zoovr::io::legacy::read(std::path::Path::new(&a)) {
            Ok(m) => {
                println!("{a}: {:?} pts={} cells={} by_type={:?} ignored={} active={:?}/{:?} notes={:?}", t.elapsed(), m.points.len(), m.cells.len(), m.source.cells_by_type, m.source.ignored_cells, m.active_point_scalars, m.active_cell_scalars, m.source.notes);
                for (assoc, list) in [("point", &m.point_data), ("cell", &m.cell_data)] {
                    for d in list {
                        println!("   {assoc} {:?} comps={} tuples={} {} range0={:?}", d.name, d.components, d.tuples(), d.vtk_type, d.range(Some(0)));
                    }
                }
            }
            Err(e) => println!("{a}: ERROR {e}"),
        }
    }
}
#[allow(dead_code)]
fn p3d() {}

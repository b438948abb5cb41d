//! Renders every dataset in `../shared/data` at 128 x 128 with the `faces`
//! model: no error, no non-finite pixel, something visible.
//!
//! Skips cleanly when the shared data is absent; a file that is present
//! must read and render.

mod raycast_util;

use raycast_util::TestMaterial;
use zoovr::camera::{Camera, CameraParams};
use zoovr::field::{select_field, Association};
use zoovr::io;
use zoovr::mesh::topology::Topology;
use zoovr::raycast::{render, RaycastOptions, Scalars, Scene};

#[test]
fn render_every_shared_dataset_at_128() {
    let mut rendered = 0;
    let mut found = 0;
    for rel in zoovr::testdata::SHARED_DATASETS {
        let Some(path) = zoovr::testdata::shared_file(rel) else {
            continue;
        };
        let opts = zoovr::testdata::read_options(rel);
        found += 1;
        let mesh = io::read(&path, &opts).unwrap_or_else(|e| panic!("{rel}: {e}"));
        mesh.sanity_check().unwrap_or_else(|e| panic!("{rel}: {e}"));
        let field = select_field(&mesh, None).unwrap_or(None);
        let (lo, hi) = field.as_ref().map_or((0.0, 1.0), |f| f.range);
        let scalars = match &field {
            Some(f) if f.association == Association::Point => Scalars::Point(&f.values),
            Some(f) => Scalars::Cell(&f.values),
            None => Scalars::Constant(1.0),
        };
        // The default-TF shape: opacity ramp 0..1 over the range, unit
        // distance = diagonal / 10.
        let unit = (mesh.diagonal() / 10.0).max(1e-300);
        // A constant field (e.g. plastic strain at t = 0) gets a range around
        // its value, as the default transfer function does.
        let (lo, hi) = if hi > lo {
            (lo, hi)
        } else {
            (lo - 1.0, lo + 1.0)
        };
        let m = TestMaterial {
            s: vec![lo, hi],
            tau: vec![0.0, 1.0 / unit],
            color: vec![[0.27, 0.0, 0.33], [0.99, 0.91, 0.14]],
        };
        let topology = Topology::build(&mesh.cells);
        let scene = Scene {
            mesh: &mesh,
            topology: &topology,
            scalars,
        };
        let p = CameraParams {
            width: 128,
            height: 128,
            azimuth: 20.0,
            elevation: 35.0,
            ..Default::default()
        };
        let cam = Camera::fit(mesh.bounds(), &p);
        let img = render(&scene, &m, &cam, &RaycastOptions::default())
            .unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(img.count_non_finite(), 0, "{rel}");
        let visible = img.pixels.iter().filter(|p| p[3] > 1e-3).count();
        assert!(
            visible > 0 || mesh.cells.is_empty(),
            "{rel}: nothing visible"
        );
        rendered += 1;
    }
    eprintln!(
        "rendered {rendered} of {} datasets",
        zoovr::testdata::SHARED_DATASETS.len()
    );
    assert_eq!(rendered, found, "every dataset present must render");
}

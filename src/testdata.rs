//! Locating test data: the shared real datasets (`../shared/data` next to the
//! project root, or `$ZOOVR_DATA`) and the project's own `meshes/`. Used by
//! tests and benchmarks, which skip cleanly when the shared data is absent.
//! Also [`Rng`], the one seeded generator of the tests and benchmarks.

use std::path::PathBuf;

/// The project root (where `Cargo.toml` is).
pub fn project_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The shared data folder, if present.
pub fn shared_data_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("ZOOVR_DATA") {
        let d = PathBuf::from(d);
        return d.is_dir().then_some(d);
    }
    let d = project_root().join("../shared/data");
    d.is_dir().then_some(d)
}

/// A file under the shared data folder, if the folder and file exist;
/// prints a skip notice otherwise.
pub fn shared_file(rel: &str) -> Option<PathBuf> {
    let p = shared_data_dir()?.join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipping: shared data file {rel} not found");
        None
    }
}

/// A file under the project's `meshes/` folder.
pub fn mesh_file(rel: &str) -> PathBuf {
    project_root().join("meshes").join(rel)
}

/// Every dataset file of the shared data folder that a test renders (one
/// dataset each; `.pvtu` pieces and series steps through their collection).
pub const SHARED_DATASETS: &[&str] = &[
    "angular_sector/AngularSector.vtk",
    "blood_vessels_pvtu/blood_vessels/T0000000500.pvtu",
    "bluntfin/bluntfin_converted.vts",
    "bluntfin/bluntfin_converted_legacy42_binary.vtk",
    "bluntfin/bluntfinxyz.bin",
    "can_crush/can.vtu",
    "can_crush/series/can_series.pvd",
    "disk_out_ref/disk_out_ref_converted.vtu",
    "disk_out_ref/disk_out_ref_converted_legacy51_binary.vtk",
    "fea_bracket_qtet/kiefer_bracket.vtu",
    "fire_room/fire_ug.vtu",
    "notch/notch_disp.vtu",
    "notch/notch_stress.vtk",
    "office_kitchen/kitchen.vtk",
    "office_kitchen/office.binary.vtk",
    "prisms_zoo/PentaHexa.vtk",
    "prisms_zoo/hexa.vtk",
    "prisms_zoo/uGridEx.vtk",
    "su2_sphere_hybrid/sphere_hybrid_converted.vtu",
    "su2_sphere_hybrid/sphere_hybrid_converted_legacy42_ascii.vtk",
    "synthetic/hex_shell_zlib.vtu",
    "synthetic/mixed.vtk",
    "tets_small/CylinderLinear.vtk",
    "tets_small/tetraMesh.vtk",
];

/// The read options for a [`SHARED_DATASETS`] entry: the PLOT3D grid of
/// bluntfin gets its solution file.
pub fn read_options(rel: &str) -> crate::io::ReadOptions {
    let mut o = crate::io::ReadOptions::default();
    if rel.ends_with("xyz.bin") {
        o.q_file = shared_file("bluntfin/bluntfinq.bin");
    }
    o
}

/// The hex_shell benchmark scene (`synthetic/hex_shell_zlib.vtu`: 250,047
/// curvilinear hexahedra in a twisted, C-shaped annular sector, with
/// `synthetic/bench_tf.json`), shared by the benchmarks; `None` without the
/// shared data.
pub fn hex_shell_scene() -> Option<crate::render::Scene> {
    let mesh = shared_file("synthetic/hex_shell_zlib.vtu")?;
    let tf = shared_file("synthetic/bench_tf.json")?;
    let mesh = crate::io::read(&mesh, &crate::io::ReadOptions::default()).ok()?;
    let spec = crate::render::SceneSpec {
        tf_file: Some(tf),
        ..Default::default()
    };
    crate::render::Scene::build(mesh, &spec).ok()
}

/// The benchmarks' stand-in without the shared data: a generated 40^3
/// warped hexahedral grid (amplitude 0.05, seed 1) with the default scene
/// settings, named `grid_40`.
pub fn grid_40_scene() -> (&'static str, crate::render::Scene) {
    let mesh = crate::generate::warped_hex_grid(
        40,
        &crate::generate::Warp {
            amplitude: 0.05,
            seed: 1,
        },
    );
    let scene = crate::render::Scene::build(mesh, &crate::render::SceneSpec::default())
        .expect("a generated grid builds");
    ("grid_40", scene)
}

/// xorshift64* (Vigna): the seeded generator of the tests and benchmarks
/// (fixed seeds, reproducible runs, no dependency). The seed must not be 0.
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `[0, 1)`.
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.f64()
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
}

//! Locating test data: the shared real datasets (`../shared/data` next to the
//! project root, or `$ZOOVR_DATA`) and the project's own `meshes/`. Used by
//! tests and benchmarks, which skip cleanly when the shared data is absent.

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

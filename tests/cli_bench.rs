//! `zoovr bench` through the real binary: the rows and columns of its CSV
//! and JSON, errors that agree with the images it wrote, the plot, the cap
//! on its estimate, usage errors, and `--with-vtk` with a Python that cannot
//! run VTK (and, where `ZOOVR_VTK_PYTHON` names one that can, with VTK).

mod cli_util;
mod render_util;

use std::path::Path;

use cli_util::{stderr, zoovr};
use zoovr::image::{compare_display, Image};
use zoovr::testdata::mesh_file;

fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let head: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|rec| rec.unwrap().iter().map(String::from).collect())
        .collect();
    (head, rows)
}

fn col<'a>(head: &[String], row: &'a [String], name: &str) -> &'a str {
    let i = head
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    &row[i]
}

fn image(dir: &Path, name: &str) -> Image {
    Image::read(&dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn rows_columns_errors_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (csv, json, plot, images) = (
        d.join("b.csv"),
        d.join("b.json"),
        d.join("b.png"),
        d.join("img"),
    );
    let file = mesh_file("curvilinear_4x4x4.vtu");
    let o = zoovr(&[
        "bench",
        file.to_str().unwrap(),
        "--modes",
        "exact-frag,preint3d,raycast",
        "--sizes",
        "32,40x24",
        "--views",
        "2",
        "--warmup",
        "0",
        "--repeats",
        "1",
        "--csv",
        csv.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
        "--images",
        images.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.contains("total s") && table.contains("native max"),
        "{table}"
    );

    // One row per (mode, setting, size, view): (2 + 3 + 3) x 2 x 2
    // (exact-frag regions and quads, three table sizes, three models).
    let (head, rows) = csv_rows(&csv);
    for c in [
        "mode",
        "size",
        "view",
        "setting",
        "load_s",
        "setup_s",
        "sort_s",
        "project_s",
        "tables_s",
        "gpu_s",
        "readback_s",
        "total_s",
        "max_err",
        "rms_err",
        "psnr",
        "native_max_err",
        "peak_rss_mb",
        "triangles",
        "pieces",
    ] {
        assert!(head.iter().any(|h| h == c), "column {c} missing: {head:?}");
    }
    assert_eq!(rows.len(), 32, "{rows:?}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["rows"].as_array().unwrap().len(), 32);
    assert_eq!(v["repeats"], 1);

    let gpu = render_util::gpu_available();
    for row in &rows {
        let get = |n: &str| col(&head, row, n);
        let (mode, setting, size, view) = (get("mode"), get("setting"), get("size"), get("view"));
        let failed = !get("error").is_empty();
        if mode != "raycast" && !gpu {
            assert!(failed, "{row:?}");
            continue;
        }
        assert!(!failed, "{row:?}");
        let total: f64 = get("total_s").parse().unwrap();
        assert!(total > 0.0, "{row:?}");
        // The errors are those of the row's image against the reference
        // images, recomputed here from the PNGs the bench wrote (8-bit, so
        // within 1/255 of the float figures).
        let setting_file = setting.replace(['=', '.'], "_");
        let own = image(
            &images,
            &format!("zoovr_{mode}_{setting_file}_{size}_v{view}.png"),
        );
        let faces = image(
            &images,
            &format!("zoovr_raycast_model_faces_{size}_v{view}.png"),
        );
        let native = image(
            &images,
            &format!("zoovr_raycast_model_native_{size}_v{view}.png"),
        );
        let max_err: f64 = get("max_err").parse().unwrap();
        let native_err: f64 = get("native_max_err").parse().unwrap();
        if setting == "model=faces" {
            assert_eq!(max_err, 0.0, "the reference against itself");
        }
        if mode != "raycast" {
            let d = compare_display(&own, &faces, [0.0; 3]).unwrap().0;
            assert!(
                (d.max_abs - max_err).abs() <= 1.0 / 255.0 + 1e-6,
                "{row:?}: {d:?}"
            );
        }
        let d = compare_display(&own, &native, [0.0; 3]).unwrap().0;
        assert!(
            (d.max_abs - native_err).abs() <= 1.0 / 255.0 + 1e-6,
            "{row:?}: {d:?}"
        );
        if setting == "model=faces" {
            // The faces field is not the native (trilinear) field of a
            // curved grid: a model error the bench must show.
            assert!(native_err > 0.01, "{row:?}");
        }
    }
    let p = image::open(&plot).unwrap();
    // One row of panels per size.
    assert_eq!((p.width(), p.height()), (1400, 40 + 2 * 440));
}

#[test]
fn the_estimate_caps_a_long_bench() {
    let file = mesh_file("zoo_3x3x3.vtu");
    let o = zoovr(&[
        "bench",
        file.to_str().unwrap(),
        "--modes",
        "raycast",
        "--sizes",
        "2048",
        "--views",
        "50",
        "--max-seconds",
        "5",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("would take about") && e.contains("--max-seconds"),
        "{e}"
    );
    assert!(e.contains("zoo_3x3x3.vtu"), "names the file: {e}");
    assert!(o.stdout.is_empty(), "nothing ran");
}

#[test]
fn usage_errors_exit_2() {
    let file = mesh_file("hexahedron.vtk");
    let f = file.to_str().unwrap();
    for (args, want) in [
        (vec!["--modes", "exact,warp"], "unknown mode 'warp'"),
        (vec!["--modes", "iso"], "--iso"),
        (vec!["--sizes", "0"], "positive"),
        (vec!["--repeats", "0"], "--repeats"),
        (
            vec!["--with-vtk", "python3", "--vtk-mappers", "pt,warp"],
            "unknown VTK mapper 'warp'",
        ),
    ] {
        let mut all = vec!["bench", f];
        all.extend(args.iter().copied());
        let o = zoovr(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
    }
    let o = zoovr(&["bench", "--help"]);
    let text = String::from_utf8_lossy(&o.stdout);
    for flag in [
        "--modes",
        "--sizes",
        "--views",
        "--csv",
        "--json",
        "--plot",
        "--with-vtk",
        "--max-seconds",
        "--repeats",
        "--warmup",
    ] {
        assert!(text.contains(flag), "{flag}: {text}");
    }
}

fn bench_with_vtk(python: &str, dir: &Path) -> std::process::Output {
    let file = mesh_file("curvilinear_4x4x4.vtu");
    zoovr(&[
        "bench",
        file.to_str().unwrap(),
        "--modes",
        "raycast",
        "--sizes",
        "48",
        "--warmup",
        "0",
        "--repeats",
        "1",
        "--with-vtk",
        python,
        "--vtk-mappers",
        "pt,raycast-linear",
        "--csv",
        dir.join("v.csv").to_str().unwrap(),
    ])
}

#[test]
fn with_vtk_names_a_missing_python_or_module() {
    let dir = tempfile::tempdir().unwrap();
    let o = bench_with_vtk("/nonexistent/python3", dir.path());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("cannot run '/nonexistent/python3'"),
        "{}",
        stderr(&o)
    );
    // A Python without VTK (the system one, where it has none).
    let has_vtk = std::process::Command::new("python3")
        .args(["-c", "import vtk"])
        .output()
        .map(|o| o.status.success());
    match has_vtk {
        Ok(false) => {
            let o = bench_with_vtk("python3", dir.path());
            assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
            let e = stderr(&o);
            assert!(
                e.contains("no vtk module") && e.contains("pip install vtk"),
                "{e}"
            );
        }
        _ => eprintln!("skipped: python3 is missing or has vtk"),
    }
}

/// With a Python that has VTK (`ZOOVR_VTK_PYTHON`): VTK's rows join the
/// table with their error against the same references.
#[test]
fn with_vtk_adds_vtk_rows() {
    let Ok(python) = std::env::var("ZOOVR_VTK_PYTHON") else {
        eprintln!("skipped: set ZOOVR_VTK_PYTHON to a Python with vtk");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let o = bench_with_vtk(&python, dir.path());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (head, rows) = csv_rows(&dir.path().join("v.csv"));
    let vtk: Vec<_> = rows
        .iter()
        .filter(|r| col(&head, r, "source") == "vtk")
        .collect();
    assert_eq!(vtk.len(), 2, "{rows:?}");
    for r in vtk {
        assert!(col(&head, r, "error").is_empty(), "{r:?}");
        let e: f64 = col(&head, r, "max_err").parse().unwrap();
        let rms: f64 = col(&head, r, "rms_err").parse().unwrap();
        // Same scene: close on average, not equal (VTK's own tets).
        assert!(e > 0.0 && rms < 0.05, "{r:?}");
    }
}

/// With `--iso`, `all` means the modes that draw surfaces (every mode,
/// iso too) and the references are the ray caster's surfaces, `native`
/// too.
#[test]
fn isosurfaces_join_every_mode_that_draws_them() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("i.csv");
    let file = mesh_file("zoo_3x3x3.vtu");
    let o = zoovr(&[
        "bench",
        file.to_str().unwrap(),
        "--iso",
        "0.5:#ff8000:0.6",
        "--sizes",
        "24",
        "--warmup",
        "0",
        "--repeats",
        "1",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (head, rows) = csv_rows(&csv);
    let modes: Vec<&str> = rows.iter().map(|r| col(&head, r, "mode")).collect();
    assert!(
        modes.contains(&"iso") && modes.contains(&"exact"),
        "{modes:?}"
    );
    // raycast: faces, tets and native, surfaces included.
    assert_eq!(modes.iter().filter(|m| **m == "raycast").count(), 3);
    let gpu = render_util::gpu_available();
    for r in &rows {
        if gpu || col(&head, r, "mode") == "raycast" {
            assert!(col(&head, r, "error").is_empty(), "{r:?}");
            assert!(!col(&head, r, "max_err").is_empty(), "{r:?}");
            assert!(!col(&head, r, "native_max_err").is_empty(), "{r:?}");
        }
    }
}

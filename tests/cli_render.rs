//! `zoovr render` through the real binary: outputs, exit codes, messages.

mod cli_util;

use std::path::Path;
use std::process::Command;

use cli_util::{no_adapter, render, stderr, zoovr};

use zoovr::field::{ArrayData, DataArray};
use zoovr::generate::{ghost_grid, Warp};
use zoovr::image::Image;
use zoovr::io::writer::{write_vtu, Compression};
use zoovr::mesh::{Cells, Mesh};
use zoovr::testdata::mesh_file;

#[test]
fn renders_png_and_exr_in_both_modes() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = mesh_file("hexahedron.vtk");
    let view = ["--size", "64x48", "--azimuth", "-30", "--elevation", "20"];
    let ray_png = dir.path().join("ray.png");
    let ray_exr = dir.path().join("ray.exr");
    let exr = ray_exr.to_str().unwrap();
    let o = render(
        &mesh,
        &ray_png,
        &[&view[..], &["--float", exr, "--mode", "raycast"]].concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let img = Image::read(&ray_png).unwrap();
    assert_eq!((img.width, img.height), (64, 48));
    let exr = Image::read(&ray_exr).unwrap();
    assert!(exr.pixels.iter().any(|p| p[3] > 0.01), "nothing drawn");

    let exact_png = dir.path().join("exact.png");
    let o = render(&mesh, &exact_png, &view);
    if no_adapter(&o) {
        eprintln!("skipping the exact mode: {}", stderr(&o));
        return;
    }
    assert!(o.status.success(), "{}", stderr(&o));
    let o = zoovr(&[
        "compare",
        exact_png.to_str().unwrap(),
        ray_png.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    let max: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("max_abs:"))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .expect("max_abs line");
    assert!(max <= 2e-2, "exact vs raycast max {max}\n{text}");
}

#[test]
fn errors_exit_1_and_name_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.png");
    let out = out.to_str().unwrap();
    let mesh = mesh_file("tetra.vtk");
    let mesh = mesh.to_str().unwrap();
    let o = zoovr(&["render", "/nonexistent/mesh.vtu", "-o", out]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("/nonexistent/mesh.vtu: cannot open"), "{e}");
    // The OS reason once, not repeated by the error chain.
    assert_eq!(e.matches("No such file or directory").count(), 1, "{e}");

    let o = zoovr(&[
        "render", mesh, "-o", out, "--field", "nope", "--mode", "raycast",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("nope"), "{}", stderr(&o));

    let o = zoovr(&[
        "render",
        mesh,
        "-o",
        "/nonexistent/dir/a.png",
        "--mode",
        "raycast",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("/nonexistent/dir/a.png"),
        "{}",
        stderr(&o)
    );
    assert!(!Path::new("/nonexistent/dir/a.png").exists());

    let o = zoovr(&[
        "render",
        mesh,
        "-o",
        out,
        "--preset",
        "nosuchmap",
        "--mode",
        "raycast",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("nosuchmap"), "{}", stderr(&o));
}

#[test]
fn usage_errors_exit_2() {
    let mesh = mesh_file("tetra.vtk");
    let mesh = mesh.to_str().unwrap();
    for bad in [
        vec!["render", mesh, "-o", "x.png", "--size", "0x10"],
        vec!["render", mesh, "-o", "x.png", "--range", "1,1"],
        vec!["render", mesh, "-o", "x.png", "--range", "nan,1"],
        vec!["render", mesh, "-o", "x.png", "--mode", "nosuchmode"],
        vec!["render", mesh, "-o", "x.png", "--split", "some"],
        vec!["render", mesh, "-o", "x.png", "--zoom", "-1"],
        vec!["render", mesh, "-o", "x.png", "--background", "2,0,0"],
    ] {
        let o = zoovr(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
    }
}

/// `-o` writes PNG and `--float` OpenEXR: a name with the other format's
/// extension is refused (exit 2, naming the flag to use), and nothing is
/// written.
#[test]
fn output_names_must_match_their_formats() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = mesh_file("tetra.vtk");
    let mesh = mesh.to_str().unwrap();
    let exr = dir.path().join("out.EXR");
    let png = dir.path().join("out.png");
    let (exr, png) = (exr.to_str().unwrap(), png.to_str().unwrap());
    for (args, flag) in [
        (vec!["render", mesh, "-o", exr], "--float"),
        (vec!["render", mesh, "-o", png, "--float", png], "-o"),
    ] {
        let o = zoovr(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(flag) && e.contains("out."), "{e}");
    }
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
}

#[test]
fn usage_errors_say_what_is_wrong() {
    let mesh = mesh_file("tetra.vtk");
    let mesh = mesh.to_str().unwrap();
    for (bad, words) in [
        (vec!["--size", "0x10"], ["--size", "0x10"]),
        (vec!["--range", "1,1"], ["--range", "1,1"]),
        (
            vec!["--piece-draw", "quads"],
            ["--piece-draw quads", "exact-frag, preint3d"],
        ),
        (
            vec![
                "--mode",
                "exact-frag",
                "--iso",
                "0.5",
                "--piece-draw",
                "quads",
            ],
            ["--piece-draw quads", "without --iso"],
        ),
    ] {
        let mut args = vec!["render", mesh, "-o", "x.png"];
        args.extend(bad);
        let o = zoovr(&args);
        assert_eq!(o.status.code(), Some(2));
        let e = stderr(&o);
        assert!(words.iter().all(|w| e.contains(w)), "{e}");
    }
}

/// The ray caster reports its field model and early-termination threshold,
/// and flags that belong to the other mode are named, not silently dropped.
#[test]
fn raycast_stats_and_other_mode_flags() {
    let dir = tempfile::tempdir().unwrap();
    let o = render(
        &mesh_file("hexahedron.vtk"),
        &dir.path().join("r.png"),
        &[
            "--size", "32x32", "--mode", "raycast", "--model", "tets", "--split", "all", "--stats",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("model tets") && e.contains("transmittance 1e-6"),
        "{e}"
    );
    assert!(
        e.contains("--split all is for the projected-cell modes"),
        "{e}"
    );
}

/// `--piece-draw quads`: exact-frag and the table modes draw their pieces
/// whole, report how many in `--stats`, and give the image of
/// `--piece-draw regions`.
#[test]
fn pieces_are_drawn_whole() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = mesh_file("zoo_3x3x3.vtu");
    for mode in ["exact-frag", "preint3d", "preint2d", "preint2d-cyl"] {
        let mut images = Vec::new();
        for draw in ["regions", "quads"] {
            let png = dir.path().join(format!("{mode}_{draw}.png"));
            let o = render(
                &mesh,
                &png,
                &[
                    "--size",
                    "48x40",
                    "--mode",
                    mode,
                    "--piece-draw",
                    draw,
                    "--stats",
                ],
            );
            if no_adapter(&o) {
                return;
            }
            assert!(o.status.success(), "{mode}: {}", stderr(&o));
            assert_eq!(
                stderr(&o).contains("pieces drawn whole"),
                draw == "quads",
                "{mode}: {}",
                stderr(&o)
            );
            images.push(Image::read(&png).unwrap());
        }
        let (d, _) = zoovr::image::compare_float(&images[0], &images[1]).unwrap();
        // Both within 2/255 of the reference (the table modes within their
        // bounds of 4e-3), 8-bit PNGs.
        assert!(d.max_abs <= 4.0 / 255.0, "{mode}: {}", d.max_abs);
    }
}

/// `--stats --json`: one JSON object on stdout with the mode, the times and
/// the mode's own counters (machine-readable for scripts and `bench`).
#[test]
fn stats_as_json() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("j.png");
    let mesh = mesh_file("hexahedron.vtk");
    let o = render(
        &mesh,
        &png,
        &["--size", "24x24", "--mode", "raycast", "--stats", "--json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["mode"], "raycast");
    assert_eq!(v["detail"]["kind"], "raycast");
    assert_eq!(v["detail"]["model"], "faces");
    assert!(v["total_s"].as_f64().unwrap() >= 0.0);
    assert!(v["load_s"].as_f64().unwrap() >= 0.0);
    // --json needs --stats.
    let o = render(&mesh, &png, &["--json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// A full disk (simulated with a file-size limit: writes fail with EFBIG, the
/// error a full or quota-limited disk gives in kind) and an output path
/// under a regular file: a clear error naming the file, exit 1, and no file
/// or temporary left behind.
#[cfg(unix)]
#[test]
fn unwritable_outputs_fail_cleanly_and_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("full.png");
    let mesh = mesh_file("hexahedron.vtk");
    let cmd = format!(
        "trap '' XFSZ; ulimit -f 4; exec '{}' render '{}' -o '{}' --size 256x256 --mode raycast",
        env!("CARGO_BIN_EXE_zoovr"),
        mesh.display(),
        png.display()
    );
    let o = Command::new("bash").arg("-c").arg(&cmd).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("full.png"), "{}", stderr(&o));
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "left behind: {left:?}");

    let o = render(
        &mesh,
        Path::new("/dev/null/x.png"),
        &["--size", "16x16", "--mode", "raycast"],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("/dev/null/x.png"), "{}", stderr(&o));
}

/// A render interrupted before it finishes leaves no output file (images are
/// written to a temporary and renamed only when complete).
#[cfg(unix)]
#[test]
fn interrupted_render_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("slow.png");
    let mesh = mesh_file("curvilinear_4x4x4.vtu");
    let mut child = Command::new(env!("CARGO_BIN_EXE_zoovr"))
        .args([
            "render",
            mesh.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--size",
            "1500x1500",
            "--mode",
            "raycast",
            "--model",
            "native",
        ])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(400));
    // SAFETY: kill(2) on our own child's pid.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGINT);
    }
    let status = child.wait().unwrap();
    assert!(
        !status.success(),
        "the render finished before the interrupt"
    );
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// `generate::ghost_grid` written as `.vtu`, and the same grid with its
/// hidden and duplicate cells removed by hand (no ghost array at all).
fn ghost_files(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let full = ghost_grid(4, &Warp::default());
    let flags = match &full.cell_data[0].data {
        ArrayData::Int(v) => v.clone(),
        other => panic!("{other:?}"),
    };
    let keep: Vec<usize> = (0..flags.len()).filter(|&c| flags[c] & 33 == 0).collect();
    assert!(keep.len() < flags.len());
    let mut cells = Cells::default();
    for &c in &keep {
        cells.push(full.cells.kinds[c], full.cells.nodes(c));
    }
    let cell_data = full.cell_data[1..]
        .iter()
        .map(|a| {
            let data = match &a.data {
                ArrayData::Int(v) => ArrayData::Int(keep.iter().map(|&c| v[c]).collect()),
                ArrayData::F32(v) => ArrayData::F32(keep.iter().map(|&c| v[c]).collect()),
                ArrayData::F64(v) => ArrayData::F64(keep.iter().map(|&c| v[c]).collect()),
            };
            DataArray { data, ..a.clone() }
        })
        .collect();
    let hand = Mesh {
        cells,
        cell_data,
        ..full.clone()
    };
    let (a, b) = (dir.join("ghost.vtu"), dir.join("by_hand.vtu"));
    write_vtu(&a, &full, Compression::None).unwrap();
    write_vtu(&b, &hand, Compression::None).unwrap();
    (a, b)
}

fn max_pixel_diff(a: &Path, b: &Path) -> f32 {
    let (a, b) = (Image::read(a).unwrap(), Image::read(b).unwrap());
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0, f32::max)
}

/// Cells flagged hidden or duplicate in `vtkGhostType` are not drawn (the
/// image equals the grid without them, in both modes), `--show-hidden`
/// draws them, and `--stats` says how many were left out.
#[test]
fn hidden_cells_are_left_out_unless_show_hidden() {
    let dir = tempfile::tempdir().unwrap();
    let (ghost, hand) = ghost_files(dir.path());
    for mode in ["raycast", "exact"] {
        let run = |file: &Path, out: &str, extra: &[&str]| {
            let png = dir.path().join(format!("{mode}_{out}.png"));
            let view = ["--size", "48x48", "--azimuth", "30", "--elevation", "25"];
            let o = render(file, &png, &[&view[..], &["--mode", mode], extra].concat());
            (o, png)
        };
        let (o, ghost_png) = run(&ghost, "ghost", &["--stats"]);
        if mode == "exact" && no_adapter(&o) {
            eprintln!("skipping the exact mode: {}", stderr(&o));
            continue;
        }
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("ghost cells  16 left out"),
            "{mode}: {}",
            stderr(&o)
        );
        let (o, hand_png) = run(&hand, "hand", &[]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        let (o, shown_png) = run(&ghost, "shown", &["--show-hidden"]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        assert_eq!(
            max_pixel_diff(&ghost_png, &hand_png),
            0.0,
            "{mode}: ghost vs removed by hand"
        );
        let d = max_pixel_diff(&ghost_png, &shown_png);
        assert!(d > 0.05, "{mode}: --show-hidden should differ, max {d}");
    }
}

#[test]
fn help_documents_show_hidden() {
    let o = zoovr(&["render", "--help"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("--show-hidden") && text.contains("vtkGhostType"),
        "{text}"
    );
}

/// A ghost array zoovr cannot read as flags (two components; a tuple count
/// that is not the cell count) is an error naming the file and the array.
#[test]
fn malformed_ghost_arrays_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    for (name, components, len) in [("two_comp.vtu", 2, 128), ("short.vtu", 1, 10)] {
        let mut m = ghost_grid(4, &Warp::default());
        m.cell_data[0].components = components;
        m.cell_data[0].data = ArrayData::Int(vec![0; len]);
        let file = dir.path().join(name);
        write_vtu(&file, &m, Compression::None).unwrap();
        let o = render(&file, &out, &["--size", "16x16", "--mode", "raycast"]);
        assert_eq!(o.status.code(), Some(1), "{name}: {}", stderr(&o));
        let e = stderr(&o);
        eprintln!("{name}: {e}");
        assert!(
            e.contains(name) && e.contains("vtkGhostType"),
            "{name}: {e}"
        );
        assert!(!out.exists());
    }
}

/// A field with NaN values renders in a projected mode and in the
/// reference, each saying what it makes of them (missing values), naming
/// the file.
#[test]
fn nan_values_are_rendered_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let mut m = ghost_grid(4, &Warp::default());
    m.cell_data.clear();
    let n = m.points.len();
    let values: Vec<f64> = (0..n)
        .map(|i| if i % 11 == 0 { f64::NAN } else { i as f64 })
        .collect();
    m.point_data = vec![DataArray {
        name: "f".into(),
        components: 1,
        data: ArrayData::F64(values),
        vtk_type: "Float64".into(),
    }];
    let file = dir.path().join("nan.vtu");
    write_vtu(&file, &m, Compression::None).unwrap();
    for (mode, says) in [
        ("exact-frag", "through a face holding one are empty"),
        ("raycast", "with one at an end are empty"),
    ] {
        let o = render(&file, &out, &["--size", "24x24", "--mode", mode]);
        let e = stderr(&o);
        assert!(o.status.success(), "{mode}: {e}");
        assert!(
            e.contains("nan.vtu") && e.contains("taken as missing") && e.contains(says),
            "{mode}: {e}"
        );
        assert!(out.exists());
    }
}

/// The table modes through the binary: `--table` and `--table-build` in
/// `--help`, the table in `--stats --json`, and sizes no device holds
/// refused with the limit named (exit 1).
#[test]
fn table_modes_flags_stats_and_refused_sizes() {
    let o = zoovr(&["render", "--help"]);
    let text = String::from_utf8_lossy(&o.stdout);
    for flag in ["--table <N>", "--table-build", "preint3d", "preint2d-cyl"] {
        assert!(text.contains(flag), "{flag}: {text}");
    }
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("t.png");
    let mesh = mesh_file("hexahedron.vtk");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            mesh.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--size",
            "24x24",
        ];
        args.extend_from_slice(extra);
        zoovr(&args)
    };
    for n in ["0", "1", "x", "1000"] {
        // 0, 1 and x: usage errors (exit 2). 1000: 16 GiB of texels, over
        // zoovr's 4 GiB and over any adapter's storage buffer (whichever
        // is checked first: the adapter's where a GPU draws), exit 1.
        let o = run(&["--mode", "preint3d", "--table", n]);
        let code = if n == "1000" { 1 } else { 2 };
        assert_eq!(o.status.code(), Some(code), "{n}: {}", stderr(&o));
        let e = stderr(&o);
        let ok = match n {
            "1000" => {
                e.contains("(4 GiB) zoovr allows") || e.contains("storage buffer of this adapter")
            }
            "x" => e.contains("not a whole number"),
            _ => e.contains("at least 2"),
        };
        assert!(ok, "{n}: {e}");
    }
    let probe = zoovr::gpu::Context::new(&Default::default());
    let Ok(ctx) = probe else {
        eprintln!("GPU parts skipped: no adapter");
        return;
    };
    // A 3D table larger than one storage buffer of the adapter (128 MiB on
    // lavapipe and GL llvmpipe; checked before the size in memory): refused
    // with the limit named.
    let max = ctx
        .limits()
        .max_storage_buffer_binding_size
        .min(ctx.limits().max_buffer_size);
    let side = ((max / 16) as f64).cbrt().floor() as u64 + 1;
    if side * side * side <= 1 << 28 {
        let big = side.to_string();
        let o = run(&["--mode", "preint3d", "--table", &big]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        let max_mib = format!("({:.1} MiB)", max as f64 / (1u64 << 20) as f64);
        assert!(
            stderr(&o).contains(&max_mib) && stderr(&o).contains("3D table"),
            "{}",
            stderr(&o)
        );
    }
    for (mode, kind) in [
        ("preint3d", "cube"),
        ("preint2d", "flat"),
        ("preint2d-cyl", "cylinder"),
    ] {
        let o = run(&[
            "--mode",
            mode,
            "--table",
            "16",
            "--table-build",
            "exact",
            "--stats",
            "--json",
        ]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["mode"], mode);
        let t = &v["detail"]["table"];
        assert_eq!(t["kind"], kind, "{v}");
        assert_eq!(t["size"][0], 16);
        assert_eq!(t["build"], "exact");
        assert!(t["texels_built"].as_u64().unwrap() > 0);
    }
}

/// `--refine-tol`: a lower tolerance refines more region triangles of the
/// exact mode (and a note says it is the exact mode's elsewhere).
#[test]
fn refine_tolerance_trades_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("r.png");
    let mesh = mesh_file("zoo_3x3x3.vtu");
    let refined = |tol: &str| -> Option<u64> {
        let o = render(
            &mesh,
            &png,
            &["--size", "48x48", "--refine-tol", tol, "--stats", "--json"],
        );
        if no_adapter(&o) {
            return None;
        }
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["detail"]["refined_triangles"].as_u64()
    };
    if let (Some(coarse), Some(fine)) = (refined("0.05"), refined("0.001")) {
        assert!(fine > coarse, "{coarse} -> {fine}");
    } else {
        eprintln!("GPU part skipped: no adapter");
    }
    let o = render(
        &mesh,
        &png,
        &[
            "--size",
            "16x16",
            "--mode",
            "raycast",
            "--refine-tol",
            "0.01",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--refine-tol is the exact mode's"),
        "{}",
        stderr(&o)
    );
    let o = render(&mesh, &png, &["--refine-tol", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// Occlusion culling: with an opaque transfer function the pieces behind
/// the first layer are left out (`hidden_pieces` in `--stats --json`), and
/// `--no-occlusion` draws them; the PNGs are the same byte for byte.
#[test]
fn no_occlusion_draws_hidden_pieces_and_the_image_is_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let tf = dir.path().join("opaque.json");
    std::fs::write(
        &tf,
        r#"{"unit_distance": 0.001,
            "opacity_points": [{"s": 0.0, "opacity": 1.0}, {"s": 1.0, "opacity": 1.0}],
            "color_points": [{"s": 0.0, "rgb": [0.9, 0.3, 0.1]}, {"s": 1.0, "rgb": [0.1, 0.5, 0.9]}]}"#,
    )
    .unwrap();
    let mesh = mesh_file("zoo_3x3x3.vtu");
    let run = |extra: &[&str], png: &std::path::Path| -> Option<u64> {
        let tf = tf.to_str().unwrap();
        let mut args = vec!["--size", "40x32", "--mode", "exact-frag", "--tf", tf];
        args.extend_from_slice(&["--stats", "--json"]);
        args.extend_from_slice(extra);
        let o = render(&mesh, png, &args);
        if no_adapter(&o) {
            return None;
        }
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["detail"]["hidden_pieces"].as_u64()
    };
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let (Some(hidden), Some(none)) = (run(&[], &a), run(&["--no-occlusion"], &b)) else {
        eprintln!("skipped: no adapter");
        return;
    };
    assert!(hidden > 0, "{hidden}");
    assert_eq!(none, 0);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

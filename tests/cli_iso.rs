//! `zoovr render --iso` through the real binary: surfaces drawn in every
//! mode that draws them, and the bad inputs (exit 2 naming the value, a
//! warning for values outside the field's range, a clear error for cell
//! data).

mod cli_util;

use cli_util::{no_adapter, render, stderr};
use zoovr::image::{compare_display, Image};
use zoovr::testdata::mesh_file;

fn lit_pixels(png: &std::path::Path) -> usize {
    let img = Image::read(png).unwrap();
    img.pixels.iter().filter(|p| p[0] > 0.1).count()
}

#[test]
fn surfaces_render_alone_and_mixed() {
    let dir = tempfile::tempdir().unwrap();
    let file = mesh_file("zoo_3x3x3.vtu");
    for (mode, extra) in [
        ("iso", vec![]),
        ("exact-frag", vec![]),
        ("preint2d", vec![]),
        ("raycast", vec!["--iso-only"]),
        ("exact", vec!["--iso-only"]),
        ("exact", vec![]),
        ("exact", vec!["--iso-mix", "blend", "--split", "all"]),
    ] {
        let out = dir.path().join(format!("{mode}.png"));
        let mut args = vec![
            "--mode",
            mode,
            "--iso",
            "0.5:#ff0000,0.8:#00ff00:0.5",
            "--size",
            "64x64",
            "--shading",
            "flat",
        ];
        args.extend(extra);
        let o = render(&file, &out, &args);
        if no_adapter(&o) {
            continue;
        }
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        assert!(lit_pixels(&out) > 200, "{mode}: no surface");
    }
}

/// With surfaces the exact mode draws exact-frag's frame (its vertex
/// integrals cannot hold a crossing inside a segment): the same image,
/// byte for byte, on whole cells and split into tets; split, it agrees
/// with `--mode raycast --model tets --iso` (the same field; zoo_3x3x3's
/// nonplanar faces make its whole cells' field differ from `faces`).
#[test]
fn the_exact_mode_with_surfaces_is_exact_frags_frame() {
    let dir = tempfile::tempdir().unwrap();
    let file = mesh_file("zoo_3x3x3.vtu");
    let args = ["--iso", "0.5:tf:0.6", "--size", "80x64", "--azimuth", "30"];
    let run = |name: &str, extra: &[&str]| -> Option<std::path::PathBuf> {
        let out = dir.path().join(format!("{name}.png"));
        let mut a: Vec<&str> = extra.to_vec();
        a.extend(args);
        let o = render(&file, &out, &a);
        if no_adapter(&o) {
            return None;
        }
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        Some(out)
    };
    for split in [&[][..], &["--split", "all"][..]] {
        let mut exact = vec!["--mode", "exact"];
        exact.extend(split);
        let mut frag = vec!["--mode", "exact-frag"];
        frag.extend(split);
        let (Some(a), Some(b)) = (run("exact", &exact), run("exact-frag", &frag)) else {
            return;
        };
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "{split:?}: exact --iso differs from exact-frag --iso"
        );
    }
    let reference = run("raycast", &["--mode", "raycast", "--model", "tets"]).unwrap();
    let a = Image::read(&dir.path().join("exact.png")).unwrap();
    let r = Image::read(&reference).unwrap();
    // Display values of the 8-bit PNGs, max over every pixel: within 2/255
    // of the reference's (measured 1/255).
    let (d, _) = compare_display(&a, &r, [0.0; 3]).unwrap();
    assert!(d.max_abs <= 2.0 / 255.0 + 1e-9, "{}", d.max_abs);
}

/// The reference draws surfaces with every field model and traversal: the
/// native field and the brute force, mixed with the volume and alone, in
/// both lights and both mixes.
#[test]
fn the_reference_draws_surfaces_with_native_and_brute() {
    let dir = tempfile::tempdir().unwrap();
    let file = mesh_file("curvilinear_4x4x4.vtu");
    for (name, extra) in [
        ("native", vec!["--model", "native"]),
        ("native-alone", vec!["--model", "native", "--iso-only"]),
        (
            "native-blend",
            vec!["--model", "native", "--iso-mix", "blend"],
        ),
        ("brute", vec!["--traversal", "brute"]),
        (
            "brute-tets",
            vec!["--traversal", "brute", "--model", "tets", "--iso-only"],
        ),
    ] {
        for shading in ["smooth", "flat"] {
            let out = dir.path().join(format!("{name}-{shading}.png"));
            let mut args = vec![
                "--mode",
                "raycast",
                "--iso",
                "0.4:#ff0000,0.6:#ff8000:0.5",
                "--size",
                "48x48",
                "--shading",
                shading,
            ];
            args.extend(&extra);
            let o = render(&file, &out, &args);
            assert!(o.status.success(), "{name}: {}", stderr(&o));
            assert!(lit_pixels(&out) > 100, "{name} {shading}: no surface");
        }
    }
}

#[test]
fn bad_isovalues_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let file = mesh_file("zoo_3x3x3.vtu");
    let many = vec!["0.5"; 1025].join(",");
    for (args, says) in [
        (vec!["--iso", "nan"], "'nan'"),
        (vec!["--iso", "0.5,abc"], "'abc'"),
        (vec!["--iso", "0.5:#12345"], "#12345"),
        (vec!["--iso", "0.5:tf:1.5"], "1.5"),
        (vec!["--iso", &many], "1025"),
        (vec!["--mode", "iso"], "--iso"),
        // Brute force has no native model, with or without surfaces.
        (
            vec![
                "--mode",
                "raycast",
                "--model",
                "native",
                "--traversal",
                "brute",
                "--iso",
                "0.5",
            ],
            "native",
        ),
    ] {
        let o = render(&file, &out, &args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn isovalues_outside_the_range_warn_and_draw_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let o = render(
        &mesh_file("zoo_3x3x3.vtu"),
        &out,
        &[
            "--mode",
            "raycast",
            "--iso-only",
            "--iso",
            "7.5",
            "--size",
            "32x32",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("outside the range"), "{}", stderr(&o));
    assert!(stderr(&o).contains("7.5"), "{}", stderr(&o));
    assert_eq!(lit_pixels(&out), 0);
}

#[test]
fn cell_data_is_refused_with_a_hint() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let mesh = zoovr::generate::ghost_grid(3, &zoovr::generate::Warp::default());
    let file = dir.path().join("cells.vtu");
    zoovr::io::writer::write_vtu(&file, &mesh, zoovr::io::writer::Compression::None).unwrap();
    let o = render(
        &file,
        &out,
        &[
            "--mode", "raycast", "--field", "value", "--iso", "1", "--size", "16x16",
        ],
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--cell-to-point"), "{}", stderr(&o));
}

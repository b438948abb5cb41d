//! `zoovr animate` through the real binary, on series the tests write
//! themselves (and on the can_crush series when the shared data is
//! present): frames equal `zoovr render` of each step with the same range,
//! the default range spans every step, the reuse case is detected per step,
//! orbit frames equal renders at the matching azimuth, separate frame
//! ranges add up byte for byte to one run, the GIF has one global palette,
//! and bad input fails with the file named and the documented exit code.
//!
//! Most checks use the CPU ray caster (`--mode raycast`), which needs no
//! adapter; the exact mode is checked where an adapter exists and skipped
//! otherwise, as in `cli_render.rs`.

mod cli_util;

use std::path::{Path, PathBuf};
use std::process::Output;

use cli_util::{no_adapter, stderr, zoovr};

use zoovr::generate::{time_series, warped_hex_grid, Warp};
use zoovr::image::Image;
use zoovr::io::writer::{write_pvd, write_series, write_vtu, Compression};
use zoovr::mesh::Mesh;
use zoovr::testdata::shared_file;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `zoovr animate --assemble DIR FLAG OUT --fps FPS`: the frames of `dir`
/// assembled into a GIF or MP4 (`flag`).
fn assemble(dir: &Path, flag: &str, out: &Path, fps: &str) -> Output {
    zoovr(&["animate", "--assemble", s(dir), flag, s(out), "--fps", fps])
}

/// Writes `meshes` as `step_K.vtu` and a `.pvd` of them into `dir`; returns
/// the collection.
fn write_steps(dir: &Path, meshes: &[(f64, Mesh)]) -> PathBuf {
    let mut entries = Vec::new();
    for (k, (t, m)) in meshes.iter().enumerate() {
        let name = format!("step_{k}.vtu");
        write_vtu(&dir.join(&name), m, Compression::None).unwrap();
        entries.push((*t, name));
    }
    let pvd = dir.join("series.pvd");
    write_pvd(&pvd, &entries).unwrap();
    write_series(&dir.join("series.vtu.series"), &entries).unwrap();
    pvd
}

/// The `--stats --json` lines of a run.
fn json_lines(o: &Output) -> Vec<serde_json::Value> {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect()
}

fn pixels(p: &Path) -> Vec<[f32; 4]> {
    Image::read(p).unwrap().pixels
}

const VIEW: [&str; 6] = ["--size", "40x32", "--azimuth", "20", "--elevation", "15"];

#[test]
fn frames_equal_renders_of_each_step_with_the_global_range() {
    let dir = tempfile::tempdir().unwrap();
    let pvd = write_steps(dir.path(), &time_series(4, 3));
    let out = dir.path().join("frames");
    let mut args = vec!["animate", s(&pvd), "-o", s(&out), "--mode", "raycast"];
    args.extend(VIEW);
    args.extend(["--stats", "--json"]);
    let o = zoovr(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = json_lines(&o);
    assert_eq!(lines.len(), 3);
    let changes: Vec<&str> = lines
        .iter()
        .map(|l| l["change"].as_str().unwrap())
        .collect();
    assert_eq!(changes, ["none", "values", "values"]);
    let range = &lines[0]["range"];
    let (lo, hi) = (range[0].as_f64().unwrap(), range[1].as_f64().unwrap());
    // The default range spans every step, so it is wider than step 0's.
    let first = zoovr(&[
        "animate",
        s(&pvd),
        "-o",
        s(&dir.path().join("first")),
        "--mode",
        "raycast",
        "--size",
        "8x8",
        "--range-from",
        "first",
        "--frames",
        "0..0",
        "--stats",
        "--json",
    ]);
    assert!(first.status.success(), "{}", stderr(&first));
    let r0 = &json_lines(&first)[0]["range"];
    let (lo0, hi0) = (r0[0].as_f64().unwrap(), r0[1].as_f64().unwrap());
    assert!(
        lo <= lo0 && hi >= hi0 && (lo < lo0 || hi > hi0),
        "{lo} {hi} vs {lo0} {hi0}"
    );
    for l in &lines {
        assert_eq!(&l["range"], range, "one range in every frame");
    }
    let range_arg = format!("{lo:?},{hi:?}");
    for k in 0..3 {
        let want = dir.path().join(format!("render_{k}.png"));
        let step = dir.path().join(format!("step_{k}.vtu"));
        let mut r = vec!["render", s(&step), "-o", s(&want), "--mode", "raycast"];
        r.extend(VIEW);
        r.extend(["--range", &range_arg]);
        let o = zoovr(&r);
        assert!(o.status.success(), "{}", stderr(&o));
        let got = out.join(format!("frame_{k:05}.png"));
        assert!(
            std::fs::read(&got).unwrap() == std::fs::read(&want).unwrap(),
            "frame {k} differs from the render of step {k}"
        );
    }
    assert!(pixels(&out.join("frame_00000.png")) != pixels(&out.join("frame_00002.png")));
}

#[test]
fn exact_mode_frames_equal_renders_and_reuse_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let series = write_steps(dir.path(), &time_series(4, 3)).with_file_name("series.vtu.series");
    let out = dir.path().join("frames");
    let mut args = vec!["animate", s(&series), "-o", s(&out), "--range", "-1,2"];
    args.extend(VIEW);
    args.extend(["--stats", "--json"]);
    let o = zoovr(&args);
    if no_adapter(&o) {
        eprintln!("skipping the exact mode: {}", stderr(&o));
        return;
    }
    assert!(o.status.success(), "{}", stderr(&o));
    // Values only, one camera: the later frames take the sort and every
    // part's regions from the frame before.
    let lines = json_lines(&o);
    for (k, l) in lines.iter().enumerate() {
        let d = &l["render"]["detail"];
        let reused = d["regions_reused"].as_u64().unwrap();
        assert!(d["regions_kept_bytes"].as_u64().unwrap() > 0, "{l}");
        if k == 0 {
            assert_eq!(reused, 0);
        } else {
            assert_eq!(l["change"], "values");
            assert_eq!(d["sort_reused"], true, "{l}");
            assert!(reused > 0, "frame {k}: {l}");
        }
    }
    for k in 0..3 {
        let want = dir.path().join(format!("render_{k}.png"));
        let step = dir.path().join(format!("step_{k}.vtu"));
        let mut r = vec!["render", s(&step), "-o", s(&want), "--range", "-1,2"];
        r.extend(VIEW);
        let o = zoovr(&r);
        assert!(o.status.success(), "{}", stderr(&o));
        let got = out.join(format!("frame_{k:05}.png"));
        assert!(
            std::fs::read(&got).unwrap() == std::fs::read(&want).unwrap(),
            "exact frame {k} differs from the render of step {k}"
        );
    }
}

#[test]
fn each_step_change_is_detected() {
    let dir = tempfile::tempdir().unwrap();
    let series = time_series(3, 2);
    let mut moved = series[1].1.clone();
    for p in &mut moved.points {
        p.x *= 1.0 + 0.05 * p.y;
    }
    let mut other = warped_hex_grid(4, &Warp::default());
    other.point_data = series[0].1.point_data.clone();
    other.point_data[0].data =
        zoovr::field::ArrayData::F64(other.points.iter().map(|p| p.x + p.y).collect());
    let pvd = write_steps(
        dir.path(),
        &[
            series[0].clone(),
            series[1].clone(),
            (1.0, moved),
            (1.5, other),
        ],
    );
    let o = zoovr(&[
        "animate",
        s(&pvd),
        "-o",
        s(&dir.path().join("f")),
        "--mode",
        "raycast",
        "--size",
        "16x16",
        "--stats",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = json_lines(&o);
    let changes: Vec<&str> = lines
        .iter()
        .map(|l| l["change"].as_str().unwrap())
        .collect();
    assert_eq!(changes, ["none", "values", "points", "cells"]);
    // The step whose cells changed is named.
    assert!(
        stderr(&o).contains("step_3.vtu: its cells differ"),
        "{}",
        stderr(&o)
    );
    let times: Vec<f64> = lines.iter().map(|l| l["time"].as_f64().unwrap()).collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 1.5]);
}

#[test]
fn orbit_frames_equal_renders_at_their_azimuth() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("one.vtu");
    write_vtu(&file, &time_series(3, 1)[0].1, Compression::None).unwrap();
    let out = dir.path().join("turn");
    let o = zoovr(&[
        "animate",
        s(&file),
        "-o",
        s(&out),
        "--mode",
        "raycast",
        "--size",
        "24x20",
        "--azimuth",
        "10",
        "--orbit",
        "30",
        "--count",
        "3",
        "--stats",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let changes: Vec<String> = json_lines(&o)
        .iter()
        .map(|l| l["change"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(changes, ["none", "camera", "camera"]);
    for (k, az) in ["10", "40", "70"].iter().enumerate() {
        let want = dir.path().join(format!("az_{k}.png"));
        let o = zoovr(&[
            "render",
            s(&file),
            "-o",
            s(&want),
            "--mode",
            "raycast",
            "--size",
            "24x20",
            "--azimuth",
            az,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            std::fs::read(out.join(format!("frame_{k:05}.png"))).unwrap()
                == std::fs::read(&want).unwrap(),
            "orbit frame {k} differs from the render at azimuth {az}"
        );
    }
}

#[test]
fn frame_ranges_add_up_to_one_run_and_assemble_into_a_gif() {
    let dir = tempfile::tempdir().unwrap();
    let pvd = write_steps(dir.path(), &time_series(3, 4));
    let whole = dir.path().join("whole");
    let parts = dir.path().join("parts");
    let base = ["--mode", "raycast", "--size", "20x16"];
    let run = |out: &Path, extra: &[&str]| {
        let mut a = vec!["animate", s(&pvd), "-o", s(out)];
        a.extend(base);
        a.extend(extra);
        let o = zoovr(&a);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    let gif_path = dir.path().join("whole.gif");
    run(&whole, &["--gif", s(&gif_path), "--fps", "4"]);
    // Separate processes share the whole run's range through a range file.
    let range_file = dir.path().join("range.json");
    let o = zoovr(&["animate", s(&pvd), "--range-only", s(&range_file)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rf = s(&range_file);
    run(&parts, &["--frames", "2..3", "--range-file", rf]);
    run(&parts, &["--frames", "0..1", "--range-file", rf]);
    for k in 0..4 {
        let name = format!("frame_{k:05}.png");
        assert!(
            std::fs::read(whole.join(&name)).unwrap() == std::fs::read(parts.join(&name)).unwrap(),
            "{name} of the ranges differs from the whole run"
        );
    }
    let assembled = dir.path().join("parts.gif");
    let o = assemble(&parts, "--gif", &assembled, "4");
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&gif_path).unwrap(),
        std::fs::read(&assembled).unwrap()
    );

    // The GIF: 4 frames, 25/100 s each, one global palette, looping.
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts
        .read_info(std::fs::File::open(&gif_path).unwrap())
        .unwrap();
    assert!(dec.global_palette().is_some_and(|p| p.len() == 256 * 3));
    assert_eq!((dec.width(), dec.height()), (20, 16));
    let mut frames = 0;
    while let Some(f) = dec.read_next_frame().unwrap() {
        assert_eq!(f.delay, 25);
        assert!(f.palette.is_none(), "frame {frames} has a local palette");
        frames += 1;
    }
    assert_eq!(frames, 4);
    assert_eq!(dec.repeat(), gif::Repeat::Infinite);
}

#[test]
fn legend_is_drawn_into_the_frames() {
    let dir = tempfile::tempdir().unwrap();
    let pvd = write_steps(dir.path(), &time_series(3, 2));
    let plain = dir.path().join("plain");
    let legend = dir.path().join("legend");
    for (out, extra) in [(&plain, None), (&legend, Some("--legend"))] {
        let mut a = vec![
            "animate",
            s(&pvd),
            "-o",
            s(out),
            "--mode",
            "raycast",
            "--size",
            "96x80",
        ];
        a.extend(extra);
        let o = zoovr(&a);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let a = pixels(&plain.join("frame_00001.png"));
    let b = pixels(&legend.join("frame_00001.png"));
    let differ = a.iter().zip(&b).filter(|(p, q)| p != q).count();
    assert!(differ > 100, "{differ} pixels differ");
    // `render --legend` too.
    let png = dir.path().join("r.png");
    let step = dir.path().join("step_0.vtu");
    let o = zoovr(&[
        "render",
        s(&step),
        "-o",
        s(&png),
        "--mode",
        "raycast",
        "--size",
        "96x80",
        "--legend",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_folder_and_a_glob_list_the_steps_in_numeric_order() {
    let dir = tempfile::tempdir().unwrap();
    let steps = dir.path().join("steps");
    std::fs::create_dir(&steps).unwrap();
    // Written as step_8, step_9, step_10: numeric order, not byte order.
    for (k, (_, m)) in time_series(3, 3).iter().enumerate() {
        write_vtu(
            &steps.join(format!("step_{}.vtu", k + 8)),
            m,
            Compression::None,
        )
        .unwrap();
    }
    // step_9 records its own time, as ParaView writes it.
    let p9 = steps.join("step_9.vtu");
    let bytes = std::fs::read(&p9).unwrap();
    let tag = b"<UnstructuredGrid>";
    let at = bytes.windows(tag.len()).position(|w| w == tag).unwrap() + tag.len();
    let field = b"<FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" \
                  NumberOfTuples=\"1\" format=\"ascii\">2.5</DataArray></FieldData>";
    let edited = [&bytes[..at], &field[..], &bytes[at..]].concat();
    std::fs::write(&p9, edited).unwrap();
    let pattern = steps.join("step_*.vtu");
    for series in [steps.as_path(), pattern.as_path()] {
        let o = zoovr(&[
            "animate",
            s(series),
            "-o",
            s(&dir.path().join("o")),
            "--mode",
            "raycast",
            "--size",
            "8x8",
            "--stats",
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let files: Vec<String> = json_lines(&o)
            .iter()
            .map(|l| l["file"].as_str().unwrap().to_string())
            .collect();
        assert!(
            files[0].ends_with("step_8.vtu") && files[2].ends_with("step_10.vtu"),
            "{files:?}"
        );
        let times: Vec<f64> = json_lines(&o)
            .iter()
            .map(|l| l["time"].as_f64().unwrap())
            .collect();
        assert_eq!(times, [0.0, 2.5, 2.0], "index, TimeValue, index");
    }
}

#[test]
fn bad_input_names_the_file_and_exits_with_the_documented_code() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let pvd = write_steps(d, &time_series(3, 3));
    let out = d.join("o");
    let go = |extra: &[&str]| {
        let mut a = vec!["animate"];
        a.extend(extra);
        a.extend(["-o", s(&out), "--mode", "raycast", "--size", "8x8"]);
        zoovr(&a)
    };
    // --frames beyond the series, --count with a series: usage (2).
    let o = go(&[s(&pvd), "--frames", "1..5"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("3 frames"), "{}", stderr(&o));
    let o = go(&[s(&pvd), "--count", "4"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // An empty glob.
    let o = go(&[s(&d.join("nothing_*.vtu"))]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("nothing_*.vtu"), "{}", stderr(&o));
    // A field a step lacks.
    let o = go(&[s(&pvd), "--field", "nope"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("step_0.vtu"), "{}", stderr(&o));
    // A corrupt step: named, and the frames before it are said complete.
    std::fs::write(
        d.join("step_2.vtu"),
        "<VTKFile type=\"UnstructuredGrid\"> garbage",
    )
    .unwrap();
    let o = go(&[s(&pvd), "--range", "0,1"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("step_2.vtu") && e.contains("frames 0..1 are complete"),
        "{e}"
    );
    assert!(!o.status.success() && !e.contains("panicked"), "{e}");
    // A missing step.
    std::fs::remove_file(d.join("step_1.vtu")).unwrap();
    let o = go(&[s(&pvd)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("step_1.vtu"), "{}", stderr(&o));
    // An output folder that cannot be made.
    let file = d.join("a_file");
    std::fs::write(&file, "x").unwrap();
    let o = zoovr(&[
        "animate",
        s(&d.join("step_0.vtu")),
        "-o",
        s(&file.join("sub")),
        "--mode",
        "raycast",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("a_file"), "{}", stderr(&o));
    // --mp4 with frames larger than the encoder takes: refused before
    // anything is rendered, the limit named.
    let big = d.join("big");
    let o = zoovr(&[
        "animate",
        s(&d.join("step_0.vtu")),
        "-o",
        s(&big),
        "--size",
        "4000x16",
        "--mp4",
        s(&d.join("a.mp4")),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("3840x2160"), "{}", stderr(&o));
    assert!(!big.exists() && !d.join("a.mp4").exists());
}

#[test]
fn can_crush_series_deforms_with_the_topology_kept() {
    let Some(pvd) = shared_file("can_crush/series/can_series.pvd") else {
        eprintln!("skipping: no shared data");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let o = zoovr(&[
        "animate",
        s(&pvd),
        "-o",
        s(&dir.path().join("can")),
        "--size",
        "64x64",
        "--stats",
        "--json",
    ]);
    if no_adapter(&o) {
        eprintln!("skipping: {}", stderr(&o));
        return;
    }
    assert!(o.status.success(), "{}", stderr(&o));
    let changes: Vec<String> = json_lines(&o)
        .iter()
        .map(|l| l["change"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(changes, ["none", "points", "points"]);
}

/// `--mp4` needs nothing installed: the file holds one H.264 sample per
/// frame, in a track of the padded size, timed by `--fps`, and
/// `--assemble` makes the same file from the frames (the decoding of the
/// samples back to the frames is checked in `zoovr::video::mp4`).
#[test]
fn mp4_is_written_in_process() {
    let dir = tempfile::tempdir().unwrap();
    let pvd = write_steps(dir.path(), &time_series(3, 3));
    let mp4_path = dir.path().join("a.mp4");
    let frames = dir.path().join("f");
    // An odd size: the encoder pads it to even.
    let o = zoovr(&[
        "animate",
        s(&pvd),
        "-o",
        s(&frames),
        "--mode",
        "raycast",
        "--size",
        "21x17",
        "--mp4",
        s(&mp4_path),
        "--fps",
        "5",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).is_empty() || !stderr(&o).contains("OpenH264"),
        "{}",
        stderr(&o)
    );
    let bytes = std::fs::read(&mp4_path).unwrap();
    assert_eq!(&bytes[4..8], b"ftyp", "not an MP4");
    let size = bytes.len() as u64;
    let mut reader = mp4::Mp4Reader::read_header(std::io::Cursor::new(bytes), size).unwrap();
    let track = &reader.tracks()[&1];
    assert_eq!((track.width(), track.height()), (22, 18));
    assert!((track.duration().as_secs_f64() - 0.6).abs() < 1e-3);
    assert_eq!(track.media_type().unwrap(), mp4::MediaType::H264);
    assert_eq!(reader.sample_count(1).unwrap(), 3);
    let first = reader.read_sample(1, 1).unwrap().unwrap();
    assert!(first.is_sync && first.bytes.len() > 8);
    // --assemble from the folder gives the same file, byte for byte.
    let again = dir.path().join("b.mp4");
    let o = assemble(&frames, "--mp4", &again, "5");
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&mp4_path).unwrap(),
        std::fs::read(&again).unwrap()
    );
}

/// The README's first animation: the example series the repository holds.
#[test]
fn the_example_flow_series_animates_with_values_reused() {
    let pvd = zoovr::testdata::mesh_file("flow/flow.pvd");
    let dir = tempfile::tempdir().unwrap();
    let o = zoovr(&[
        "animate",
        s(&pvd),
        "-o",
        s(&dir.path().join("f")),
        "--mode",
        "raycast",
        "--size",
        "24x24",
        "--frames",
        "0..3",
        "--legend",
        "--stats",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = json_lines(&o);
    let changes: Vec<&str> = lines
        .iter()
        .map(|l| l["change"].as_str().unwrap())
        .collect();
    assert_eq!(changes, ["none", "values", "values", "values"]);
    assert_eq!(lines[3]["time"].as_f64(), Some(0.75));
}

/// `--iso` values outside the range the field takes over the series are
/// named in a warning (their surface is in no frame); values inside are not.
#[test]
fn isovalues_outside_the_series_range_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let pvd = write_steps(dir.path(), &time_series(3, 2));
    let out = dir.path().join("frames");
    let o = zoovr(&[
        "animate",
        s(&pvd),
        "-o",
        s(&out),
        "--mode",
        "raycast",
        "--iso",
        "1e9,0.5",
        "--size",
        "16x16",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("isovalue 1000000000 is outside the range") && e.contains("in no frame"),
        "{e}"
    );
    assert!(!e.contains("isovalue 0.5 is outside"), "{e}");
    // With --range the data range is unknown: no warning.
    let o = zoovr(&[
        "animate",
        s(&pvd),
        "-o",
        s(&out),
        "--mode",
        "raycast",
        "--iso",
        "1e9",
        "--range",
        "0,1",
        "--size",
        "16x16",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("outside the range"), "{}", stderr(&o));
}

//! `zoovr compare` runs as a real binary on images written to a temp dir.

use std::path::Path;
use std::process::Command;

use zoovr::image::Image;

fn zoovr(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_zoovr"))
        .args(args)
        .output()
        .expect("run zoovr");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn field(out: &str, key: &str) -> f64 {
    let line = out.lines().find(|l| l.starts_with(key)).expect(key);
    line[key.len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn identical_and_different_pngs() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = Image::new(4, 2);
    a.set(1, 1, [0.2, 0.4, 0.6, 1.0]);
    let mut b = a.clone();
    // One channel differs by 51/255 = 0.2 in display values.
    b.set(3, 0, [0.2, 0.0, 0.0, 1.0]);
    let (pa, pb) = (dir.path().join("a.png"), dir.path().join("b.png"));
    a.write_png(&pa, [0.0; 3], false).unwrap();
    b.write_png(&pb, [0.0; 3], false).unwrap();

    let (code, out, err) = zoovr(&["compare", s(&pa), s(&pa)]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(field(&out, "max_abs:"), 0.0);
    assert!(out.contains("psnr:    inf"), "{out}");

    let diff = dir.path().join("d.png");
    let (code, out, err) = zoovr(&["compare", s(&pa), s(&pb), "--diff", s(&diff)]);
    assert_eq!(code, 0, "{err}");
    assert!((field(&out, "max_abs:") - 0.2).abs() < 1e-6, "{out}");
    assert!(out.contains("at pixel (3, 0)"));
    let rms = (0.04f64 / 24.0).sqrt();
    assert!((field(&out, "rms:") - rms).abs() < 1e-6);
    assert!((field(&out, "psnr:") - (-20.0 * rms.log10())).abs() < 1e-2);
    let d = Image::read(&diff).unwrap();
    assert!((d.get(3, 0)[0] - 0.2).abs() < 1.0 / 255.0 && d.get(0, 0)[0] == 0.0);
}

#[test]
fn exr_files_compare_float_values() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = Image::new(3, 3);
    a.set(2, 2, [0.001, 0.0, 0.0, 0.5]);
    let b = Image::new(3, 3);
    let (pa, pb) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    a.write_exr(&pa).unwrap();
    b.write_exr(&pb).unwrap();
    let (code, out, err) = zoovr(&["compare", s(&pa), s(&pb)]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("float"));
    assert!((field(&out, "max_abs:") - 0.5).abs() < 1e-7, "{out}");
}

#[test]
fn unreadable_files_and_size_mismatch_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let pa = dir.path().join("a.png");
    Image::new(2, 2).write_png(&pa, [0.0; 3], false).unwrap();
    let missing = dir.path().join("missing.png");
    let (code, _, err) = zoovr(&["compare", s(&pa), s(&missing)]);
    assert_eq!(code, 1);
    assert!(err.contains("missing.png"), "{err}");
    let junk = dir.path().join("junk.png");
    std::fs::write(&junk, b"not a png").unwrap();
    let (code, _, err) = zoovr(&["compare", s(&junk), s(&pa)]);
    assert_eq!(code, 1);
    assert!(err.contains("junk.png"), "{err}");
    let pb = dir.path().join("b.png");
    Image::new(3, 2).write_png(&pb, [0.0; 3], false).unwrap();
    let (code, _, err) = zoovr(&["compare", s(&pa), s(&pb)]);
    assert_eq!(code, 1);
    assert!(err.contains("size"), "{err}");
    let (code, _, _) = zoovr(&["compare", s(&pa)]);
    assert_eq!(code, 2);
}

//! Transfer-function files: the shared benchmark TF, the project format
//! (round trip, jumps, independent emission), ParaView colour maps and the
//! typed errors for bad files.

use zoovr::integrate::RayMaterial;
use zoovr::tf::{EmissionModel, TfError, TransferFunction};

#[test]
fn bench_tf_loads_as_is() {
    let Some(p) = zoovr::testdata::shared_file("synthetic/bench_tf.json") else {
        return;
    };
    let tf = TransferFunction::from_json_file(&p, 123.0).expect("bench_tf.json loads");
    assert_eq!(tf.scalar.as_deref(), Some("f"));
    assert_eq!(tf.unit_distance, Some(0.5));
    assert_eq!(tf.model(), EmissionModel::Glow);
    // extinction = opacity / unit distance, piecewise linear.
    assert_eq!(tf.tau_at(0.1), 0.0);
    assert!((tf.tau_at(0.35) - 1.0).abs() < 1e-15);
    assert!((tf.tau_at(0.29) - 0.5).abs() < 1e-12);
    assert!((tf.tau_at(0.7) - 1.8).abs() < 1e-12);
    assert!((tf.tau_at(1.0) - 0.4).abs() < 1e-15);
    // Colour points.
    assert_eq!(tf.color_at(0.45), [0.1, 0.9, 0.3]);
    let c = tf.color_at(0.15);
    assert!((c[1] - 0.3).abs() < 1e-12 && c[0] == 0.0 && c[2] == 1.0);
    // Breakpoints: union of opacity and colour scalars.
    assert_eq!(
        tf.breakpoints(),
        &[0.0, 0.28, 0.3, 0.4, 0.45, 0.6, 0.62, 0.75, 0.8, 1.0]
    );
}

const PROJECT: &str = r#"{
  "zoovr_tf": 1,
  "scalar": "Density",
  "emission": "glow",
  "unit_distance": 0.5,
  "points": [
    { "s": 0.0, "opacity": 0.0, "rgb": [0.0, 0.0, 1.0] },
    { "s": 0.4, "opacity": 0.5, "rgb": [0.0, 0.6, 1.0] },
    { "s": 0.4, "tau": 3.0,     "rgb": [1.0, 0.2, 0.0] },
    { "s": 1.0, "tau": 0.5,     "rgb": [0.8, 0.0, 0.3] }
  ]
}"#;

#[test]
fn project_format_with_jump_and_round_trip() {
    let tf = TransferFunction::from_json_str(PROJECT, 1.0).expect("loads");
    assert_eq!(tf.scalar.as_deref(), Some("Density"));
    assert!((tf.tau_at(0.2) - 0.5).abs() < 1e-15);
    assert_eq!(tf.tau_at(0.4), 3.0); // right-continuous at the jump
    assert!((tf.tau_at(0.39999999) - 1.0).abs() < 1e-6);
    assert_eq!(tf.nodes().len(), 4);
    let again = TransferFunction::from_json_str(&tf.to_json(), 1.0).expect("round trip");
    assert_eq!(again.nodes(), tf.nodes());
    assert_eq!(again.scalar, tf.scalar);
}

#[test]
fn independent_emission_and_separate_lists() {
    let text = r#"{ "zoovr_tf": 1, "emission": "independent",
        "extinction_points": [ {"s": 0, "tau": 0}, {"s": 10, "tau": 2} ],
        "color_points": [ {"s": 0, "rgb": [1, 1, 1]} ],
        "emission_points": [ {"s": 0, "rgb": [0, 0, 0]}, {"s": 5, "rgb": [1, 2, 3]} ] }"#;
    let tf = TransferFunction::from_json_str(text, 1.0).expect("loads");
    assert_eq!(tf.model(), EmissionModel::Independent);
    let m = tf.material(2.5);
    assert!((m.tau - 0.5).abs() < 1e-15);
    assert_eq!(m.source, [0.5, 1.0, 1.5]);
    assert_eq!(tf.material(7.0).source, [1.0, 2.0, 3.0]);
    let back = TransferFunction::from_json_str(&tf.to_json(), 1.0).expect("round trip");
    assert_eq!(back.nodes(), tf.nodes());
    assert_eq!(back.model(), EmissionModel::Independent);
}

#[test]
fn paraview_colour_maps() {
    // Array form, RGB space, opacity points with default midpoint/sharpness.
    let pv = r#"[{ "Name": "test", "ColorSpace": "RGB",
        "RGBPoints": [0, 0, 0, 1, 10, 1, 0, 0],
        "Points": [0, 0, 0.5, 0, 10, 0.8, 0.5, 0] }]"#;
    let tf = TransferFunction::from_json_str(pv, 2.0).expect("loads");
    assert!((tf.tau_at(5.0) - 0.2).abs() < 1e-15);
    assert_eq!(tf.color_at(5.0), [0.5, 0.0, 0.5]);
    assert_eq!(tf.breakpoints(), &[0.0, 10.0]);
    // Object form, Lab space, no opacity: resampled into 32 pieces, ramp.
    let lab = r#"{ "ColorSpace": "Lab", "RGBPoints": [0, 0, 0, 1, 1, 1, 1, 0] }"#;
    let tf = TransferFunction::from_json_str(lab, 1.0).expect("loads");
    assert_eq!(tf.breakpoints().len(), 33);
    assert_eq!(tf.color_at(0.0), [0.0, 0.0, 1.0]);
    assert_eq!(tf.color_at(1.0), [1.0, 1.0, 0.0]);
    assert!((tf.tau_at(0.5) - 0.5).abs() < 1e-15);
    // Lab interpolation of blue -> yellow passes through a grey, unlike RGB.
    let mid = tf.color_at(0.5);
    assert!((mid[0] - mid[2]).abs() < 0.15, "{mid:?}");
    // Non-default midpoint/sharpness: resampled, stays within the end values.
    let sharp =
        r#"{ "RGBPoints": [0, 1, 1, 1, 1, 1, 1, 1], "Points": [0, 0, 0.3, 0.5, 1, 1, 0.5, 0] }"#;
    let tf = TransferFunction::from_json_str(sharp, 1.0).expect("loads");
    assert_eq!(tf.breakpoints().len(), 33);
    assert!((0.0..=1.0).contains(&tf.tau_at(0.3)));
}

fn err(text: &str) -> TfError {
    TransferFunction::from_json_str(text, 1.0).expect_err("must fail")
}

#[test]
fn bad_files_give_typed_errors() {
    // Syntax error with line and column.
    match err("{\n  \"points\": [\n    {\"s\": 0, }\n  ]\n}") {
        TfError::Json { line, column, .. } => assert_eq!((line, column), (3, 14)),
        e => panic!("{e}"),
    }
    // NaN is not JSON.
    assert!(matches!(
        err(r#"{"points": [{"s": NaN, "tau": 1, "rgb": [0,0,0]}]}"#),
        TfError::Json { .. }
    ));
    // Type error also located.
    match err("{\n \"points\": [{\"s\": \"zero\", \"tau\": 1, \"rgb\": [0,0,0]}]}") {
        TfError::Json { line, .. } => assert_eq!(line, 2),
        e => panic!("{e}"),
    }
    assert!(matches!(
        err(
            r#"{"points": [{"s": 1, "tau": 1, "rgb": [0,0,0]}, {"s": 0, "tau": 1, "rgb": [0,0,0]}]}"#
        ),
        TfError::Unsorted { index: 1, .. }
    ));
    assert!(matches!(
        err(r#"{"points": [{"s": 0, "tau": -1, "rgb": [0,0,0]}]}"#),
        TfError::Negative { .. }
    ));
    assert!(matches!(err(r#"{"points": []}"#), TfError::Empty));
    assert!(matches!(
        err(r#"{"points": [{"s": 0, "tau": 1e150, "rgb": [0,0,0]}]}"#),
        TfError::OutOfRange { .. }
    ));
    assert!(matches!(
        err(r#"{"zoovr_tf": 2, "points": []}"#),
        TfError::Version(2)
    ));
    assert!(matches!(
        err(r#"{"points": [{"s": 0, "opacity": 1.5, "rgb": [0,0,0]}]}"#),
        TfError::OpacityRange { .. }
    ));
    assert!(matches!(err(r#"{"pionts": []}"#), TfError::Json { .. }));
    assert!(matches!(
        err(r#"{"points": [{"s": 0, "rgb": [0,0,0]}]}"#),
        TfError::Format(_)
    ));
    assert!(matches!(
        err(r#"{"RGBPoints": [0, 1, 1]}"#),
        TfError::Format(_)
    ));
    assert!(matches!(err(r#"[]"#), TfError::Empty));
    assert!(matches!(
        err(r#"{"RGBPoints": [1, 0, 0, 0, 0, 1, 1, 1]}"#),
        TfError::Unsorted { .. }
    ));
    assert!(matches!(
        TransferFunction::from_json_str(PROJECT.replace("0.5,\n", "-1,\n").as_str(), 1.0),
        Err(TfError::UnitDistance(_))
    ));
    let e = err("{\n  \"points\": [\n    {\"s\": 0, }\n  ]\n}");
    assert!(e.to_string().contains("line 3, column 14"), "{e}");
}

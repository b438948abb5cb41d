//! The golden vectors of the segment integral (`tests/data/golden.json`:
//! mpmath, 50 digits; format in docs/math.md section 7) and readers of its
//! numbers, shared by the tests that check an integrator against them.
#![allow(dead_code)]

use serde_json::Value;

/// The parsed golden file.
pub fn golden() -> Value {
    let p = zoovr::testdata::project_root().join("tests/data/golden.json");
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&text).expect("golden.json parses")
}

/// A number of the file.
pub fn f(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

/// An RGB triple of the file.
pub fn rgb(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    [f(&a[0]), f(&a[1]), f(&a[2])]
}

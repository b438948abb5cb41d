//! Every vector of `tests/data/golden.json` (mpmath reference, 50 digits;
//! format in docs/math.md section 7):
//! 200 segments (basis integrals, both emission models, through `weights`
//! and through a two-node transfer function) and 10 whole rays, within the
//! file's recommended tolerances.

// Channels are compared across parallel arrays by index.
#![allow(clippy::needless_range_loop)]

mod golden_util;

use golden_util::{f, golden, rgb};
use serde_json::Value;
use zoovr::integrate::{self, weights};
use zoovr::tf::{EmissionModel, Node, TransferFunction};

fn close(got: f64, exp: f64, what: &str, id: &str) {
    let tol = 1e-12 * exp.abs() + 1e-300;
    assert!(
        (got - exp).abs() <= tol,
        "{id} {what}: got {got:e}, expected {exp:e} (diff {:e})",
        (got - exp).abs()
    );
}

#[test]
fn golden_segments() {
    let g = golden();
    let segs = g["segments"].as_array().expect("segments");
    assert_eq!(segs.len(), 200);
    for seg in segs {
        let id = seg["id"].as_str().unwrap_or("?");
        let inp = &seg["inputs"];
        let exp = &seg["expected"];
        let (l, tf_, tb) = (f(&inp["l"]), f(&inp["tau_f"]), f(&inp["tau_b"]));
        let (cf, cb, ef, eb) = (
            rgb(&inp["c_f"]),
            rgb(&inp["c_b"]),
            rgb(&inp["E_f"]),
            rgb(&inp["E_b"]),
        );
        let (a, b) = (tf_ * l, tb * l);
        let w = weights(a, b);
        for (name, got) in [
            ("alpha", w.alpha),
            ("psi", w.psi),
            ("phi_f", w.phi_f),
            ("phi_b", w.phi_b),
            ("w_f", w.w_f),
            ("w_b", w.w_b),
        ] {
            close(got, f(&exp[name]), name, id);
        }
        let t_exp = f(&exp["T"]);
        let t_tol = (1e-12 + 2.3e-16 * 0.5 * (a + b)) * t_exp + 1e-300;
        assert!((w.t - t_exp).abs() <= t_tol, "{id} T: {} vs {t_exp}", w.t);
        let ca = rgb(&exp["C_associated"]);
        let ce = rgb(&exp["C_emission"]);
        for k in 0..3 {
            close(cf[k] * w.w_f + cb[k] * w.w_b, ca[k], "C_associated", id);
            close(
                l * (ef[k] * w.phi_f + eb[k] * w.phi_b),
                ce[k],
                "C_emission",
                id,
            );
        }
        // The same segment through a transfer function (scalar 0 -> 1 over
        // one linear piece), both models.
        for (model, expected) in [(EmissionModel::Glow, ca), (EmissionModel::Independent, ce)] {
            let nodes = [
                Node {
                    s: 0.0,
                    tau: tf_,
                    color: cf,
                    emission: ef,
                },
                Node {
                    s: 1.0,
                    tau: tb,
                    color: cb,
                    emission: eb,
                },
            ];
            let tf = TransferFunction::from_nodes(&nodes, model).expect("valid");
            let v = integrate::segment(&tf, l, 0.0, 1.0);
            close(v.alpha, f(&exp["alpha"]), "segment alpha", id);
            for k in 0..3 {
                close(v.color[k], expected[k], "segment C", id);
            }
        }
    }
}

fn ray_tf(tf: &Value, model: EmissionModel) -> TransferFunction {
    let s: Vec<f64> = tf["s"].as_array().expect("s").iter().map(f).collect();
    let tau: Vec<f64> = tf["tau"].as_array().expect("tau").iter().map(f).collect();
    let c: Vec<[f64; 3]> = tf["c"].as_array().expect("c").iter().map(rgb).collect();
    let e: Vec<[f64; 3]> = tf["E"].as_array().expect("E").iter().map(rgb).collect();
    let nodes: Vec<Node> = (0..s.len())
        .map(|i| Node {
            s: s[i],
            tau: tau[i],
            color: c[i],
            emission: e[i],
        })
        .collect();
    TransferFunction::from_nodes(&nodes, model).expect("valid golden TF")
}

#[test]
fn golden_rays() {
    let g = golden();
    let rays = g["rays"].as_array().expect("rays");
    assert_eq!(rays.len(), 10);
    for ray in rays {
        let id = ray["id"].as_str().unwrap_or("?");
        let cells: Vec<(f64, f64, f64)> = ray["cells"]
            .as_array()
            .expect("cells")
            .iter()
            .map(|c| (f(&c[0]), f(&c[1]), f(&c[2])))
            .collect();
        for (model, key) in [
            (EmissionModel::Glow, "associated"),
            (EmissionModel::Independent, "emission"),
        ] {
            let tf = ray_tf(&ray["tf"], model);
            let (c, alpha) = integrate::ray(&tf, &cells);
            let exp = &ray["expected"][key];
            close(alpha, f(&exp["alpha"]), "ray alpha", id);
            let ce = rgb(&exp["C"]);
            for k in 0..3 {
                close(c[k], ce[k], key, id);
            }
        }
    }
}

#[test]
fn golden_slices_match_the_slicing_rule() {
    let g = golden();
    // The optical depth of each cell equals the sum over the file's
    // `slices_double` (sub-segments of the slicing rule): tells a slicing bug
    // from an integration bug.
    for ray in g["rays"].as_array().expect("rays") {
        let tf = ray_tf(&ray["tf"], EmissionModel::Glow);
        let cells = ray["cells"].as_array().expect("cells");
        let slices = ray["slices_double"].as_array().expect("slices");
        for (cell, sl) in cells.iter().zip(slices) {
            let (l, sf, sb) = (f(&cell[0]), f(&cell[1]), f(&cell[2]));
            let exp_depth: f64 = sl
                .as_array()
                .expect("slice list")
                .iter()
                .map(|p| 0.5 * f(&p[0]) * (f(&p[1]) + f(&p[2])))
                .sum();
            let got = integrate::segment(&tf, l, sf, sb).depth;
            assert!(
                (got - exp_depth).abs() <= 1e-13 * exp_depth.abs() + 1e-300,
                "{} depth {got} vs {exp_depth}",
                ray["id"]
            );
        }
    }
}

//! Pre-integration tables: texels equal the exact integrals, local updates
//! equal full refills, and the interpolation error of every table kind
//! against the exact integral over a dense random sample, as a function of
//! resolution (printed with `--nocapture`; thresholds asserted).

// Channels are compared across parallel arrays by index.
#![allow(clippy::needless_range_loop)]

use zoovr::integrate::cylinder::{cyl_to_table, CylinderTable};
use zoovr::integrate::fast::FastColour;
use zoovr::integrate::table2d::{Table2d, Table2dKind};
use zoovr::integrate::table3d::Table3d;
use zoovr::integrate::{self, TableError};
use zoovr::tf::{EmissionModel, Node, TransferFunction};

fn node(s: f64, tau: f64, c: [f64; 3]) -> Node {
    Node {
        s,
        tau,
        color: c,
        emission: [0.0; 3],
    }
}

/// Smooth TF (no jumps), extinction up to 6.
fn smooth_tf() -> TransferFunction {
    TransferFunction::from_nodes(
        &[
            node(0.0, 0.0, [0.0, 0.0, 1.0]),
            node(0.3, 1.0, [0.0, 0.6, 1.0]),
            node(0.5, 6.0, [0.1, 0.9, 0.3]),
            node(0.7, 2.0, [1.0, 0.9, 0.0]),
            node(1.0, 0.5, [0.8, 0.0, 0.3]),
        ],
        EmissionModel::Glow,
    )
    .unwrap()
}

/// TF with a jump at 0.35, extinction up to 8.
fn jump_tf() -> TransferFunction {
    TransferFunction::from_nodes(
        &[
            node(0.0, 0.0, [1.0, 0.0, 0.0]),
            node(0.2, 2.0, [1.0, 0.5, 0.0]),
            node(0.35, 5.0, [1.0, 1.0, 0.0]),
            node(0.35, 0.5, [0.0, 1.0, 0.0]),
            node(0.6, 8.0, [0.0, 1.0, 1.0]),
            node(0.8, 1.0, [0.0, 0.0, 1.0]),
            node(1.0, 0.0, [1.0, 0.0, 1.0]),
        ],
        EmissionModel::Glow,
    )
    .unwrap()
}

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `(C rms, C max, alpha rms, alpha max)` of a lookup against the exact
/// integral over `n` random segments, `s in [0, 1]`, `l in [0, l_max]`.
fn measure(
    tf: &TransferFunction,
    l_max: f64,
    n: usize,
    lookup: impl Fn(f64, f64, f64) -> [f64; 4],
) -> [f64; 4] {
    let mut r = Rng(0xDEAD_BEEF_1234_5678);
    let (mut c2, mut cm, mut a2, mut am) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..n {
        let (sf, sb, l) = (r.next(), r.next(), r.next() * l_max);
        let exact = integrate::segment(tf, l, sf, sb);
        let got = lookup(sf, sb, l);
        for k in 0..3 {
            let e = (got[k] - exact.color[k]).abs();
            c2 += e * e / 3.0;
            cm = cm.max(e);
        }
        let e = (got[3] - exact.alpha).abs();
        a2 += e * e;
        am = am.max(e);
    }
    [(c2 / n as f64).sqrt(), cm, (a2 / n as f64).sqrt(), am]
}

fn row(name: &str, res: &str, e: [f64; 4]) {
    eprintln!(
        "| {name} | {res} | {:.1e} | {:.1e} | {:.1e} | {:.1e} |",
        e[0], e[1], e[2], e[3]
    );
}

#[test]
fn table3d_texels_are_exact_integrals_and_lookup_hits_them() {
    let tf = jump_tf();
    let t = Table3d::exact(&tf, 17, 9, (0.0, 1.0), 2.0).unwrap();
    assert_eq!(t.extent(), (17, 17, 9));
    assert_eq!(t.bytes().len(), 17 * 17 * 9 * 16);
    for &(i, j, k) in &[(0, 0, 0), (3, 11, 4), (16, 2, 8), (7, 7, 5)] {
        let (sf, sb, l) = (i as f64 / 16.0, j as f64 / 16.0, k as f64 / 4.0);
        let e = integrate::segment(&tf, l, sf, sb);
        let tx = t.texel(i, j, k);
        let want = [e.color[0], e.color[1], e.color[2], e.alpha];
        for c in 0..4 {
            assert_eq!(tx[c], want[c] as f32 as f64);
        }
        assert_eq!(t.lookup(sf, sb, l), tx);
    }
    // Clamped outside the range.
    assert_eq!(t.lookup(-1.0, 2.0, 9.0), t.texel(0, 16, 8));
}

#[test]
fn local_update_equals_full_refill() {
    let old = smooth_tf();
    let mut nodes = old.nodes();
    nodes[2].tau = 1.5; // change at s = 0.5: affects (0.3, 0.7)
    nodes[2].color = [1.0, 0.0, 0.0];
    let new = TransferFunction::from_nodes(&nodes, EmissionModel::Glow).unwrap();
    let mut t = Table3d::exact(&old, 33, 8, (0.0, 1.0), 1.0).unwrap();
    t.update(&new, 0.3, 0.7);
    let full = Table3d::exact(&new, 33, 8, (0.0, 1.0), 1.0).unwrap();
    assert_eq!(t.data, full.data);
    let mut f = Table3d::fast(&old, 33, 8, (0.0, 1.0), 1.0, FastColour::MeanGlow).unwrap();
    f.update(&new, 0.7, 0.3);
    let full = Table3d::fast(&new, 33, 8, (0.0, 1.0), 1.0, FastColour::MeanGlow).unwrap();
    for (a, b) in f.data.iter().zip(&full.data) {
        assert!((a - b).abs() <= 1e-6 * b.abs().max(1e-3), "{a} {b}");
    }
    let mut t2 = Table2d::new(&old, 33, (0.0, 1.0), 0.5, Table2dKind::DepthGlow).unwrap();
    t2.update(&new, 0.3, 0.7);
    let full2 = Table2d::new(&new, 33, (0.0, 1.0), 0.5, Table2dKind::DepthGlow).unwrap();
    assert_eq!(t2.data, full2.data);
    let mut c = CylinderTable::new(&old, 33, 17, (0.0, 1.0), 0.5).unwrap();
    c.update(&new, 0.7, 0.3);
    let full_c = CylinderTable::new(&new, 33, 17, (0.0, 1.0), 0.5).unwrap();
    assert_eq!(c.data, full_c.data);
    let mut stale_c = CylinderTable::new(&old, 33, 17, (0.0, 1.0), 0.5).unwrap();
    stale_c.update(&new, 0.9, 1.0);
    assert_ne!(stale_c.data, full_c.data);
    // The unchanged corner really was not recomputed: an update over an
    // interval that misses the change leaves the old values in place.
    let mut stale = Table3d::exact(&old, 33, 8, (0.0, 1.0), 1.0).unwrap();
    stale.update(&new, 0.9, 1.0);
    assert_ne!(stale.data, full.data);
}

#[test]
fn fast_fill_has_exact_opacity_and_bounded_colour() {
    let tf = jump_tf();
    let f = Table3d::fast(&tf, 33, 9, (0.0, 1.0), 1.0, FastColour::MeanGlow).unwrap();
    for i in 0..33 {
        for j in 0..33 {
            for k in 0..9 {
                let e = integrate::segment(&tf, k as f64 / 8.0, i as f64 / 32.0, j as f64 / 32.0);
                let tx = f.texel(i, j, k);
                assert!(
                    (tx[3] - e.alpha).abs() < 1e-6,
                    "alpha {} vs {}",
                    tx[3],
                    e.alpha
                );
                // Mean glow x alpha: bounded by the colour range (<= 1).
                assert!(tx[..3].iter().all(|&c| (0.0..=1.0 + 1e-6).contains(&c)));
            }
        }
    }
}

#[test]
fn cylinder_texels_are_exact_on_their_planes() {
    let tf = smooth_tf();
    let t = CylinderTable::new(&tf, 17, 9, (0.0, 1.0), 2.0).unwrap();
    for &(p, iu, iv) in &[(0usize, 4usize, 8usize), (3, 16, 0), (6, 9, 12), (8, 5, 5)] {
        let (a, u, v) = (p as f64 / 8.0, iu as f64 / 16.0, iv as f64 / 16.0);
        let (sf, sb, l) = cyl_to_table(a, u, v);
        let e = integrate::segment(&tf, 2.0 * l, sf, sb);
        let o = 4 * ((p * 17 + iv) * 17 + iu);
        assert_eq!(t.data[o + 3], e.alpha as f32);
        assert_eq!(t.data[o], e.color[0] as f32);
    }
    assert!(matches!(
        CylinderTable::new(&tf, 1, 9, (0.0, 1.0), 1.0),
        Err(TableError::Dimension { .. })
    ));
    assert!(Table3d::exact(&tf, 4096, 4096, (0.0, 1.0), 1.0).is_err());
    assert!(Table2d::new(&tf, 8, (0.0, 1.0), 0.0, Table2dKind::LinearInL).is_err());
}

/// Error tables against the exact integrals at modest resolutions (fast);
/// thresholds are loose upper bounds (about 2x) of the measured values, so a
/// regression in filling or interpolation fails.
#[test]
fn table_errors_against_exact_integrals() {
    error_tables(false);
}

/// The full error report (up to 128x128x64; about 10 s at opt-level 1):
/// `cargo test --test integrate_tables -- --ignored --nocapture`.
#[test]
#[ignore = "slow: full resolution sweep for the report"]
fn table_error_report() {
    error_tables(true);
}

fn error_tables(full: bool) {
    let n = if full { 4000 } else { 1500 };
    let res3: &[(usize, usize)] = if full {
        &[(16, 16), (32, 16), (64, 32), (128, 64)]
    } else {
        &[(16, 16), (32, 16), (64, 32)]
    };
    let res_fast: &[(usize, usize)] = if full {
        &[(64, 32), (128, 64)]
    } else {
        &[(64, 32)]
    };
    let res2: &[usize] = if full { &[64, 256] } else { &[64] };
    let res_cyl: &[(usize, usize)] = if full {
        &[(32, 32), (64, 64), (64, 256), (128, 128), (128, 512)]
    } else {
        &[(32, 32), (64, 128)]
    };
    let l_max = 1.0;
    eprintln!("| table | resolution | C rms | C max | alpha rms | alpha max |");
    eprintln!("| --- | --- | --- | --- | --- | --- |");
    for (tf_name, tf) in [("smooth", smooth_tf()), ("jump", jump_tf())] {
        let mut prev_rms = f64::INFINITY;
        for &(ns, nl) in res3 {
            let t = Table3d::exact(&tf, ns, nl, (0.0, 1.0), l_max).unwrap();
            let e = measure(&tf, l_max, n, |a, b, l| t.lookup(a, b, l));
            row(
                &format!("3D exact, {tf_name}"),
                &format!("{ns}x{ns}x{nl}"),
                e,
            );
            assert!(e[0] < prev_rms, "3D error must fall with resolution");
            prev_rms = e[0];
            if ns == 64 && tf_name == "smooth" {
                assert!(e[1] < 0.02 && e[3] < 0.012, "{e:?}");
            }
        }
        for &(ns, nl) in res_fast {
            let t = Table3d::fast(&tf, ns, nl, (0.0, 1.0), l_max, FastColour::MeanGlow).unwrap();
            let e = measure(&tf, l_max, n, |a, b, l| t.lookup(a, b, l));
            row(
                &format!("3D integral functions (mean glow), {tf_name}"),
                &format!("{ns}x{ns}x{nl}"),
                e,
            );
            let t =
                Table3d::fast(&tf, ns, nl, (0.0, 1.0), l_max, FastColour::NoAttenuation).unwrap();
            let e2 = measure(&tf, l_max, n, |a, b, l| t.lookup(a, b, l));
            row(
                &format!("3D integral functions (no attenuation), {tf_name}"),
                &format!("{ns}x{ns}x{nl}"),
                e2,
            );
            assert!(e[0] < e2[0], "mean glow beats no attenuation");
        }
        for &ns in res2 {
            for (kind, name) in [
                (Table2dKind::LinearInL, "2D linear in l"),
                (Table2dKind::DepthGlow, "2D depth + glow"),
            ] {
                let t = Table2d::new(&tf, ns, (0.0, 1.0), 0.5 * l_max, kind).unwrap();
                let e = measure(&tf, l_max, n, |a, b, l| t.lookup(a, b, l));
                row(
                    &format!("{name}, {tf_name}"),
                    &format!("{ns}x{ns}, l_ref = 0.5"),
                    e,
                );
            }
        }
        for &(ns, planes) in res_cyl {
            let t = CylinderTable::new(&tf, ns, planes, (0.0, 1.0), l_max).unwrap();
            let e = measure(&tf, l_max, n, |a, b, l| t.lookup(a, b, l));
            row(
                &format!("cylindrical, {tf_name}"),
                &format!("{ns}x{ns}x{planes} planes"),
                e,
            );
            if tf_name == "smooth" && ns == 64 {
                assert!(e[1] < 0.03 && e[3] < 0.03, "{e:?}");
            }
        }
    }
    // Thin segments: the depth + glow 2D table keeps the opacity exact up to
    // interpolation, the linear one does not.
    let tf = smooth_tf();
    let lin = Table2d::new(&tf, 128, (0.0, 1.0), 1.0, Table2dKind::LinearInL).unwrap();
    let dg = Table2d::new(&tf, 128, (0.0, 1.0), 1.0, Table2dKind::DepthGlow).unwrap();
    let e_lin = measure(&tf, 1.0, n, |a, b, l| lin.lookup(a, b, l));
    let e_dg = measure(&tf, 1.0, n, |a, b, l| dg.lookup(a, b, l));
    assert!(e_dg[3] < e_lin[3], "{e_dg:?} {e_lin:?}");
}

/// The cylindrical re-mapping of a 3D table reproduces the 3D table at its
/// texels' equation-9 coordinates, and its error against the exact integral
/// is close to that of the table it came from.
#[test]
fn cylinder_from_table3d_carries_the_3d_table() {
    let tf = smooth_tf();
    let t3 = Table3d::exact(&tf, 33, 17, (0.0, 1.0), 1.0).unwrap();
    let c = CylinderTable::from_table3d(&t3, 4 * 33).unwrap();
    assert_eq!((c.s_axis, c.l_max), (t3.s_axis, 1.0));
    let ns = 33;
    for p in [0, 17, 66, 100, 131] {
        for (iu, iv) in [(0, 0), (5, 9), (32, 16), (20, 32)] {
            let a = p as f64 / 131.0;
            let (sf, sb, l) = cyl_to_table(a, iu as f64 / 32.0, iv as f64 / 32.0);
            let want = t3.lookup(sf, sb, l);
            let o = 4 * ((p * ns + iv) * ns + iu);
            for k in 0..4 {
                assert!(
                    (c.data[o + k] as f64 - want[k]).abs() < 1e-6,
                    "{p} {iu} {iv}"
                );
            }
        }
    }
    let e3 = measure(&tf, 1.0, 1500, |a, b, l| t3.lookup(a, b, l));
    let ec = measure(&tf, 1.0, 1500, |a, b, l| c.lookup(a, b, l));
    assert!(
        ec[0] < 2.0 * e3[0] + 1e-4 && ec[2] < 2.0 * e3[2] + 1e-4,
        "{ec:?} vs {e3:?}"
    );
}

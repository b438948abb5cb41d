//! Synthetic meshes for tests, benchmarks and `meshes/`: deterministic, no
//! files needed.
//!
//! - [`warped_hex_grid`]: an `nx x ny x nz` curvilinear hexahedral grid on the
//!   unit cube, moved by a smooth warp (a sum of sines with
//!   seed-dependent phases) that bends every quad face out of its plane
//!   while keeping every cell positively oriented (the warp's Jacobian stays
//!   within `amplitude * 2 pi` of the identity; keep `amplitude <= 0.08`).
//!   Point order is VTK's structured order (i fastest), hexahedra are in VTK
//!   node order, positively oriented. Point scalar `f` (Float32) in [0, 1].
//! - [`zoo_grid`]: a conforming grid of all four zoo kinds on the unit cube:
//!   hexahedra (first third in x), wedge columns (second third: every cube
//!   split by the vertical plane through its nodes 0 and 2, whole columns so
//!   the triangles match), and "pyramid cubes" (last third: six pyramids
//!   from an added centre point; a pyramid whose base is shared with another
//!   pyramid cube or lies on the boundary is split into two tetrahedra by the
//!   smallest-vertex diagonal, so neighbours agree).
//! - [`ring_grid`]: a square ring of hexahedra (a square hole through the
//!   middle): non-convex, one component.
//! - [`time_series`]: the warped grid with `f` advancing in time.
//! - [`flow_series`]: a curved channel (three quarters of an annulus, so
//!   non-convex, its faces bent out of plane by a wavy floor and roof) with
//!   the speed of an analytic flow in it: a free vortex `1 / r` around the
//!   channel's axis carrying a Gaussian puff that travels along it. Same
//!   points and cells in every step, only the values move: the example
//!   series in `meshes/flow/`.
//! - [`ghost_grid`]: the warped grid as VTK exports a reservoir grid with
//!   inactive cells: a `vtkGhostType` cell array marking some cells hidden
//!   and some duplicate, VTK's id arrays, an integer and a float cell array.
//!
//! Every generated mesh is positively oriented and conforming; tests rely
//! on that (no inverted consistent tetrahedra).

use glam::DVec3;

use crate::field::{ArrayData, DataArray};
use crate::mesh::{lattice_hex, CellKind, Mesh, SourceInfo};

/// Warp parameters for [`warped_hex_grid`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Warp {
    /// Displacement amplitude in units of the unit cube (0 = straight grid).
    pub amplitude: f64,
    /// Seed for the phases of the warp (deterministic).
    pub seed: u64,
}

impl Default for Warp {
    fn default() -> Self {
        Warp {
            amplitude: 0.05,
            seed: 1,
        }
    }
}

fn phases(seed: u64) -> [f64; 6] {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    std::array::from_fn(|_| {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU
    })
}

/// The warp applied to a point of the unit cube.
pub fn warp_point(p: DVec3, w: &Warp) -> DVec3 {
    use std::f64::consts::TAU;
    let ph = phases(w.seed);
    let a = w.amplitude;
    DVec3::new(
        p.x + a * (TAU * p.y + ph[0]).sin() * (TAU * p.z + ph[1]).sin(),
        p.y + a * (TAU * p.z + ph[2]).sin() * (TAU * p.x + ph[3]).sin(),
        p.z + a * (TAU * p.x + ph[4]).sin() * (TAU * p.y + ph[5]).sin(),
    )
}

/// The smooth scalar `f` in [0, 1] at a point (and time `t`).
pub fn scalar_f(p: DVec3, t: f64) -> f64 {
    0.5 + 0.5 * (3.0 * p.x + 2.0 * p.y - 1.0 + t).sin() * (2.5 * p.z + 0.5 * t).cos()
}

fn f_array(points: &[DVec3], t: f64) -> DataArray {
    DataArray {
        name: "f".into(),
        components: 1,
        data: ArrayData::F32(points.iter().map(|&p| scalar_f(p, t) as f32).collect()),
        vtk_type: "Float32".into(),
    }
}

fn finish(mut mesh: Mesh, t: f64) -> Mesh {
    let mut by_type = std::collections::BTreeMap::new();
    for &k in &mesh.cells.kinds {
        *by_type.entry(k.vtk_name().to_string()).or_insert(0) += 1;
    }
    mesh.point_data.push(f_array(&mesh.points, t));
    mesh.active_point_scalars = Some("f".into());
    mesh.source = SourceInfo {
        cells_by_type: by_type,
        ..Default::default()
    };
    mesh
}

/// Grid points of the unit cube, warped.
fn grid_points(nx: usize, ny: usize, nz: usize, w: &Warp) -> Vec<DVec3> {
    let mut pts = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let p = DVec3::new(
                    i as f64 / nx.max(1) as f64,
                    j as f64 / ny.max(1) as f64,
                    k as f64 / nz.max(1) as f64,
                );
                pts.push(warp_point(p, w));
            }
        }
    }
    pts
}

/// An `n x n x n` warped hexahedral grid (see the module docs).
pub fn warped_hex_grid(n: usize, warp: &Warp) -> Mesh {
    warped_hex_grid_dims([n, n, n], warp)
}

/// An `nx x ny x nz` warped hexahedral grid.
pub fn warped_hex_grid_dims(dims: [usize; 3], warp: &Warp) -> Mesh {
    let [nx, ny, nz] = dims;
    let mut mesh = Mesh {
        points: grid_points(nx, ny, nz, warp),
        ..Default::default()
    };
    let cells = &mut mesh.cells;
    let n = nx * ny * nz;
    cells.kinds = vec![CellKind::Hexahedron; n];
    cells.offsets = (0..=n as u32).map(|c| c * 8).collect();
    cells.conn.reserve(n * 8);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                cells
                    .conn
                    .extend_from_slice(&lattice_hex(nx + 1, ny + 1, [i, j, k]));
            }
        }
    }
    if n == 0 {
        cells.offsets.clear();
    }
    finish(mesh, 0.0)
}

/// Value of the [`ghost_grid`] cell array `value` in hidden cells (an
/// "inactive" marker far outside the other cells' range).
pub const GHOST_GRID_HIDDEN_VALUE: f32 = -999.0;

/// The `vtkGhostType` flags of cell `(i, j, k)` of an `n`-grid in
/// [`ghost_grid`]: 32 (hidden) where `(i + 2j + 3k) % 5 == 0`, plus 1
/// (duplicate) on the column `i = n - 1, j = 1` (for `n = 4` its bottom
/// cell has both flags).
pub fn ghost_grid_flags(n: usize, i: usize, j: usize, k: usize) -> u8 {
    let mut g = 0;
    if (i + 2 * j + 3 * k) % 5 == 0 {
        g |= 32;
    }
    if i + 1 == n && j == 1 {
        g |= 1;
    }
    g
}

/// An `n x n x n` warped hexahedral grid shaped like VTK's export of a
/// reservoir grid with inactive cells. Point data: `vtkOriginalPointIds`
/// (Int64) only. Cell data, in this order: `vtkGhostType` (UInt8, the flags
/// of [`ghost_grid_flags`]), `vtkOriginalCellIds` (Int64), `layer` (Int32,
/// the `k` index) and `value` (Float32: [`scalar_f`] at the cell centre;
/// 2 in duplicate cells and [`GHOST_GRID_HIDDEN_VALUE`] in hidden ones, so
/// a range over every cell differs from the range over the others).
pub fn ghost_grid(n: usize, warp: &Warp) -> Mesh {
    let mut mesh = warped_hex_grid(n, warp);
    mesh.point_data.clear();
    mesh.active_point_scalars = None;
    let np = mesh.points.len() as i64;
    let (mut ghost, mut layer, mut value) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let g = ghost_grid_flags(n, i, j, k);
                let c = ghost.len();
                let centre = mesh
                    .cells
                    .nodes(c)
                    .iter()
                    .map(|&p| mesh.points[p as usize])
                    .sum::<DVec3>()
                    / 8.0;
                ghost.push(g as i64);
                layer.push(k as i64);
                value.push(if g & 32 != 0 {
                    GHOST_GRID_HIDDEN_VALUE
                } else if g & 1 != 0 {
                    2.0
                } else {
                    scalar_f(centre, 0.0) as f32
                });
            }
        }
    }
    let nc = ghost.len() as i64;
    let int = |name: &str, vtk_type: &str, data: Vec<i64>| DataArray {
        name: name.into(),
        components: 1,
        data: ArrayData::Int(data),
        vtk_type: vtk_type.into(),
    };
    mesh.point_data = vec![int("vtkOriginalPointIds", "Int64", (0..np).collect())];
    mesh.cell_data = vec![
        int("vtkGhostType", "UInt8", ghost),
        int("vtkOriginalCellIds", "Int64", (0..nc).collect()),
        int("layer", "Int32", layer),
        DataArray {
            name: "value".into(),
            components: 1,
            data: ArrayData::F32(value),
            vtk_type: "Float32".into(),
        },
    ];
    mesh
}

/// The kind of cube `i` of `n` along x in [`zoo_grid`].
#[derive(Clone, Copy, PartialEq, Eq)]
enum Block {
    Hex,
    Wedges,
    Pyramids,
}

fn block(i: isize, n: usize) -> Option<Block> {
    if i < 0 || i >= n as isize {
        return None;
    }
    let i = i as usize;
    Some(if 3 * i < n {
        Block::Hex
    } else if 3 * i < 2 * n {
        Block::Wedges
    } else {
        Block::Pyramids
    })
}

/// A conforming `n x n x n` grid of hexahedra, wedges, pyramids and
/// tetrahedra (see the module docs); `n >= 3` gives all four kinds.
pub fn zoo_grid(n: usize, warp: &Warp) -> Mesh {
    use crate::mesh::tetra::triangulate_face;
    let mut mesh = Mesh {
        points: grid_points(n, n, n, warp),
        ..Default::default()
    };
    let h = 1.0 / n.max(1) as f64;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = lattice_hex(n + 1, n + 1, [i, j, k]);
                match block(i as isize, n) {
                    Some(Block::Hex) | None => mesh.cells.push(CellKind::Hexahedron, &c),
                    Some(Block::Wedges) => {
                        mesh.cells
                            .push(CellKind::Wedge, &[c[0], c[1], c[2], c[4], c[5], c[6]]);
                        mesh.cells
                            .push(CellKind::Wedge, &[c[0], c[2], c[3], c[4], c[6], c[7]]);
                    }
                    Some(Block::Pyramids) => {
                        let centre = DVec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * h;
                        let apex = mesh.points.len() as u32;
                        mesh.points.push(warp_point(centre, warp));
                        // Outward faces of the cube and the cube across each.
                        let across = [
                            (i as isize - 1, j, k),
                            (i as isize + 1, j, k),
                            (i as isize, j.wrapping_sub(1), k),
                            (i as isize, j + 1, k),
                            (i as isize, j, k.wrapping_sub(1)),
                            (i as isize, j, k + 1),
                        ];
                        for (lf, &(ai, aj, ak)) in CellKind::Hexahedron.faces().iter().zip(&across)
                        {
                            let f: Vec<u32> = lf.iter().map(|&l| c[l as usize]).collect();
                            // Split where the base is not shared with a hexahedron or wedge.
                            let split = !(aj < n && ak < n)
                                || matches!(block(ai, n), None | Some(Block::Pyramids));
                            if split {
                                triangulate_face(&f, |t| {
                                    mesh.cells.push(CellKind::Tetra, &[apex, t[0], t[1], t[2]]);
                                });
                            } else {
                                mesh.cells
                                    .push(CellKind::Pyramid, &[f[0], f[3], f[2], f[1], apex]);
                            }
                        }
                    }
                }
            }
        }
    }
    finish(mesh, 0.0)
}

/// A square ring of hexahedra: an `n x n x m` grid (`m = max(1, n / 3)`)
/// without the cells whose `i` and `j` are both in `[n/3, n - n/3)`; unused
/// points are removed. Needs `n >= 3` for a hole.
pub fn ring_grid(n: usize, warp: &Warp) -> Mesh {
    let m = (n / 3).max(1);
    let full = warped_hex_grid_dims([n, n, m], warp);
    let (lo, hi) = (n / 3, n - n / 3);
    let mut mesh = Mesh {
        points: full.points,
        ..Default::default()
    };
    for k in 0..m {
        for j in 0..n {
            for i in 0..n {
                if (lo..hi).contains(&i) && (lo..hi).contains(&j) {
                    continue;
                }
                mesh.cells
                    .push(CellKind::Hexahedron, &lattice_hex(n + 1, n + 1, [i, j, k]));
            }
        }
    }
    remove_unused_points(&mut mesh);
    finish(mesh, 0.0)
}

pub use crate::mesh::subset::remove_unused_points;

/// One positively oriented, convex cell of `kind` (unit size) with the point
/// scalar `f`. [`CellKind::Polyhedron`] gives a "house": a cube with a
/// pyramid roof (5 quads, 4 triangles).
pub fn single_cell(kind: CellKind) -> Mesh {
    let ring = |n: usize, z: f64| -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / n as f64;
                DVec3::new(0.5 + 0.5 * a.cos(), 0.5 + 0.5 * a.sin(), z)
            })
            .collect()
    };
    let square = |z: f64| -> Vec<DVec3> {
        [(0., 0.), (1., 0.), (1., 1.), (0., 1.)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, z))
            .collect()
    };
    let mut mesh = Mesh::default();
    match kind {
        CellKind::Tetra => {
            mesh.points = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        }
        CellKind::Pyramid => {
            mesh.points = square(0.0);
            mesh.points.push(DVec3::new(0.5, 0.5, 1.0));
        }
        CellKind::Wedge => {
            // VTK parametric order: (0, 1, 2) turns counter-clockwise seen
            // from (3, 4, 5).
            mesh.points = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
            mesh.points
                .extend([DVec3::Z, DVec3::new(1., 0., 1.), DVec3::new(0., 1., 1.)]);
        }
        CellKind::Hexahedron => {
            mesh.points = square(0.0);
            mesh.points.extend(square(1.0));
        }
        CellKind::PentagonalPrism | CellKind::HexagonalPrism => {
            let n = if kind == CellKind::PentagonalPrism {
                5
            } else {
                6
            };
            mesh.points = ring(n, 0.0);
            mesh.points.extend(ring(n, 1.0));
        }
        CellKind::Polyhedron => {
            mesh.points = square(0.0);
            mesh.points.extend(square(1.0));
            mesh.points.push(DVec3::new(0.5, 0.5, 1.6));
            let mut faces: Vec<Vec<u32>> = CellKind::Hexahedron.faces()[..5]
                .iter()
                .map(|f| f.iter().map(|&l| l as u32).collect())
                .collect();
            for i in 0..4u32 {
                faces.push(vec![4 + i, 4 + (i + 1) % 4, 8]);
            }
            mesh.cells.push_polyhedron(faces);
            return finish(mesh, 0.0);
        }
    }
    let nodes: Vec<u32> = (0..mesh.points.len() as u32).collect();
    mesh.cells.push(kind, &nodes);
    finish(mesh, 0.0)
}

/// Three long, thin tetrahedra in cyclic overlap, the classic visibility
/// cycle: seen along `z` each one lies in front of the next where they cross
/// (a "pinwheel" around the `z` axis), though no two of them touch. No
/// back-to-front order of the three exists; the sorter can only group them
/// (`visibility::Order::groups`). Stick `k` lies on the line `p . v_k = 1`
/// (`v_k` the in-plane normal at angle `120 k` degrees), runs from `s = -3`
/// to `s = 3` along it with depth `z = s / 2`; it is a segment of width 0.8
/// (along `v_k`) at one end and of thickness 0.8 (along `z`) at the other.
/// Neighbouring sticks cross at `s = -+sqrt 3`, `z` 1.73 apart.
pub fn interlocked_tets() -> Mesh {
    let mut mesh = Mesh::default();
    let (len, dz, w, t) = (3.0, 0.5, 0.8, 0.8);
    for k in 0..3 {
        let a = k as f64 * std::f64::consts::TAU / 3.0;
        let u = DVec3::new(a.cos(), a.sin(), 0.0);
        let v = DVec3::new(-a.sin(), a.cos(), 0.0);
        let at = |s: f64| v + u * s + DVec3::Z * (s * dz);
        let base = mesh.points.len() as u32;
        mesh.points.extend([
            at(-len) - v * (0.5 * w),
            at(-len) + v * (0.5 * w),
            at(len) - DVec3::Z * (0.5 * t),
            at(len) + DVec3::Z * (0.5 * t),
        ]);
        mesh.cells
            .push(CellKind::Tetra, &[base, base + 1, base + 2, base + 3]);
    }
    finish(mesh, 0.0)
}

/// `steps` time steps `(time, mesh)` of an `n^3` warped grid: same geometry,
/// `f` evaluated at `t = 0, 0.5, 1, ...`.
pub fn time_series(n: usize, steps: usize) -> Vec<(f64, Mesh)> {
    let base = warped_hex_grid(n, &Warp::default());
    (0..steps)
        .map(|s| {
            let t = s as f64 * 0.5;
            let mut m = base.clone();
            m.point_data = vec![f_array(&m.points, t)];
            (t, m)
        })
        .collect()
}

/// Steps `(time, mesh)` of a curved channel (module docs): `nr x nt x nz`
/// hexahedra over radius 0.4..1, angle 0..270 degrees, height 0..0.5 (the
/// floor and roof waved by `0.04 r sin(3 theta)`), with the point scalar
/// `speed` (Float32) at `t = 0, 0.25, 0.5, ...`.
pub fn flow_series(nr: usize, nt: usize, nz: usize, steps: usize) -> Vec<(f64, Mesh)> {
    use std::f64::consts::PI;
    let (r0, r1, sweep, height) = (0.4, 1.0, 1.5 * PI, 0.5);
    let mut base = Mesh::default();
    let mut polar = Vec::new();
    for k in 0..=nz {
        for j in 0..=nt {
            for i in 0..=nr {
                let r = r0 + (r1 - r0) * i as f64 / nr as f64;
                let th = sweep * j as f64 / nt as f64;
                let z = height * k as f64 / nz as f64 + 0.04 * r * (3.0 * th).sin();
                base.points.push(DVec3::new(r * th.cos(), r * th.sin(), z));
                polar.push((r, th, z));
            }
        }
    }
    for k in 0..nz {
        for j in 0..nt {
            for i in 0..nr {
                base.cells.push(
                    CellKind::Hexahedron,
                    &lattice_hex(nr + 1, nt + 1, [i, j, k]),
                );
            }
        }
    }
    let base = finish(base, 0.0);
    (0..steps)
        .map(|s| {
            let t = s as f64 * 0.25;
            // The puff's centre moves along the channel, a quarter turn a
            // second, and wraps.
            let centre = (0.3 + t * 0.5 * PI) % sweep;
            let speed: Vec<f32> = polar
                .iter()
                .map(|&(r, th, z)| {
                    let d2 = (th - centre).powi(2) / 0.08
                        + (r - 0.7).powi(2) / 0.02
                        + (z - 0.25).powi(2) / 0.03;
                    (0.4 / r + (-d2).exp() * (1.0 + 0.3 * (6.0 * th - 2.0 * t).sin())) as f32
                })
                .collect();
            let mut m = base.clone();
            m.point_data = vec![DataArray {
                name: "speed".into(),
                components: 1,
                data: ArrayData::F32(speed),
                vtk_type: "Float32".into(),
            }];
            m.active_point_scalars = Some("speed".into());
            (t, m)
        })
        .collect()
}

//! Generated test meshes for the visibility tests, benchmark and fuzz target:
//! structured hexahedral grids on the unit cube with random point jitter
//! (nonplanar faces everywhere), optionally with cells removed (holes,
//! cavities, notches) to make them non-convex.

use glam::DVec3;

use crate::mesh::{lattice_hex, CellKind, Mesh};

/// A jittered structured grid.
#[derive(Clone, Copy, Debug)]
pub struct GridSpec {
    /// Cells along x, y, z.
    pub dims: [usize; 3],
    /// Jitter amplitude as a fraction of the cell size (keep below 0.25 so no
    /// cell inverts).
    pub jitter: f64,
    /// Seed of the jitter.
    pub seed: u64,
    /// Jitter boundary points only within the boundary planes, so the domain
    /// stays the unit cube (a convex mesh with nonplanar interior faces).
    pub planar_boundary: bool,
}

/// A small xorshift generator (reproducible meshes and test inputs).
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    /// The next number, uniform in `[0, 1)`.
    pub(crate) fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The grid of `spec`, keeping the cells `(i, j, k)` for which `keep` is true.
pub fn grid(spec: &GridSpec, keep: impl Fn(usize, usize, usize) -> bool) -> Mesh {
    let [nx, ny, nz] = spec.dims;
    let mut rng = Rng(spec.seed.wrapping_mul(0x2545_F491_4F6C_DD1D) | 1);
    let mut mesh = Mesh::default();
    let n = [nx, ny, nz];
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let idx = [i, j, k];
                let mut p = [0.0; 3];
                for a in 0..3 {
                    let h = 1.0 / n[a].max(1) as f64;
                    let on_boundary = idx[a] == 0 || idx[a] == n[a];
                    let r = rng.next_f64() * 2.0 - 1.0;
                    let jit = if spec.planar_boundary && on_boundary {
                        0.0
                    } else {
                        r * spec.jitter * h
                    };
                    p[a] = idx[a] as f64 * h + jit;
                }
                mesh.points.push(DVec3::from_array(p));
            }
        }
    }
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                if !keep(i, j, k) {
                    continue;
                }
                mesh.cells.push(
                    CellKind::Hexahedron,
                    &lattice_hex(nx + 1, ny + 1, [i, j, k]),
                );
            }
        }
    }
    mesh.source
        .cells_by_type
        .insert("hexahedron".into(), mesh.cells.len());
    mesh
}

/// A grid with a square through-hole along z in the middle (genus 1) and a
/// closed cavity near one corner: non-convex with an inner boundary.
pub fn holed_grid(spec: &GridSpec) -> Mesh {
    let [nx, ny, nz] = spec.dims;
    let (hx0, hx1) = (nx * 3 / 8, (nx * 5 / 8).max(nx * 3 / 8 + 1));
    let (hy0, hy1) = (ny * 3 / 8, (ny * 5 / 8).max(ny * 3 / 8 + 1));
    let cav = |a: usize, n: usize| a > n / 8 && a <= n / 8 + (n / 6).max(1);
    grid(spec, |i, j, k| {
        let through = i >= hx0 && i < hx1 && j >= hy0 && j < hy1;
        let cavity = cav(i, nx) && cav(j, ny) && cav(k, nz);
        !through && !cavity
    })
}

/// A U-shaped (notched) grid: a slot cut from the top half, so the mesh sees
/// itself across empty space.
pub fn notched_grid(spec: &GridSpec) -> Mesh {
    let [nx, _, nz] = spec.dims;
    grid(spec, |i, _, k| {
        !(i >= nx / 3 && i < 2 * nx / 3 && k >= nz / 2)
    })
}

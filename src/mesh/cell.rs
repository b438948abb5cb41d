//! Cell kinds and their local topology tables.
//!
//! Every 3D cell zoovr renders is a convex (or nearly convex) polyhedron whose
//! corner nodes are stored in the VTK node order of its kind, with two
//! exceptions normalised by the readers:
//! - VTK_VOXEL (11) is stored as a [`CellKind::Hexahedron`] (nodes reordered
//!   `0 1 3 2 4 5 7 6`); the original type is still counted in
//!   [`crate::mesh::SourceInfo::cells_by_type`].
//! - quadratic cells keep only their corner nodes, as the linear kind.
//!
//! Local faces are listed so that, for a cell with positive signed volume,
//! the right-hand rule over the face's vertex order gives the outward normal
//! (the VTK convention). Inverted cells (negative signed volume) are repaired
//! by [`CellKind::reorder_for_inversion`].

/// The kinds of 3D cells. Discriminants are the VTK cell type codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum CellKind {
    Tetra = 10,
    Hexahedron = 12,
    Wedge = 13,
    Pyramid = 14,
    PentagonalPrism = 15,
    HexagonalPrism = 16,
    /// A general convex polyhedron given by its faces (VTK_POLYHEDRON).
    Polyhedron = 42,
}

const TET_FACES: &[&[u8]] = &[&[0, 1, 3], &[1, 2, 3], &[2, 0, 3], &[0, 2, 1]];
const HEX_FACES: &[&[u8]] = &[
    &[0, 4, 7, 3],
    &[1, 2, 6, 5],
    &[0, 1, 5, 4],
    &[3, 7, 6, 2],
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
];
// Positive wedges follow VTK's parametric coordinates (nodes 0, 1, 2 at
// (0,0,0), (1,0,0), (0,1,0); 3, 4, 5 above them): the normal of (0, 1, 2)
// points towards (3, 4, 5). With this orientation all 7,950 wedges of the
// su2_sphere_hybrid dataset and the 4 of notch count as negative (as VTK's
// cell quality filter counts them). VTK's own
// wedge face table lists these faces inward; ours lists them outward.
const WEDGE_FACES: &[&[u8]] = &[
    &[0, 2, 1],
    &[3, 4, 5],
    &[0, 1, 4, 3],
    &[1, 2, 5, 4],
    &[2, 0, 3, 5],
];
const PYRAMID_FACES: &[&[u8]] = &[
    &[0, 3, 2, 1],
    &[0, 1, 4],
    &[1, 2, 4],
    &[2, 3, 4],
    &[3, 0, 4],
];
const PENTA_FACES: &[&[u8]] = &[
    &[0, 4, 3, 2, 1],
    &[5, 6, 7, 8, 9],
    &[0, 1, 6, 5],
    &[1, 2, 7, 6],
    &[2, 3, 8, 7],
    &[3, 4, 9, 8],
    &[4, 0, 5, 9],
];
const HEXA_PRISM_FACES: &[&[u8]] = &[
    &[0, 5, 4, 3, 2, 1],
    &[6, 7, 8, 9, 10, 11],
    &[0, 1, 7, 6],
    &[1, 2, 8, 7],
    &[2, 3, 9, 8],
    &[3, 4, 10, 9],
    &[4, 5, 11, 10],
    &[5, 0, 6, 11],
];

const TET_EDGES: &[[u8; 2]] = &[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
const HEX_EDGES: &[[u8; 2]] = &[
    [0, 1],
    [1, 2],
    [3, 2],
    [0, 3],
    [4, 5],
    [5, 6],
    [7, 6],
    [4, 7],
    [0, 4],
    [1, 5],
    [3, 7],
    [2, 6],
];
const WEDGE_EDGES: &[[u8; 2]] = &[
    [0, 1],
    [1, 2],
    [2, 0],
    [3, 4],
    [4, 5],
    [5, 3],
    [0, 3],
    [1, 4],
    [2, 5],
];
const PYRAMID_EDGES: &[[u8; 2]] = &[
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 0],
    [0, 4],
    [1, 4],
    [2, 4],
    [3, 4],
];
const PENTA_EDGES: &[[u8; 2]] = &[
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 4],
    [4, 0],
    [5, 6],
    [6, 7],
    [7, 8],
    [8, 9],
    [9, 5],
    [0, 5],
    [1, 6],
    [2, 7],
    [3, 8],
    [4, 9],
];
const HEXA_PRISM_EDGES: &[[u8; 2]] = &[
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 4],
    [4, 5],
    [5, 0],
    [6, 7],
    [7, 8],
    [8, 9],
    [9, 10],
    [10, 11],
    [11, 6],
    [0, 6],
    [1, 7],
    [2, 8],
    [3, 9],
    [4, 10],
    [5, 11],
];

impl CellKind {
    /// The kinds with a fixed node list (every kind but
    /// [`CellKind::Polyhedron`]), all convex in their reference shape.
    pub const FIXED: [CellKind; 6] = [
        CellKind::Tetra,
        CellKind::Pyramid,
        CellKind::Wedge,
        CellKind::Hexahedron,
        CellKind::PentagonalPrism,
        CellKind::HexagonalPrism,
    ];

    /// Corners of the kind's unit reference cell in its VTK node order:
    /// convex with planar faces (unit simplex corners, unit square base and
    /// apex above its centre, unit cube; the prisms on the unit circle from
    /// `z = 0` to `z = 1`). Empty for [`CellKind::Polyhedron`]. Tests,
    /// benchmarks and fuzzing map it affinely to make random cells.
    pub fn reference_corners(self) -> Vec<glam::DVec3> {
        let v = glam::DVec3::new;
        let ngon = |n: usize| -> Vec<glam::DVec3> {
            (0..2 * n)
                .map(|i| {
                    let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
                    v(a.cos(), a.sin(), (i / n) as f64)
                })
                .collect()
        };
        match self {
            CellKind::Tetra => vec![v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.), v(0., 0., 1.)],
            CellKind::Pyramid => vec![
                v(0., 0., 0.),
                v(1., 0., 0.),
                v(1., 1., 0.),
                v(0., 1., 0.),
                v(0.5, 0.5, 1.),
            ],
            CellKind::Wedge => vec![
                v(0., 0., 0.),
                v(1., 0., 0.),
                v(0., 1., 0.),
                v(0., 0., 1.),
                v(1., 0., 1.),
                v(0., 1., 1.),
            ],
            CellKind::Hexahedron => vec![
                v(0., 0., 0.),
                v(1., 0., 0.),
                v(1., 1., 0.),
                v(0., 1., 0.),
                v(0., 0., 1.),
                v(1., 0., 1.),
                v(1., 1., 1.),
                v(0., 1., 1.),
            ],
            CellKind::PentagonalPrism => ngon(5),
            CellKind::HexagonalPrism => ngon(6),
            CellKind::Polyhedron => Vec::new(),
        }
    }

    /// Number of corner nodes; `None` for general polyhedra (variable).
    pub fn corner_count(self) -> Option<usize> {
        match self {
            CellKind::Tetra => Some(4),
            CellKind::Pyramid => Some(5),
            CellKind::Wedge => Some(6),
            CellKind::Hexahedron => Some(8),
            CellKind::PentagonalPrism => Some(10),
            CellKind::HexagonalPrism => Some(12),
            CellKind::Polyhedron => None,
        }
    }

    /// Local faces (indices into the cell's node list), outward for a
    /// positively oriented cell. Empty for [`CellKind::Polyhedron`], whose faces
    /// are stored per cell in [`crate::mesh::Cells`].
    pub fn faces(self) -> &'static [&'static [u8]] {
        match self {
            CellKind::Tetra => TET_FACES,
            CellKind::Pyramid => PYRAMID_FACES,
            CellKind::Wedge => WEDGE_FACES,
            CellKind::Hexahedron => HEX_FACES,
            CellKind::PentagonalPrism => PENTA_FACES,
            CellKind::HexagonalPrism => HEXA_PRISM_FACES,
            CellKind::Polyhedron => &[],
        }
    }

    /// Local edges (pairs of local node indices). Empty for polyhedra.
    pub fn edges(self) -> &'static [[u8; 2]] {
        match self {
            CellKind::Tetra => TET_EDGES,
            CellKind::Pyramid => PYRAMID_EDGES,
            CellKind::Wedge => WEDGE_EDGES,
            CellKind::Hexahedron => HEX_EDGES,
            CellKind::PentagonalPrism => PENTA_EDGES,
            CellKind::HexagonalPrism => HEXA_PRISM_EDGES,
            CellKind::Polyhedron => &[],
        }
    }

    /// The permutation of local nodes that mirrors an inverted cell into a
    /// positively oriented one of the same kind (applied as
    /// `new[i] = old[perm[i]]`). For prisms this swaps the two caps; for a
    /// tetrahedron or pyramid it swaps two base nodes.
    pub fn reorder_for_inversion(self) -> &'static [u8] {
        match self {
            CellKind::Tetra => &[0, 2, 1, 3],
            CellKind::Pyramid => &[0, 3, 2, 1, 4],
            CellKind::Wedge => &[3, 4, 5, 0, 1, 2],
            CellKind::Hexahedron => &[4, 5, 6, 7, 0, 1, 2, 3],
            CellKind::PentagonalPrism => &[5, 6, 7, 8, 9, 0, 1, 2, 3, 4],
            CellKind::HexagonalPrism => &[6, 7, 8, 9, 10, 11, 0, 1, 2, 3, 4, 5],
            CellKind::Polyhedron => &[],
        }
    }

    /// VTK's lower-case name of the kind (as used in `info --json`).
    pub fn vtk_name(self) -> &'static str {
        vtk_type_name(self as u8)
    }

    /// The kind a VTK cell type code maps to, with the number of nodes the
    /// file must give. Quadratic and higher-order cells map to their linear
    /// kind. Returns `None` for 0D-2D cells and unknown codes.
    pub fn from_vtk_type(code: u8) -> Option<CellKind> {
        Some(match code {
            10 | 24 | 71 => CellKind::Tetra,
            11 | 12 | 25 | 29 | 33 | 72 => CellKind::Hexahedron,
            13 | 26 | 32 | 73 => CellKind::Wedge,
            14 | 27 | 74 => CellKind::Pyramid,
            15 => CellKind::PentagonalPrism,
            16 => CellKind::HexagonalPrism,
            42 => CellKind::Polyhedron,
            _ => return None,
        })
    }
}

/// VTK's lower-case name for a cell type code (`vtkCellTypes::GetClassNameFromTypeId`
/// without the `vtk` prefix, in snake case).
pub fn vtk_type_name(code: u8) -> &'static str {
    match code {
        0 => "empty_cell",
        1 => "vertex",
        2 => "poly_vertex",
        3 => "line",
        4 => "poly_line",
        5 => "triangle",
        6 => "triangle_strip",
        7 => "polygon",
        8 => "pixel",
        9 => "quad",
        10 => "tetra",
        11 => "voxel",
        12 => "hexahedron",
        13 => "wedge",
        14 => "pyramid",
        15 => "pentagonal_prism",
        16 => "hexagonal_prism",
        21 => "quadratic_edge",
        22 => "quadratic_triangle",
        23 => "quadratic_quad",
        24 => "quadratic_tetra",
        25 => "quadratic_hexahedron",
        26 => "quadratic_wedge",
        27 => "quadratic_pyramid",
        28 => "biquadratic_quad",
        29 => "triquadratic_hexahedron",
        30 => "quadratic_linear_quad",
        31 => "quadratic_linear_wedge",
        32 => "biquadratic_quadratic_wedge",
        33 => "biquadratic_quadratic_hexahedron",
        34 => "biquadratic_triangle",
        35 => "cubic_line",
        36 => "quadratic_polygon",
        37 => "triquadratic_pyramid",
        42 => "polyhedron",
        68 => "lagrange_curve",
        69 => "lagrange_triangle",
        70 => "lagrange_quadrilateral",
        71 => "lagrange_tetrahedron",
        72 => "lagrange_hexahedron",
        73 => "lagrange_wedge",
        74 => "lagrange_pyramid",
        _ => "unknown",
    }
}

/// Whether a VTK cell type code is a 0D, 1D or 2D cell (ignored and counted).
pub fn vtk_type_is_lower_dim(code: u8) -> bool {
    matches!(
        code,
        0..=9 | 21..=23 | 28 | 30 | 34..=36 | 68..=70
    )
}

/// Voxel node order to hexahedron node order: `hex[i] = voxel[VOXEL_TO_HEX[i]]`.
pub const VOXEL_TO_HEX: [usize; 8] = [0, 1, 3, 2, 4, 5, 7, 6];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_edge_is_in_exactly_two_faces() {
        for kind in CellKind::FIXED {
            for e in kind.edges() {
                let mut n = 0;
                for f in kind.faces() {
                    for k in 0..f.len() {
                        let (a, b) = (f[k], f[(k + 1) % f.len()]);
                        if (a, b) == (e[0], e[1]) || (a, b) == (e[1], e[0]) {
                            n += 1;
                        }
                    }
                }
                assert_eq!(n, 2, "{kind:?} edge {e:?}");
            }
            // Euler: V - E + F = 2
            let v = kind.corner_count().unwrap() as i64;
            assert_eq!(v - kind.edges().len() as i64 + kind.faces().len() as i64, 2);
        }
    }
}

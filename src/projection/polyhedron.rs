//! The input of projection: one convex piece in camera view space, with its
//! boundary triangulated, and the builders that make one from a mesh cell or
//! a tetrahedron.
//!
//! Winding: triangles are wound so that, *in world space*, the right-hand rule
//! gives the outward normal (the mesh convention). View space (x right, y up,
//! z = depth) is left-handed, so the triple products computed on view
//! coordinates change sign; [`Polyhedron::volume`] accounts for that and is
//! positive for a correctly wound piece. The builders fix the winding of
//! inverted cells by flipping every triangle when the volume is negative.
//! Quad faces are the two triangles of the smallest-vertex diagonal and n-gons
//! fans from their smallest vertex ([`crate::mesh::tetra::triangulate_face`]
//! on global ids), so neighbouring cells triangulate shared faces alike.

use glam::DVec3;

use super::ProjectionError;
use crate::camera::Camera;
use crate::mesh::tetra::triangulate_face;
use crate::mesh::Cells;

/// Local faces of a tetrahedron (the VTK order used by [`crate::mesh`]).
const TET_FACES: [[u32; 3]; 4] = [[0, 1, 3], [1, 2, 3], [2, 0, 3], [0, 2, 1]];

/// A convex piece in view space, triangulated on its boundary.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Polyhedron {
    /// View-space positions ([`Camera::to_view`]).
    pub points: Vec<DVec3>,
    /// Scalar per point (linear on each boundary triangle).
    pub scalars: Vec<f64>,
    /// Boundary triangles, outward by the right-hand rule in world space.
    pub triangles: Vec<[u32; 3]>,
    /// View-space gradient of the field per point, for smooth isosurface
    /// shading ([`crate::render::gradients`]); empty unless the piece's
    /// source fills it (builders leave it empty; [`super::Clipper`]
    /// interpolates it at the points it cuts, like the scalar).
    pub gradients: Vec<DVec3>,
    /// World-space position per point, when the piece's source has them
    /// (empty otherwise): the exact pixel-centre decisions of
    /// [`crate::render::ties`] are taken on these, the very numbers the
    /// reference ray caster decides on, so that both give a centre on a
    /// shared edge or an edge-on face to the same side. [`Self::set_cell`]
    /// fills them; [`super::Clipper`] interpolates them at the points it
    /// cuts, with the same canonical edge order and weight as the view
    /// position.
    pub world: Vec<DVec3>,
    /// Points whose scalar is not a number in the field, ascending: their
    /// entries in `scalars` (and `gradients`) are finite stand-ins, and a
    /// boundary triangle holding one has no scalar anywhere, so every ray
    /// entering or leaving the piece through it is empty, as the
    /// reference's segments with a NaN end are (the driver leaves out the
    /// regions in front of or behind such a triangle). Set by the piece's
    /// source for whole cells ([`crate::render::pieces`]); empty elsewhere.
    pub holes: Vec<u32>,
}

impl Polyhedron {
    /// Empties the piece, keeping its allocations.
    pub fn clear(&mut self) {
        self.holes.clear();
        self.points.clear();
        self.scalars.clear();
        self.triangles.clear();
        self.gradients.clear();
        self.world.clear();
    }

    /// A tetrahedron from view-space corners (either orientation).
    pub fn from_tet(points: [DVec3; 4], scalars: [f64; 4]) -> Polyhedron {
        let mut p = Polyhedron::default();
        p.set_tet(points, scalars);
        p
    }

    /// A tetrahedron from world-space corners, seen by `camera` (either
    /// orientation): view positions by [`Camera::to_view`], and
    /// [`Self::world`] kept.
    pub fn from_world_tet(world: [DVec3; 4], scalars: [f64; 4], camera: &Camera) -> Polyhedron {
        let mut p = Polyhedron::from_tet(world.map(|w| camera.to_view(w)), scalars);
        p.world.extend_from_slice(&world);
        p
    }

    /// Makes `self` the tetrahedron `points` (see [`Self::from_tet`]).
    pub fn set_tet(&mut self, points: [DVec3; 4], scalars: [f64; 4]) {
        self.clear();
        self.points.extend_from_slice(&points);
        self.scalars.extend_from_slice(&scalars);
        self.triangles.extend_from_slice(&TET_FACES);
        self.orient_outward();
    }

    /// The piece of mesh cell `c`: world points are converted with
    /// [`Camera::to_view`], scalars read by global point id.
    pub fn from_cell(
        cells: &Cells,
        c: usize,
        world: &[DVec3],
        scalar: impl Fn(u32) -> f64,
        camera: &Camera,
    ) -> Result<Polyhedron, ProjectionError> {
        let mut p = Polyhedron::default();
        p.set_cell(cells, c, world, scalar, camera)?;
        Ok(p)
    }

    /// Makes `self` the piece of mesh cell `c` (see [`Self::from_cell`]);
    /// allocation-free once the buffers have grown.
    pub fn set_cell(
        &mut self,
        cells: &Cells,
        c: usize,
        world: &[DVec3],
        scalar: impl Fn(u32) -> f64,
        camera: &Camera,
    ) -> Result<(), ProjectionError> {
        self.clear();
        if c >= cells.len() || c + 1 >= cells.offsets.len() {
            return Err(ProjectionError::NoSuchCell(c));
        }
        let nodes = cells.nodes(c);
        for &n in nodes {
            let w = world
                .get(n as usize)
                .ok_or(ProjectionError::IndexOutOfRange(n))?;
            self.points.push(camera.to_view(*w));
            self.world.push(*w);
            self.scalars.push(scalar(n));
        }
        let mut bad = None;
        let tris = &mut self.triangles;
        cells.for_each_face(c, |_, face| {
            triangulate_face(face, |t| {
                let mut l = [0u32; 3];
                for k in 0..3 {
                    match nodes.iter().position(|&n| n == t[k]) {
                        Some(i) => l[k] = i as u32,
                        None => bad = Some(t[k]),
                    }
                }
                tris.push(l);
            });
        });
        if let Some(n) = bad {
            return Err(ProjectionError::IndexOutOfRange(n));
        }
        self.orient_outward();
        Ok(())
    }

    /// Signed volume, positive for outward (world right-hand) winding.
    pub fn volume(&self) -> f64 {
        let mut v = 0.0;
        let o = self.points.first().copied().unwrap_or(DVec3::ZERO);
        for t in &self.triangles {
            let get = |i: u32| self.points.get(i as usize).copied().unwrap_or(o) - o;
            v += get(t[0]).dot(get(t[1]).cross(get(t[2])));
        }
        // View space is left-handed: negate.
        -v / 6.0
    }

    /// Flips every triangle when the signed volume is negative.
    pub fn orient_outward(&mut self) {
        if self.volume() < 0.0 {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
    }

    /// Checks indices, lengths and finiteness.
    pub fn validate(&self) -> Result<(), ProjectionError> {
        if self.scalars.len() != self.points.len() {
            return Err(ProjectionError::LengthMismatch {
                points: self.points.len(),
                scalars: self.scalars.len(),
            });
        }
        if self.points.iter().any(|p| !p.is_finite()) || self.scalars.iter().any(|s| !s.is_finite())
        {
            return Err(ProjectionError::NonFinite);
        }
        for t in &self.triangles {
            for &i in t {
                if i as usize >= self.points.len() {
                    return Err(ProjectionError::IndexOutOfRange(i));
                }
            }
        }
        Ok(())
    }
}

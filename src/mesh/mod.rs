//! [`TriangleMesh`]: triangles that share their vertices, with a tree of their own,
//! watertight by construction.

/// Runs `$query` in the lanes the mesh picked when it was built: with `$L` AVX2's four
/// `f64` lanes and the whole query compiled for AVX2 where the CPU has it, `wide`'s
/// portable ones otherwise; `$token` is what makes them. (Once per query, and no check
/// per leaf: as Embree picks its kernels at commit.)
macro_rules! kernel {
    ($mesh:expr, |$token:ident, $L:ident| $query:expr) => {
        match $mesh.lanes {
            #[cfg(target_arch = "x86_64")]
            Some($token) => {
                type $L = crate::simd::Avx4;
                $token.run(
                    #[inline(always)]
                    || $query,
                )
            }
            _ => {
                type $L = wide::f64x4;
                let $token = ();
                $query
            }
        }
    };
}

// By operation: build, update (refit), query (the tree's walks), intersect (the face
// test), sample (a mesh as a light), face (one face as a shape), filter (cut-outs).
mod block;
mod build;
mod face;
mod filter;
mod intersect;
mod query;
mod sample;
mod update;

pub use face::Face;
pub use filter::{Candidate, Filtered};

use build::{LARGEST_UNCHECKED, add_area, area_of, corners, cross, face_area, face_box, reorder};

use alloc::vec::Vec;

use glam::{DVec2, DVec3};

use crate::record::{Found, Made};
use crate::tree::{Shape, Tree};
use crate::{Aabb, GeometryError, HitRecord, Hittable, Interval, MaterialId, Ray};

/// An indexed triangle mesh: vertex positions shared by faces that name them by index,
/// optional per-vertex normals and texture coordinates, and a tree over the faces.
///
/// Built from slices (reading a file format is left to the caller: `tobj`, say). A hit
/// reports which face it is in [`HitRecord::primitive`], numbered as the caller's list of
/// faces numbers them; `uv` is the interpolated texture coordinates where the mesh has
/// them and the barycentric coordinates `(b1, b2)` of the hit (the weights of the face's
/// second and third vertices) where it does not; `shading_normal` is the interpolated
/// vertex normal where it has them. [`TriangleMesh::faces`] gives each face as a
/// [`Hittable`] of its own, with its barycentrics.
///
/// **Watertight.** Inside or outside is decided by the three edge functions of the face in
/// a frame of the ray (Woop, Benthin and Wald 2013, "Watertight Ray/Triangle
/// Intersection"; pbrt-v4's `IntersectTriangle`), computed from the shared vertices so that
/// an edge's value in one face is exactly the negative of its value in the neighbour: a ray
/// through a shared edge or vertex always finds a face. Where a value is within its
/// rounding bound of zero, its sign is settled in double-double arithmetic, so that a hit
/// is a hit of the exact ray on the exact triangle however far away the ray comes from.
///
/// **Degenerate faces** (two vertices at one position, or three on a line, so that the
/// cross product of the edges is zero) are kept out of the tree and never hit; the other
/// faces keep their numbers.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Hittable, Interval, Ray, TriangleMesh};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// // A unit square of two triangles sharing the diagonal, and a degenerate third face.
/// let vertices = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
/// let square = TriangleMesh::new(&vertices, &[[0, 1, 2], [0, 0, 3], [0, 2, 3]])?;
/// assert_eq!((square.face_count(), square.hittable_face_count()), (3, 2));
///
/// // Straight through the diagonal: one of its two faces takes it.
/// let ray = Ray::new(DVec3::new(0.5, 0.5, 1.0), DVec3::NEG_Z);
/// let hit = square.hit(&ray, Interval::FORWARD).unwrap();
/// assert!(hit.t == 1.0 && (hit.primitive == Some(0) || hit.primitive == Some(2)));
///
/// let ray = Ray::new(DVec3::new(0.2, 0.7, 1.0), DVec3::NEG_Z);
/// assert_eq!(square.hit(&ray, Interval::FORWARD).unwrap().primitive, Some(2));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    /// The vertices, in the mesh's own order: those the hittable faces use as the faces, in
    /// the tree's order, first name them, so that a leaf's corners lie together in memory
    /// (on a soup, where every face has corners of its own, one run of bytes a leaf); then
    /// those only degenerate faces use, kept for updates that make their faces hittable.
    vertices: Vec<DVec3>,
    /// The caller's number of each vertex: `vertices[i]` is the caller's
    /// `source[i]`-th.
    source: Vec<u32>,
    /// How many vertices the caller gave (what normals and uvs are given for).
    vertex_count: usize,
    /// How many of `vertices` (the first ones) the hittable faces use.
    hittable_vertices: usize,
    /// The faces kept out of the tree, by the caller's numbers (of the face, and of its
    /// vertices): what a rebuild needs when an update makes them hittable.
    degenerate: Vec<(u32, [u32; 3])>,
    /// Empty, or one per vertex (of `vertices`).
    normals: Vec<DVec3>,
    /// Empty, or one per vertex (of `vertices`).
    uvs: Vec<DVec2>,
    /// The faces that can be hit, in the tree's order, as indices into `vertices`;
    /// `tree.order[i]` is the caller's number of `triangles[i]`.
    triangles: Vec<[u32; 3]>,
    tree: Tree,
    /// How many faces the caller gave, degenerate ones included.
    faces: usize,
    bbox: Aabb,
    /// Whether the box reaches near f64's end ([`Aabb::near_overflow`]), where a hit's
    /// point can overflow: settled once here, not for every crossing.
    near_overflow: bool,
    material: MaterialId,
    /// Running sums of the triangles' areas, in the tree's order, at the end of every
    /// block of [`AREA_BLOCK`] faces: what sampling by area picks a face from.
    area_sums: Vec<f64>,
    /// The tree's cost at its build (see [`TriangleMesh::cost`]).
    built_cost: f64,
    /// Where the CPU has AVX2 (detected once, at the build, as Embree picks its kernels at
    /// commit): a leaf's faces are tested in its lanes, else in `wide`'s portable ones.
    lanes: Option<crate::simd::Avx2>,
}

/// How many faces share one running sum of areas: sampling by area finds the block by
/// the sums and the face within it by adding its faces' areas again, in the same order,
/// so that it picks exactly the face a sum for every face would, for a quarter of the
/// memory.
const AREA_BLOCK: usize = 4;

/// How the mesh's tree weighs a node against its faces: a face test costs a little more
/// than a node visit, and leaves of up to four faces keep the tree small (see
/// [`TriangleMesh::heap_bytes`]) without the leaves of eight large faces that a room of
/// walls got at twice the node cost, every ray testing most of them. (Tried: the node cost
/// of a `Bvh`, no faster and larger; with nodes of eight, a node cost of 2 or 3, smaller
/// but slower in rooms; `docs/performance.md` has the figures.)
pub(crate) const MESH_SHAPE: Shape = Shape {
    traversal_cost: 1.5,
    max_leaf: 4,
};

impl TriangleMesh {
    /// The same mesh with one normal per vertex, interpolated into each hit's
    /// `shading_normal` (normalized there; where the interpolation is zero, the face's own
    /// normal is used).
    ///
    /// # Errors
    /// [`GeometryError::LengthMismatch`] unless there is one normal per vertex,
    /// [`GeometryError::NonFiniteElement`] for a NaN or infinite one.
    pub fn with_normals(mut self, normals: &[DVec3]) -> Result<Self, GeometryError> {
        self.normals = self.per_vertex("normals", normals, |n| n.is_finite())?;
        Ok(self)
    }

    /// The same mesh with texture coordinates per vertex, interpolated into each hit's `uv`.
    ///
    /// # Errors
    /// [`GeometryError::LengthMismatch`] unless there is one pair per vertex,
    /// [`GeometryError::NonFiniteElement`] for a NaN or infinite one.
    pub fn with_uvs(mut self, uvs: &[DVec2]) -> Result<Self, GeometryError> {
        self.uvs = self.per_vertex("uvs", uvs, |uv| uv.is_finite())?;
        Ok(self)
    }

    /// The same mesh with material `material`, carried into every hit (the face index in
    /// [`HitRecord::primitive`] lets a renderer choose per face).
    #[inline]
    #[must_use]
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.material = material;
        self
    }

    /// How many faces were given, degenerate ones included.
    #[inline]
    #[must_use]
    pub fn face_count(&self) -> usize {
        self.faces
    }

    /// How many vertices were given: what [`TriangleMesh::set_vertices`],
    /// [`TriangleMesh::with_normals`] and [`TriangleMesh::with_uvs`] take one of each for.
    #[inline]
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// How many faces can be hit: those that are not degenerate.
    #[inline]
    #[must_use]
    pub fn hittable_face_count(&self) -> usize {
        self.triangles.len()
    }

    /// The positions of the vertices, in the mesh's own order: those that hittable faces
    /// use as its tree, leaf by leaf, first meets them, so that a leaf's corners lie
    /// together in memory; then those only degenerate faces use (a vertex no face names is
    /// not kept). Not the order given to [`TriangleMesh::new`]:
    /// [`Face::indices`] gives a face's corners by the caller's numbering,
    /// [`Face::corners`] their positions.
    #[inline]
    #[must_use]
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// The normals given ([`TriangleMesh::with_normals`]), one for each of
    /// [`TriangleMesh::vertices`] in its order; empty for a mesh without them.
    /// [`Face::normals`] gives a face's three.
    #[inline]
    #[must_use]
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// The texture coordinates given ([`TriangleMesh::with_uvs`]), one for each of
    /// [`TriangleMesh::vertices`] in its order; empty for a mesh without them.
    /// [`Face::uvs`] gives a face's three.
    #[inline]
    #[must_use]
    pub fn uvs(&self) -> &[DVec2] {
        &self.uvs
    }

    /// The material.
    #[inline]
    #[must_use]
    pub fn material(&self) -> MaterialId {
        self.material
    }

    /// The total area of the faces.
    #[inline]
    #[must_use]
    pub fn area(&self) -> f64 {
        self.area_sums.last().copied().unwrap_or(0.0)
    }

    /// The bytes the mesh holds on the heap: vertices, indices, normals and uvs, the tree
    /// and the sampling table.
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        use core::mem::size_of;
        self.vertices.capacity() * size_of::<DVec3>()
            + self.source.capacity() * size_of::<u32>()
            + self.normals.capacity() * size_of::<DVec3>()
            + self.uvs.capacity() * size_of::<DVec2>()
            + self.triangles.capacity() * size_of::<[u32; 3]>()
            + self.area_sums.capacity() * size_of::<f64>()
            + self.degenerate.capacity() * size_of::<(u32, [u32; 3])>()
            + self.tree.heap_bytes()
    }

    /// For each face in the mesh's own order, its number in the caller's list.
    #[cfg(feature = "gltf")]
    pub(crate) fn face_numbers(&self) -> &[u32] {
        &self.tree.order
    }

    /// The face at `position` in the mesh's own order.
    #[cfg(feature = "gltf")]
    pub(crate) fn face_at(&self, position: usize) -> Face<'_> {
        Face {
            mesh: self,
            position,
        }
    }

    /// The hittable faces, each a [`Hittable`] of its own, in no particular order.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = Face<'_>> {
        (0..self.triangles.len()).map(|position| Face {
            mesh: self,
            position,
        })
    }
}

impl Hittable for TriangleMesh {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let (position, crossing) = self.nearest(ray, ray_t)?;
        self.record_at(ray, position, crossing.t, crossing.barycentric())
    }

    /// The face's barycentrics in `coords`, its position in the tree's order in `part`.
    fn find(&self, ray: &Ray, ray_t: Interval, _: &mut Made) -> Option<Found> {
        let (position, crossing) = self.nearest(ray, ray_t)?;
        Some(Found::new(
            crossing.t,
            crossing.barycentric(),
            position as u32,
        ))
    }

    /// `None` for a `found` naming no face of this mesh.
    fn record(&self, ray: &Ray, _: Interval, found: &Found) -> Option<HitRecord> {
        let position = found.part as usize;
        (position < self.triangles.len())
            .then(|| self.record_at(ray, position, found.t, found.coords))?
    }

    /// The box of the vertices of the hittable faces.
    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    /// Stops at the first face found that the ray crosses within `ray_t`.
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        kernel!(self, |lanes, L| self.any::<L>(
            lanes,
            ray,
            ray_t,
            &mut (),
            |_, _| true
        ))
    }
}

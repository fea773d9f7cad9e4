//! [`TriangleMesh`]: triangles that share their vertices, with a tree of their own,
//! watertight by construction.

mod intersect;
mod light;

use alloc::vec;
use alloc::vec::Vec;

use glam::{DVec2, DVec3};

use crate::TreeCost;
use crate::aabb::BoxRay;
use crate::bvh::{Shape, Tally, Tree, Visits};
use crate::math::{gamma, length, unit_and_length};
use crate::{Aabb, Found, GeometryError, HitRecord, Hittable, Interval, MaterialId, Ray};

use intersect::{Crossing, Sheared};

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
}

/// How many faces share one running sum of areas: sampling by area finds the block by
/// the sums and the face within it by adding its faces' areas again, in the same order,
/// so that it picks exactly the face a sum for every face would, for a quarter of the
/// memory (2 bytes a face instead of 8).
const AREA_BLOCK: usize = 4;

/// How the mesh's tree weighs a node against its faces: a face test costs a little more
/// than a node visit, and leaves of up to four faces keep the tree small (see
/// [`TriangleMesh::heap_bytes`]: about 62 bytes a face on the bunny) without the leaves
/// of eight large faces that a room of walls got at twice the node cost, every ray testing
/// most of them. (At the node cost of a `Bvh`, 67 bytes a face on the bunny, and no
/// faster on the triad of `benches/peers`.)
const MESH_SHAPE: Shape = Shape {
    traversal_cost: 1.5,
    max_leaf: 4,
};

impl TriangleMesh {
    /// The mesh of `faces`, each three indices into `vertices`.
    ///
    /// # Errors
    /// - [`GeometryError::NonFiniteElement`] for a NaN or infinite vertex;
    /// - [`GeometryError::IndexOutOfRange`] for a face naming a vertex past the end;
    /// - [`GeometryError::OutOfRange`] for a face whose edges' cross product overflows
    ///   (coordinates past about 1e154);
    /// - [`GeometryError::TooMany`] for more than `u32::MAX` faces.
    pub fn new(vertices: &[DVec3], faces: &[[u32; 3]]) -> Result<Self, GeometryError> {
        Self::build(vertices, faces, false)
    }

    /// [`TriangleMesh::new`], with the tree built on every core: the same mesh.
    ///
    /// # Errors
    /// As [`TriangleMesh::new`].
    #[cfg(feature = "rayon")]
    #[cfg_attr(docsrs, doc(cfg(feature = "rayon")))]
    pub fn new_parallel(vertices: &[DVec3], faces: &[[u32; 3]]) -> Result<Self, GeometryError> {
        Self::build(vertices, faces, true)
    }

    fn build(
        vertices: &[DVec3],
        faces: &[[u32; 3]],
        parallel: bool,
    ) -> Result<Self, GeometryError> {
        if faces.len() > u32::MAX as usize {
            return Err(GeometryError::TooMany {
                what: "faces",
                count: faces.len(),
                max: u32::MAX as usize,
            });
        }
        if let Some(index) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(GeometryError::NonFiniteElement {
                what: "vertex",
                index,
            });
        }
        let mut kept: Vec<u32> = Vec::with_capacity(faces.len());
        let mut degenerate = Vec::new();
        for (face, &corners) in (0u32..).zip(faces) {
            for index in corners {
                if index as usize >= vertices.len() {
                    return Err(GeometryError::IndexOutOfRange {
                        face: face as usize,
                        index,
                        vertices: vertices.len(),
                    });
                }
            }
            let [a, b, c] = corners.map(|i| vertices[i as usize]);
            let cross = (b - a).cross(c - a);
            if !cross.is_finite() {
                return Err(GeometryError::OutOfRange);
            }
            if cross == DVec3::ZERO {
                degenerate.push((face, corners));
            } else {
                kept.push(face);
            }
        }
        let box_of = |i: usize| face_box(corners(vertices, faces[kept[i] as usize]));
        let (mut tree, bbox) = Tree::build(kept.len(), box_of, MESH_SHAPE, parallel);
        for position in &mut tree.order {
            *position = kept[*position as usize];
        }
        drop(kept);
        // The vertices renumbered as the faces, in the tree's order, first name them.
        let mut renumbered = vec![u32::MAX; vertices.len()];
        let mut source = Vec::new();
        let mut name = |i: u32| {
            let slot = &mut renumbered[i as usize];
            if *slot == u32::MAX {
                // Below u32::MAX: indices are u32, so there are at most 2^32 distinct
                // vertices, and the last would need 96 GiB of them.
                *slot = source.len() as u32;
                source.push(i);
            }
            *slot
        };
        let triangles: Vec<[u32; 3]> = tree
            .order
            .iter()
            .map(|&f| faces[f as usize].map(&mut name))
            .collect();
        // Numbered from 0 in order of first use: as many as the largest number, plus one.
        let hittable_vertices = triangles
            .iter()
            .flatten()
            .max()
            .map_or(0, |&m| m as usize + 1);
        // Then those only degenerate faces name, for an update that makes them hittable
        // (a vertex no face names is not kept).
        for &(_, corners) in &degenerate {
            corners.into_iter().for_each(|i| {
                name(i);
            });
        }
        drop(renumbered);
        source.shrink_to_fit();
        let vertex_count = vertices.len();
        let vertices: Vec<DVec3> = source.iter().map(|&i| vertices[i as usize]).collect();
        let built_cost = tree.sah_cost();
        let blocks = triangles.len().div_ceil(AREA_BLOCK);
        let mut mesh = Self {
            vertices,
            source,
            vertex_count,
            hittable_vertices,
            degenerate,
            normals: Vec::new(),
            uvs: Vec::new(),
            triangles,
            tree,
            faces: faces.len(),
            near_overflow: bbox.near_overflow(),
            bbox,
            material: MaterialId::default(),
            area_sums: Vec::with_capacity(blocks),
            built_cost,
        };
        mesh.sum_areas();
        Ok(mesh)
    }

    /// Fills the running sums of the faces' areas.
    fn sum_areas(&mut self) {
        let mut total = 0.0;
        self.area_sums.clear();
        for (p, &face) in self.triangles.iter().enumerate() {
            let area = face_area(corners(&self.vertices, face));
            add_area(
                &mut self.area_sums,
                &mut total,
                p,
                self.triangles.len(),
                area,
            );
        }
    }

    /// Moves the vertices to `vertices` (one for each the mesh was built from, in the
    /// caller's numbering), keeping the faces, and refits the tree to them: every box
    /// recomputed bottom up, the tree's shape kept; normals and uvs are kept (see
    /// [`TriangleMesh::set_normals`]). The mesh answers as [`TriangleMesh::new`] of the
    /// moved vertices would (watertight, and exactly as the loop over its faces), with the
    /// faces keeping their numbers. Where a face turns degenerate or stops being so, or the
    /// moved faces no longer fit the tree's `f32` boxes, the tree is rebuilt instead.
    ///
    /// A refit is linear in the faces and allocates nothing, but keeps a tree chosen for
    /// where the faces were: watch [`TriangleMesh::cost`].
    ///
    /// # Errors
    /// As [`TriangleMesh::new`] for the vertices ([`GeometryError::LengthMismatch`] unless
    /// there is one per vertex given at build); the mesh is then left as it was.
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Hittable, Interval, Ray, TriangleMesh};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// let mut corners = [DVec3::ZERO, DVec3::X, DVec3::Y];
    /// let mut mesh = TriangleMesh::new(&corners, &[[0, 1, 2]])?;
    /// let ray = Ray::new(DVec3::new(0.25, 0.25, 5.0), DVec3::NEG_Z);
    /// assert_eq!(mesh.hit(&ray, Interval::FORWARD).unwrap().t, 5.0);
    ///
    /// // Lifted by 1: the same face, refitted.
    /// corners.iter_mut().for_each(|c| c.z += 1.0);
    /// mesh.set_vertices(&corners)?;
    /// assert_eq!(mesh.hit(&ray, Interval::FORWARD).unwrap().t, 4.0);
    ///
    /// // A NaN is refused, and the mesh stays where it was.
    /// corners[0].x = f64::NAN;
    /// assert!(mesh.set_vertices(&corners).is_err());
    /// assert_eq!(mesh.hit(&ray, Interval::FORWARD).unwrap().t, 4.0);
    /// # Ok(())
    /// # }
    /// ```
    pub fn set_vertices(&mut self, vertices: &[DVec3]) -> Result<(), GeometryError> {
        if vertices.len() != self.vertex_count {
            return Err(GeometryError::LengthMismatch {
                what: "vertices",
                expected: self.vertex_count,
                found: vertices.len(),
            });
        }
        // One pass over them: finite, and their box (so how large).
        let (mut lo, mut hi, mut finite) = (DVec3::INFINITY, DVec3::NEG_INFINITY, true);
        for v in vertices {
            finite &= v.is_finite();
            (lo, hi) = (lo.min(*v), hi.max(*v));
        }
        if !finite {
            let index = vertices.iter().position(|v| !v.is_finite()).unwrap_or(0);
            return Err(GeometryError::NonFiniteElement {
                what: "vertex",
                index,
            });
        }
        // Every error found before anything changes. A cross product of edges can only
        // overflow past 2^500: its terms are products of two coordinate differences, each
        // below 2^502, and f64 reaches 2^1024.
        let largest = lo.abs().max(hi.abs()).max_element();
        if largest > LARGEST_UNCHECKED {
            let kept = self
                .triangles
                .iter()
                .map(|face| face.map(|i| self.source[i as usize]));
            let dropped = self.degenerate.iter().map(|&(_, face)| face);
            if kept
                .chain(dropped)
                .any(|face| !cross(face.map(|i| vertices[i as usize])).is_finite())
            {
                return Err(GeometryError::OutOfRange);
            }
        }
        // A face that stops being degenerate joins the tree: a new tree.
        if self
            .degenerate
            .iter()
            .any(|&(_, face)| cross(face.map(|i| vertices[i as usize])) != DVec3::ZERO)
        {
            return self.rebuild_from(vertices);
        }
        for (v, &i) in self.vertices.iter_mut().zip(&self.source) {
            *v = vertices[i as usize];
        }
        // The box of the hittable faces' corners: the box of every vertex where they use
        // them all (as they mostly do), else a pass over the ones they use.
        if self.hittable_vertices != self.vertex_count {
            (lo, hi) = self.vertices[..self.hittable_vertices]
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(*v), hi.max(*v))
                });
        }
        // The tree centred on the box of the faces' corners, as the build centres it (on
        // their boxes, grown by an ulp or two: the same centre but for a rounding). The
        // refit meets the faces in order: their areas are summed on the way.
        let (triangles, positions, sums) = (&self.triangles, &self.vertices, &mut self.area_sums);
        let (mut total, mut degenerate) = (0.0, false);
        sums.clear();
        let refitted = self.tree.refit(Some(0.5 * lo + 0.5 * hi), |p| {
            let face = corners(positions, triangles[p]);
            let n = cross(face);
            degenerate |= n == DVec3::ZERO;
            add_area(sums, &mut total, p, triangles.len(), area_of(n));
            face_box(face)
        });
        match refitted {
            // A face that turned degenerate leaves the tree: a new tree too.
            Some(bbox) if !degenerate => {
                self.bbox = bbox;
                self.near_overflow = bbox.near_overflow();
                Ok(())
            }
            _ => self.rebuild_from(vertices),
        }
    }

    /// New normals, one per vertex, as [`TriangleMesh::with_normals`] takes them.
    ///
    /// # Errors
    /// As [`TriangleMesh::with_normals`]; the mesh is then left as it was.
    pub fn set_normals(&mut self, normals: &[DVec3]) -> Result<(), GeometryError> {
        self.normals = self.per_vertex("normals", normals, |n| n.is_finite())?;
        Ok(())
    }

    /// New texture coordinates, one pair per vertex, as [`TriangleMesh::with_uvs`] takes
    /// them.
    ///
    /// # Errors
    /// As [`TriangleMesh::with_uvs`]; the mesh is then left as it was.
    pub fn set_uvs(&mut self, uvs: &[DVec2]) -> Result<(), GeometryError> {
        self.uvs = self.per_vertex("uvs", uvs, |uv| uv.is_finite())?;
        Ok(())
    }

    /// The tree's cost by the surface area heuristic, now and at its last build: see
    /// [`TreeCost`] for when to [`TriangleMesh::rebuild`].
    #[must_use]
    pub fn cost(&self) -> TreeCost {
        TreeCost {
            built: self.built_cost,
            now: self.tree.sah_cost(),
        }
    }

    /// Builds the tree again over the vertices where they are now, as
    /// [`TriangleMesh::new`] would (normals, uvs and material kept).
    pub fn rebuild(&mut self) {
        let mut vertices = vec![DVec3::ZERO; self.vertex_count];
        for (v, &i) in self.vertices.iter().zip(&self.source) {
            vertices[i as usize] = *v;
        }
        // The vertices passed every check when they were given.
        let rebuilt = self.rebuild_from(&vertices);
        debug_assert!(rebuilt.is_ok());
    }

    /// The mesh of the same faces, normals, uvs and material on `vertices` (in the
    /// caller's numbering), built afresh.
    fn rebuild_from(&mut self, vertices: &[DVec3]) -> Result<(), GeometryError> {
        let mut faces = vec![[0u32; 3]; self.faces];
        for (face, &index) in self.triangles.iter().zip(&self.tree.order) {
            faces[index as usize] = face.map(|i| self.source[i as usize]);
        }
        for &(index, face) in &self.degenerate {
            faces[index as usize] = face;
        }
        let mut mesh = Self::build(vertices, &faces, false)?;
        mesh.normals = reorder(&self.normals, &self.source, &mesh.source);
        mesh.uvs = reorder(&self.uvs, &self.source, &mesh.source);
        mesh.material = self.material;
        *self = mesh;
        Ok(())
    }

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

    /// The hittable faces, each a [`Hittable`] of its own, in no particular order.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = Face<'_>> {
        (0..self.triangles.len()).map(|position| Face {
            mesh: self,
            position,
        })
    }

    /// The corners of the face at `position` of the tree's order.
    #[inline(always)]
    fn corners_at(&self, position: usize) -> [DVec3; 3] {
        corners(&self.vertices, self.triangles[position])
    }

    /// The crossing of the face at `position` with `ray`, if its `t` (kept within the
    /// face's box along the ray) lies in `ray_t`, and the exact crossing at or beyond
    /// `ray_t.min` whatever its rounding (the contract's clause 5: a ray spawned from a face never
    /// finds it again, which a rounded `t` of zero or just above would break).
    #[inline(always)]
    fn cross(
        &self,
        sheared: &Sheared,
        box_ray: &mut Option<BoxRay>,
        ray: &Ray,
        ray_t: Interval,
        position: usize,
    ) -> Option<Crossing> {
        let p = self.corners_at(position);
        let mut crossing = sheared.test(&p, ray_t.min)?;
        let beyond = crossing.t - crossing.t_error >= ray_t.min || ray_t.min == f64::NEG_INFINITY;
        // (The face a bounce or shadow ray leaves is crossed at about zero, and rejected
        // here, before its box is computed.)
        if !beyond {
            return None;
        }
        crossing.t = face_box(p).clamp_hit_on(ray, box_ray, crossing.t)?;
        if !ray_t.contains(crossing.t) {
            return None;
        }
        // Away from f64's end the hit's point and error bound cannot overflow (the weights
        // sum to one, the bound is a few ulps of three such terms); near it, only a
        // crossing whose record can be made counts, so that `occluded` answers as `hit`.
        if self.near_overflow && self.point(position, crossing.barycentric()).is_none() {
            return None;
        }
        Some(crossing)
    }

    /// The point of `crossing` on the face at `position`, and its error bound; `None` where
    /// either overflows.
    #[inline]
    fn point(&self, position: usize, b: DVec3) -> Option<(DVec3, DVec3)> {
        let [p0, p1, p2] = self.corners_at(position);
        let (w0, w1, w2) = (b.x * p0, b.y * p1, b.z * p2);
        let point = w0 + w1 + w2;
        // pbrt-v4 (`Triangle::InteractionFromIntersection`): the weights sum to one to
        // within a few roundings, and the sum of the weighted corners adds its own.
        let point_error = gamma(7) * (w0.abs() + w1.abs() + w2.abs());
        (point.is_finite() && point_error.is_finite()).then_some((point, point_error))
    }

    /// The closest crossing, its position in the tree's order, by the same rule as
    /// [`Bvh::hit_with_index`](crate::Bvh::hit_with_index): of faces hit at exactly the
    /// same `t`, the one the caller numbered first.
    #[inline]
    fn closest(
        &self,
        ray: &Ray,
        ray_t: Interval,
        tally: &mut impl Tally,
    ) -> Option<(usize, Crossing)> {
        let sheared = Sheared::new(ray)?;
        let mut box_ray = None;
        let mut closest: Option<(usize, Crossing)> = None;
        let mut t_max = ray_t.max;
        let order = &self.tree.order;
        let mut tests = 0u32;
        self.tree
            .walk::<true>(ray, ray_t, &mut t_max, tally, |first, count, t_max| {
                tests += count as u32;
                for position in first..first + count {
                    if let Some(c) = self.cross(
                        &sheared,
                        &mut box_ray,
                        ray,
                        Interval::new(ray_t.min, *t_max),
                        position,
                    ) && (c.t < *t_max
                        || closest.is_none_or(|(best, _)| order[position] < order[best]))
                    {
                        *t_max = c.t;
                        closest = Some((position, c));
                    }
                }
                false
            });
        tally.tests(tests);
        closest
    }

    /// Whether any face crosses `ray` within `ray_t`.
    #[inline]
    fn any(&self, ray: &Ray, ray_t: Interval, tally: &mut impl Tally) -> bool {
        let Some(sheared) = Sheared::new(ray) else {
            return false;
        };
        let mut box_ray = None;
        let mut found = false;
        let mut t_max = ray_t.max;
        let mut tests = 0u32;
        self.tree
            .walk::<false>(ray, ray_t, &mut t_max, tally, |first, count, _| {
                found = (first..first + count).any(|p| {
                    tests += 1;
                    self.cross(&sheared, &mut box_ray, ray, ray_t, p).is_some()
                });
                found
            });
        tally.tests(tests);
        found
    }

    /// What [`TriangleMesh::hit`](Hittable::hit) costs on `ray`: the tree's nodes whose
    /// children's boxes it tests, and the faces it tests (see [`Bvh::hit_visits`]).
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::{Interval, Ray, TriangleMesh};
    ///
    /// let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
    /// let mesh = TriangleMesh::new(&square, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    /// let down = Ray::new(DVec3::new(0.7, 0.2, 1.0), DVec3::NEG_Z);
    /// let cost = mesh.hit_visits(&down, Interval::FORWARD);
    /// assert!(cost.nodes == 1 && (1..=2).contains(&cost.tests));
    /// ```
    ///
    /// [`Bvh::hit_visits`]: crate::Bvh::hit_visits
    #[must_use]
    pub fn hit_visits(&self, ray: &Ray, ray_t: Interval) -> Visits {
        let mut visits = Visits::default();
        self.closest(ray, ray_t, &mut visits);
        visits
    }

    /// What [`TriangleMesh::occluded`](Hittable::occluded) costs on `ray`, as
    /// [`TriangleMesh::hit_visits`] counts.
    #[must_use]
    pub fn occluded_visits(&self, ray: &Ray, ray_t: Interval) -> Visits {
        let mut visits = Visits::default();
        self.any(ray, ray_t, &mut visits);
        visits
    }

    /// The hit record of `crossing` of the face at `position`.
    fn record_at(&self, ray: &Ray, position: usize, t: f64, b: DVec3) -> Option<HitRecord> {
        let face = self.triangles[position];
        let [p0, p1, p2] = self.corners_at(position);
        let (point, point_error) = self.point(position, b)?;
        let (normal, _) = unit_and_length((p1 - p0).cross(p2 - p0));
        let uv = if self.uvs.is_empty() {
            DVec2::new(b.y, b.z)
        } else {
            let [a, c, d] = face.map(|i| self.uvs[i as usize]);
            b.x * a + b.y * c + b.z * d
        };
        let mut record = HitRecord::new(ray, t, point, normal)
            .with_point_error(point_error)
            .with_uv(uv)
            .with_material(self.material)
            .with_primitive(self.tree.order[position]);
        if !self.normals.is_empty() {
            let [a, c, d] = face.map(|i| self.normals[i as usize]);
            let (shading, length) = unit_and_length(b.x * a + b.y * c + b.z * d);
            if length > 0.0 && shading.is_finite() {
                record = record.with_shading_normal(shading);
            }
        }
        normal.is_finite().then_some(record)
    }
}

impl Hittable for TriangleMesh {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let (position, crossing) = self.closest(ray, ray_t, &mut ())?;
        self.record_at(ray, position, crossing.t, crossing.barycentric())
    }

    /// The face's barycentrics in `coords`, its position in the tree's order in `part`.
    fn find(&self, ray: &Ray, ray_t: Interval) -> Option<Found> {
        let (position, crossing) = self.closest(ray, ray_t, &mut ())?;
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
        self.any(ray, ray_t, &mut ())
    }
}

/// One face of a [`TriangleMesh`], as a [`Hittable`] of its own: exactly the decision and
/// the hit the mesh makes for that face, so that a loop over the faces finds what the
/// mesh's tree finds.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Hittable, Interval, Ray, TriangleMesh};
///
/// let mesh = TriangleMesh::new(&[DVec3::ZERO, DVec3::X, DVec3::Y], &[[0, 1, 2]]).unwrap();
/// let face = mesh.faces().next().unwrap();
/// let ray = Ray::new(DVec3::new(0.25, 0.5, 1.0), DVec3::NEG_Z);
/// let (hit, b) = face.hit_barycentric(&ray, Interval::FORWARD).unwrap();
/// assert_eq!((face.index(), hit.t), (0, 1.0));
/// assert_eq!(b, DVec3::new(0.25, 0.25, 0.5)); // the weights of the three corners
/// assert_eq!(hit.point, DVec3::new(0.25, 0.5, 0.0));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Face<'a> {
    mesh: &'a TriangleMesh,
    position: usize,
}

impl Face<'_> {
    /// The face's number in the list the mesh was built from.
    #[inline]
    #[must_use]
    pub fn index(&self) -> u32 {
        self.mesh.tree.order[self.position]
    }

    /// The face's three vertex indices, as the caller numbered the vertices.
    #[inline]
    #[must_use]
    pub fn indices(&self) -> [u32; 3] {
        self.mesh.triangles[self.position].map(|i| self.mesh.source[i as usize])
    }

    /// The face's three corners.
    #[inline]
    #[must_use]
    pub fn corners(&self) -> [DVec3; 3] {
        self.mesh.corners_at(self.position)
    }

    /// The hit and its barycentric coordinates: the weights of the three corners, each at
    /// least 0, summing to 1 to within rounding.
    #[must_use]
    pub fn hit_barycentric(&self, ray: &Ray, ray_t: Interval) -> Option<(HitRecord, DVec3)> {
        let sheared = Sheared::new(ray)?;
        let crossing = self
            .mesh
            .cross(&sheared, &mut None, ray, ray_t, self.position)?;
        let record = self
            .mesh
            .record_at(ray, self.position, crossing.t, crossing.barycentric())?;
        Some((record, crossing.barycentric()))
    }
}

impl Hittable for Face<'_> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.hit_barycentric(ray, ray_t).map(|(hit, _)| hit)
    }

    #[inline]
    fn bounding_box(&self) -> Aabb {
        face_box(self.mesh.corners_at(self.position))
    }
}

#[inline(always)]
fn corners(vertices: &[DVec3], [a, b, c]: [u32; 3]) -> [DVec3; 3] {
    [
        vertices[a as usize],
        vertices[b as usize],
        vertices[c as usize],
    ]
}

/// The cross product of a face's edges from its first corner: its normal, of twice its
/// area in length.
#[inline(always)]
fn cross([a, b, c]: [DVec3; 3]) -> DVec3 {
    (b - a).cross(c - a)
}

/// A face's area, as the running sums add it.
#[inline(always)]
fn face_area(p: [DVec3; 3]) -> f64 {
    area_of(cross(p))
}

/// Adds the area of the face at position `p` of `faces` to the running `total`, and keeps
/// the total at the end of each block of [`AREA_BLOCK`] faces (and of the last): the one
/// way the running sums are made, so that a sampled face is the same however they were.
#[inline(always)]
fn add_area(sums: &mut Vec<f64>, total: &mut f64, p: usize, faces: usize, area: f64) {
    *total += area;
    if p % AREA_BLOCK == AREA_BLOCK - 1 || p + 1 == faces {
        sums.push(*total);
    }
}

/// The area of a face whose [`cross`] is `n`.
#[inline(always)]
fn area_of(n: DVec3) -> f64 {
    0.5 * length(n)
}

/// Past this magnitude a vertex's faces are checked for a cross product that overflows
/// before an update changes anything (see [`TriangleMesh::set_vertices`]).
const LARGEST_UNCHECKED: f64 = 3.273_390_607_896_142e150; // 2^500

/// The box of a face's corners, grown by an ulp or two of its coordinates: a ray whose
/// crossing is settled within double-double rounding of an edge still meets it.
#[inline(always)]
fn face_box([a, b, c]: [DVec3; 3]) -> Aabb {
    let (min, max) = (a.min(b).min(c), a.max(b).max(c));
    // Never flat: an axis-aligned face's box has the thickness of an `f32` ulp of the
    // face's size (about what the tree's `f32` boxes add to it anyway), so that its hits
    // are settled within it by `clamp_hit`'s fast path, not the slab test, for rays from
    // up to about 10^7 times its size away.
    let thickness = (max - min).max_element() * f64::from(f32::EPSILON);
    Aabb { min, max }.grown(gamma(2) * min.abs().max(max.abs()) + DVec3::splat(thickness))
}

impl TriangleMesh {
    /// `values`, one for each vertex the caller gave, checked and put in the mesh's order
    /// of vertices.
    fn per_vertex<T: Copy>(
        &self,
        what: &'static str,
        values: &[T],
        finite: impl Fn(&T) -> bool,
    ) -> Result<Vec<T>, GeometryError> {
        if values.len() != self.vertex_count {
            return Err(GeometryError::LengthMismatch {
                what,
                expected: self.vertex_count,
                found: values.len(),
            });
        }
        if let Some(index) = values.iter().position(|v| !finite(v)) {
            return Err(GeometryError::NonFiniteElement { what, index });
        }
        Ok(self.source.iter().map(|&i| values[i as usize]).collect())
    }
}

/// Per-vertex `values` in the order `from` numbers the vertices (`from[i]` the caller's
/// number of `values[i]`), put in the order `to` numbers them; empty stays empty.
fn reorder<T: Copy + Default>(values: &[T], from: &[u32], to: &[u32]) -> Vec<T> {
    if values.is_empty() {
        return Vec::new();
    }
    let mut by_caller = vec![T::default(); from.len()];
    for (value, &i) in values.iter().zip(from) {
        by_caller[i as usize] = *value;
    }
    to.iter().map(|&i| by_caller[i as usize]).collect()
}

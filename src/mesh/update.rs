//! A [`TriangleMesh`] that changes: vertices moved (the tree refitted, or rebuilt when it
//! has grown too costly), normals and `uv`s replaced.

use alloc::vec;

use glam::{DVec2, DVec3};

use super::{
    LARGEST_UNCHECKED, TriangleMesh, add_area, area_of, corners, cross, face_box, reorder,
};
use crate::{GeometryError, TreeCost};

impl TriangleMesh {
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
    pub(super) fn rebuild_from(&mut self, vertices: &[DVec3]) -> Result<(), GeometryError> {
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
}

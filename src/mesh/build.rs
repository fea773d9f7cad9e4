//! Building a [`TriangleMesh`]: its faces checked, its tree built over them, its vertices
//! and faces stored in the tree's order, and the running sums of its faces' areas.

use alloc::vec;
use alloc::vec::Vec;

use glam::DVec3;

use super::{AREA_BLOCK, MESH_SHAPE, TriangleMesh};
use crate::math::{gamma, length};
use crate::tree::Tree;
use crate::{Aabb, GeometryError, MaterialId};

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

    pub(super) fn build(
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
            lanes: crate::simd::Avx2::detect(),
        };
        mesh.sum_areas();
        Ok(mesh)
    }

    /// Fills the running sums of the faces' areas.
    pub(super) fn sum_areas(&mut self) {
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

    /// `values`, one for each vertex the caller gave, checked and put in the mesh's order
    /// of vertices.
    pub(super) fn per_vertex<T: Copy>(
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

#[inline(always)]
pub(super) fn corners(vertices: &[DVec3], [a, b, c]: [u32; 3]) -> [DVec3; 3] {
    [
        vertices[a as usize],
        vertices[b as usize],
        vertices[c as usize],
    ]
}

/// The cross product of a face's edges from its first corner: its normal, of twice its
/// area in length.
#[inline(always)]
pub(super) fn cross([a, b, c]: [DVec3; 3]) -> DVec3 {
    (b - a).cross(c - a)
}

/// A face's area, as the running sums add it.
#[inline(always)]
pub(super) fn face_area(p: [DVec3; 3]) -> f64 {
    area_of(cross(p))
}

/// Adds the area of the face at position `p` of `faces` to the running `total`, and keeps
/// the total at the end of each block of [`AREA_BLOCK`] faces (and of the last): the one
/// way the running sums are made, so that a sampled face is the same however they were.
#[inline(always)]
pub(super) fn add_area(sums: &mut Vec<f64>, total: &mut f64, p: usize, faces: usize, area: f64) {
    *total += area;
    if p % AREA_BLOCK == AREA_BLOCK - 1 || p + 1 == faces {
        sums.push(*total);
    }
}

/// The area of a face whose [`cross`] is `n`.
#[inline(always)]
pub(super) fn area_of(n: DVec3) -> f64 {
    0.5 * length(n)
}

/// Past this magnitude a vertex's faces are checked for a cross product that overflows
/// before an update changes anything (see [`TriangleMesh::set_vertices`]).
pub(super) const LARGEST_UNCHECKED: f64 = 3.273_390_607_896_142e150; // 2^500

/// The box of a face's corners, grown by an ulp or two of its coordinates: a ray whose
/// crossing is settled within double-double rounding of an edge still meets it.
#[inline(always)]
pub(super) fn face_box([a, b, c]: [DVec3; 3]) -> Aabb {
    let (min, max) = (a.min(b).min(c), a.max(b).max(c));
    // Never flat: an axis-aligned face's box has the thickness of an `f32` ulp of the
    // face's size (about what the tree's `f32` boxes add to it anyway), so that its hits
    // are settled within it by `clamp_hit`'s fast path, not the slab test, for rays from
    // up to about 10^7 times its size away.
    let thickness = (max - min).max_element() * f64::from(f32::EPSILON);
    Aabb { min, max }.grown(gamma(2) * min.abs().max(max.abs()) + DVec3::splat(thickness))
}

/// Per-vertex `values` in the order `from` numbers the vertices (`from[i]` the caller's
/// number of `values[i]`), put in the order `to` numbers them; empty stays empty.
pub(super) fn reorder<T: Copy + Default>(values: &[T], from: &[u32], to: &[u32]) -> Vec<T> {
    if values.is_empty() {
        return Vec::new();
    }
    let mut by_caller = vec![T::default(); from.len()];
    for (value, &i) in values.iter().zip(from) {
        by_caller[i as usize] = *value;
    }
    to.iter().map(|&i| by_caller[i as usize]).collect()
}

//! The queries of a [`TriangleMesh`]: a face's crossing (`intersect.rs`'s watertight test,
//! with the bound that keeps a spawned ray off its face), the closest and the any-hit walks
//! of its tree, and the record of the winner.

use glam::{DVec2, DVec3};

use super::block::LANES;
use super::intersect::{Crossing, Sheared};
use super::{TriangleMesh, corners, face_box};
use crate::aabb::BoxRay;
use crate::math::{gamma, unit_and_length};
use crate::simd::Lanes;
use crate::tree::{Tally, Visits, wins};
use crate::{HitRecord, Interval, Ray};

/// The point at barycentrics `b` on the face of `corners`, and its error bound; `None`
/// where either overflows.
#[inline(always)]
fn point([p0, p1, p2]: [DVec3; 3], b: DVec3) -> Option<(DVec3, DVec3)> {
    let (w0, w1, w2) = (b.x * p0, b.y * p1, b.z * p2);
    let point = w0 + w1 + w2;
    // pbrt-v4 (`Triangle::InteractionFromIntersection`): the weights sum to one to within
    // a few roundings, and the sum of the weighted corners adds its own.
    let point_error = gamma(7) * (w0.abs() + w1.abs() + w2.abs());
    (point.is_finite() && point_error.is_finite()).then_some((point, point_error))
}

impl TriangleMesh {
    /// The corners of the face at `position` of the tree's order.
    #[inline(always)]
    pub(super) fn corners_at(&self, position: usize) -> [DVec3; 3] {
        corners(&self.vertices, self.triangles[position])
    }

    /// The test of the leaf of `count` faces from position `first`, in lanes of `L`, a
    /// block of at most [`LANES`] at a time (one block: a mesh's leaves hold at most that
    /// many): `found(position, crossing)` for each face crossed, in order, until it returns
    /// `true` (and then `true`).
    #[inline(always)]
    fn cross_leaf<L: Lanes>(
        &self,
        lanes: L::Token,
        sheared: &Sheared,
        (first, count): (usize, usize),
        t_min: f64,
        mut found: impl FnMut(usize, Crossing) -> bool,
    ) -> bool {
        // (A loop of its own: `Iterator::any`'s closures, left out of line, would take the
        // lanes out of the AVX2 copy.)
        let (mut block, end) = (first, first + count);
        while block < end {
            let next = (block + LANES).min(end);
            let faces = &self.triangles[block..next];
            if sheared.test_block::<L>(
                lanes,
                &self.vertices,
                faces,
                t_min,
                #[inline(always)]
                |i, c| found(block + i, c),
            ) {
                return true;
            }
            block = next;
        }
        false
    }

    /// The crossing of the face at `position` with `ray`, if its `t` (kept within the
    /// face's box along the ray) lies in `ray_t`, and the exact crossing at or beyond
    /// `ray_t.min` whatever its rounding (the contract's clause 5: a ray spawned from a face never
    /// finds it again, which a rounded `t` of zero or just above would break).
    ///
    /// With `ANY` (a query that needs only whether a face is crossed, not its `t`), a
    /// crossing whose `t` lies inside `ray_t` by more than its error is kept without the
    /// box's clamp, which could only move `t` to within that error of itself (the box holds
    /// the face, and its slab test pads its far distances by more than the near ones
    /// round): the same answer, without the face's box and the clamp's comparisons.
    #[inline(always)]
    pub(super) fn cross<const ANY: bool>(
        &self,
        sheared: &Sheared,
        box_ray: &mut Option<BoxRay>,
        ray: &Ray,
        ray_t: Interval,
        position: usize,
    ) -> Option<Crossing> {
        let crossing = sheared.test(&self.corners_at(position), ray_t.min)?;
        self.keep::<ANY>(crossing, box_ray, ray, ray_t, position)
    }

    /// [`TriangleMesh::cross`] after the face test: whether the test's `crossing` of the
    /// face at `position` counts.
    #[inline(always)]
    pub(super) fn keep<const ANY: bool>(
        &self,
        mut crossing: Crossing,
        box_ray: &mut Option<BoxRay>,
        ray: &Ray,
        ray_t: Interval,
        position: usize,
    ) -> Option<Crossing> {
        let beyond = crossing.t - crossing.t_error >= ray_t.min || ray_t.min == f64::NEG_INFINITY;
        // (The face a bounce or shadow ray leaves is crossed at about zero, and rejected
        // here, before its box is computed.)
        if !beyond {
            return None;
        }
        if ANY && !self.near_overflow {
            // The clamped `t` is within `t_error` of the exact crossing's, and the box's
            // near distances (where the clamp can put it) within a few ulps of it past that.
            let slack = crossing.t_error
                + (crossing.t_error + crossing.t.abs()) * (4.0 * f64::EPSILON)
                + f64::MIN_POSITIVE;
            if crossing.t - slack > ray_t.min && crossing.t + slack < ray_t.max {
                return Some(crossing);
            }
        }
        crossing.t = face_box(self.corners_at(position)).clamp_hit_on(ray, box_ray, crossing.t)?;
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
    /// either overflows. (A call from the walk: inlined there, or its corners shared with
    /// the record's through one function, the skylight room's shadow rays took 20 to 60
    /// instructions more.)
    #[inline]
    pub(super) fn point(&self, position: usize, b: DVec3) -> Option<(DVec3, DVec3)> {
        point(self.corners_at(position), b)
    }

    /// The closest crossing, its position in the tree's order, by the same rule as
    /// [`Bvh::hit_with_index`](crate::Bvh::hit_with_index): of faces hit at exactly the
    /// same `t`, the one the caller numbered first. (Inlined always, here and below, so
    /// that the mesh's AVX2 kernel compiles the walk for AVX2.)
    ///
    /// A crossing counts only where `accept` takes it (a filter's say, asked once per face
    /// the walk crosses; always yes, and compiled away, for the mesh's own queries).
    #[inline(always)]
    pub(super) fn closest<L: Lanes>(
        &self,
        lanes: L::Token,
        ray: &Ray,
        ray_t: Interval,
        tally: &mut impl Tally,
        accept: impl Fn(usize, &Crossing) -> bool,
    ) -> Option<(usize, Crossing)> {
        // (Tried: the box test's form of the ray made here too, shared with the walk and
        // the clamp: a bunny bounce 29 instructions more, the node's offsets not hoisted.)
        let sheared = Sheared::new(ray)?;
        let mut box_ray = None;
        let mut closest: Option<(usize, Crossing)> = None;
        let mut t_max = ray_t.max;
        let order = &self.tree.order;
        let mut tests = 0u32;
        // A leaf's faces tested together, in lanes (`block.rs`), inlined into the walk here
        // and in `any` so that the lanes are AVX2's where the walk is compiled for it.
        // (Tried: a pass over leaf blocks of four faces in `f32` lanes ruling out certain
        // misses first, more instructions a ray; the first step alone in `f64` lanes, its
        // survivors tested again one at a time, slower: `docs/performance.md`.)
        self.tree.walk_on::<true, L::Boxes>(
            lanes,
            ray,
            ray_t,
            &mut t_max,
            tally,
            #[inline(always)]
            |first, count, t_max| {
                tests += count as u32;
                self.cross_leaf::<L>(
                    lanes,
                    &sheared,
                    (first, count),
                    ray_t.min,
                    #[inline(always)]
                    |position, c| {
                        if let Some(c) = self.keep::<false>(
                            c,
                            &mut box_ray,
                            ray,
                            Interval::new(ray_t.min, *t_max),
                            position,
                        ) && wins(c.t, *t_max, || {
                            let best = closest.map(|(best, _)| order[best] as usize);
                            (order[position] as usize, best)
                        }) && accept(position, &c)
                        {
                            *t_max = c.t;
                            closest = Some((position, c));
                        }
                        false
                    },
                );
                false
            },
        );
        tally.tests(tests);
        closest
    }

    /// The mesh's own closest crossing (`hit` and `find`), in the kernel it picked.
    #[inline]
    pub(super) fn nearest(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, Crossing)> {
        kernel!(self, |lanes, L| self.closest::<L>(
            lanes,
            ray,
            ray_t,
            &mut (),
            |_, _| true
        ))
    }

    /// Whether any face crosses `ray` within `ray_t` (and `accept` takes it).
    #[inline(always)]
    pub(super) fn any<L: Lanes>(
        &self,
        lanes: L::Token,
        ray: &Ray,
        ray_t: Interval,
        tally: &mut impl Tally,
        accept: impl Fn(usize, &Crossing) -> bool,
    ) -> bool {
        let Some(sheared) = Sheared::new(ray) else {
            return false;
        };
        let mut box_ray = None;
        let mut found = false;
        let mut t_max = ray_t.max;
        let mut tests = 0u32;
        self.tree.walk_on::<false, L::Boxes>(
            lanes,
            ray,
            ray_t,
            &mut t_max,
            tally,
            #[inline(always)]
            |first, count, _| {
                found = self.cross_leaf::<L>(
                    lanes,
                    &sheared,
                    (first, count),
                    ray_t.min,
                    #[inline(always)]
                    |position, c| {
                        let kept = self
                            .keep::<true>(c, &mut box_ray, ray, ray_t, position)
                            .is_some_and(|c| accept(position, &c));
                        // (Counted as the faces before the one found, and that one.)
                        if kept {
                            tests += (position - first) as u32 + 1;
                        }
                        kept
                    },
                );
                if !found {
                    tests += count as u32;
                }
                found
            },
        );
        tally.tests(tests);
        found
    }

    /// What [`TriangleMesh::hit`](crate::Hittable::hit) costs on `ray`: the tree's nodes whose
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
        kernel!(self, |lanes, L| self.closest::<L>(
            lanes,
            ray,
            ray_t,
            &mut visits,
            |_, _| true
        ));
        visits
    }

    /// What [`TriangleMesh::occluded`](crate::Hittable::occluded) costs on `ray`, as
    /// [`TriangleMesh::hit_visits`] counts.
    #[must_use]
    pub fn occluded_visits(&self, ray: &Ray, ray_t: Interval) -> Visits {
        let mut visits = Visits::default();
        kernel!(self, |lanes, L| self.any::<L>(
            lanes,
            ray,
            ray_t,
            &mut visits,
            |_, _| true
        ));
        visits
    }

    /// The texture coordinates of the face at `position` at barycentrics `b`: interpolated
    /// where the mesh has them, `(b1, b2)` where it does not.
    #[inline]
    pub(super) fn uv_at(&self, position: usize, b: DVec3) -> DVec2 {
        if self.uvs.is_empty() {
            DVec2::new(b.y, b.z)
        } else {
            let [a, c, d] = self.triangles[position].map(|i| self.uvs[i as usize]);
            b.x * a + b.y * c + b.z * d
        }
    }

    /// The hit record of `crossing` of the face at `position`.
    pub(super) fn record_at(
        &self,
        ray: &Ray,
        position: usize,
        t: f64,
        b: DVec3,
    ) -> Option<HitRecord> {
        let face = self.triangles[position];
        // (The corners loaded once for the point and the normal.)
        let corners = self.corners_at(position);
        let [p0, p1, p2] = corners;
        let (point, point_error) = point(corners, b)?;
        let (normal, _) = unit_and_length((p1 - p0).cross(p2 - p0));
        let uv = self.uv_at(position, b);
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

#[cfg(test)]
mod tests {
    use crate::{Hittable, Interval, Ray, TriangleMesh};
    use glam::{DMat3, DVec3};
    use proptest::prelude::*;
    use wide::f64x4;

    /// A bumpy grid of `n` x `n` squares (two faces each, vertices shared), turned, scaled
    /// and moved: shared edges and vertices at every magnitude.
    fn grid(n: u32, bumps: &[f64], turn: DMat3, scale: f64, offset: DVec3) -> TriangleMesh {
        let side = n + 1;
        let vertices: Vec<DVec3> = (0..side * side)
            .map(|i| {
                let (x, y) = (f64::from(i % side), f64::from(i / side));
                let z = bumps[i as usize % bumps.len()];
                turn * DVec3::new(x, y, z) * scale + offset
            })
            .collect();
        let mut faces = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let a = y * side + x;
                faces.push([a, a + 1, a + side + 1]);
                faces.push([a, a + side + 1, a + side]);
            }
        }
        TriangleMesh::new(&vertices, &faces).unwrap()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// The queries compiled for AVX2 (where this CPU has it) answer as the portable
        /// ones, bit for bit in face, `t` and barycentrics, on rays through vertices and
        /// edges, grazing, from far away, with directions of every length, and spawned from
        /// the hits (bounce and shadow rays), at offsets to 1e12 and sizes 1e-6 to 1e6.
        #[test]
        fn wide_queries_answer_as_portable_ones(
            bumps in prop::collection::vec(-0.5f64..0.5, 1..8),
            flat in any::<bool>(),
            angles in prop_oneof![Just([0.0; 3]), prop::array::uniform3(-3.2f64..3.2)],
            scale in prop_oneof![Just(1.0), Just(1e-6), Just(1e6), 1e-3f64..1e3],
            offset in prop_oneof![Just(0.0), Just(1e6), Just(1e9), Just(-1e12), -10.0f64..10.0],
            targets in prop::collection::vec((0u32..=12, 0u32..=12, 0usize..4), 1..24),
            froms in prop::collection::vec(prop::array::uniform3(-1.0f64..1.0), 1..24),
            lengths in prop::collection::vec(-30i32..=30, 1..24),
            far in prop_oneof![Just(1.0), Just(1e3), Just(1e9)],
            grazing in any::<bool>(),
        ) {
            let turn = DMat3::from_euler(glam::EulerRot::XYZ, angles[0], angles[1], angles[2]);
            let offset = DVec3::new(offset, -0.7 * offset, 0.3 * offset);
            // Flat and unturned: every face's box is as thin as its padding, the clamp's
            // closest call.
            let bumps = if flat { vec![0.0] } else { bumps };
            let mesh = grid(12, &bumps, turn, scale, offset);
            let (mut inside, mut hits) = (0, 0);
            for (k, &(i, j, kind)) in targets.iter().enumerate() {
                // A vertex, the middle of an edge (exactly, in the grid's frame), a point
                // inside a face (its corners weighted 1/2, 1/4, 1/4), or a corner of the
                // whole grid: on the bumpy surface, where the grid has one.
                let height = |x: u32, y: u32| {
                    if x <= 12 && y <= 12 {
                        bumps[(y * 13 + x) as usize % bumps.len()]
                    } else {
                        0.0
                    }
                };
                let (x, y, z) = match kind {
                    0 => (f64::from(i), f64::from(j), height(i, j)),
                    1 => (
                        f64::from(i) + 0.5,
                        f64::from(j),
                        0.5 * (height(i, j) + height(i + 1, j)),
                    ),
                    2 => {
                        // In the face of corners (x, y), (x + 1, y + 1), (x, y + 1).
                        let (x, y) = (i % 12, j % 12);
                        let z = 0.5 * height(x, y)
                            + 0.25 * (height(x + 1, y + 1) + height(x, y + 1));
                        (f64::from(x) + 0.25, f64::from(y) + 0.5, z)
                    }
                    _ => {
                        let (x, y) = (12 * (i % 2), 12 * (j % 2));
                        (f64::from(x), f64::from(y), height(x, y))
                    }
                };
                let target = turn * DVec3::new(x, y, z) * scale + offset;
                let from = DVec3::from(froms[k % froms.len()]);
                let away = if grazing {
                    // Nearly in the grid's plane.
                    turn * DVec3::new(from.x, from.y, 1e-9 * from.z.signum())
                } else {
                    turn * (from + DVec3::Z * 2.0)
                };
                let origin = target + away * scale * 12.0 * far;
                let length = 2f64.powi(lengths[k % lengths.len()]);
                let ray = Ray::new(origin, (target - origin) * length / (far * 12.0 * scale));
                let mut rays = vec![ray];
                inside += usize::from(kind == 2);
                if let Some(hit) = mesh.hit(&ray, Interval::FORWARD) {
                    hits += usize::from(kind == 2);
                    rays.push(hit.spawn_ray(ray.direction));
                    rays.push(hit.spawn_ray(-ray.direction));
                    rays.push(hit.spawn_ray(turn * DVec3::from(froms[(k + 1) % froms.len()])));
                }
                for ray in &rays {
                    for ray_t in [Interval::FORWARD, Interval::new(0.0, 1.0), Interval::UNIVERSE] {
                        let portable = mesh.closest::<f64x4>((), ray, ray_t, &mut (), |_, _| true);
                        let fast = kernel!(mesh, |lanes, L| mesh.closest::<L>(lanes, ray, ray_t, &mut (), |_, _| true));
                        let key = |c: Option<(usize, super::Crossing)>| {
                            c.map(|(p, c)| (p, c.t.to_bits(), c.barycentric().to_array().map(f64::to_bits)))
                        };
                        prop_assert_eq!(key(portable), key(fast));
                        prop_assert_eq!(
                            mesh.any::<f64x4>((), ray, ray_t, &mut (), |_, _| true),
                            kernel!(mesh, |lanes, L| mesh.any::<L>(lanes, ray, ray_t, &mut (), |_, _| true))
                        );
                    }
                    // Any hit answers as the closest hit with the range ending, or
                    // starting, a few ulps either side of the closest crossing, where the
                    // any-hit query's shortcut past the box clamp stops applying.
                    if let Some((_, c)) = mesh.closest::<f64x4>((), ray, Interval::FORWARD, &mut (), |_, _| true) {
                        for ulps in -3i64..=3 {
                            let end = f64::from_bits((c.t.to_bits() as i64 + ulps) as u64);
                            for ray_t in [Interval::new(0.0, end), Interval::new(end, f64::INFINITY)] {
                                let closest = mesh.closest::<f64x4>((), ray, ray_t, &mut (), |_, _| true).is_some();
                                prop_assert_eq!(mesh.any::<f64x4>((), ray, ray_t, &mut (), |_, _| true), closest);
                                prop_assert_eq!(
                                    kernel!(mesh, |lanes, L| mesh.any::<L>(lanes, ray, ray_t, &mut (), |_, _| true)),
                                    closest
                                );
                            }
                        }
                    }
                }
            }
            // Rays aimed inside a face from off the grid's plane find it or a face before it
            // (the comparison above is of hits, not only of misses), where the grid is large
            // enough against its offset for its faces to be where they were meant to be:
            // 2^30 of its coordinates' ulps across. (Aimed at the plane `z = 0` rather than
            // at the surface, a ray could pass under a bump at the grid's edge and miss.)
            let resolved = 12.0 * scale >= offset.abs().max_element() * 2f64.powi(-22);
            prop_assert!(grazing || !resolved || hits == inside);
        }
    }
}

//! The queries of a [`TriangleMesh`]: a face's crossing (`intersect.rs`'s watertight test,
//! with the bound that keeps a spawned ray off its face), the closest and the any-hit walks
//! of its tree, and the record of the winner.

use glam::{DVec2, DVec3};

use super::intersect::{Crossing, Sheared};
use super::{TriangleMesh, corners, face_box};
use crate::aabb::BoxRay;
use crate::bvh::{Tally, Visits};
use crate::math::{gamma, unit_and_length};
use crate::{HitRecord, Interval, Ray};

impl TriangleMesh {
    /// The corners of the face at `position` of the tree's order.
    #[inline(always)]
    pub(super) fn corners_at(&self, position: usize) -> [DVec3; 3] {
        corners(&self.vertices, self.triangles[position])
    }

    /// The crossing of the face at `position` with `ray`, if its `t` (kept within the
    /// face's box along the ray) lies in `ray_t`, and the exact crossing at or beyond
    /// `ray_t.min` whatever its rounding (the contract's clause 5: a ray spawned from a face never
    /// finds it again, which a rounded `t` of zero or just above would break).
    #[inline(always)]
    pub(super) fn cross(
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
    pub(super) fn point(&self, position: usize, b: DVec3) -> Option<(DVec3, DVec3)> {
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
    pub(super) fn closest(
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
    pub(super) fn any(&self, ray: &Ray, ray_t: Interval, tally: &mut impl Tally) -> bool {
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
        self.closest(ray, ray_t, &mut visits);
        visits
    }

    /// What [`TriangleMesh::occluded`](crate::Hittable::occluded) costs on `ray`, as
    /// [`TriangleMesh::hit_visits`] counts.
    #[must_use]
    pub fn occluded_visits(&self, ray: &Ray, ray_t: Interval) -> Visits {
        let mut visits = Visits::default();
        self.any(ray, ray_t, &mut visits);
        visits
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

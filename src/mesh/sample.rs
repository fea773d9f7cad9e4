//! A [`TriangleMesh`] as a light: sampled uniformly by area.

use glam::{DVec2, DVec3};

use super::intersect::Sheared;
use super::{AREA_BLOCK, TriangleMesh, face_area};
use crate::math::{direction_scale, sqrt, unit_and_length};
use crate::sample::{reaching, toward_middle, unit_direction};
use crate::{Interval, PdfHittable, Ray};

/// Sampled uniformly by area: a face with probability in proportion to its area, then a
/// point uniformly on it. An emissive mesh is then a light like any other.
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{PdfHittable, TriangleMesh};
///
/// // A 2 x 2 square of two triangles, 1 above the origin.
/// let y = 1.0;
/// let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, z)| DVec3::new(x, y, z));
/// let light = TriangleMesh::new(&corners, &[[0, 1, 2], [0, 2, 3]]).unwrap();
/// // Toward (0.5, 1, 0): distance^2 1.25, cosine 1 / sqrt(1.25), area 4.
/// let pdf = light.pdf_value(DVec3::ZERO, DVec3::new(0.5, 1.0, 0.0));
/// assert!((pdf - 1.25f64.powf(1.5) / 4.0).abs() < 1e-15);
/// let d = light.sample_direction(DVec3::ZERO, DVec2::new(0.3, 0.6));
/// assert!(d.y > 0.0 && light.pdf_value(DVec3::ZERO, d) > 0.0);
/// ```
impl PdfHittable for TriangleMesh {
    /// The sum, over every face the ray from `origin` along `direction` crosses (at `t >=
    /// 0`, not only the nearest: sampling picks points whether or not they are in view),
    /// of `distance^2 / (|cos| area)`. 0 where nothing is crossed and wherever the sum is
    /// not a finite number. A direction through an edge that two faces share counts both
    /// (such directions have measure zero: no estimate changes).
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        // As for a quad: a direction of ordinary length (an exact scaling) keeps `t` and
        // `t |d|` within f64's range.
        let direction = direction * direction_scale(direction);
        let ray = Ray::new(origin, direction);
        let (Some(sheared), area) = (Sheared::new(&ray), self.area()) else {
            return 0.0;
        };
        let (unit, length) = unit_and_length(direction);
        let mut sum = 0.0;
        let mut t_max = f64::INFINITY;
        let mut box_ray = None;
        self.tree.walk::<false>(
            &ray,
            Interval::FORWARD,
            &mut t_max,
            &mut (),
            |first, count, _| {
                for position in first..first + count {
                    if let Some(c) = self.cross::<false>(
                        &sheared,
                        &mut box_ray,
                        &ray,
                        Interval::FORWARD,
                        position,
                    ) {
                        let [p0, p1, p2] = self.corners_at(position);
                        let (normal, _) = unit_and_length((p1 - p0).cross(p2 - p0));
                        let distance = c.t * length;
                        sum += distance * distance / (normal.dot(unit).abs() * area);
                    }
                }
                false
            },
        );
        if sum < f64::INFINITY { sum } else { 0.0 }
    }

    /// The unit direction toward a point `p` drawn uniformly by area: `u.x` picks the face (by the
    /// running sums of the areas) and, rescaled within the face's share, with `u.y` the
    /// point on it (the square-root warp, as for [`Triangle`](crate::Triangle)). `u` is
    /// first clamped into `[0, 1]^2`; the zero vector for a mesh without area or a
    /// non-finite origin.
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        let area = self.area();
        if !(origin.is_finite() && area > 0.0) {
            return DVec3::ZERO;
        }
        let u = u.clamp(DVec2::ZERO, DVec2::ONE);
        let target = u.x * area;
        // The block whose running sum first passes the target, then the face within it
        // whose area, added in the same order, does: the face a sum for every face picks.
        let block = self
            .area_sums
            .partition_point(|&c| c <= target)
            .min(self.area_sums.len() - 1);
        let mut below = if block == 0 {
            0.0
        } else {
            self.area_sums[block - 1]
        };
        let first = block * AREA_BLOCK;
        let last = (first + AREA_BLOCK).min(self.triangles.len()) - 1;
        let (mut position, mut share) = (last, 0.0);
        for p in first..=last {
            let above = below + face_area(self.corners_at(p));
            if above > target || p == last {
                (position, share) = (p, above - below);
                break;
            }
            below = above;
        }
        let within = ((target - below) / share).clamp(0.0, 1.0);
        let [p0, p1, p2] = self.corners_at(position);
        let within = DVec2::new(if within.is_finite() { within } else { 0.0 }, u.y);
        let sample = |k: f64| {
            // The point within the face, from `within` moved toward the middle of the
            // square (not at all for `k = 1`), which stays on the face.
            let w = toward_middle(within, k);
            let s = sqrt(w.x);
            let (b1, b2) = (1.0 - s, w.y * s);
            let toward = |k: f64| (k * p0 - k * origin) + (b1 * k * (p1 - p0) + b2 * k * (p2 - p0));
            let direction = toward(1.0);
            unit_direction(if direction.is_finite() {
                direction
            } else {
                toward(0.25)
            })
        };
        // A point on the face's edge (`u.x` or `u.y` at 0 or 1, as a sampler's first points
        // are) may aim just past it, and past the mesh where the edge is its border: drawn
        // again a little toward the face's middle, so that the density is positive (the
        // contract's clause 6). The face's own crossing is what the density sums.
        reaching(sample, |d| {
            let ray = Ray::new(origin, d);
            Sheared::new(&ray).is_some_and(|sheared| {
                self.cross::<false>(&sheared, &mut None, &ray, Interval::FORWARD, position)
                    .is_some()
            })
        })
    }
}

//! Rigid motions of any hittable: the book's `rotate_y` and `translate` instances.

use glam::{BVec3, DMat3, DQuat, DVec2, DVec3, DVec4};

use crate::instance;
use crate::light::{reaching, toward_middle};
use crate::math::{direction_scale, gamma, ordinary, sin_cos};
use crate::{Aabb, Found, GeometryError, HitRecord, Hittable, Interval, Made, PdfHittable, Ray};

/// `object` moved rigidly: rotated about the origin, then translated. Rays are taken into
/// the object's space (`t` is unchanged by a rigid motion), hit there, and the hit comes
/// back; nothing about the object is copied or rebuilt.
///
/// Solid-angle densities do not change under a rigid motion either, so a transformed
/// [`PdfHittable`] stays one.
///
/// **No scale.** Build a scaled copy at its size instead (a [`Sphere`](crate::Sphere) of
/// another radius, a [`Quad`](crate::Quad) of longer edges, a
/// [`TriangleMesh`](crate::TriangleMesh) of scaled vertices, which a refit makes in
/// place): a scale that is not a power of two rounds every coordinate it carries between
/// the spaces, and that rounding, grown by the scale, would have to join every error bound
/// the object states in its own space (its hit points', its tolerance), on top of the
/// rotation's; built at its size, the object states its bounds for the size it has.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::{Cuboid, Hittable, Interval, Ray, Transformed};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// // The book's tall box: turned 15 degrees about y, then moved into place.
/// let tall = Cuboid::new(DVec3::ZERO, DVec3::new(165.0, 330.0, 165.0))?;
/// let tall = Transformed::translate(Transformed::rotate_y(tall, 15.0)?, DVec3::new(265.0, 0.0, 295.0))?;
///
/// let down = Ray::new(DVec3::new(350.0, 1000.0, 375.0), DVec3::new(0.0, -1.0, 0.0));
/// let hit = tall.hit(&down, Interval::FORWARD).unwrap();
/// // A turn about y leaves y coordinates alone, exactly: so is the top face's hit.
/// assert_eq!((hit.t, hit.normal), (670.0, DVec3::Y));
/// assert!(tall.bounding_box().contains(hit.point));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transformed<T> {
    object: T,
    /// Object to world.
    rotation: DMat3,
    /// World to object: the transpose, the inverse of a rotation.
    inverse: DMat3,
    translation: DVec3,
    bbox: Aabb,
    /// Whether the box reaches near f64's end ([`Aabb::near_overflow`]), where moving a hit
    /// can overflow: settled once here, not on every `occluded`.
    near_overflow: bool,
    instance: Option<u32>,
}

impl<T: Hittable> Transformed<T> {
    /// `object` rotated by `rotation` (normalized here), then moved by `translation`.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite `rotation` or `translation`,
    /// [`GeometryError::ZeroVector`] for a zero quaternion.
    pub fn new(object: T, rotation: DQuat, translation: DVec3) -> Result<Self, GeometryError> {
        if !rotation.is_finite() {
            return Err(GeometryError::NonFinite { what: "rotation" });
        }
        let largest = DVec4::from(rotation).abs().max_element();
        if largest == 0.0 {
            return Err(GeometryError::ZeroVector { what: "rotation" });
        }
        // Scaled first, so that the length neither overflows nor underflows.
        let unit = (rotation / largest).normalize();
        Self::from_matrix(object, DMat3::from_quat(unit), translation)
    }

    /// `object` rotated by `degrees` about the y axis (from z toward x, as the book's
    /// `rotate_y`). Multiples of 90 degrees give an exact matrix of 0s and ±1s.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite angle.
    pub fn rotate_y(object: T, degrees: f64) -> Result<Self, GeometryError> {
        if !degrees.is_finite() {
            return Err(GeometryError::NonFinite {
                what: "rotation angle",
            });
        }
        // `%` is exact, so whole quarter turns are recognized whatever the multiple of 360.
        let (sin, cos) = match degrees % 360.0 {
            0.0 => (0.0, 1.0),
            90.0 | -270.0 => (1.0, 0.0),
            180.0 | -180.0 => (0.0, -1.0),
            270.0 | -90.0 => (-1.0, 0.0),
            reduced => sin_cos(reduced.to_radians()),
        };
        let rotation = DMat3::from_cols(
            DVec3::new(cos, 0.0, -sin),
            DVec3::Y,
            DVec3::new(sin, 0.0, cos),
        );
        Self::from_matrix(object, rotation, DVec3::ZERO)
    }

    /// `object` moved by `offset`.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite offset.
    pub fn translate(object: T, offset: DVec3) -> Result<Self, GeometryError> {
        Self::from_matrix(object, DMat3::IDENTITY, offset)
    }

    fn from_matrix(object: T, rotation: DMat3, translation: DVec3) -> Result<Self, GeometryError> {
        if !translation.is_finite() {
            return Err(GeometryError::NonFinite {
                what: "translation",
            });
        }
        let object_box = object.bounding_box();
        let bbox = world_box(&object_box, &rotation, translation);
        if object_box.is_bounded() && !bbox.is_bounded() {
            // Moved past f64's range.
            return Err(GeometryError::OutOfRange);
        }
        Ok(Self {
            object,
            rotation,
            inverse: rotation.transpose(),
            translation,
            near_overflow: bbox.near_overflow(),
            bbox,
            instance: None,
        })
    }
}

impl<T> Transformed<T> {
    /// The same instance, naming itself `id` in the hits that come through it
    /// ([`HitRecord::instance`]): the outermost instance with an id names the hit, so in a
    /// top-level [`Bvh`](crate::Bvh) of instances of shared meshes, the id says which
    /// instance and [`HitRecord::primitive`] which face.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use hitkit::glam::{DQuat, DVec3};
    /// use hitkit::{Bvh, Hittable, Interval, Ray, Transformed, TriangleMesh};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// let square = Arc::new(TriangleMesh::new(
    ///     &[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
    ///     &[[0, 1, 2], [0, 2, 3]],
    /// )?);
    /// let row: Bvh<_> = (0..10)
    ///     .map(|i| {
    ///         let at = DVec3::new(2.0 * f64::from(i), 0.0, 0.0);
    ///         Transformed::new(square.clone(), DQuat::IDENTITY, at).map(|t| t.with_instance_id(i))
    ///     })
    ///     .collect::<Result<_, _>>()?;
    /// let ray = Ray::new(DVec3::new(14.2, 0.7, 1.0), DVec3::NEG_Z);
    /// let hit = row.hit(&ray, Interval::FORWARD).unwrap();
    /// assert_eq!((hit.instance, hit.primitive), (Some(7), Some(1)));
    /// # Ok(())
    /// # }
    /// ```
    #[inline]
    #[must_use]
    pub fn with_instance_id(mut self, id: u32) -> Self {
        self.instance = Some(id);
        self
    }

    /// The id given by [`Transformed::with_instance_id`], if any.
    #[inline]
    #[must_use]
    pub fn instance_id(&self) -> Option<u32> {
        self.instance
    }

    /// The object, in its own space.
    #[inline]
    #[must_use]
    pub fn object(&self) -> &T {
        &self.object
    }

    /// The rotation, object to world.
    #[inline]
    #[must_use]
    pub fn rotation(&self) -> DMat3 {
        self.rotation
    }

    /// The translation, applied after the rotation.
    #[inline]
    #[must_use]
    pub fn translation(&self) -> DVec3 {
        self.translation
    }

    /// A world-space point in object space.
    #[inline]
    fn point_to_object(&self, p: DVec3) -> DVec3 {
        self.inverse * (p - self.translation)
    }

    #[inline]
    fn ray_to_object(&self, ray: &Ray) -> Ray {
        Ray::new(
            self.point_to_object(ray.origin),
            self.inverse * ray.direction,
        )
        .at_time(ray.time)
    }

    /// An object-space hit in world space.
    ///
    /// The point's error bound: the object's bound `e` is carried through the rotation as
    /// `|R| e`, and computing `R p + t` adds its own rounding. Each coordinate of `R p + t`
    /// is a sum of three products and `t`: every term is rounded at most 4 times (one
    /// product, three sums), so the error is at most `gamma(4) (|R| |p| + |t|)`
    /// componentwise (Higham 3.1). One more rounding each, `(1 + gamma(4))` on the carried
    /// part and `gamma(5)` on the new one, covers the evaluation of the bound itself.
    ///
    /// And the way back: a ray spawned from the hit is moved into the object's space
    /// again, `R^T (p - t)`, which rounds its origin by `gamma(4) |R^T| (|p| + |t|)` there,
    /// `|R| |R^T| <= 1` (every entry, by Cauchy-Schwarz) times that in world space, so at
    /// most `gamma(5)` of `|p| + |t|` summed over the axes on each. Without it the origin
    /// could land back on the surface's inner side, and the object find the surface the
    /// ray leaves (the contract's clause 5).
    #[inline]
    fn hit_to_world(&self, hit: HitRecord) -> HitRecord {
        let abs = self.rotation.abs();
        let carried = (1.0 + gamma(4)) * (abs * hit.point_error);
        let rounding = gamma(5) * (abs * hit.point.abs() + self.translation.abs());
        let point = self.rotation * hit.point + self.translation;
        let back = gamma(5) * (point.abs() + self.translation.abs()).element_sum();
        HitRecord {
            point,
            point_error: carried + rounding + DVec3::splat(back),
            // Unit length to within a few ulps: the rotation is orthonormal to rounding.
            normal: self.rotation * hit.normal,
            shading_normal: self.rotation * hit.shading_normal,
            instance: self.instance.or(hit.instance),
            ..hit
        }
    }
}

/// The box of the 8 moved corners of `bbox`, grown by the rounding of moving them (as in
/// `hit_to_world`): it holds the exact moved box, so the moved object.
fn world_box(bbox: &Aabb, rotation: &DMat3, translation: DVec3) -> Aabb {
    if bbox.is_empty() {
        return Aabb::EMPTY;
    }
    if !bbox.is_bounded() {
        return Aabb::UNIVERSE;
    }
    let (lo, hi) = (bbox.min(), bbox.max());
    let corners: [DVec3; 8] = core::array::from_fn(|i| {
        let pick = BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0);
        *rotation * DVec3::select(pick, hi, lo) + translation
    });
    let magnitude = lo.abs().max(hi.abs());
    Aabb::from_points(&corners).grown(gamma(5) * (rotation.abs() * magnitude + translation.abs()))
}

impl<T: Hittable> Hittable for Transformed<T> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        if !ordinary(ray.direction) {
            return self.hit_rescaled(ray, ray_t);
        }
        let mut hit = self.hit_to_world(self.object.hit(&self.ray_to_object(ray), ray_t)?);
        hit.t = instance::settle(&self.bbox, ray, ray_t, hit.t)?;
        (hit.point.is_finite() && hit.point_error.is_finite()).then_some(hit)
    }

    /// The box of the object's box moved, grown by the rounding of moving it;
    /// [`Aabb::UNIVERSE`] if the object's box is unbounded.
    #[inline]
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    /// The object's crossing, found along the ray in object space, with its `t` kept
    /// within this instance's box along `ray`, as `hit` reports it.
    #[inline]
    fn find(&self, ray: &Ray, ray_t: Interval, made: &mut Made) -> Option<Found> {
        // Near f64's end the record can overflow, so `hit` decides there (and for a
        // direction of extreme length, which it rescales).
        if self.near_overflow || !ordinary(ray.direction) {
            return self.hit(ray, ray_t).map(|hit| made.keep(hit));
        }
        let local = self.ray_to_object(ray);
        let found = self.object.find(&local, ray_t, made)?;
        instance::found_in_world(
            found,
            made,
            &self.bbox,
            ray,
            ray_t,
            |f| self.object.record(&local, ray_t, f),
            |h| self.hit_to_world(h),
        )
    }

    #[inline]
    fn record(&self, ray: &Ray, ray_t: Interval, found: &Found) -> Option<HitRecord> {
        instance::record_in_world(
            found,
            |f| self.object.record(&self.ray_to_object(ray), ray_t, f),
            |h| self.hit_to_world(h),
        )
    }

    #[inline]
    fn occluded(&self, ray: &Ray, ray_t: Interval) -> bool {
        // Near f64's end, moving the hit can overflow, and `hit` then finds nothing; along
        // a direction of extreme length, so can `t`.
        if self.near_overflow || !ordinary(ray.direction) {
            return self.hit(ray, ray_t).is_some();
        }
        // What `hit` asks of the moved box too: the rounding of moving the ray can let the
        // object find a crossing that the world-space box, and so `hit`, turns away. Asked
        // last, so that it costs a slab test only where the object is occluded.
        self.object.occluded(&self.ray_to_object(ray), ray_t) && self.bbox.hit(ray, ray_t)
    }
}

impl<T: Hittable> Transformed<T> {
    /// [`Hittable::hit`] for a direction of extreme length: along the same ray with the
    /// direction scaled (exactly) to an ordinary one before it is turned, which would
    /// otherwise round its components into the subnormals or past `f64::MAX`; `None` for a
    /// ray that cannot be traced.
    #[cold]
    #[inline(never)]
    fn hit_rescaled(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let (scaled, scale) = ray.rescaled()?;
        let mut hit = self.hit(&scaled, ray_t.scaled(1.0 / scale))?;
        hit.t = Ray::t_from_rescaled(hit.t, scale, Interval::UNIVERSE)?;
        hit.t = instance::settle(&self.bbox, ray, ray_t, hit.t)?;
        Some(hit)
    }
}

impl<T: PdfHittable> PdfHittable for Transformed<T> {
    /// The object's density for the same direction in its own space: densities over solid
    /// angle are unchanged by a rigid motion.
    #[inline]
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        // Scaled (exactly) to an ordinary length before turning, as rays are.
        let direction = direction * direction_scale(direction);
        self.object
            .pdf_value(self.point_to_object(origin), self.inverse * direction)
    }

    /// The object's sample, turned. Turning rounds: where that takes a direction on the
    /// object's edge just past it, the object is sampled again from `u` moved a little
    /// toward the middle of the square, so that the density is positive (the contract's
    /// clause 6).
    #[inline]
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        let local = self.point_to_object(origin);
        reaching(
            |k| self.turned(self.object.sample_direction(local, toward_middle(u, k))),
            |d| self.pdf_value(origin, d) > 0.0,
        )
    }
}

impl<T> Transformed<T> {
    /// A direction of the object's space in world space, without overflow where that is
    /// possible; the zero vector where it is not.
    #[inline]
    fn turned(&self, local: DVec3) -> DVec3 {
        let direction = self.rotation * local;
        if direction.is_finite() {
            direction
        } else {
            // A rotation can lengthen a component by up to sqrt(3): a quarter of a finite
            // direction turns without overflow, and points the same way.
            let quarter = self.rotation * (0.25 * local);
            if quarter.is_finite() {
                quarter
            } else {
                DVec3::ZERO
            }
        }
    }
}

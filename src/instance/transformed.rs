//! Instances of any hittable: the book's `rotate_y` and `translate`, and any invertible
//! affine map (scales, shears, mirrors).

use glam::{BVec3, DAffine3, DMat3, DQuat, DVec2, DVec3, DVec4};

use super::frame::{Affine, Frame, Rigid};
use crate::instance;
use crate::math::{direction_scale, gamma, ordinary, sin_cos};
use crate::record::{Found, Made};
use crate::sample::{direction_of, reaching, toward_middle};
use crate::{
    Aabb, Emission, GeometryError, HitRecord, Hittable, Interval, LightSample, PdfHittable, Ray,
    ShadingContext,
};

/// `object` moved: rotated about the origin (or any invertible linear map, see
/// [`Transformed::affine`]), then translated. Rays are taken into the object's space (`t`
/// is the same in both), hit there, and the hit comes back; nothing about the object is
/// copied or rebuilt.
///
/// A transformed [`PdfHittable`] stays one, its densities carried to the world (by a
/// rigid motion, unchanged).
///
/// **Scales.** `Transformed<T>` is rigid ([`Rigid`]): exact where a rigid motion is (a
/// turn about y leaves y alone; quarter turns are exact), and a rotation changes no `t`,
/// length or density. [`Transformed::affine`] and [`Transformed::scale`] give a
/// `Transformed<T, Affine>` under any invertible affine map, whose bounds grow by the
/// map's rounding both ways (see there); the rigid one does not pay for that.
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
pub struct Transformed<T, F = Rigid> {
    object: T,
    /// The linear part, object to world and back.
    frame: F,
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
        Self::from_frame(object, Rigid::new(DMat3::from_quat(unit)), translation)
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
        Self::from_frame(object, Rigid::new(rotation), DVec3::ZERO)
    }

    /// `object` moved by `offset`.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite offset.
    pub fn translate(object: T, offset: DVec3) -> Result<Self, GeometryError> {
        Self::from_frame(object, Rigid::new(DMat3::IDENTITY), offset)
    }
}

impl<T: Hittable> Transformed<T, Affine> {
    /// `object` under the affine map `transform` (object to world): its linear part any
    /// invertible matrix (scales, non-uniform ones too, shears, mirrors), then its
    /// translation. The object is not copied: a thousand instances of one
    /// `Arc<TriangleMesh>` at a thousand sizes hold its faces once.
    ///
    /// What the contract's bounds become: a hit's `point_error` is the object's carried by
    /// `|M|` plus the rounding of the map both ways, at most `16 k` ulps of the point and
    /// the translation for a map of condition number `k` (the crate docs' clause 1): a
    /// rotation times scales, even strongly non-uniform ones, adds a few tens of ulps, a
    /// shear of condition `k` up to `k` times as many. A ray spawned from the hit starts outside
    /// the surface in the object's own space (the way back is bounded through the map's
    /// right residual `M M^-1 - I`, and the normal's rounding is paid for). Past a
    /// condition number of about 2^46 (up to the limit below), where that rounding is no
    /// longer below 1/16 of the point, a hit's bound is `f64::MAX`: true, and a ray
    /// spawned from it finds nothing.
    /// Densities over solid angle are the object's times the Jacobian between the spheres
    /// of directions.
    ///
    /// ```
    /// use hitkit::glam::{DAffine3, DQuat, DVec3};
    /// use hitkit::{Hittable, Interval, Ray, Sphere, Transformed};
    ///
    /// # fn main() -> Result<(), hitkit::GeometryError> {
    /// // A unit ball stretched into an ellipsoid 4 wide, 1 tall and 1 deep, then moved.
    /// let map = DAffine3::from_scale_rotation_translation(
    ///     DVec3::new(2.0, 0.5, 0.5),
    ///     DQuat::IDENTITY,
    ///     DVec3::new(0.0, 0.0, -10.0),
    /// );
    /// let ellipsoid = Transformed::affine(Sphere::new(DVec3::ZERO, 1.0)?, map)?;
    /// let hit = ellipsoid.hit(&Ray::new(DVec3::new(-5.0, 0.0, -10.0), DVec3::X), Interval::FORWARD).unwrap();
    /// assert_eq!((hit.t, hit.normal), (3.0, DVec3::NEG_X));
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a NaN or infinite entry;
    /// [`GeometryError::InvalidParameter`] for a singular matrix, or one so nearly singular
    /// that its inverse cannot be computed to within a half (a condition number past about
    /// 2^50); [`GeometryError::OutOfRange`] where the matrix's determinant or inverse over-
    /// or underflows, or the map takes a bounded object past `f64`'s range.
    pub fn affine(object: T, transform: DAffine3) -> Result<Self, GeometryError> {
        if !transform.translation.is_finite() {
            return Err(GeometryError::NonFinite {
                what: "translation",
            });
        }
        Self::from_frame(
            object,
            Affine::new(transform.matrix3)?,
            transform.translation,
        )
    }

    /// `object` scaled by `factors` along the axes (about the origin; negative factors
    /// mirror it).
    ///
    /// # Errors
    /// As [`Transformed::affine`]: a zero or non-finite factor is an error.
    pub fn scale(object: T, factors: DVec3) -> Result<Self, GeometryError> {
        Self::affine(object, DAffine3::from_scale(factors))
    }
}

impl<T: Hittable, F: Frame> Transformed<T, F> {
    fn from_frame(object: T, frame: F, translation: DVec3) -> Result<Self, GeometryError> {
        if !translation.is_finite() {
            return Err(GeometryError::NonFinite {
                what: "translation",
            });
        }
        let object_box = object.bounding_box();
        let bbox = world_box(&object_box, &frame, translation);
        if object_box.is_bounded() && !bbox.is_bounded() {
            // Moved past f64's range.
            return Err(GeometryError::OutOfRange);
        }
        Ok(Self {
            object,
            frame,
            translation,
            near_overflow: bbox.near_overflow(),
            bbox,
            instance: None,
        })
    }
}

impl<T, F: Frame> Transformed<T, F> {
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

    /// The translation, applied after the linear part.
    #[inline]
    #[must_use]
    pub fn translation(&self) -> DVec3 {
        self.translation
    }

    /// A world-space point in object space.
    #[inline]
    fn point_to_object(&self, p: DVec3) -> DVec3 {
        self.frame.to_object(p - self.translation)
    }

    #[inline]
    fn ray_to_object(&self, ray: &Ray) -> Ray {
        Ray::new(
            self.point_to_object(ray.origin),
            self.frame.to_object(ray.direction),
        )
        .at_time(ray.time)
        .with_mask(ray.mask)
    }

    /// An object-space hit in world space (its bounds: [`Frame::hit_to_world`]).
    #[inline]
    fn hit_to_world(&self, hit: HitRecord) -> HitRecord {
        HitRecord {
            instance: self.instance.or(hit.instance),
            ..self.frame.hit_to_world(hit, self.translation)
        }
    }
}

impl<T> Transformed<T> {
    /// The rotation, object to world.
    #[inline]
    #[must_use]
    pub fn rotation(&self) -> DMat3 {
        self.frame.rotation
    }
}

impl<T> Transformed<T, Affine> {
    /// The linear part, object to world: the matrix given, as given.
    #[inline]
    #[must_use]
    pub fn matrix(&self) -> DMat3 {
        self.frame.matrix()
    }
}

/// The box of the 8 moved corners of `bbox`, grown by the rounding of moving them (as in
/// [`Frame::hit_to_world`]): it holds the exact moved box, so the moved object.
fn world_box(bbox: &Aabb, frame: &impl Frame, translation: DVec3) -> Aabb {
    if bbox.is_empty() {
        return Aabb::EMPTY;
    }
    if !bbox.is_bounded() {
        return Aabb::UNIVERSE;
    }
    let (lo, hi) = (bbox.min(), bbox.max());
    let corners: [DVec3; 8] = core::array::from_fn(|i| {
        let pick = BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0);
        frame.to_world(DVec3::select(pick, hi, lo)) + translation
    });
    let magnitude = lo.abs().max(hi.abs());
    Aabb::from_points(&corners).grown(gamma(5) * (frame.abs() * magnitude + translation.abs()))
}

impl<T: Hittable, F: Frame> Hittable for Transformed<T, F> {
    #[inline]
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.hit_by(ray, ray_t, T::hit)
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

impl<T: Hittable, F: Frame> Transformed<T, F> {
    /// [`Hittable::hit`], with the object asked by `hit_object` (its `hit`, or its
    /// [`light_hit`](PdfHittable::light_hit)).
    #[inline(always)]
    fn hit_by(
        &self,
        ray: &Ray,
        ray_t: Interval,
        hit_object: impl Fn(&T, &Ray, Interval) -> Option<HitRecord>,
    ) -> Option<HitRecord> {
        if !ordinary(ray.direction) {
            return self.hit_rescaled(ray, ray_t, hit_object);
        }
        let mut hit = self.hit_to_world(hit_object(&self.object, &self.ray_to_object(ray), ray_t)?);
        hit.t = instance::settle(&self.bbox, ray, ray_t, hit.t)?;
        hit.point.is_finite().then_some(hit)
    }

    /// [`Transformed::hit_by`] for a direction of extreme length: along the same ray with
    /// the direction scaled (exactly) to an ordinary one before it is turned, which would
    /// otherwise round its components into the subnormals or past `f64::MAX`; `None` for a
    /// ray that cannot be traced.
    #[cold]
    #[inline(never)]
    fn hit_rescaled(
        &self,
        ray: &Ray,
        ray_t: Interval,
        hit_object: impl Fn(&T, &Ray, Interval) -> Option<HitRecord>,
    ) -> Option<HitRecord> {
        let (scaled, scale) = ray.rescaled()?;
        let mut hit = self.hit_by(&scaled, ray_t.scaled(1.0 / scale), hit_object)?;
        hit.t = Ray::t_from_rescaled(hit.t, scale, Interval::UNIVERSE)?;
        hit.t = instance::settle(&self.bbox, ray, ray_t, hit.t)?;
        Some(hit)
    }
}

impl<T: PdfHittable, F: Frame> PdfHittable for Transformed<T, F> {
    /// The object's density for the same direction in its own space: unchanged by a rigid
    /// motion; under an [`Affine`] one, times the Jacobian between the two spheres of
    /// directions.
    #[inline]
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        // Scaled (exactly) to an ordinary length before turning, as rays are.
        let direction = direction * direction_scale(direction);
        let density = self.object.pdf_value(
            self.point_to_object(origin),
            self.frame.to_object(direction),
        );
        self.frame.density_to_world(density, direction)
    }

    /// The object's sample, in world space. Moving it rounds: where that takes a direction on the
    /// object's edge just past it, the object is sampled again from `u` moved a little
    /// toward the middle of the square, so that the density is positive (the contract's
    /// clause 6).
    #[inline]
    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        let local = self.point_to_object(origin);
        reaching(
            |k| {
                self.frame
                    .direction_to_world(self.object.sample_direction(local, toward_middle(u, k)))
            },
            |d| self.pdf_value(origin, d) > 0.0,
        )
    }

    /// The provided sample (the direction [`sample_direction`](PdfHittable::sample_direction)
    /// draws, its surface found along it); for an object of no density (a
    /// [`PunctualLight`](crate::PunctualLight), whose direction is the zero vector), its own
    /// delta sample in its space, moved to the world: its point under the map, the
    /// direction and distance measured there, its falloff its own (its `pdf` over its
    /// squared distance); a sun's direction turned by the map.
    fn sample_light(&self, at: &ShadingContext, u: DVec2) -> Option<LightSample> {
        let direction = self.sample_direction(at.point, u);
        if direction != DVec3::ZERO {
            return LightSample::along(self, at, direction);
        }
        let from = ShadingContext::at(self.point_to_object(at.point));
        let local = self.object.sample_light(&from, u).filter(|s| s.delta)?;
        let (point, distance, pdf) = if local.distance == f64::INFINITY {
            let direction = direction_of(self.frame.to_world(local.direction))?;
            (direction, f64::INFINITY, local.pdf)
        } else {
            let point = self.frame.to_world(local.record.point) + self.translation;
            let distance = crate::math::length(point - at.point);
            let per_square = local.pdf / (local.distance * local.distance);
            (point, distance, distance * distance * per_square)
        };
        let direction = if distance == f64::INFINITY {
            point
        } else {
            direction_of(point - at.point)?
        };
        if !(pdf > 0.0 && pdf.is_finite() && distance > 0.0) {
            return None;
        }
        let ray = Ray::new(at.point, direction);
        let mut record = HitRecord::new(&ray, distance, point, -direction);
        record.material = local.record.material;
        record.instance = self.instance.or(local.record.instance);
        Some(LightSample {
            direction,
            distance,
            record,
            pdf,
            light: local.light,
            delta: true,
        })
    }

    #[inline]
    fn light_hit(&self, ray: &Ray, ray_t: Interval) -> Option<(usize, HitRecord)> {
        let which = core::cell::Cell::new(0);
        let hit = self.hit_by(ray, ray_t, |object, ray, ray_t| {
            object.light_hit(ray, ray_t).map(|(light, hit)| {
                which.set(light);
                hit
            })
        })?;
        Some((which.get(), hit))
    }

    /// The object's emission with its normal in world space: by the inverse transpose
    /// (`n . M^-1 e_j` for each axis `e_j`), which keeps the side of the front face under a
    /// mirror as the instance's hits report it (a cone: the side of its axis, which bounds it
    /// under any map); [`Emission::Everywhere`] where that normal
    /// is not a finite, non-zero vector (a map of extreme condition).
    fn emission(&self) -> Emission {
        let to_world = |n: DVec3| {
            let n = crate::sample::direction_of(n)?;
            let w = DVec3::new(
                n.dot(self.frame.to_object(DVec3::X)),
                n.dot(self.frame.to_object(DVec3::Y)),
                n.dot(self.frame.to_object(DVec3::Z)),
            );
            (w.is_finite() && w != DVec3::ZERO).then_some(w)
        };
        match self.object.emission() {
            Emission::Everywhere => Emission::Everywhere,
            Emission::OneSide(n) => to_world(n).map_or(Emission::Everywhere, Emission::OneSide),
            Emission::BothSides(n) => to_world(n).map_or(Emission::Everywhere, Emission::BothSides),
            // A linear map turns a cone into one of another shape, but keeps the half-space
            // it lies in: the half-space bounds it.
            Emission::Cone { axis, .. } => {
                to_world(axis).map_or(Emission::Everywhere, Emission::OneSide)
            }
        }
    }
}

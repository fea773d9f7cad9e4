//! What a hit reports: [`HitRecord`], and the [`MaterialId`] it carries from the shape to
//! the renderer.

use glam::{DVec2, DVec3};

use crate::{Interval, Ray};

/// Names a material. The library carries the id from shape to hit record; the renderer
/// owns the materials and decides what an id means (an index into its own table, say).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct MaterialId(pub u32);

/// What a closest-hit search carries for a shape's crossing: its `t`, and what the shape
/// needs to build the [`HitRecord`] later ([`Hittable::record`](crate::Hittable::record)),
/// for the closest crossing alone. 40 bytes: a search copies one per better candidate.
///
/// `coords` and `part` mean what the shape that made it says (a quad's `(alpha, beta)`, a
/// mesh's barycentrics and face); only that shape reads them back. Or the crossing is
/// [made](Found::is_made): its whole record was made during the search (by a shape that
/// implements `hit` alone, or a container, through the provided
/// [`find`](crate::Hittable::find)) and kept in the search's [`Made`], so that no object
/// is asked twice.
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::custom::Found;
///
/// let found = Found::new(2.0, DVec3::new(0.25, 0.5, 0.0), 3);
/// assert_eq!((found.t, found.part, found.is_made()), (2.0, 3, false));
/// assert!(core::mem::size_of::<Option<Found>>() <= 40);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Found {
    /// Ray parameter of the crossing, as [`HitRecord::t`] will report it.
    pub t: f64,
    /// The shape's own coordinates of the crossing.
    pub coords: DVec3,
    /// Which part of the shape (a face, an object): the shape's own numbering.
    pub part: u32,
    /// Whether the record was made during the search, and kept in its [`Made`].
    made: bool,
}

impl Found {
    /// A crossing at `t` with the shape's own coordinates and part.
    #[inline]
    #[must_use]
    pub fn new(t: f64, coords: DVec3, part: u32) -> Self {
        Self {
            t,
            coords,
            part,
            made: false,
        }
    }

    /// A crossing at `t`, with no coordinates or part.
    #[inline]
    #[must_use]
    pub fn at(t: f64) -> Self {
        Self::new(t, DVec3::ZERO, 0)
    }

    /// Whether this crossing's record was made during the search: it is in the [`Made`]
    /// the search passed ([`Made::keep`]), and [`Made::record`] returns it from there.
    #[inline]
    #[must_use]
    pub fn is_made(&self) -> bool {
        self.made
    }
}

/// Where a closest-hit search keeps a record that was made whole while searching: the
/// record of a shape that implements [`hit`](crate::Hittable::hit) alone (the provided
/// [`find`](crate::Hittable::find) calls it and keeps what it returns, with
/// [`Made::keep`]), or of a container's winner. The search passes one to each
/// [`find`](crate::Hittable::find) it calls, keeps it where that candidate wins, and gets
/// the winner's record through [`Made::record`]: the kept one, or the shape's
/// [`record`](crate::Hittable::record). So a shape that implements `hit` alone is asked
/// once per query, and a record travels only where one was made, never inside every
/// [`Found`].
///
/// ```
/// use hitkit::glam::DVec3;
/// use hitkit::custom::Made;
/// use hitkit::{Hittable, Interval, Quad, Ray, Sphere};
///
/// let shapes: Vec<Box<dyn Hittable>> = vec![
///     Box::new(Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0).unwrap()),
///     Box::new(Quad::new(DVec3::new(-1.0, -1.0, -2.0), DVec3::X * 2.0, DVec3::Y * 2.0).unwrap()),
/// ];
/// let ray = Ray::new(DVec3::ZERO, DVec3::NEG_Z);
/// // The closest of the two, as a list finds it: a record for the winner alone.
/// let (mut best, mut kept) = (None, Made::new());
/// for (i, shape) in shapes.iter().enumerate() {
///     let max = best.map_or(f64::INFINITY, |(_, f): (usize, hitkit::custom::Found)| f.t);
///     let mut made = Made::new();
///     if let Some(found) = shape.find(&ray, Interval::new(0.0, max), &mut made) {
///         if found.is_made() {
///             kept = made;
///         }
///         best = Some((i, found));
///     }
/// }
/// let (i, found) = best.unwrap();
/// let hit = kept.record(&shapes[i], &ray, Interval::FORWARD, &found).unwrap();
/// assert_eq!((i, hit.t), (1, 2.0));
/// ```
///
/// What it holds means something only for a made [`Found`]: a search tells by
/// [`Found::is_made`], so a new one is a zeroed record (set by a few stores, where an
/// empty `Option<HitRecord>` was copied in whole, as records of more than 128 bytes are).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Made(HitRecord);

impl Default for Made {
    fn default() -> Self {
        Self::new()
    }
}

impl Made {
    /// One that holds no record of a made crossing yet.
    #[inline]
    #[must_use]
    pub const fn new() -> Self {
        Self(HitRecord {
            t: 0.0,
            point: DVec3::ZERO,
            point_error: DVec3::ZERO,
            normal: DVec3::ZERO,
            shading_normal: DVec3::ZERO,
            front_face: false,
            uv: DVec2::ZERO,
            material: MaterialId(0),
            primitive: None,
            instance: None,
            time: 0.0,
            mask: u32::MAX,
        })
    }

    /// Keeps `record` (replacing what was kept), and returns its crossing at `record.t`,
    /// [made](Found::is_made).
    #[inline]
    pub fn keep(&mut self, record: HitRecord) -> Found {
        self.0 = record;
        Found {
            made: true,
            ..Found::at(record.t)
        }
    }

    /// The record kept.
    #[inline]
    pub(crate) fn kept(&self) -> &HitRecord {
        &self.0
    }

    /// The record kept, to be changed in place (an instance moves it to the world).
    #[inline]
    pub(crate) fn kept_mut(&mut self) -> &mut HitRecord {
        &mut self.0
    }
}

/// Where a ray met a surface.
///
/// `normal` is unit length and faces against the ray; `front_face` says whether the ray
/// came from the side the shape's outward normal points to.
///
/// Which part of which object was hit, through any nesting: `primitive` is set by a
/// [`TriangleMesh`](crate::TriangleMesh) (its face, in the caller's numbering; other
/// shapes leave it `None`), and `instance` by a [`Transformed`](crate::Transformed) given an id with
/// [`with_instance_id`](crate::Transformed::with_instance_id); a `Bvh`, `Box`, `Arc` or
/// list passes both on unchanged. Fields of the record (not a generic query) keep
/// [`Hittable`](crate::Hittable) object safe, and cost nothing to pass along.
///
/// # What it costs
/// A search builds one record per query, for the closest hit alone
/// ([`find`](crate::Hittable::find), then [`record`](crate::Hittable::record)), so its
/// fields are paid once a ray: `t`, `material`, `primitive`, `instance`, `time` and
/// `mask` are copies; `normal` and `front_face` one dot product; `point` and `point_error` a few
/// products and sums (a quad's point from `(alpha, beta)`, kept in its box); the
/// `shading_normal` a copy of `normal`, or a mesh's interpolation of its vertex normals;
/// `uv` a quad's `(alpha, beta)`, but a sphere's an `acos` and an `atan2`, its dearest
/// field. In `benches/port` (callgrind), a quad's record takes about 160 instructions (its
/// search about 100) and a sphere's about 330. A query that needs less asks for
/// less: [`occluded`](crate::Hittable::occluded) for a shadow ray, `find` where `t` alone
/// is read (a medium's exit). At 160 bytes, a record is past the 128 that the compiler
/// copies in registers: pass it by reference where you can.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HitRecord {
    /// Ray parameter of the hit, in units of the ray's direction.
    pub t: f64,
    /// The hit point.
    pub point: DVec3,
    /// A bound on the absolute error of each coordinate of `point`: the exact surface
    /// point lies within `point ± point_error`. [`HitRecord::spawn_ray`] uses it.
    pub point_error: DVec3,
    /// Unit surface normal, facing against the incoming ray: the geometric normal, which
    /// [`HitRecord::spawn_ray`] goes by.
    pub normal: DVec3,
    /// Unit normal for shading, on the same side as `normal`: interpolated from a mesh's
    /// vertex normals where it has them, otherwise `normal` itself.
    pub shading_normal: DVec3,
    /// Whether the ray hit the side the outward normal points to.
    pub front_face: bool,
    /// Surface coordinates; each shape documents its mapping.
    pub uv: DVec2,
    /// The material of the shape that was hit.
    pub material: MaterialId,
    /// The part of the shape that was hit: a [`TriangleMesh`](crate::TriangleMesh)'s face
    /// index; `None` for other shapes.
    pub primitive: Option<u32>,
    /// The id of the outermost [`Transformed`](crate::Transformed) instance with one that
    /// the hit came through; `None` if none.
    pub instance: Option<u32>,
    /// The ray's [`time`](Ray::time), which [`HitRecord::spawn_ray`] passes on.
    pub time: f64,
    /// The [`mask`](Ray::mask) of the ray that made the hit (through any instance or
    /// [`Masked`](crate::Masked) wrapper: the mask it came with), which
    /// [`HitRecord::spawn_ray`] and [`HitRecord::spawn_ray_to`] pass on, so that a bounce
    /// or a shadow ray sees what its parent saw. Set another with [`Ray::with_mask`] on the
    /// spawned ray.
    #[cfg_attr(feature = "serde", serde(default = "crate::ray::every_bit"))]
    pub mask: u32,
}

impl HitRecord {
    /// A record whose `normal` and `front_face` are set from the shape's unit
    /// `outward_normal` and the ray's direction; its `point_error` is zero (an exact point),
    /// its `uv` zero and its material the default, until set with
    /// [`with_point_error`](Self::with_point_error), [`with_uv`](Self::with_uv) and
    /// [`with_material`](Self::with_material); its shading normal is `normal`, its ids
    /// `None`, and its time the ray's.
    ///
    /// ```
    /// use hitkit::glam::{DVec2, DVec3};
    /// use hitkit::{HitRecord, MaterialId, Ray};
    ///
    /// let ray = Ray::new(DVec3::new(0.0, 0.0, 2.0), DVec3::new(0.0, 0.0, -1.0));
    /// // The plane z = 0, outward normal +z: the ray comes from the front.
    /// let hit = HitRecord::new(&ray, 2.0, DVec3::ZERO, DVec3::Z)
    ///     .with_point_error(DVec3::splat(1e-16))
    ///     .with_uv(DVec2::new(0.5, 0.5))
    ///     .with_material(MaterialId(3));
    /// assert!(hit.front_face);
    /// assert_eq!(hit.normal, DVec3::Z);
    /// ```
    #[inline]
    #[must_use]
    pub fn new(ray: &Ray, t: f64, point: DVec3, outward_normal: DVec3) -> Self {
        let front_face = ray.direction.dot(outward_normal) < 0.0;
        let normal = if front_face {
            outward_normal
        } else {
            -outward_normal
        };
        Self {
            t,
            point,
            point_error: DVec3::ZERO,
            normal,
            front_face,
            shading_normal: normal,
            uv: DVec2::ZERO,
            material: MaterialId::default(),
            primitive: None,
            instance: None,
            time: ray.time,
            mask: ray.mask,
        }
    }

    /// The same record with the shading normal `shading_normal` (unit length), turned to
    /// the side of `normal` if it points away from it.
    #[inline]
    #[must_use]
    pub fn with_shading_normal(mut self, shading_normal: DVec3) -> Self {
        self.shading_normal = if shading_normal.dot(self.normal) < 0.0 {
            -shading_normal
        } else {
            shading_normal
        };
        self
    }

    /// The same record with `primitive` set to `Some(primitive)`.
    #[inline]
    #[must_use]
    pub fn with_primitive(mut self, primitive: u32) -> Self {
        self.primitive = Some(primitive);
        self
    }

    /// The same record with a bound on the absolute error of each coordinate of `point`.
    #[inline]
    #[must_use]
    pub fn with_point_error(mut self, point_error: DVec3) -> Self {
        self.point_error = point_error;
        self
    }

    /// The same record with surface coordinates `uv`.
    #[inline]
    #[must_use]
    pub fn with_uv(mut self, uv: DVec2) -> Self {
        self.uv = uv;
        self
    }

    /// The same record with material `material`.
    #[inline]
    #[must_use]
    pub fn with_material(mut self, material: MaterialId) -> Self {
        self.material = material;
        self
    }

    /// A ray leaving the hit point along `direction` that does not hit the same surface
    /// again at `t >= 0`, with no epsilon on the renderer's side: trace it with
    /// [`Interval::FORWARD`](crate::Interval::FORWARD). It is sent at the record's `time`.
    ///
    /// The origin is moved off the surface, to the side `direction` points to, by the
    /// point's error bound projected on the normal, then rounded one more float away
    /// (pbrt-v4's `OffsetRayOrigin`); a coordinate at zero (a wall on a coordinate plane)
    /// is moved to about `1.5e-271` (`2^-900`), well past the subnormal numbers, which are
    /// slow to compute with and which a CPU in denormals-are-zero mode reads as zero.
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Hittable, Interval, Quad, Ray};
    /// let floor = Quad::new(DVec3::new(-1e9, 0.0, -1e9), DVec3::X * 2e9, DVec3::Z * 2e9).unwrap();
    /// let down = Ray::new(DVec3::new(1e8 + 0.3, 1.0, 0.7), DVec3::new(0.3, -1.0, 0.1));
    /// let hit = floor.hit(&down, Interval::FORWARD).unwrap();
    /// let bounce = hit.spawn_ray(DVec3::new(0.2, 1.0, 0.0));
    /// assert!(floor.hit(&bounce, Interval::FORWARD).is_none());
    /// ```
    #[inline]
    #[must_use]
    pub fn spawn_ray(&self, direction: DVec3) -> Ray {
        Ray::new(self.spawn_origin(direction), direction)
            .at_time(self.time)
            .with_mask(self.mask)
    }

    /// A shadow ray from this hit to `target` (a light's surface, as
    /// [`LightSample::record`](crate::LightSample::record) gives it), and the range to
    /// trace it over: it finds neither the surface it leaves nor `target`'s own surface at
    /// the far end, and finds whatever lies between, with no epsilon on the renderer's side
    /// (as pbrt-v4's `SpawnRayTo`, whose `1 - ShadowEpsilon` is derived here).
    ///
    /// The ray starts where [`spawn_ray`](Self::spawn_ray) starts one toward `target`, and
    /// ends, at `t = 1`, a little off `target`'s surface on this hit's side of it (pbrt-v4
    /// offsets both ends the same way): by `target.point_error` projected on its normal, and
    /// by `2^-46` of the coordinates' magnitudes, four times the `2^-48` within which the
    /// shapes decide their crossings (the tolerance of the contract's clause 2). A shape's
    /// computed crossing of the far surface then lies beyond `t = 1`, at any angle: the gap
    /// and the crossing's rounding both grow as `1 / |n . d|`. An occluder within that
    /// distance of the light's surface (`2^-46` of the coordinates, about `1e-14` of them)
    /// is not seen.
    ///
    /// A target at infinity (its `t` infinite: a sun's sample, see
    /// [`LightSample::delta`](crate::LightSample::delta)) gives [`spawn_ray`](Self::spawn_ray)
    /// toward it (against its normal, which faces this hit) and the range `[0, infinity]`:
    /// everything along the way occludes.
    ///
    /// ```
    /// use hitkit::glam::{DVec2, DVec3};
    /// use hitkit::{Hittable, Interval, PdfHittable, Quad, Ray, ShadingContext};
    ///
    /// let floor = Quad::new(DVec3::new(-5.0, 0.0, -5.0), DVec3::X * 10.0, DVec3::Z * 10.0).unwrap();
    /// let lamp = Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X * 2.0, DVec3::Z * 2.0).unwrap();
    /// let scene = vec![floor, lamp];
    /// let down = Ray::new(DVec3::new(0.3, 5.0, 3.0), DVec3::new(0.0, -1.0, -0.2));
    /// let hit = scene.hit(&down, Interval::FORWARD).unwrap();
    /// let sample = lamp.sample_light(&ShadingContext::from(&hit), DVec2::new(0.3, 0.9)).unwrap();
    /// let (shadow, range) = hit.spawn_ray_to(&sample.record);
    /// // Neither the floor nor the lamp itself occludes it.
    /// assert!(!scene.occluded(&shadow, range));
    /// ```
    #[inline]
    #[must_use]
    pub fn spawn_ray_to(&self, target: &HitRecord) -> (Ray, Interval) {
        if target.t == f64::INFINITY {
            let ray = self.spawn_ray(-target.normal);
            let range = if ray.is_valid() {
                Interval::FORWARD
            } else {
                Interval::EMPTY
            };
            return (ray, range);
        }
        let toward = if target.normal.dot(self.point - target.point) < 0.0 {
            -target.normal
        } else {
            target.normal
        };
        let height = target.normal.abs().dot(target.point_error)
            + FAR_END * (self.point.abs().max_element() + target.point.abs().max_element());
        let end = target.point + height * toward;
        let origin = self.spawn_origin(end - self.point);
        let ray = Ray::new(origin, end - origin)
            .at_time(self.time)
            .with_mask(self.mask);
        if ray.is_valid() && end.is_finite() {
            (ray, Interval::new(0.0, 1.0))
        } else {
            (ray, Interval::EMPTY)
        }
    }

    /// Where [`spawn_ray`](Self::spawn_ray) starts a ray along `direction`.
    #[inline(always)]
    fn spawn_origin(&self, direction: DVec3) -> DVec3 {
        let toward = if direction.dot(self.normal) < 0.0 {
            -self.normal
        } else {
            self.normal
        };
        // Near the end of f64's range the bound itself overflows; the largest finite offset
        // then keeps `0 * inf` (a zero normal component) from making the origin NaN.
        let offset = self.normal.abs().dot(self.point_error).min(f64::MAX);
        let mut origin = self.point + offset * toward;
        // One more float away along every axis the normal has a component on, so that the
        // origin leaves the surface even where the error bound is zero; and from zero (a
        // wall at `x = 0`), well past the subnormals, where that step would land: the
        // distances from such an origin, and their products with a direction's shear or
        // reciprocal, would be subnormal, slow, and read as zero with the CPU's
        // denormals-are-zero mode on (back on the surface). (Tried: a branch-free step of
        // `2^-52 |x|` per axis, selected by the normal's signs; within noise.)
        for axis in 0..3 {
            if toward[axis] > 0.0 {
                origin[axis] = off_zero(origin[axis].next_up());
            } else if toward[axis] < 0.0 {
                origin[axis] = -off_zero(-origin[axis].next_down());
            }
        }
        // Near the end of the range, the origin stays finite (at the end of it).
        origin.clamp(DVec3::splat(f64::MIN), DVec3::splat(f64::MAX))
    }
}

/// How far [`HitRecord::spawn_ray_to`] ends a shadow ray off the far surface, relative to
/// the coordinates' magnitude: `2^-46`, four times the tolerance within which shapes decide
/// their crossings (`2^-48`, the contract's clause 2), so that the end lies beyond both
/// the surface's own rounding and that widening (`tests/next_event.rs` holds it).
const FAR_END: f64 = 1.0 / (1u64 << 46) as f64;

/// `x`, a coordinate just stepped up, unless it lies within [`SPAWN_FLOOR`] of zero: then
/// the floor (or zero, from just below zero), which lies past it.
#[inline(always)]
fn off_zero(x: f64) -> f64 {
    if x.abs() >= SPAWN_FLOOR {
        x
    } else if x > 0.0 {
        SPAWN_FLOOR
    } else {
        0.0
    }
}

/// The least magnitude [`HitRecord::spawn_ray`] steps a coordinate off zero to, `2^-900`
/// (about `1.5e-271`): the distances from it times a rounding bound (about `2^-50`) and a
/// reciprocal direction component (down to about `2^-32` for an ordinary direction) stay normal,
/// as they do in the bounds of a crossing's `t`. (At `2^-969`, such products were still
/// subnormal, and flushing them made shadow rays from walls at zero faster.)
const SPAWN_FLOOR: f64 = f64::from_bits((1023 - 900) << 52);

//! Lights of no extent: a point, a spot and a sun (glTF's `KHR_lights_punctual`, pbrt-v4's
//! `PointLight`, `SpotLight` and `DistantLight`). No ray finds them and no direction has a
//! density toward them: next-event estimation alone reaches them, with a delta sample.

use core::f64::consts::PI;

use glam::{DVec2, DVec3};

use crate::math::{sin_cos, unit_and_length};
use crate::sample::direction_of;
use crate::{
    Aabb, Emission, GeometryError, HitRecord, Hittable, Interval, LightSample, MaterialId,
    PdfHittable, Ray, ShadingContext,
};

/// A light at a point (shining every way, or in a cone) or at infinity (the sun): what
/// glTF's `KHR_lights_punctual` and most exporters write for a lamp.
///
/// It has no surface: a ray never hits it (`hit` is `None`) and no direction has a
/// density toward it ([`pdf_value`](PdfHittable::pdf_value) and
/// [`light_pdf`](PdfHittable::light_pdf) are 0). Next-event estimation reaches it
/// through [`sample_light`](PdfHittable::sample_light), whose [`LightSample`] says so
/// ([`LightSample::delta`]): its `pdf` is then what the light's emitted value (its
/// material's: an intensity in candela for a point or spot, an illuminance in lux for a
/// sun, as glTF gives them) is divided by, `distance^2 / falloff` (times the probability
/// of picking the light, in a [`LightTree`](crate::LightTree), [`Mixture`](crate::Mixture)
/// or list), so that `emitted * cos / pdf` is the irradiance it brings, the estimate
/// every light shares; and multiple importance sampling weighs the sample 1, since no
/// other strategy finds the light.
///
/// The book's [`sample_direction`](PdfHittable::sample_direction) has no direction to
/// give (the zero vector): a mixture or tree that picks such a light there returns no
/// direction, a sample of weight 0, and its `pdf_value` counts only the lights with
/// density, so an estimate made with those two stays unbiased for those lights and
/// leaves the punctual ones to `sample_light`.
///
/// Through an instance ([`Transformed`](crate::Transformed)) it moves with the map: its
/// position mapped, a spot's cone and falloff its own (the falloff taken in its own
/// space), a sun's direction turned.
///
/// ```
/// use hitkit::glam::{DVec2, DVec3};
/// use hitkit::{HitRecord, Hittable, Interval, PdfHittable, PunctualLight, Ray, ShadingContext};
///
/// # fn main() -> Result<(), hitkit::GeometryError> {
/// let bulb = PunctualLight::point(DVec3::new(0.0, 2.0, 0.0))?;
/// let floor = ShadingContext::on_surface(DVec3::new(1.0, 0.0, 0.0), DVec3::Y);
/// let sample = bulb.sample_light(&floor, DVec2::new(0.3, 0.8)).unwrap();
/// assert!(sample.delta && (sample.distance - 5f64.sqrt()).abs() < 1e-15);
/// // An intensity of 10 candela: irradiance I cos / d^2 at the floor.
/// let cos = sample.direction.dot(DVec3::Y);
/// let irradiance = 10.0 * cos / sample.pdf;
/// assert!((irradiance - 10.0 * (2.0 / 5f64.sqrt()) / 5.0).abs() < 1e-14);
/// assert_eq!(bulb.light_pdf(&floor, sample.direction), 0.0); // no density: a delta
///
/// // A sun shining straight down: its shadow ray runs to infinity.
/// let sun = PunctualLight::sun(DVec3::NEG_Y)?;
/// let sample = sun.sample_light(&floor, DVec2::ZERO).unwrap();
/// assert_eq!((sample.direction, sample.distance, sample.pdf), (DVec3::Y, f64::INFINITY, 1.0));
/// let ground = Ray::new(DVec3::new(1.0, 1.0, 0.0), DVec3::NEG_Y);
/// let hit = HitRecord::new(&ground, 1.0, DVec3::new(1.0, 0.0, 0.0), DVec3::Y);
/// let (shadow, range) = hit.spawn_ray_to(&sample.record);
/// assert_eq!((shadow.direction, range.max), (DVec3::Y, f64::INFINITY));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PunctualLight {
    kind: Kind,
    material: MaterialId,
}

/// Where a [`PunctualLight`] is and how it shines.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// At a point, the same every way.
    Point(DVec3),
    /// At a point, within a cone about `axis` (a unit vector): full within `cos_inner`,
    /// none beyond `cos_outer`.
    Spot {
        position: DVec3,
        axis: DVec3,
        cos_inner: f64,
        cos_outer: f64,
        outer: f64,
    },
    /// At infinity, its light travelling along the unit vector.
    Sun(DVec3),
}

impl PunctualLight {
    /// A light at `position`, the same in every direction.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a position that is not finite.
    pub fn point(position: DVec3) -> Result<Self, GeometryError> {
        Ok(Self::of(Kind::Point(finite(position, "light position")?)))
    }

    /// A light at `position` shining along `direction` in a cone: at full intensity within
    /// `inner` radians of `direction`, none beyond `outer`, and between them glTF's
    /// smooth falloff (the square of a ramp in the cosine from `cos outer` to
    /// `cos inner`: see [`PunctualLight::falloff`]). `inner == outer` is a hard edge.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a position, direction or angle that is not
    /// finite; [`GeometryError::ZeroVector`] for a direction of length 0;
    /// [`GeometryError::InvalidParameter`] unless `0 <= inner <= outer <= PI / 2` (and
    /// `outer > 0`), glTF's bounds.
    pub fn spot(
        position: DVec3,
        direction: DVec3,
        inner: f64,
        outer: f64,
    ) -> Result<Self, GeometryError> {
        let position = finite(position, "light position")?;
        let axis = unit(direction, "light direction")?;
        if !inner.is_finite() || !outer.is_finite() {
            return Err(GeometryError::NonFinite { what: "cone angle" });
        }
        if !(outer > 0.0 && outer <= PI / 2.0) {
            return Err(GeometryError::InvalidParameter {
                what: "outer cone angle",
                value: outer,
                domain: "(0, PI / 2]",
            });
        }
        if !(0.0..=outer).contains(&inner) {
            return Err(GeometryError::InvalidParameter {
                what: "inner cone angle",
                value: inner,
                domain: "[0, outer cone angle]",
            });
        }
        Ok(Self::of(Kind::Spot {
            position,
            axis,
            cos_inner: sin_cos(inner).1,
            cos_outer: sin_cos(outer).1,
            outer,
        }))
    }

    /// A light at infinity whose light travels along `direction` (a sun shining straight
    /// down: `-Y`), the same at every point.
    ///
    /// # Errors
    /// [`GeometryError::NonFinite`] for a direction that is not finite;
    /// [`GeometryError::ZeroVector`] for one of length 0.
    pub fn sun(direction: DVec3) -> Result<Self, GeometryError> {
        Ok(Self::of(Kind::Sun(unit(direction, "light direction")?)))
    }

    fn of(kind: Kind) -> Self {
        Self {
            kind,
            material: MaterialId::default(),
        }
    }

    /// The same light with material `id`: what its samples' records carry, for the
    /// renderer's emitted value.
    #[must_use]
    pub fn with_material(mut self, id: MaterialId) -> Self {
        self.material = id;
        self
    }

    /// Its material.
    #[must_use]
    pub fn material(&self) -> MaterialId {
        self.material
    }

    /// Its position; `None` for a sun.
    #[must_use]
    pub fn position(&self) -> Option<DVec3> {
        match self.kind {
            Kind::Point(p) | Kind::Spot { position: p, .. } => Some(p),
            Kind::Sun(_) => None,
        }
    }

    /// The direction it shines along, a unit vector: a spot's axis, the direction a sun's
    /// light travels; `None` for a point light.
    #[must_use]
    pub fn direction(&self) -> Option<DVec3> {
        match self.kind {
            Kind::Point(_) => None,
            Kind::Spot { axis, .. } => Some(axis),
            Kind::Sun(d) => Some(d),
        }
    }

    /// The share of its intensity it sends along the unit vector `toward` (from the
    /// light): 1 for a point light and a sun; for a spot, with `c` the cosine between
    /// `toward` and its axis, `t^2` for `t = (c - cos outer) / (cos inner - cos outer)`
    /// clamped to `[0, 1]` (glTF's suggested falloff), a step at `cos outer` where the two
    /// angles are equal.
    ///
    /// ```
    /// use hitkit::glam::DVec3;
    /// use hitkit::PunctualLight;
    ///
    /// let spot = PunctualLight::spot(DVec3::ZERO, DVec3::NEG_Y, 0.0, 60f64.to_radians()).unwrap();
    /// assert_eq!(spot.falloff(DVec3::NEG_Y), 1.0);
    /// // Halfway in the cosine, from cos 60 = 0.5 to cos 0 = 1: a quarter.
    /// let c: f64 = 0.75;
    /// let along = DVec3::new((1.0 - c * c).sqrt(), -c, 0.0);
    /// assert!((spot.falloff(along) - 0.25).abs() < 1e-15);
    /// assert_eq!(spot.falloff(DVec3::X), 0.0);
    /// ```
    #[must_use]
    pub fn falloff(&self, toward: DVec3) -> f64 {
        match self.kind {
            Kind::Point(_) | Kind::Sun(_) => 1.0,
            Kind::Spot {
                axis,
                cos_inner,
                cos_outer,
                ..
            } => {
                let c = axis.dot(toward);
                if c >= cos_inner {
                    1.0
                } else if c <= cos_outer {
                    0.0
                } else {
                    let t = ((c - cos_outer) / (cos_inner - cos_outer)).clamp(0.0, 1.0);
                    t * t
                }
            }
        }
    }

    /// Its power (radiant or luminous flux) at `intensity` (candela, or watts per
    /// steradian): the integral of `intensity * falloff` over the sphere, `4 PI intensity`
    /// for a point light and `2 PI intensity ((1 - cos inner) + (cos inner - cos outer) / 3)`
    /// for a spot; for a sun, whose power is not bounded and does not weigh a
    /// [`LightTree`](crate::LightTree)'s pick (see [`LightTree::new`](crate::LightTree::new)),
    /// `intensity` itself. What [`LightTree::new`](crate::LightTree::new) weighs it by beside
    /// lights of area.
    #[must_use]
    pub fn power(&self, intensity: f64) -> f64 {
        match self.kind {
            Kind::Point(_) => 4.0 * PI * intensity,
            Kind::Spot {
                cos_inner,
                cos_outer,
                ..
            } => 2.0 * PI * intensity * ((1.0 - cos_inner) + (cos_inner - cos_outer) / 3.0),
            Kind::Sun(_) => intensity,
        }
    }
}

/// `v` if finite.
fn finite(v: DVec3, what: &'static str) -> Result<DVec3, GeometryError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(GeometryError::NonFinite { what })
    }
}

/// `v` as a unit vector, if finite and not zero.
fn unit(v: DVec3, what: &'static str) -> Result<DVec3, GeometryError> {
    direction_of(finite(v, what)?).ok_or(GeometryError::ZeroVector { what })
}

impl Hittable for PunctualLight {
    /// `None`: no ray finds a point or a direction.
    #[inline]
    fn hit(&self, _: &Ray, _: Interval) -> Option<HitRecord> {
        None
    }

    /// The position's box (of no extent); a sun's is unbounded, which makes it one of a
    /// [`LightTree`](crate::LightTree)'s infinite lights.
    fn bounding_box(&self) -> Aabb {
        self.position().map_or(Aabb::UNIVERSE, |p| Aabb::new(p, p))
    }
}

impl PdfHittable for PunctualLight {
    /// 0: no direction has a density toward a delta light.
    #[inline]
    fn pdf_value(&self, _: DVec3, _: DVec3) -> f64 {
        0.0
    }

    /// The zero vector: no direction drawn by a density (see the type's docs).
    #[inline]
    fn sample_direction(&self, _: DVec3, _: DVec2) -> DVec3 {
        DVec3::ZERO
    }

    /// The light itself, `u` unused: toward the position (or the sun), at its distance
    /// (infinite for a sun, whose record's `t` is infinite too and whose `point` is the
    /// unit direction toward it, a point at infinity; [`HitRecord::spawn_ray_to`] then
    /// aims along it to infinity), with `pdf` the squared distance over
    /// [`PunctualLight::falloff`] (1 for a sun) and `delta` set. The record's normal faces
    /// the context's point (`front_face` true); its point is exact (`point_error` 0).
    ///
    /// `None` for a point that is not finite, at the light's position, outside a spot's
    /// cone, or so far that the squared distance overflows.
    fn sample_light(&self, at: &ShadingContext, _: DVec2) -> Option<LightSample> {
        if !at.point.is_finite() {
            return None;
        }
        let Some(position) = self.position() else {
            let Kind::Sun(travel) = self.kind else {
                return None;
            };
            let direction = -travel;
            let ray = Ray::new(at.point, direction);
            let mut record = HitRecord::new(&ray, f64::INFINITY, direction, travel);
            record.material = self.material;
            return Some(LightSample {
                direction,
                distance: f64::INFINITY,
                record,
                pdf: 1.0,
                light: 0,
                delta: true,
            });
        };
        let (direction, distance) = unit_and_length(position - at.point);
        let pdf = distance * distance / self.falloff(-direction);
        if !(distance > 0.0 && pdf > 0.0 && pdf.is_finite() && direction.is_finite()) {
            return None;
        }
        let ray = Ray::new(at.point, direction);
        let mut record = HitRecord::new(&ray, distance, position, -direction);
        record.material = self.material;
        Some(LightSample {
            direction,
            distance,
            record,
            pdf,
            light: 0,
            delta: true,
        })
    }

    /// 0: see [`pdf_value`](PdfHittable::pdf_value).
    #[inline]
    fn light_pdf(&self, _: &ShadingContext, _: DVec3) -> f64 {
        0.0
    }

    /// Every way for a point light and a sun; a spot, its outer cone.
    fn emission(&self) -> Emission {
        match self.kind {
            Kind::Spot { axis, outer, .. } => Emission::Cone { axis, angle: outer },
            Kind::Point(_) | Kind::Sun(_) => Emission::Everywhere,
        }
    }
}

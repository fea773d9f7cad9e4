//! The `serde` feature: the value types serialize field by field; the shapes serialize as
//! what builds them and deserialize through their constructors, so that a scene file can
//! never make a shape the constructors would refuse (a NaN corner, parallel edges, a ring
//! without a hole's domain): such input is a deserialization error carrying the
//! [`GeometryError`]'s message.
//!
//! The plain value types (`Ray`, `Interval`, `MaterialId`, `HitRecord`, `PlaneHit`, the
//! unit interiors, `Exact`, `Sampling`, `Polygon`) derive their implementations where they
//! are defined.

use glam::DVec3;
use serde::de::{DeserializeOwned, Deserializer, Error as _};
use serde::ser::Serializer;
use serde::{Deserialize, Serialize};

use crate::{Aabb, GeometryError, Interior, MaterialId, Plane, Quad, Ring, Sampling, Sphere};

/// A box as its two corners, unpadded: deserializing what was serialized gives the same
/// box. Corners must not be NaN (JSON cannot say NaN anyway; other formats can).
#[derive(Serialize, Deserialize)]
#[serde(rename = "Aabb")]
struct AabbCorners {
    min: DVec3,
    max: DVec3,
}

impl Serialize for Aabb {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        AabbCorners {
            min: self.min,
            max: self.max,
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Aabb {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let AabbCorners { min, max } = AabbCorners::deserialize(deserializer)?;
        if min.is_nan() || max.is_nan() {
            return Err(D::Error::custom(GeometryError::NonFinite {
                what: "box corner",
            }));
        }
        // A box with min above max on an axis is empty, as `Aabb::is_empty` says.
        Ok(Self { min, max })
    }
}

#[derive(Serialize, Deserialize)]
#[serde(rename = "Ring")]
struct RingInner {
    inner: f64,
}

impl Serialize for Ring {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        RingInner {
            inner: self.inner(),
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Ring {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let RingInner { inner } = RingInner::deserialize(deserializer)?;
        Ring::new(inner).map_err(D::Error::custom)
    }
}

#[derive(Serialize, Deserialize)]
#[serde(rename = "Plane")]
struct PlaneSpec {
    q: DVec3,
    u: DVec3,
    v: DVec3,
    #[serde(default)]
    material: MaterialId,
}

impl Serialize for Plane {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        PlaneSpec {
            q: self.q(),
            u: self.u(),
            v: self.v(),
            material: self.material(),
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Plane {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let PlaneSpec { q, u, v, material } = PlaneSpec::deserialize(deserializer)?;
        Plane::new(q, u, v)
            .map(|plane| plane.with_material(material))
            .map_err(D::Error::custom)
    }
}

#[derive(Serialize, Deserialize)]
#[serde(rename = "Quad")]
struct QuadSpec<S> {
    q: DVec3,
    u: DVec3,
    v: DVec3,
    shape: S,
    #[serde(default)]
    material: MaterialId,
    #[serde(default)]
    sampling: Sampling,
}

impl<S: Interior + Serialize + Clone> Serialize for Quad<S> {
    fn serialize<Z: Serializer>(&self, serializer: Z) -> Result<Z::Ok, Z::Error> {
        let plane = self.plane();
        QuadSpec {
            q: plane.q(),
            u: plane.u(),
            v: plane.v(),
            shape: self.shape().clone(),
            material: plane.material(),
            sampling: self.sampling(),
        }
        .serialize(serializer)
    }
}

impl<'de, S: Interior + DeserializeOwned> Deserialize<'de> for Quad<S> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let spec = QuadSpec::<S>::deserialize(deserializer)?;
        Quad::with_interior(spec.q, spec.u, spec.v, spec.shape)
            .map(|quad| {
                quad.with_material(spec.material)
                    .with_sampling(spec.sampling)
            })
            .map_err(D::Error::custom)
    }
}

#[derive(Serialize, Deserialize)]
#[serde(rename = "Sphere")]
struct SphereSpec {
    center: DVec3,
    radius: f64,
    #[serde(default)]
    material: MaterialId,
}

impl Serialize for Sphere {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        SphereSpec {
            center: self.center(),
            radius: self.radius(),
            material: self.material(),
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Sphere {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let SphereSpec {
            center,
            radius,
            material,
        } = SphereSpec::deserialize(deserializer)?;
        Sphere::new(center, radius)
            .map(|sphere| sphere.with_material(material))
            .map_err(D::Error::custom)
    }
}

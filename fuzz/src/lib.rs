//! What the fuzz targets share: numbers drawn from bytes the way scenes go wrong (any bit
//! pattern, small integers that make shared corners and axis-aligned faces, offsets far
//! from the origin, sizes at every scale, values within ulps of each other), shapes built
//! through their public constructors (bad input must be an error, never a panic), and the
//! answer every tree is held to: the loop over its objects (the contract's clause 3).

use std::sync::Arc;

pub mod seed;

use arbitrary::{Arbitrary, Result, Unstructured};
use hitkit::glam::{DAffine3, DMat3, DVec3};
use hitkit::{
    Cuboid, Disk, HitRecord, Hittable, Interval, Parallelogram, PdfHittable, Quad, Ray, Ring,
    Sphere, Transformed, Triangle,
};

/// A number as scenes make them, or any bit pattern.
#[derive(Clone, Copy, Debug)]
pub struct Num(pub f64);

impl<'a> Arbitrary<'a> for Num {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let tag: u8 = u.arbitrary()?;
        Ok(Num(match tag % 8 {
            // NaN, infinities, subnormals, anything.
            0 => f64::from_bits(u.arbitrary()?),
            // Shared corners, axis-aligned faces, zero components.
            1 | 2 => f64::from(u.int_in_range(-8i8..=8)?),
            3 => f64::from(u.arbitrary::<i16>()?) / 64.0,
            // Any scale, 1e-12 to 1e12.
            4 => {
                let mantissa = f64::from(u.arbitrary::<i16>()?) / 1024.0;
                mantissa * 10f64.powi(u.int_in_range(-12..=12)?)
            }
            // Within ulps of 1: nearly parallel edges, grazing directions.
            5 => 1.0 + f64::from(u.arbitrary::<i8>()?) * f64::EPSILON,
            // Far from the origin, and not a power of two.
            6 => f64::from(u.arbitrary::<i32>()?) * 1e3 + 0.3,
            _ => f64::from(u.arbitrary::<u16>()?) / 65536.0,
        }))
    }
}

/// A vector of three [`Num`]s.
#[derive(Clone, Copy, Debug, Arbitrary)]
pub struct V(pub Num, pub Num, pub Num);

impl V {
    pub fn get(self) -> DVec3 {
        DVec3::new(self.0.0, self.1.0, self.2.0)
    }
}

/// A ray and the interval it is asked over.
#[derive(Clone, Copy, Debug, Arbitrary)]
pub struct RaySpec {
    pub origin: V,
    pub direction: V,
    /// Whether to ask over `[min, max]` rather than `Interval::FORWARD`.
    pub bounded: bool,
    pub min: Num,
    pub max: Num,
}

impl RaySpec {
    pub fn get(&self) -> (Ray, Interval) {
        let ray = Ray::new(self.origin.get(), self.direction.get());
        let interval = if self.bounded {
            Interval::new(self.min.0, self.max.0)
        } else {
            Interval::FORWARD
        };
        (ray, interval)
    }
}

/// A shape, as a scene file or a user's code would build it.
#[derive(Clone, Debug, Arbitrary)]
pub enum Spec {
    Quad {
        q: V,
        u: V,
        v: V,
        interior: u8,
        inner: Num,
    },
    Sphere {
        centre: V,
        radius: Num,
    },
    Cuboid {
        a: V,
        b: V,
    },
    /// A quad under an affine map (columns and translation).
    Mapped {
        q: V,
        u: V,
        v: V,
        columns: [V; 3],
        offset: V,
    },
}

impl Spec {
    /// The shape as a light, where its constructor takes the numbers.
    pub fn light(&self) -> Option<Arc<dyn PdfHittable>> {
        Some(match self {
            Spec::Quad {
                q,
                u,
                v,
                interior,
                inner,
            } => {
                let (q, u, v) = (q.get(), u.get(), v.get());
                match interior % 4 {
                    0 => Arc::new(Quad::with_interior(q, u, v, Parallelogram).ok()?),
                    1 => Arc::new(Quad::with_interior(q, u, v, Triangle).ok()?),
                    2 => Arc::new(Quad::with_interior(q, u, v, Disk).ok()?),
                    _ => Arc::new(Quad::with_interior(q, u, v, Ring::new(inner.0).ok()?).ok()?),
                }
            }
            Spec::Sphere { centre, radius } => Arc::new(Sphere::new(centre.get(), radius.0).ok()?),
            Spec::Cuboid { .. } => return None,
            Spec::Mapped {
                q,
                u,
                v,
                columns,
                offset,
            } => {
                let quad = Quad::new(q.get(), u.get(), v.get()).ok()?;
                let matrix = DMat3::from_cols(columns[0].get(), columns[1].get(), columns[2].get());
                let map = DAffine3::from_mat3_translation(matrix, offset.get());
                Arc::new(Transformed::affine(quad, map).ok()?)
            }
        })
    }

    /// The shape, where its constructor takes the numbers.
    pub fn shape(&self) -> Option<Arc<dyn Hittable>> {
        match self {
            Spec::Cuboid { a, b } => Some(Arc::new(Cuboid::new(a.get(), b.get()).ok()?)),
            _ => self.light().map(|l| l as Arc<dyn Hittable>),
        }
    }
}

/// What the `tree` target reads.
#[derive(Debug, Arbitrary)]
pub struct TreeInput {
    pub shapes: Vec<Spec>,
    pub rays: Vec<RaySpec>,
}

/// What the `mesh` target reads.
#[derive(Debug, Arbitrary)]
pub struct MeshInput {
    pub vertices: Vec<V>,
    pub faces: Vec<[u8; 3]>,
    pub moved: Vec<V>,
    pub rays: Vec<RaySpec>,
}

/// A change the `update` target makes to its tree.
#[derive(Debug, Arbitrary)]
pub enum Op {
    Insert(V, Num),
    Remove(u16),
    /// Moves the objects of odd number by the offset, then refits.
    Move(V),
    Optimize(u8),
    Rebuild,
}

/// What the `update` target reads.
#[derive(Debug, Arbitrary)]
pub struct UpdateInput {
    pub start: Vec<(V, Num)>,
    pub ops: Vec<Op>,
    pub rays: Vec<RaySpec>,
}

/// What the `light` target reads.
#[derive(Debug, Arbitrary)]
pub struct LightInput {
    pub light: Spec,
    pub origin: V,
    pub normal: Option<V>,
    pub samples: Vec<(u16, u16)>,
}

/// The closest hit among `objects` by asking each in turn (ties to the lower index), and
/// its index: the answer a tree over them must give.
pub fn closest<T: Hittable + ?Sized>(
    objects: &[&T],
    ray: &Ray,
    ray_t: Interval,
) -> Option<(usize, HitRecord)> {
    let mut best: Option<(usize, HitRecord)> = None;
    for (i, object) in objects.iter().enumerate() {
        let max = best.map_or(ray_t.max, |(_, h)| h.t);
        if let Some(hit) = object.hit(ray, Interval::new(ray_t.min, max))
            && best.is_none_or(|(_, b)| hit.t < b.t)
        {
            best = Some((i, hit));
        }
    }
    best
}

/// Clause 4 (nothing returned is NaN or infinite) and the record's own promises: `t`
/// within the interval asked, a unit normal.
pub fn check_record(hit: &HitRecord, ray_t: Interval, what: &str) {
    assert!(
        hit.t.is_finite() && hit.point.is_finite() && hit.normal.is_finite(),
        "{what}: a record not finite: {hit:?}"
    );
    assert!(
        ray_t.min <= hit.t && hit.t <= ray_t.max,
        "{what}: t outside {ray_t:?}: {hit:?}"
    );
    // A unit vector computed in f64: within a few ulps of length 1.
    assert!(
        (hit.normal.length() - 1.0).abs() < 1e-14,
        "{what}: normal not unit: {hit:?}"
    );
}

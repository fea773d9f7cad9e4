//! What the fuzz targets share: numbers drawn from bytes the way scenes go wrong (any bit
//! pattern, small integers that make shared corners and axis-aligned faces, offsets far
//! from the origin, sizes at every scale, values within ulps of each other), shapes built
//! through their public constructors (bad input must be an error, never a panic), and the
//! answer every tree is held to: the loop over its objects (the contract's clause 3).

use std::sync::Arc;

pub mod seed;

use arbitrary::{Arbitrary, Result, Unstructured};
use hitkit::glam::{DAffine3, DMat3, DQuat, DVec3};
use hitkit::{
    Cuboid, Disk, HitRecord, Hittable, Interval, Parallelogram, PdfHittable, PunctualLight, Quad,
    Ray, Ring, Sphere, Transformed, Triangle,
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

    /// `p`, exactly.
    pub fn of(p: DVec3) -> Self {
        V(Num(p.x), Num(p.y), Num(p.z))
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

    /// The same shape moved by `map` (a turn, a uniform scale and a move), as a scene's
    /// copies are made: from the moved numbers, through the constructors. (A box stays
    /// aligned to the axes: the box of its two moved corners.)
    pub fn moved(&self, map: &DAffine3) -> Spec {
        let point = |x: &V| V::of(map.transform_point3(x.get()));
        let vector = |x: &V| V::of(map.transform_vector3(x.get()));
        match self {
            Spec::Quad {
                q,
                u,
                v,
                interior,
                inner,
            } => Spec::Quad {
                q: point(q),
                u: vector(u),
                v: vector(v),
                interior: *interior,
                inner: *inner,
            },
            Spec::Sphere { centre, radius } => Spec::Sphere {
                centre: point(centre),
                radius: Num(radius.0 * map.matrix3.x_axis.length()),
            },
            Spec::Cuboid { a, b } => Spec::Cuboid {
                a: point(a),
                b: point(b),
            },
            Spec::Mapped {
                q,
                u,
                v,
                columns,
                offset,
            } => Spec::Mapped {
                q: *q,
                u: *u,
                v: *v,
                columns: columns.map(|c| vector(&c)),
                offset: point(offset),
            },
        }
    }

    /// The shape, where its constructor takes the numbers.
    pub fn shape(&self) -> Option<Arc<dyn Hittable>> {
        match self {
            Spec::Cuboid { a, b } => Some(Arc::new(Cuboid::new(a.get(), b.get()).ok()?)),
            _ => self.light().map(|l| l as Arc<dyn Hittable>),
        }
    }
}

/// Many copies of what an input holds, about one point and along one line: coincident
/// copies, nested shells, fans of slivers meeting at a point, strands. Trees of them have
/// every child of every node entered, level after level: the walks' worst case, which
/// arbitrary shapes and rays almost never reach.
#[derive(Clone, Copy, Debug, Arbitrary)]
pub struct Crowd {
    /// How many copies (see [`Crowd::count`]).
    pub count: u16,
    /// Copy `i` of `n` is scaled about `centre` by `1 - shrink / 256 * i / n`: the same
    /// for 0 (coincident copies), each inside the last otherwise (nested shells).
    pub shrink: u8,
    /// Copy `i` of `n` is turned about the line by `turn / 256` of a turn times `i / n`:
    /// a fan about it (slivers meeting at a point, where a copy has a corner there).
    pub turn: u8,
    pub centre: V,
    /// The line the copies lie along, `centre` to `centre + along` (zero: about one
    /// point; turned about the z axis then).
    pub along: V,
    /// Whether each ray is turned to aim at `centre`, where the crowd meets.
    pub aim: bool,
}

impl Crowd {
    /// Copies to make: 1 to 1,024 (enough for trees of four full levels, and of dozens
    /// when inserted one by one).
    pub fn count(&self) -> usize {
        usize::from(self.count % 1024) + 1
    }

    /// Copy `i`'s map: scaled and turned about `centre`, moved along the line.
    pub fn map(&self, i: usize) -> DAffine3 {
        let share = i as f64 / self.count() as f64;
        let (centre, along) = (self.centre.get(), self.along.get());
        let axis = along.try_normalize().unwrap_or(DVec3::Z);
        let angle = f64::from(self.turn) / 256.0 * std::f64::consts::TAU * share;
        let scale = 1.0 - f64::from(self.shrink) / 256.0 * share;
        let turned = DMat3::from_quat(DQuat::from_axis_angle(axis, angle)) * scale;
        // p -> centre + turned (p - centre) + share along
        DAffine3::from_mat3_translation(turned, centre - turned * centre + share * along)
    }

    /// `spec`'s ray, turned to aim at `centre` where asked (and where that is a direction).
    pub fn ray(&self, spec: &RaySpec) -> (Ray, Interval) {
        let (ray, ray_t) = spec.get();
        let toward = self.centre.get() - ray.origin;
        if self.aim && toward.is_finite() && toward != DVec3::ZERO {
            (Ray::new(ray.origin, toward), ray_t)
        } else {
            (ray, ray_t)
        }
    }
}

/// The rays of `specs`, each aimed by `crowd` where there is one.
pub fn rays(specs: &[RaySpec], crowd: Option<&Crowd>) -> Vec<(Ray, Interval)> {
    specs
        .iter()
        .map(|s| crowd.map_or_else(|| s.get(), |c| c.ray(s)))
        .collect()
}

/// What the `tree` target reads.
#[derive(Debug, Arbitrary)]
pub struct TreeInput {
    pub shapes: Vec<Spec>,
    pub rays: Vec<RaySpec>,
    /// Copies of the shapes, in turn, added to them.
    pub crowd: Option<Crowd>,
}

/// What the `mesh` target reads.
#[derive(Debug, Arbitrary)]
pub struct MeshInput {
    pub vertices: Vec<V>,
    pub faces: Vec<[u8; 3]>,
    pub moved: Vec<V>,
    pub rays: Vec<RaySpec>,
    /// Copies of the whole mesh, as one mesh (up to 4,096 faces in all).
    pub crowd: Option<Crowd>,
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
    /// Copies of the first ball, inserted one by one before the changes.
    pub crowd: Option<Crowd>,
}

/// What the `light` target reads.
#[derive(Debug, Arbitrary)]
pub struct LightInput {
    pub light: Spec,
    pub origin: V,
    pub normal: Option<V>,
    pub samples: Vec<(u16, u16)>,
    /// A point, spot or sun beside the light.
    pub punctual: Option<Punctual>,
}

/// A [`PunctualLight`] from arbitrary numbers: `kind` picks point, spot or sun.
#[derive(Clone, Copy, Debug, Arbitrary)]
pub struct Punctual {
    pub kind: u8,
    pub position: V,
    pub direction: V,
    pub inner: Num,
    pub outer: Num,
}

impl Punctual {
    /// The light, where its constructor takes the numbers.
    pub fn light(&self) -> Option<PunctualLight> {
        let (p, d) = (self.position.get(), self.direction.get());
        match self.kind % 3 {
            0 => PunctualLight::point(p).ok(),
            1 => PunctualLight::spot(p, d, self.inner.0, self.outer.0).ok(),
            _ => PunctualLight::sun(d).ok(),
        }
    }
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

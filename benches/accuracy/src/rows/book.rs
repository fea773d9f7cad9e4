//! The baseline: the quad and box tests of "Ray Tracing: The Next Week" (v4), reimplemented
//! in `f64` exactly as the book writes them, epsilons included.

use hitkit::glam::{DVec2, DVec3};
use hitkit::{Aabb, HitRecord, Hittable, Interval, MaterialId, Ray};

/// The book's renderer traces every ray over `(0.001, infinity)`.
pub const T_MIN: f64 = 0.001;
/// Below this `|n . d|` the book calls a ray parallel to a quad.
pub const PARALLEL_EPSILON: f64 = 1e-8;
/// The book pads every box side thinner than this to this width.
pub const BOX_PADDING: f64 = 0.0001;

/// Which region of the plane the book's test accepts, in `(alpha, beta)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BookShape {
    /// `0 <= alpha <= 1` and `0 <= beta <= 1` (the book's `is_interior`).
    Parallelogram,
    /// `alpha >= 0`, `beta >= 0`, `alpha + beta <= 1`.
    Triangle,
}

/// The book's `quad`: `n = u x v`, `normal = n / |n|`, `D = normal . q`, `w = n / (n . n)`.
#[derive(Clone, Copy, Debug)]
pub struct BookQuad {
    q: DVec3,
    u: DVec3,
    v: DVec3,
    w: DVec3,
    normal: DVec3,
    d: f64,
    shape: BookShape,
}

impl BookQuad {
    /// The quad with corner `q` and edges `u`, `v`, as the book's constructor computes it.
    pub fn new(q: DVec3, u: DVec3, v: DVec3, shape: BookShape) -> Self {
        let n = u.cross(v);
        let normal = n / n.length();
        Self {
            q,
            u,
            v,
            w: n / n.dot(n),
            normal,
            d: normal.dot(q),
            shape,
        }
    }

    /// The book's `is_interior` (with the unit interval closed, as its `contains` is).
    fn is_interior(&self, alpha: f64, beta: f64) -> bool {
        let unit = |x: f64| (0.0..=1.0).contains(&x);
        match self.shape {
            BookShape::Parallelogram => unit(alpha) && unit(beta),
            BookShape::Triangle => alpha >= 0.0 && beta >= 0.0 && alpha + beta <= 1.0,
        }
    }

    /// The book's `set_bounding_box`: the union of the boxes of the two diagonals.
    pub fn bounding_box(&self) -> BookBox {
        let (q, u, v) = (self.q, self.u, self.v);
        BookBox::from_points(q, q + u + v).union(&BookBox::from_points(q + u, q + v))
    }
}

impl Hittable for BookQuad {
    /// The book's `quad::hit`, step by step; the record's point is the book's `r.at(t)` and
    /// carries no error bound.
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        let denom = self.normal.dot(ray.direction);
        if denom.abs() < PARALLEL_EPSILON {
            return None;
        }
        let t = (self.d - self.normal.dot(ray.origin)) / denom;
        if !ray_t.contains(t) {
            return None;
        }
        let intersection = ray.at(t);
        let planar = intersection - self.q;
        let alpha = self.w.dot(planar.cross(self.v));
        let beta = self.w.dot(self.u.cross(planar));
        if !self.is_interior(alpha, beta) {
            return None;
        }
        Some(
            HitRecord::new(ray, t, intersection, self.normal)
                .with_uv(DVec2::new(alpha, beta))
                .with_material(MaterialId(0)),
        )
    }

    /// The book's box, as a hitkit `Aabb` (which pads it again; unused by the workloads).
    fn bounding_box(&self) -> Aabb {
        let b = BookQuad::bounding_box(self);
        Aabb::new(b.min, b.max)
    }
}

/// The book's `aabb`: three closed intervals, here as two corners.
#[derive(Clone, Copy, Debug)]
pub struct BookBox {
    min: DVec3,
    max: DVec3,
}

impl BookBox {
    /// The book's `aabb(a, b)`: the box of two points, each side padded to at least
    /// `0.0001` (`pad_to_minimums`, `interval::expand`).
    pub fn from_points(a: DVec3, b: DVec3) -> Self {
        let (mut min, mut max) = (a.min(b), a.max(b));
        for axis in 0..3 {
            if max[axis] - min[axis] < BOX_PADDING {
                let padding = BOX_PADDING / 2.0;
                min[axis] -= padding;
                max[axis] += padding;
            }
        }
        Self { min, max }
    }

    /// Another box's corners as they are (to run the book's slab test on hitkit's box).
    pub fn from_aabb(aabb: &Aabb) -> Self {
        Self {
            min: aabb.min(),
            max: aabb.max(),
        }
    }

    /// The book's `aabb(box0, box1)`: the smallest box holding both.
    pub fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The book's slab test, `aabb::hit`: `t0 = (min - o) * (1 / d)`,
    /// `t1 = (max - o) * (1 / d)`, ordered by `t0 < t1`, `ray_t` narrowed, and a miss once
    /// `ray_t.max <= ray_t.min`. A ray lying in a slab plane gets `0 * inf = NaN` there.
    pub fn hit(&self, ray: &Ray, mut ray_t: Interval) -> bool {
        for axis in 0..3 {
            let adinv = 1.0 / ray.direction[axis];
            let t0 = (self.min[axis] - ray.origin[axis]) * adinv;
            let t1 = (self.max[axis] - ray.origin[axis]) * adinv;
            if t0 < t1 {
                if t0 > ray_t.min {
                    ray_t.min = t0;
                }
                if t1 < ray_t.max {
                    ray_t.max = t1;
                }
            } else {
                if t1 > ray_t.min {
                    ray_t.min = t1;
                }
                if t0 < ray_t.max {
                    ray_t.max = t0;
                }
            }
            if ray_t.max <= ray_t.min {
                return false;
            }
        }
        true
    }

    /// Whether the slab test computes a NaN slab distance for `ray` (on any axis).
    pub fn computes_nan(&self, ray: &Ray) -> bool {
        (0..3).any(|axis| {
            let adinv = 1.0 / ray.direction[axis];
            let t0 = (self.min[axis] - ray.origin[axis]) * adinv;
            let t1 = (self.max[axis] - ray.origin[axis]) * adinv;
            t0.is_nan() || t1.is_nan()
        })
    }
}

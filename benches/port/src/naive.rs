//! The book's own geometry (*Ray Tracing in One Weekend* series), in Rust as its ports write
//! it: the formulas, the `1e-8` parallel test, the `0.0001` box padding and the `0.001`
//! `t_min` included, and a binary BVH of boxed nodes split at the median of the longest
//! axis. hitkit's `Ray` and `HitRecord` serve as plain data, so one renderer drives both.

use std::f64::consts::PI;

use hitkit::glam::{DVec2, DVec3};
use hitkit::{HitRecord, MaterialId, Ray};

/// The renderer's `t_min`, as the book's `ray_color` passes it.
pub const T_MIN: f64 = 0.001;
const PARALLEL: f64 = 1e-8;
const PAD: f64 = 0.0001;

#[derive(Clone, Copy)]
pub struct Span {
    pub min: f64,
    pub max: f64,
}

impl Span {
    fn contains(&self, x: f64) -> bool {
        self.min <= x && x <= self.max
    }
    fn surrounds(&self, x: f64) -> bool {
        self.min < x && x < self.max
    }
}

/// The book's `aabb`: an interval per axis, none thinner than `0.0001`.
#[derive(Clone, Copy)]
pub struct BookBox {
    pub min: DVec3,
    pub max: DVec3,
}

impl BookBox {
    pub const EMPTY: Self = Self {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };

    pub fn new(a: DVec3, b: DVec3) -> Self {
        let (mut min, mut max) = (a.min(b), a.max(b));
        for axis in 0..3 {
            if max[axis] - min[axis] < PAD {
                min[axis] -= PAD / 2.0;
                max[axis] += PAD / 2.0;
            }
        }
        Self { min, max }
    }

    pub fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    fn hit(&self, ray: &Ray, mut span: Span) -> bool {
        for axis in 0..3 {
            let inv = 1.0 / ray.direction[axis];
            let t0 = (self.min[axis] - ray.origin[axis]) * inv;
            let t1 = (self.max[axis] - ray.origin[axis]) * inv;
            let (t0, t1) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
            span.min = span.min.max(t0);
            span.max = span.max.min(t1);
            if span.max <= span.min {
                return false;
            }
        }
        true
    }
}

/// The book's `hittable`.
pub trait Hittable: Send + Sync {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord>;
    fn bounding_box(&self) -> BookBox;
    fn pdf_value(&self, _origin: DVec3, _direction: DVec3) -> f64 {
        0.0
    }
    fn random(&self, _origin: DVec3, _u: DVec2) -> DVec3 {
        DVec3::X
    }
}

fn record(
    ray: &Ray,
    t: f64,
    point: DVec3,
    outward: DVec3,
    uv: DVec2,
    material: MaterialId,
) -> HitRecord {
    HitRecord::new(ray, t, point, outward)
        .with_uv(uv)
        .with_material(material)
}

pub struct Sphere {
    center: DVec3,
    motion: DVec3,
    radius: f64,
    material: MaterialId,
}

impl Sphere {
    pub fn new(center: DVec3, radius: f64, material: MaterialId) -> Self {
        Self::moving(center, center, radius, material)
    }
    pub fn moving(from: DVec3, to: DVec3, radius: f64, material: MaterialId) -> Self {
        Self {
            center: from,
            motion: to - from,
            radius,
            material,
        }
    }
}

impl Hittable for Sphere {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord> {
        let center = self.center + ray.time * self.motion;
        let oc = center - ray.origin;
        let a = ray.direction.length_squared();
        let h = ray.direction.dot(oc);
        let c = oc.length_squared() - self.radius * self.radius;
        let discriminant = h * h - a * c;
        if discriminant < 0.0 {
            return None;
        }
        let sqrtd = discriminant.sqrt();
        let mut root = (h - sqrtd) / a;
        if !span.surrounds(root) {
            root = (h + sqrtd) / a;
            if !span.surrounds(root) {
                return None;
            }
        }
        let p = ray.at(root);
        let outward = (p - center) / self.radius;
        let theta = (-outward.y).acos();
        let phi = (-outward.z).atan2(outward.x) + PI;
        Some(record(
            ray,
            root,
            p,
            outward,
            DVec2::new(phi / (2.0 * PI), theta / PI),
            self.material,
        ))
    }

    fn bounding_box(&self) -> BookBox {
        let r = DVec3::splat(self.radius);
        let end = self.center + self.motion;
        BookBox::new(self.center - r, self.center + r).union(&BookBox::new(end - r, end + r))
    }

    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        if self
            .hit(
                &Ray::new(origin, direction),
                Span {
                    min: T_MIN,
                    max: f64::INFINITY,
                },
            )
            .is_none()
        {
            return 0.0;
        }
        let distance_squared = (self.center - origin).length_squared();
        let cos_theta_max = (1.0 - self.radius * self.radius / distance_squared).sqrt();
        1.0 / (2.0 * PI * (1.0 - cos_theta_max))
    }

    fn random(&self, origin: DVec3, u: DVec2) -> DVec3 {
        let direction = self.center - origin;
        let distance_squared = direction.length_squared();
        let z = 1.0 + u.y * ((1.0 - self.radius * self.radius / distance_squared).sqrt() - 1.0);
        let phi = 2.0 * PI * u.x;
        let s = (1.0 - z * z).sqrt();
        let w = direction.normalize();
        let (a, b) = w.any_orthonormal_pair();
        phi.cos() * s * a + phi.sin() * s * b + z * w
    }
}

pub struct Quad {
    q: DVec3,
    u: DVec3,
    v: DVec3,
    w: DVec3,
    normal: DVec3,
    d: f64,
    area: f64,
    material: MaterialId,
}

impl Quad {
    pub fn new(q: DVec3, u: DVec3, v: DVec3, material: MaterialId) -> Self {
        let n = u.cross(v);
        let normal = n.normalize();
        Self {
            q,
            u,
            v,
            w: n / n.dot(n),
            normal,
            d: normal.dot(q),
            area: n.length(),
            material,
        }
    }
}

impl Hittable for Quad {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord> {
        let denom = self.normal.dot(ray.direction);
        if denom.abs() < PARALLEL {
            return None;
        }
        let t = (self.d - self.normal.dot(ray.origin)) / denom;
        if !span.contains(t) {
            return None;
        }
        let p = ray.at(t);
        let planar = p - self.q;
        let alpha = self.w.dot(planar.cross(self.v));
        let beta = self.w.dot(self.u.cross(planar));
        let unit = |x: f64| (0.0..=1.0).contains(&x);
        if !(unit(alpha) && unit(beta)) {
            return None;
        }
        Some(record(
            ray,
            t,
            p,
            self.normal,
            DVec2::new(alpha, beta),
            self.material,
        ))
    }

    fn bounding_box(&self) -> BookBox {
        let (q, u, v) = (self.q, self.u, self.v);
        BookBox::new(q, q + u + v).union(&BookBox::new(q + u, q + v))
    }

    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        let Some(rec) = self.hit(
            &Ray::new(origin, direction),
            Span {
                min: T_MIN,
                max: f64::INFINITY,
            },
        ) else {
            return 0.0;
        };
        let distance_squared = rec.t * rec.t * direction.length_squared();
        let cosine = (direction.dot(rec.normal) / direction.length()).abs();
        distance_squared / (cosine * self.area)
    }

    fn random(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.q + u.x * self.u + u.y * self.v - origin
    }
}

/// The book's `hittable_list`.
pub struct List(pub Vec<Box<dyn Hittable>>);

impl Hittable for List {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord> {
        let mut closest = None;
        let mut max = span.max;
        for object in &self.0 {
            if let Some(rec) = object.hit(ray, Span { min: span.min, max }) {
                max = rec.t;
                closest = Some(rec);
            }
        }
        closest
    }

    fn bounding_box(&self) -> BookBox {
        self.0
            .iter()
            .fold(BookBox::EMPTY, |b, o| b.union(&o.bounding_box()))
    }

    /// The book's list of lights: the mean of their densities.
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.0
            .iter()
            .map(|o| o.pdf_value(origin, direction))
            .sum::<f64>()
            / self.0.len() as f64
    }

    fn random(&self, origin: DVec3, u: DVec2) -> DVec3 {
        let n = self.0.len();
        let i = ((u.x * n as f64) as usize).min(n - 1);
        self.0[i].random(origin, DVec2::new(u.x * n as f64 - i as f64, u.y))
    }
}

/// The book's box: six quads in a list.
pub fn cuboid(a: DVec3, b: DVec3, material: MaterialId) -> List {
    let (min, max) = (a.min(b), a.max(b));
    let (dx, dy, dz) = (
        DVec3::new(max.x - min.x, 0.0, 0.0),
        DVec3::new(0.0, max.y - min.y, 0.0),
        DVec3::new(0.0, 0.0, max.z - min.z),
    );
    let quad = |q, u, v| Box::new(Quad::new(q, u, v, material)) as Box<dyn Hittable>;
    List(vec![
        quad(DVec3::new(min.x, min.y, max.z), dx, dy),
        quad(DVec3::new(max.x, min.y, max.z), -dz, dy),
        quad(DVec3::new(max.x, min.y, min.z), -dx, dy),
        quad(min, dz, dy),
        quad(DVec3::new(min.x, max.y, max.z), dx, -dz),
        quad(min, dx, dz),
    ])
}

/// The book's `bvh_node`: a box and two boxed children.
pub struct BvhNode {
    left: Box<dyn Hittable>,
    right: Option<Box<dyn Hittable>>,
    bbox: BookBox,
}

impl BvhNode {
    pub fn new(mut objects: Vec<Box<dyn Hittable>>) -> Self {
        let bbox = objects
            .iter()
            .fold(BookBox::EMPTY, |b, o| b.union(&o.bounding_box()));
        let extent = bbox.max - bbox.min;
        let axis = if extent.x > extent.y && extent.x > extent.z {
            0
        } else if extent.y > extent.z {
            1
        } else {
            2
        };
        if objects.len() == 1 {
            return Self {
                left: objects.pop().unwrap(),
                right: None,
                bbox,
            };
        }
        if objects.len() == 2 {
            let right = objects.pop().unwrap();
            return Self {
                left: objects.pop().unwrap(),
                right: Some(right),
                bbox,
            };
        }
        objects.sort_by(|a, b| a.bounding_box().min[axis].total_cmp(&b.bounding_box().min[axis]));
        let right = objects.split_off(objects.len() / 2);
        Self {
            left: Box::new(BvhNode::new(objects)),
            right: Some(Box::new(BvhNode::new(right))),
            bbox,
        }
    }
}

impl Hittable for BvhNode {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord> {
        if !self.bbox.hit(ray, span) {
            return None;
        }
        let left = self.left.hit(ray, span);
        let max = left.map_or(span.max, |r| r.t);
        let right = self
            .right
            .as_ref()
            .and_then(|r| r.hit(ray, Span { min: span.min, max }));
        right.or(left)
    }

    fn bounding_box(&self) -> BookBox {
        self.bbox
    }
}

/// The book's `translate`.
pub struct Translate {
    object: Box<dyn Hittable>,
    offset: DVec3,
}

impl Translate {
    pub fn new(object: Box<dyn Hittable>, offset: DVec3) -> Self {
        Self { object, offset }
    }
}

impl Hittable for Translate {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord> {
        let moved = Ray::new(ray.origin - self.offset, ray.direction).at_time(ray.time);
        let mut rec = self.object.hit(&moved, span)?;
        rec.point += self.offset;
        Some(rec)
    }

    fn bounding_box(&self) -> BookBox {
        let b = self.object.bounding_box();
        BookBox {
            min: b.min + self.offset,
            max: b.max + self.offset,
        }
    }
}

/// The book's `rotate_y`.
pub struct RotateY {
    object: Box<dyn Hittable>,
    sin: f64,
    cos: f64,
    bbox: BookBox,
}

impl RotateY {
    pub fn new(object: Box<dyn Hittable>, degrees: f64) -> Self {
        let (sin, cos) = degrees.to_radians().sin_cos();
        let b = object.bounding_box();
        let mut bbox = BookBox::EMPTY;
        for i in 0..8 {
            let pick = |bit: usize, lo: f64, hi: f64| if i & bit == 0 { lo } else { hi };
            let (x, y, z) = (
                pick(1, b.min.x, b.max.x),
                pick(2, b.min.y, b.max.y),
                pick(4, b.min.z, b.max.z),
            );
            let p = DVec3::new(cos * x + sin * z, y, -sin * x + cos * z);
            bbox = bbox.union(&BookBox { min: p, max: p });
        }
        Self {
            object,
            sin,
            cos,
            bbox,
        }
    }

    fn to_object(&self, v: DVec3) -> DVec3 {
        DVec3::new(
            self.cos * v.x - self.sin * v.z,
            v.y,
            self.sin * v.x + self.cos * v.z,
        )
    }

    fn to_world(&self, v: DVec3) -> DVec3 {
        DVec3::new(
            self.cos * v.x + self.sin * v.z,
            v.y,
            -self.sin * v.x + self.cos * v.z,
        )
    }
}

impl Hittable for RotateY {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord> {
        let turned =
            Ray::new(self.to_object(ray.origin), self.to_object(ray.direction)).at_time(ray.time);
        let mut rec = self.object.hit(&turned, span)?;
        rec.point = self.to_world(rec.point);
        rec.normal = self.to_world(rec.normal);
        rec.shading_normal = rec.normal;
        Some(rec)
    }

    fn bounding_box(&self) -> BookBox {
        self.bbox
    }
}

/// The book's `constant_medium`, with its `0.0001` between the entry and the exit.
pub struct Medium<U> {
    boundary: Box<dyn Hittable>,
    neg_inv_density: f64,
    material: MaterialId,
    uniform: U,
}

impl<U: Fn(&Ray) -> f64 + Send + Sync> Medium<U> {
    pub fn new(
        boundary: Box<dyn Hittable>,
        density: f64,
        material: MaterialId,
        uniform: U,
    ) -> Self {
        Self {
            boundary,
            neg_inv_density: -1.0 / density,
            material,
            uniform,
        }
    }
}

impl<U: Fn(&Ray) -> f64 + Send + Sync> Hittable for Medium<U> {
    fn hit(&self, ray: &Ray, span: Span) -> Option<HitRecord> {
        let all = Span {
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
        };
        let rec1 = self.boundary.hit(ray, all)?;
        let rec2 = self.boundary.hit(
            ray,
            Span {
                min: rec1.t + 0.0001,
                max: f64::INFINITY,
            },
        )?;
        let (mut t1, t2) = (rec1.t.max(span.min), rec2.t.min(span.max));
        if t1 >= t2 {
            return None;
        }
        t1 = t1.max(0.0);
        let length = ray.direction.length();
        let inside = (t2 - t1) * length;
        let distance = self.neg_inv_density * (self.uniform)(ray).ln();
        if distance > inside {
            return None;
        }
        let t = t1 + distance / length;
        Some(record(
            ray,
            t,
            ray.at(t),
            -ray.direction.normalize(),
            DVec2::ZERO,
            self.material,
        ))
    }

    fn bounding_box(&self) -> BookBox {
        self.boundary.bounding_box()
    }
}

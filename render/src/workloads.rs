//! The scenes and rays every measurement shares: the tests, the criterion benches, the
//! peers comparison and the accuracy tables trace the same work.

use hitkit::Ray;
use hitkit::glam::DVec3;

/// A triangle as its three corners.
pub type Tri = [DVec3; 3];

/// SplitMix64 (Steele, Lea and Flood 2014): a fixed stream for a fixed seed, on every
/// platform and every version of every crate.
#[derive(Clone, Debug)]
pub struct SplitMix(u64);

impl SplitMix {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    pub fn vec3(&mut self) -> DVec3 {
        DVec3::new(self.next_f64(), self.next_f64(), self.next_f64())
    }

    /// Uniform on the unit sphere.
    pub fn direction(&mut self) -> DVec3 {
        let z = 2.0 * self.next_f64() - 1.0;
        let phi = core::f64::consts::TAU * self.next_f64();
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// `n` random triangles in the unit cube, edges about 0.01 long.
pub fn triangle_soup(n: usize, seed: u64) -> Vec<Tri> {
    let mut rng = SplitMix::new(seed);
    (0..n)
        .map(|_| {
            let a = rng.vec3();
            let mut corner = || a + 0.01 * rng.direction();
            [a, corner(), corner()]
        })
        .collect()
}

/// The box of all corners.
pub fn bounds(tris: &[Tri]) -> (DVec3, DVec3) {
    tris.iter()
        .flatten()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        })
}

/// Incoherent rays: origins uniform in the box, directions uniform on the sphere.
pub fn random_rays((lo, hi): (DVec3, DVec3), n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = SplitMix::new(seed);
    (0..n)
        .map(|_| Ray::new(lo + (hi - lo) * rng.vec3(), rng.direction()))
        .collect()
}

/// Coherent rays: a `side` x `side` pinhole camera grid looking at the box's centre from
/// outside it, the box filling the view.
pub fn camera_rays((lo, hi): (DVec3, DVec3), side: usize) -> Vec<Ray> {
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    let eye = centre + DVec3::new(0.3, 0.4, 1.0).normalize() * radius * 2.5;
    let forward = (centre - eye).normalize();
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    // Half-angle so that the bounding sphere just fits: sin = radius / distance.
    let half = (radius / (eye - centre).length()).asin().tan();
    let mut rays = Vec::with_capacity(side * side);
    for j in 0..side {
        for i in 0..side {
            let x = (2.0 * (i as f64 + 0.5) / side as f64 - 1.0) * half;
            let y = (1.0 - 2.0 * (j as f64 + 0.5) / side as f64) * half;
            rays.push(Ray::new(eye, forward + x * right + y * up));
        }
    }
    rays
}

/// Corner `i` (0 to 7) of the unit cube: `(i & 1, i >> 1 & 1, i >> 2 & 1)`.
pub fn cube_corner(i: u32) -> DVec3 {
    DVec3::new(
        f64::from(i & 1),
        f64::from((i >> 1) & 1),
        f64::from((i >> 2) & 1),
    )
}

/// The unit cube's six faces as twelve triangles over its corners ([`cube_corner`]), two a
/// face sharing its diagonal: a closed box (or room) of shared vertices, as users model one.
pub fn cube_faces() -> Vec<[u32; 3]> {
    [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ]
    .iter()
    .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
    .collect()
}

/// The CPU's name (from /proc/cpuinfo where there is one) and the number of cores, to name
/// the machine beside every figure printed.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines().find_map(|l| {
                l.strip_prefix("model name")
                    .and_then(|r| r.split_once(':'))
                    .map(|(_, n)| n.trim().to_owned())
            })
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("{cpu}, {cores} cores")
}

/// A subdivided icosahedron on the unit sphere: `levels` times, every face split in four
/// with the new vertices pushed out onto the sphere; `20 * 4^levels` faces sharing
/// `10 * 4^levels + 2` vertices, each face's corners in outward (counter-clockwise) order.
/// A closed mesh with shared vertices, as large as wanted.
pub fn icosphere(levels: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut unit: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut middle = std::collections::HashMap::with_capacity(faces.len() * 3 / 2);
        let mut mid = |a: u32, b: u32, unit: &mut Vec<DVec3>| {
            *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                unit.push((unit[a as usize] + unit[b as usize]).normalize());
                (unit.len() - 1) as u32
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (
                    mid(a, b, &mut unit),
                    mid(b, c, &mut unit),
                    mid(c, a, &mut unit),
                );
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    (unit, faces)
}

/// An instance of a shared mesh, as the instancing test and bench build them.
pub type Instance = hitkit::Transformed<std::sync::Arc<hitkit::TriangleMesh>>;

/// `count` instances of the icosphere of `levels` (ids 0 to `count - 1`), each turned at
/// random and moved to `corner + spread * [0, 1)^3`; and the same triangles moved one by
/// one as `Transformed` moves points (its rotation, then the translation) and flattened
/// into one list of vertices and faces, face `f` of instance `i` at `i * faces + f`. What
/// the instancing test and bench compare.
#[allow(dead_code)] // not every includer traces instances
pub fn instances(
    levels: u32,
    count: u32,
    corner: f64,
    spread: f64,
    rng: &mut SplitMix,
) -> (Vec<Instance>, Vec<DVec3>, Vec<[u32; 3]>) {
    use hitkit::glam::DQuat;
    let (unit, faces) = icosphere(levels);
    let shared = std::sync::Arc::new(hitkit::TriangleMesh::new(&unit, &faces).unwrap());
    let (mut instances, mut vertices, mut flat) = (Vec::new(), Vec::new(), Vec::new());
    for id in 0..count {
        let rot = DQuat::from_axis_angle(rng.direction(), core::f64::consts::TAU * rng.next_f64());
        let at = corner + spread * rng.vec3();
        let instance = hitkit::Transformed::new(shared.clone(), rot, at).unwrap();
        let base = vertices.len() as u32;
        vertices.extend(unit.iter().map(|&p| instance.rotation() * p + at));
        flat.extend(faces.iter().map(|f| f.map(|i| i + base)));
        instances.push(instance.with_instance_id(id));
    }
    (instances, vertices, flat)
}

/// A point of the triangle `[a, b, c]` by `kind % 3`: the corner `a`, a random point of
/// the edge from `a` to `b`, or a random point inside.
#[allow(dead_code)] // not every includer aims at faces
pub fn face_point(rng: &mut SplitMix, [a, b, c]: [DVec3; 3], kind: usize) -> DVec3 {
    match kind % 3 {
        0 => a,
        1 => a + rng.next_f64() * (b - a),
        _ => {
            let (x, y) = (rng.next_f64(), rng.next_f64());
            let (x, y) = if x + y > 1.0 {
                (1.0 - x, 1.0 - y)
            } else {
                (x, y)
            };
            a + x * (b - a) + y * (c - a)
        }
    }
}

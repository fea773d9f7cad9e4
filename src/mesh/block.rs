//! The exact face test (`intersect.rs`) on a leaf's faces four at a time: every step the
//! test of one face takes in the common case, the same operations in the same order, in
//! four `f64` lanes (one AVX2 instruction each where the mesh's kernel is AVX2's, two SSE2
//! ones otherwise: `simd::Lanes`). A lane the certain arithmetic cannot settle takes the
//! test of one face, which decides it as it always did; so each lane's answer is the
//! one-face test's, bit for bit (Rust never fuses a multiply and an add unless asked to).

use glam::DVec3;

use super::intersect::{Crossing, EDGE_ERROR, Sheared};
use crate::math::gamma;
use crate::simd::Lanes;

/// Faces a block holds: the mesh's leaves hold at most this many (`MESH_SHAPE`).
pub(super) const LANES: usize = 4;

/// `f` of each of three (`[T; 3]::map`, which the compiler leaves out of line here).
#[inline(always)]
fn each<T, U>([a, b, c]: [T; 3], mut f: impl FnMut(T) -> U) -> [U; 3] {
    [f(a), f(b), f(c)]
}

/// Corner `k` of each of `faces` (at least one), less the ray's origin, as lanes of the
/// ray's permuted axes (a block of fewer than four faces repeats its last): the axes picked
/// as the corners are loaded.
#[inline(always)]
fn offsets<L: Lanes>(
    token: L::Token,
    ray: &Sheared,
    origin: &[L; 3],
    vertices: &[DVec3],
    faces: &[[u32; 3]],
    k: usize,
) -> [L; 3] {
    let last = faces.len() - 1;
    let corner = |i: usize| &vertices[faces[i.min(last)][k] as usize];
    let [x, y, z] = L::transpose(token, [corner(0), corner(1), corner(2), corner(3)]);
    // The lanes in the ray's order of axes (`Sheared::axes`, a cyclic shift).
    let [a, b, c] = match ray.axes[2] {
        0 => [y, z, x],
        1 => [z, x, y],
        _ => [x, y, z],
    };
    [a - origin[0], b - origin[1], c - origin[2]]
}

impl Sheared {
    /// What [`Sheared::test`] answers for each of `faces` (one to [`LANES`] of them, as
    /// indices into `vertices`), computed in lanes of `L`: `found(i, crossing)` for each
    /// face `i` crossed, in their order, until it returns `true` (and then `true`).
    ///
    /// The corners are gathered into lanes (a block of fewer faces repeats its last one,
    /// and ignores it), their offsets from the origin permuted as whole lanes. Signs mixed
    /// beyond their bounds rule a lane out, as in the one-face test; a lane left in doubt
    /// there takes that test whole (the careful path); every other lane is crossed, and
    /// its `t`, its determinant and the drop before `t_min` are computed in lanes too, its
    /// error bound (for the few crossings that survive) by the one-face test's last step.
    #[inline(always)]
    pub(super) fn test_block<L: Lanes>(
        &self,
        token: L::Token,
        vertices: &[DVec3],
        faces: &[[u32; 3]],
        t_min: f64,
        mut found: impl FnMut(usize, Crossing) -> bool,
    ) -> bool {
        let n = faces.len().min(LANES);
        if n == 0 {
            return false;
        }
        // Corner `k`'s offsets `p - o`, lane by lane, axis by axis in the ray's frame.
        let o = self.origin.as_ref();
        let [ix, iy, iz] = self.axes;
        let origin = [
            L::splat(token, o[ix]),
            L::splat(token, o[iy]),
            L::splat(token, o[iz]),
        ];
        let a = [
            offsets::<L>(token, self, &origin, vertices, faces, 0),
            offsets::<L>(token, self, &origin, vertices, faces, 1),
            offsets::<L>(token, self, &origin, vertices, faces, 2),
        ];
        let s = self.shear;
        let (sx, sy, sz) = (
            L::splat(token, s.x),
            L::splat(token, s.y),
            L::splat(token, s.z),
        );
        let x = each(a, |[ax, _, az]| ax + sx * az);
        let y = each(a, |[_, ay, az]| ay + sy * az);
        let edge = |j: usize, k: usize| x[j] * y[k] - y[j] * x[k];
        let e = [edge(1, 2), edge(2, 0), edge(0, 1)];
        let m = each(a, |[ax, ay, az]| ax.abs() + ay.abs() + az.abs());
        let error = L::splat(token, EDGE_ERROR);
        let b = [
            error * m[1] * m[2],
            error * m[2] * m[0],
            error * m[0] * m[1],
        ];
        let positive = e[0].gt(b[0]) | e[1].gt(b[1]) | e[2].gt(b[2]);
        let negative = e[0].lt(-b[0]) | e[1].lt(-b[1]) | e[2].lt(-b[2]);
        // Mixed signs beyond their bounds: the common way out, for all four at once.
        let live = ((1 << n) - 1) & !L::bits(positive & negative);
        if live == 0 {
            return false;
        }
        let oriented = each(e, L::abs);
        let certain = L::bits(oriented[0].gt(b[0]) & oriented[1].gt(b[1]) & oriented[2].gt(b[2]));
        // Certain and not mixed: three signs alike and none zero, so the oriented values
        // (`e` times the orientation's sign, exactly) are the absolute ones.
        let [e0, e1, e2] = oriented;
        let det = e0 + e1 + e2;
        let t = (e0 * a[0][2] + e1 * a[1][2] + e2 * a[2][2]) * sz / det;
        let infinity = L::splat(token, f64::INFINITY);
        let finite = L::bits(t.abs().lt(infinity) & det.lt(infinity));
        let z_scaled = a[0][2].abs().max(a[1][2].abs()).max(a[2][2].abs()) * sz.abs();
        // The one-face test's drop before `t_min`, where the direction is not scaled.
        let behind = if self.scale == 1.0 {
            L::bits((t - L::splat(token, 2.0 * gamma(4)) * z_scaled).lt(L::splat(token, t_min)))
        } else {
            0
        };
        let crossed = live & certain & finite & !behind;
        let careful = live & !certain;
        let mut left = crossed | careful;
        if left == 0 {
            return false;
        }
        let (x, y) = (each(x, L::to_array), each(y, L::to_array));
        let a = each(a, |c| each(c, L::to_array));
        let ([e0, e1, e2], det, t, z_scaled) = (
            each(oriented, L::to_array),
            det.to_array(),
            t.to_array(),
            z_scaled.to_array(),
        );
        while left != 0 {
            let i = left.trailing_zeros() as usize;
            left &= left - 1;
            let crossing = if careful & (1 << i) != 0 {
                self.test_one(vertices, faces[i], t_min)
            } else {
                let corner = |k: usize| {
                    (
                        x[k][i],
                        y[k][i],
                        DVec3::new(a[k][0][i], a[k][1][i], a[k][2][i]),
                    )
                };
                self.finish(
                    [corner(0), corner(1), corner(2)],
                    DVec3::new(e0[i], e1[i], e2[i]),
                    det[i],
                    t[i],
                    z_scaled[i],
                )
            };
            if let Some(crossing) = crossing
                && found(i, crossing)
            {
                return true;
            }
        }
        false
    }

    /// The one-face test of a lane the block leaves in doubt: rare, kept out of the lanes'
    /// code.
    #[cold]
    #[inline(never)]
    fn test_one(&self, vertices: &[DVec3], face: [u32; 3], t_min: f64) -> Option<Crossing> {
        self.test(&face.map(|i| vertices[i as usize]), t_min)
    }
}

#[cfg(test)]
mod tests {
    use super::{LANES, Lanes};
    use crate::Ray;
    use crate::math::Stream;
    use crate::mesh::intersect::Sheared;
    use glam::DVec3;

    /// Every block of `faces` (each length from one to four, from each start) through lanes
    /// of `L`, answer for answer and bit for bit against the one-face test: which faces are
    /// crossed, and each crossing's `t`, error bound, edge functions and determinant.
    fn agree<L: Lanes>(
        token: L::Token,
        vertices: &[DVec3],
        faces: &[[u32; 3]],
        ray: &Ray,
        t_min: f64,
    ) -> usize {
        let Some(sheared) = Sheared::new(ray) else {
            return 0;
        };
        let mut crossed = 0;
        for start in 0..faces.len() {
            for n in 1..=LANES.min(faces.len() - start) {
                let block = &faces[start..start + n];
                let mut lanes = [None; LANES];
                let stopped = sheared.test_block::<L>(token, vertices, block, t_min, |i, c| {
                    assert!(lanes[i].is_none(), "lane {i} offered twice");
                    lanes[i] = Some(c.bits());
                    false
                });
                assert!(!stopped);
                for (i, face) in block.iter().enumerate() {
                    let one = sheared.test(&face.map(|v| vertices[v as usize]), t_min);
                    assert_eq!(
                        lanes[i],
                        one.map(|c| c.bits()),
                        "{ray:?} face {face:?} t_min {t_min}"
                    );
                    crossed += usize::from(one.is_some());
                }
                assert!(lanes[n..].iter().all(Option::is_none));
            }
        }
        crossed
    }

    /// A fan of thin faces about a shared vertex and a bumpy grid, moved to offsets up to
    /// 1e9 and scaled from 1e-6 to 1e6 (and about 1e150 and 1e-150), and rays that decide
    /// them every way: through their shared vertices and edges (signs left in doubt: the
    /// careful path), from far away, grazing, along directions whose length is scaled
    /// (1e-300 and 1e300), and starting on the faces (the drop before `t_min`).
    fn each_case(mut check: impl FnMut(&[DVec3], &[[u32; 3]], &Ray, f64) -> usize) {
        let mut stream = Stream(0x5eed_b10c);
        let mut crossed = 0;
        for case in 0..120 {
            // Near f64's ends too, where the edge functions' products overflow or underflow.
            let scale = match case % 10 {
                8 => stream.power(140, 160),
                9 => stream.power(-160, -140),
                _ => stream.power(-6, 6),
            };
            let offset = stream.vector() * stream.power(0, 9);
            let mut vertices = vec![DVec3::ZERO];
            let mut faces = Vec::new();
            // A fan of slivers meeting at the origin.
            for i in 0..6u32 {
                let angle = f64::from(i) * 0.02;
                vertices.push(DVec3::new(angle.cos(), angle.sin(), 0.1 * f64::from(i % 2)));
            }
            for i in 1..6u32 {
                faces.push([0, i, i + 1]);
            }
            // A bumpy grid of 3 x 3 squares, two faces each.
            let base = vertices.len() as u32;
            for j in 0..4u32 {
                for i in 0..4u32 {
                    let bump = 0.3 * stream.uniform() * f64::from((i + j) % 2);
                    vertices.push(DVec3::new(f64::from(i), f64::from(j), bump - 2.0));
                }
            }
            for j in 0..3u32 {
                for i in 0..3u32 {
                    let v = base + j * 4 + i;
                    faces.push([v, v + 1, v + 5]);
                    faces.push([v, v + 5, v + 4]);
                }
            }
            let vertices: Vec<DVec3> = vertices.iter().map(|v| *v * scale + offset).collect();
            for _ in 0..12 {
                // Aimed at a vertex, at an edge's midpoint, or at a point inside a face.
                let face = stream.pick(&faces);
                let [p, q, r] = face.map(|v| vertices[v as usize]);
                let target = match case % 3 {
                    0 => p,
                    1 => (p + q) * 0.5,
                    _ => (p + q + r) / 3.0,
                };
                let direction = match (case / 3) % 4 {
                    0 => stream.unit(),
                    // Grazing the plane z = 0 of the fan.
                    1 => DVec3::new(stream.range(-1.0, 1.0), stream.range(-1.0, 1.0), 1e-9),
                    2 => stream.unit() * 1e-300,
                    _ => stream.unit() * 1e300,
                };
                let length = direction.length();
                let distance = stream.power(-3, 8) * scale;
                let origin = target - direction / length * distance;
                let ray = Ray::new(origin, direction);
                for t_min in [0.0, f64::NEG_INFINITY, distance / length, -1.0] {
                    crossed += check(&vertices, &faces, &ray, t_min);
                }
                // From a face's corner and from inside it: what a spawned ray starts on.
                let ray = Ray::new(target, stream.unit());
                crossed += check(&vertices, &faces, &ray, 0.0);
            }
        }
        // (That the cases cross faces at all, through every kind of lane.)
        assert!(crossed > 1000, "{crossed}");
    }

    #[test]
    fn portable_lanes_answer_as_the_one_face_test() {
        each_case(|vertices, faces, ray, t_min| {
            agree::<wide::f64x4>((), vertices, faces, ray, t_min)
        });
    }

    /// The same for AVX2's lanes, where the CPU has them (every x86-64 CI machine of the
    /// last decade; elsewhere this test checks nothing and says so).
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn avx_lanes_answer_as_the_one_face_test() {
        let Some(avx) = crate::simd::Avx2::detect() else {
            eprintln!("no AVX2 here: its lanes untested");
            return;
        };
        each_case(|vertices, faces, ray, t_min| {
            agree::<crate::simd::Avx4>(avx, vertices, faces, ray, t_min)
        });
    }
}

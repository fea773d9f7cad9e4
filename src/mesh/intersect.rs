//! The watertight ray/triangle test (Woop, Benthin and Wald 2013; pbrt-v4's
//! `IntersectTriangle`), with the signs of its edge functions settled where rounding leaves
//! them in doubt.

use glam::{DVec3, Vec3Swizzles};

use crate::Ray;
use crate::math::{Dd, UNIT_ROUNDOFF, direction_scale, gamma, l1};

/// A ray in the frame the test works in, set up once per ray: the axes permuted so that
/// `z` is the direction's largest component (a cyclic permutation, which keeps
/// orientations), and the shear that takes the direction to `(0, 0, 1)`. The direction is
/// first scaled by a power of two where its length is extreme ([`direction_scale`]:
/// exactly, so every sign is the same), so that `1 / d_z` is finite for a direction of any
/// length; `t` is scaled back.
pub(super) struct Sheared {
    pub(super) origin: DVec3,
    /// The scaled direction.
    direction: DVec3,
    /// The axes in the permuted frame's order: `axes[2]` is the direction's largest
    /// component.
    pub(super) axes: [usize; 3],
    /// `-d_x / d_z` and `-d_y / d_z` in the permuted frame, and `1 / d_z`.
    pub(super) shear: DVec3,
    /// What the direction was scaled by: `t` along the scaled direction is `t * scale`
    /// along the ray's own.
    pub(super) scale: f64,
}

/// A face the ray crosses: `t`, a bound on its error, and what gives the barycentric
/// weights of its three corners.
#[derive(Clone, Copy, Debug)]
pub(super) struct Crossing {
    pub(super) t: f64,
    /// The exact crossing lies within `t ± t_error` ([`t_error`]); infinite where rounding
    /// leaves even its side of the origin unknown.
    pub(super) t_error: f64,
    /// The edge functions, oriented (each at least zero), and their sum (positive).
    edges: DVec3,
    det: f64,
}

impl Crossing {
    /// Every field's bits, for tests that compare two ways of computing a crossing.
    #[cfg(test)]
    pub(super) fn bits(&self) -> [u64; 6] {
        [
            self.t,
            self.t_error,
            self.edges.x,
            self.edges.y,
            self.edges.z,
            self.det,
        ]
        .map(f64::to_bits)
    }

    /// The barycentric weights of the face's three corners: divided out only for the
    /// crossing a query keeps (a shadow ray needs none).
    #[inline]
    pub(super) fn barycentric(&self) -> DVec3 {
        self.edges / self.det
    }
}

/// Bounds on an edge function's error. Each sheared coordinate `x = a_x + s_x a_z` (with
/// `a = p - o`, and `s_x = -d_x / d_z`, `|s_x| <= 1`) carries five roundings (`a`'s two
/// coordinates, `s_x`, the product and the sum), so errs by at most `gamma(5) m` for
/// `m = |a|_1`; the edge function `x_1 y_2 - y_1 x_2` inherits
/// `gamma(5) (m_1 r_2 + m_2 r_1) + 2 gamma(5)^2 m_1 m_2` from them (`r = |x| + |y|`) and
/// adds `gamma(2) r_1 r_2` of its own. Doubled, for the rounding of the bound itself: the
/// tight bound ([`tight_bound`]). Since `r <= m` to within rounding, the loose bound
/// `EDGE_ERROR m_1 m_2` holds too and costs less: the test tries it first. The tight one
/// matters for rays from far away (`m` much larger than the face), where the loose one
/// would leave every sign in doubt.
pub(super) const EDGE_ERROR: f64 = 2.0 * (4.0 * gamma(5) + 2.0 * gamma(2));

/// The same for the determinant as double-double arithmetic computes it ([`settle`]),
/// `(p - o) . ((q - p) x d)`, over `|p - o|_1 |q - p|_1 |d|_1`: the differences are exact,
/// and every operation after them errs by at most `4 u^2` of the magnitudes it combines
/// (Hida, Li and Bailey 2001), in chains of fewer than ten: `256 u^2` is ample.
const EDGE_ERROR_DD: f64 = 256.0 * UNIT_ROUNDOFF * UNIT_ROUNDOFF;

/// Corners farther than this from the ray's origin (in `|.|_1`) are not decided: the
/// products of their coordinates could overflow.
const LARGEST: f64 = 1e150;

impl Sheared {
    /// `None` for a direction that cannot be traced (zero, infinite or NaN: its shear is
    /// not finite). An origin that is not finite is left to the test, which crosses no face
    /// from it (its offsets are NaN or beyond `LARGEST`), and to the walks, which check the
    /// whole ray before their first box.
    #[inline(always)]
    pub(super) fn new(ray: &Ray) -> Option<Self> {
        let scale = direction_scale(ray.direction);
        let direction = ray.direction * scale;
        let d = direction.abs();
        let kz = if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        };
        let p = permute(direction, kz);
        let shear = DVec3::new(-p.x / p.z, -p.y / p.z, 1.0 / p.z);
        shear.is_finite().then_some(Self {
            origin: ray.origin,
            direction,
            axes: [[1, 2, 0], [2, 0, 1], [0, 1, 2]][kz],
            shear,
            scale,
        })
    }

    /// Whether the ray crosses the triangle `p`, and where. The three edge functions are
    /// computed from the corners alone, each exactly the negative of the same edge's in a
    /// face that shares it (the products commute, and rounding is symmetric): a ray through
    /// a shared edge is inside one face or the other, or on the edge and inside both.
    ///
    /// A value within its rounding bound of zero has its sign settled in double-double
    /// arithmetic ([`settle`]); the rare one that even that leaves in doubt keeps its `f64`
    /// sign (or zero), which its neighbour's value mirrors. Every sign decided either way is the
    /// exact one or the mirrored one, so faces sharing an edge agree on which side the ray
    /// passes.
    ///
    /// A crossing whose `t` minus its error bound is below `t_min` may be dropped (it
    /// does not count: see `TriangleMesh::cross`).
    #[inline(always)]
    pub(super) fn test(&self, p: &[DVec3; 3], t_min: f64) -> Option<Crossing> {
        let s = self.shear;
        let a0 = permute(p[0] - self.origin, self.axes[2]);
        let a1 = permute(p[1] - self.origin, self.axes[2]);
        let a2 = permute(p[2] - self.origin, self.axes[2]);
        let (x0, y0) = (a0.x + s.x * a0.z, a0.y + s.y * a0.z);
        let (x1, y1) = (a1.x + s.x * a1.z, a1.y + s.y * a1.z);
        let (x2, y2) = (a2.x + s.x * a2.z, a2.y + s.y * a2.z);
        let e0 = x1 * y2 - y1 * x2;
        let e1 = x2 * y0 - y2 * x0;
        let e2 = x0 * y1 - y0 * x1;
        // Mixed signs, each beyond its bound: a miss (the common case), decided without
        // the bounds where the signs are not mixed. (A mesh's walk takes these steps for a
        // leaf's faces at once, in lanes: `block.rs`. Tried: faces behind `t_min` dropped
        // first, no faster; a first pass in `f32` on copies of the corners, slower and
        // larger.)
        let (m0, m1, m2) = (l1(a0), l1(a1), l1(a2));
        let (b0, b1, b2) = (
            EDGE_ERROR * m1 * m2,
            EDGE_ERROR * m2 * m0,
            EDGE_ERROR * m0 * m1,
        );
        let positive = (e0 > b0) | (e1 > b1) | (e2 > b2);
        let negative = (e0 < -b0) | (e1 < -b1) | (e2 < -b2);
        if positive & negative {
            return None;
        }
        let certain = (e0.abs() > b0) & (e1.abs() > b1) & (e2.abs() > b2);
        let (s0, s1, s2) = if certain {
            (sign(e0), sign(e1), sign(e2))
        } else {
            // Coordinates so large that the products may overflow (a ray from past about
            // 1e150): no decision.
            let m = m0.max(m1).max(m2);
            if m.is_nan() || m >= LARGEST {
                return None;
            }
            let (r0, r1, r2) = (
                x0.abs() + y0.abs(),
                x1.abs() + y1.abs(),
                x2.abs() + y2.abs(),
            );
            let settled = |e: f64, b: f64, tight: f64, i: usize, j: usize| {
                if e.abs() > b || e.abs() > tight {
                    sign(e)
                } else {
                    settle(self, p[i], p[j]).unwrap_or(sign(e))
                }
            };
            (
                settled(e0, b0, tight_bound(m1, r1, m2, r2), 1, 2),
                settled(e1, b1, tight_bound(m2, r2, m0, r0), 2, 0),
                settled(e2, b2, tight_bound(m0, r0, m1, r1), 0, 1),
            )
        };
        let positive = (s0 > 0.0) | (s1 > 0.0) | (s2 > 0.0);
        let negative = (s0 < 0.0) | (s1 < 0.0) | (s2 < 0.0);
        if positive == negative {
            // Mixed signs, or all zero (a ray in the plane of the face).
            return None;
        }
        // The values with the face's orientation; zero on the edge, and where the sign was
        // settled against the computed value (whose size is then below its rounding).
        let o = if positive { 1.0 } else { -1.0 };
        let orient = |e: f64, s: f64| if s * o > 0.0 { (e * o).max(0.0) } else { 0.0 };
        let (e0, e1, e2) = (orient(e0, s0), orient(e1, s1), orient(e2, s2));
        let det = e0 + e1 + e2;
        let t = (e0 * a0.z + e1 * a1.z + e2 * a2.z) * s.z / det;
        // (The weights `e_i / det` lie in [0, 1] where `det` is finite.)
        if !(t.abs() < f64::INFINITY && det < f64::INFINITY) {
            return None;
        }
        let edges = DVec3::new(e0, e1, e2);
        let z = a0.z.abs().max(a1.z.abs()).max(a2.z.abs());
        let z_scaled = z * s.z.abs();
        // A crossing that cannot lie beyond `t_min` by more than its error, whatever the
        // edge functions' error, is dropped before that error is computed (the face a
        // bounce or shadow ray leaves, crossed at about zero): [`t_error`] is at least
        // `4 gamma(4) z_scaled` (its first term, with `E / margin >= 1`), so half that, as
        // computed, is below it as computed, and `t` minus it below `t` minus the error.
        if self.scale == 1.0 && t - 2.0 * gamma(4) * z_scaled < t_min {
            return None;
        }
        self.finish(
            [(x0, y0, a0), (x1, y1, a1), (x2, y2, a2)],
            edges,
            det,
            t,
            z_scaled,
        )
    }

    /// The test's last step, once a face is crossed and not dropped before `t_min`: the
    /// bound on `t`'s error, and `t` along the ray's own direction. `corners` are the
    /// sheared `x`, `y` and the permuted offset from the origin of each corner, `edges` the
    /// oriented edge functions and `det` their sum, `z_scaled` the corners' largest depth
    /// times `|1 / d_z|`. (Shared by the test of one face and of four.)
    #[inline(always)]
    pub(super) fn finish(
        &self,
        corners: [(f64, f64, DVec3); 3],
        edges: DVec3,
        det: f64,
        t: f64,
        z_scaled: f64,
    ) -> Option<Crossing> {
        let s = self.shear;
        // The edge functions' error, from what enters each corner's sheared coordinates,
        // `X = |a_x| + |s_x a_z|` and `Y = |a_y| + |s_y a_z|`: each coordinate is within
        // `gamma(4)` of them of its exact value (the difference's rounding, `s`'s, the
        // product's and the sum's), so `x_1 y_2 - y_1 x_2` is within
        // `gamma(4) (|x_1| Y_2 + |y_2| X_1 + |y_1| X_2 + |x_2| Y_1)
        //   + 2 gamma(4)^2 (X_1 Y_2 + X_2 Y_1) + gamma(2) (|x_1 y_2| + |y_1 x_2|)`;
        // doubled, for the rounding of the bound itself. Sharper than the bounds the signs
        // were decided by: it keeps `t` known for a ray from far away (small `x`, `y`,
        // large `X`, `Y`) and for one grazing the face (a tiny shear), and it covers an
        // edge function set to zero against its computed sign (the exact value is then
        // within it of zero).
        let size = |a: DVec3| (a.x.abs() + (s.x * a.z).abs(), a.y.abs() + (s.y * a.z).abs());
        let corners = corners.map(|(x, y, a)| (x, y, size(a)));
        let edge = |(xi, yi, (bxi, byi)): (f64, f64, (f64, f64)),
                    (xj, yj, (bxj, byj)): (f64, f64, (f64, f64))| {
            let g = gamma(4);
            g * (xi.abs() * byj + yj.abs() * bxi + yi.abs() * bxj + xj.abs() * byi)
                + 2.0 * g * g * (bxi * byj + bxj * byi)
                + gamma(2) * ((xi * yj).abs() + (yi * xj).abs())
        };
        let edge_error = 2.0
            * (edge(corners[1], corners[2])
                + edge(corners[2], corners[0])
                + edge(corners[0], corners[1]));
        let t_error = t_error(t, det, edge_error, z_scaled, s.z.abs());
        if self.scale == 1.0 {
            return Some(Crossing {
                t,
                t_error,
                edges,
                det,
            });
        }
        // Back to the ray's own direction: exact, but for a `t` that under- or overflows
        // (and then errs by at most the smallest normal number, with underflow flushed to
        // zero or not).
        let t = t * self.scale;
        (t.abs() < f64::INFINITY).then_some(Crossing {
            t,
            t_error: t_error * self.scale + f64::MIN_POSITIVE,
            edges,
            det,
        })
    }
}

/// The exact sign (`+-1`) of the edge function of the corners `p` and `q`, or `None` where
/// double-double arithmetic cannot settle it either. The edge function is `1 / d_z` times
/// `det(p - o, q - o, d)` (the shear subtracts multiples of `d` from `p - o` and `q - o`,
/// which leaves their determinant with `d` unchanged), and that determinant is
/// `(p - o) . ((q - p) x d)`: one factor as large as the ray's distance, the other as
/// small as the edge, so that the cancellation a ray from far away brings stays within
/// double-double's reach (the form `(p - o) x (q - o)` would square the distance).
#[cold]
#[inline(never)]
fn settle(ray: &Sheared, p: DVec3, q: DVec3) -> Option<f64> {
    let (o, d) = (ray.origin, ray.direction);
    let a = [Dd::diff(p.x, o.x), Dd::diff(p.y, o.y), Dd::diff(p.z, o.z)];
    let e = [Dd::diff(q.x, p.x), Dd::diff(q.y, p.y), Dd::diff(q.z, p.z)];
    // (q - p) x d, then its dot product with p - o.
    let cross = |i: usize, j: usize| e[i].mul_f64(d[j]).add(e[j].mul_f64(d[i]).neg());
    let c = [cross(1, 2), cross(2, 0), cross(0, 1)];
    let value = a[0].mul(c[0]).add(a[1].mul(c[1])).add(a[2].mul(c[2])).hi;
    let size = |x: [Dd; 3]| x[0].hi.abs() + x[1].hi.abs() + x[2].hi.abs();
    let bound = EDGE_ERROR_DD * size(a) * size(e) * d.abs().element_sum();
    let d_z = d[ray.axes[2]];
    (value.abs() > bound).then(|| {
        if (value > 0.0) == (d_z > 0.0) {
            1.0
        } else {
            -1.0
        }
    })
}

/// A bound on the error of the computed `t = (e_0 z_0 + e_1 z_1 + e_2 z_2) s_z / E`, with
/// `E = e_0 + e_1 + e_2` (`e_i >= 0`, oriented), each `e_i` off by at most its rounding
/// bound (`edge_error` is their sum, `delta`), `z_i` the corners' depths (one rounding
/// each) and `s_z = 1 / d_z` (one more). The numerator errs by at most
/// `Z (delta + gamma(4) E)` (`Z = max |z_i|`), the denominator by `delta + gamma(2) E`, and
/// since `|sum e_i z_i| <= Z E`, the quotient by at most
/// `2 Z |s_z| (delta + gamma(4) E) / (E - delta - gamma(2) E)`, to which the product, the
/// division and `s_z` add `gamma(3) |t|`. Doubled, for second-order terms and the rounding
/// of the bound itself (as pbrt-v4 triples its own, `Triangle::Intersect`). Infinite where
/// the edge functions' error reaches their sum: then not even the side of the origin the
/// crossing is on is known.
///
/// Underflow adds an absolute error to each result, of at most `eta`, the smallest normal
/// number (which covers gradual underflow and a CPU flushing it to zero alike): to the
/// depths (the corners' `z`, whose weights sum to `E`), the three products and two sums
/// of the numerator, the product with `s_z` and the quotient, at most
/// `eta (|s_z| + (5 |s_z| + 1) / E + 1)`, doubled as above (and divided by the margin,
/// below `E`, rather than by `E`: one division for the whole bound); and `Z |s_z|` itself
/// may have underflowed by `eta`. This is what keeps a ray from a wall at `x = 0`, whose
/// depths are all about the smallest normal number, from finding the wall it leaves at a
/// `t` of zero with no error.
#[inline(always)]
fn t_error(t: f64, det: f64, edge_error: f64, z_scaled: f64, s_z: f64) -> f64 {
    let eta = f64::MIN_POSITIVE;
    let margin = det - edge_error - gamma(2) * det;
    if margin > 0.0 {
        let over_margin =
            2.0 * (z_scaled + eta) * (edge_error + gamma(4) * det) + eta * (5.0 * s_z + 1.0);
        2.0 * (over_margin / margin + gamma(3) * t.abs() + eta * (s_z + 1.0))
    } else {
        f64::INFINITY
    }
}

/// The tight bound on the error of the edge function of two corners with `|p - o|_1` of
/// `m` and sheared `|x| + |y|` of `r` (see [`EDGE_ERROR`]).
#[inline(always)]
fn tight_bound(m1: f64, r1: f64, m2: f64, r2: f64) -> f64 {
    let g = gamma(5);
    2.0 * (g * (m1 * r2 + m2 * r1) + 2.0 * g * g * m1 * m2 + gamma(2) * r1 * r2)
}

/// `+-1` by the sign of `e`, 0 for zero (and NaN).
#[inline(always)]
fn sign(e: f64) -> f64 {
    if e > 0.0 {
        1.0
    } else if e < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `v` with its axes permuted cyclically so that axis `kz` comes last (`Sheared::axes`' order).
#[inline(always)]
fn permute(v: DVec3, kz: usize) -> DVec3 {
    match kz {
        0 => v.yzx(),
        1 => v.zxy(),
        _ => v,
    }
}

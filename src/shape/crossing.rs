//! The exact-crossing machinery of a [`Plane`]: where the exact crossing of a ray can lie
//! given the rounding of the computed one ([`CrossingRegion`]), the quick clear decision
//! that settles most crossings without it, and the refined (double-double) crossing for the
//! few that need it. The flat shapes ([`Quad`](crate::Quad) and its interiors) decide by it.

use glam::{DVec2, DVec3};

use super::plane::{Plane, PlaneHit};
use crate::math::{Dd, UNIT_ROUNDOFF, gamma, l1, ordinary_length, power_of_two_scale, sqrt};
use crate::{Interval, Ray};

/// What [`Plane::crossing`] found: a crossing clearly inside a shape that fills its
/// rectangle (a hit, with no region computed), one the quick test left undecided (for
/// [`Plane::settle_pending`], out of line), or a direction to rescale.
pub(crate) enum Crossing {
    Inside(PlaneHit),
    Pending(Pending),
    /// A direction of extreme length (or a ray that cannot be traced): to be decided again
    /// along the same ray with the direction scaled to an ordinary length
    /// ([`Ray::rescaled`]), where no bound below over- or underflows.
    Rescale,
}

/// A crossing the quick clear decision left undecided, with what [`Plane::crossing`]
/// computed for it: `q - o`, the point `p`, `c = |n.d|` and `d1 = |d|_1`.
#[derive(Clone, Copy)]
pub(crate) struct Pending {
    hit: PlaneHit,
    q_minus_o: DVec3,
    p: DVec3,
    c: f64,
    d1: f64,
}

/// What [`Plane::settle_pending`] decided: a hit clearly inside a filled shape, or the
/// crossing and its region, for the shape to decide
/// ([`Interior::meets`](crate::Interior::meets)).
pub(crate) enum Decided {
    Inside(PlaneHit),
    Region(PlaneHit, CrossingRegion),
}

/// A decision [`Plane::crossing`] reaches without the reach's division.
enum Clearly {
    Outside,
    Inside,
}

/// What a crossing's error bounds are made of ([`Plane::crossing_region`]), computed once
/// for the clear decision and the region both: the reach's numerator before its `t` and
/// tolerance terms (`gamma(4) |q - o|_1 + gamma(3) |t| |d|_1 + e (|p|_1 + across)`), the
/// error across the ray before the frame's, the tolerance and the drift, the slack (the
/// height gained per unit of `t`, less its error), `c = |n.d|` and `|d|_1`. The change of
/// `(alpha, beta)` per unit of `t` (the region's `along`, two dot products) is left to the
/// region, which most crossings never need: the clear decision bounds it by `|d|_1` times
/// the coordinate scale.
#[derive(Clone, Copy)]
struct Parts {
    numerator: f64,
    across: f64,
    slack: f64,
    c: f64,
    d1: f64,
}

/// Where the exact crossing of a ray with a plane can lie, in `(alpha, beta)`, given the
/// rounding of the computed one ([`Plane::crossing_region`]): within `radius` (per
/// coordinate) of a point `center + s * along` with `|s| <= reach`.
///
/// The rounding of a crossing is of two kinds. Along the ray, `t` is uncertain, and as the
/// ray grazes the plane that uncertainty grows without bound: `reach` (in units of `t`)
/// carries it, and `along` (how `alpha` and `beta` move per unit of `t`) points it along
/// the ray's shadow on the plane. Every point of that segment is still within a tiny
/// world-space distance of the ray itself. Across the ray, the crossing is known to within
/// a few ulps of the magnitudes involved, whatever the angle: `radius`. A shape that meets
/// the region is therefore met by the ray to within that world-space distance, and a ray
/// that crosses the plane inside a shape always finds the shape meeting its region:
/// shapes that share an edge leave no crack, and nothing beside a shape is hit.
///
/// Both also hold the plane's [`tolerance`](Plane::tolerance), the world-space width by
/// which shapes widen to close the gaps that separately rounded corners leave: across, and
/// along the ray as far as it takes the ray to rise by it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossingRegion {
    /// The computed crossing.
    pub center: DVec2,
    /// The change of `(alpha, beta)` per unit of `t` along the ray; infinite where it is
    /// beyond f64's range.
    pub along: DVec2,
    /// How far along the ray, in units of `t`, the exact crossing can be; may be infinite.
    pub reach: f64,
    /// How far across, in `alpha` and `beta`.
    pub radius: DVec2,
}

impl CrossingRegion {
    /// The point `s` along the segment: `center + s * along`.
    #[inline]
    #[must_use]
    pub fn at(&self, s: f64) -> DVec2 {
        self.center + s * self.along
    }

    /// `reach * |along|` per coordinate: how far the segment extends from its centre
    /// (0 where `along` is 0, even for an infinite reach).
    #[inline]
    #[must_use]
    pub fn half_length(&self) -> DVec2 {
        let scaled = |w: f64| if w == 0.0 { 0.0 } else { self.reach * w.abs() };
        DVec2::new(scaled(self.along.x), scaled(self.along.y))
    }
}

impl Plane {
    /// Where the exact crossing of `ray` with the plane can be, given that `hit` (from
    /// [`Plane::intersect`]) was computed in `f64`: see [`CrossingRegion`]. Shapes decide
    /// whether they are hit by whether they meet it
    /// ([`Interior::meets`](crate::Interior::meets)).
    ///
    /// Derivation (first order in the unit roundoff `u_r`; `|.|_1` bounds the Euclidean
    /// norm from above). With `a = |q - o|_1`, `b = |t| |d|_1`, `P = |p|_1` for the computed
    /// `p = t d - (q - o)`, `c = |n.d|`, and `e` the relative error of the computed frame
    /// (`v x w` and `w x u` carry `2 gamma(2) (1 + 1/s) + 2 u_r`, `s` the sine between `u`
    /// and `v`; the computed normal is tilted by less):
    /// - `p` is within `gamma(2) (a + b)` of the exact point of the ray at this `t`, in any
    ///   direction (three roundings per coordinate), and `alpha = p.(v x w)` adds the dot
    ///   product's `gamma(3) P`. These do not depend on the angle of the ray: `radius`.
    /// - The frame's error is a fixed linear map, applied alike to the centre and to `along`:
    ///   it moves the whole segment, by at most `e (|u|_1 + |v|_1)` where it matters, at
    ///   points of the shape (every built-in interior lies within `|alpha u + beta v|_1 <=
    ///   |u|_1 + |v|_1`). That joins `radius` too.
    /// - `t = n.(q - o) / n.d` errs by `gamma(4) a` in the numerator and `gamma(3) |d|_1` in
    ///   the denominator, and the tilt of the computed normal puts the exact crossing up to
    ///   `e (P + |t* - t| |d|_1)` above the plane the computed `t` belongs to. Solved for
    ///   `|t* - t|`: `(gamma(4) a + gamma(3) b + e P) / (c - (gamma(3) + e) |d|_1) + gamma(2) |t|`,
    ///   infinite when the ray is within that angle of parallel: `reach`, along the ray.
    /// - `along = (d.(v x w), d.(w x u))` rounds by `gamma(3) |d|_1` per coordinate: over
    ///   the reach, a sideways drift of `reach gamma(3) |d|_1`, which joins `radius`.
    ///
    /// The plane's [`tolerance`](Plane::tolerance) `T` joins `radius`, and `reach` as `T / c`
    /// (for slopes down to 2^-52): shapes meeting the region are then met by the ray to
    /// within `T` in world space, whether their neighbours' rounding left the gap between
    /// them in the plane or across it (coplanar tiles whose planes differ by a fraction of
    /// an ulp in height leave a gap of that height over the slope, for a grazing ray).
    ///
    /// ```
    /// use hitkit::{glam::DVec3, Interval, Plane, Ray};
    /// let plane = Plane::new(DVec3::splat(1e9), DVec3::X, DVec3::Y).unwrap();
    /// let ray = Ray::new(DVec3::new(1e9 + 0.5, 1e9 + 0.5, 1e9 + 1.0), DVec3::NEG_Z);
    /// let hit = plane.intersect(&ray, Interval::UNIVERSE).unwrap();
    /// let region = plane.crossing_region(&ray, &hit);
    /// assert!(region.radius.x > 0.0 && region.radius.x < 1e-5 && region.reach < 1e-5);
    /// // A grazing ray: far along, but not across.
    /// let grazing = Ray::new(DVec3::new(1e9 + 0.5, 1e9 + 0.5, 1e9 + 1e-6), DVec3::new(1.0, 0.0, -1e-6));
    /// let hit = plane.intersect(&grazing, Interval::UNIVERSE).unwrap();
    /// let region = plane.crossing_region(&grazing, &hit);
    /// assert!(region.reach > 1.0 && region.radius.y < 1e-5);
    /// ```
    #[must_use]
    pub fn crossing_region(&self, ray: &Ray, hit: &PlaneHit) -> CrossingRegion {
        let q_minus_o = self.q - ray.origin;
        let c = self.normal.dot(ray.direction).abs();
        self.region_of(ray, hit, q_minus_o, hit.t * ray.direction - q_minus_o, c)
    }

    /// [`Plane::intersect`] along a ray whose direction was [rescaled](Ray::rescaled).
    #[cold]
    #[inline(never)]
    pub(super) fn intersect_rescaled(
        &self,
        (scaled, scale): (Ray, f64),
        ray_t: Interval,
    ) -> Option<PlaneHit> {
        let mut hit = self.intersect_as::<false>(&scaled, ray_t.scaled(1.0 / scale))?;
        hit.t = Ray::t_from_rescaled(hit.t, scale, ray_t)?;
        Some(hit)
    }

    /// [`Plane::intersect`] and the first of [`Plane::crossing_region`]'s work, sharing
    /// `q - o`, the point `p` and `n.d`: what a quad computes for every plane it meets.
    /// With a `window` (the rectangle of `(alpha, beta)` holding the shape, and whether the
    /// shape fills it: see [`Interior::coordinate_bounds`](crate::Interior::coordinate_bounds)),
    /// crossings the quick test finds clearly outside it are rejected, and crossings clearly
    /// inside a filled one come back as [`Crossing::Inside`]; the rest come back
    /// [pending](Plane::settle_pending), with what was computed for them.
    #[inline(always)]
    pub(crate) fn crossing(
        &self,
        ray: &Ray,
        ray_t: Interval,
        window: Option<([DVec2; 2], bool)>,
    ) -> Option<Crossing> {
        let q_minus_o = self.q - ray.origin;
        let numerator = self.normal.dot(q_minus_o);
        let denom = self.normal.dot(ray.direction);
        if ray_t.min >= 0.0 && numerator * denom < 0.0 {
            return None;
        }
        let t = numerator / denom;
        let d1 = l1(ray.direction);
        // (Decided by `d1`, which the bounds need anyway. Tried: a test of the direction's
        // components on every call; slower on the quads scene.) An ordinary direction's
        // `n.d` is finite; an infinite or NaN `t` (a ray parallel to the plane, or nearly
        // so from far away) makes an infinite or NaN bound below, which decides nothing
        // quickly, and the pending decision turns it away (its coordinates are not finite).
        let ordinary = ordinary_length(d1);
        if !(ordinary && t >= ray_t.min) {
            return (!ordinary).then_some(Crossing::Rescale);
        }
        let c = denom.abs();
        let (m, slack) = self.quick_terms(q_minus_o, t, c, d1);
        if self.clearly_past(t, ray_t.max, m, slack) {
            return None;
        }
        // The same point as `intersect`'s `(o - q) + t d`: negating a difference is exact.
        let p = t * ray.direction - q_minus_o;
        let (alpha, beta) = (p.dot(self.to_alpha), p.dot(self.to_beta));
        let hit = PlaneHit { t, alpha, beta };
        // Most crossings a render tests are clearly outside the shape or inside it: decided
        // by bounds that need no more than `m` (see `Quick`), as the exact decision would.
        if let Some((window, filled)) = window {
            match self.clearly_quick(&hit, m, slack, d1, ray_t.min, window) {
                Some(Clearly::Outside) => return None,
                Some(Clearly::Inside) if filled => return Some(Crossing::Inside(hit)),
                _ => {}
            }
        }
        Some(Crossing::Pending(Pending {
            hit,
            q_minus_o,
            p,
            c,
            d1,
        }))
    }

    /// The rest of [`Plane::crossing`], for the few crossings its quick test leaves
    /// undecided: the exact error terms, the clear decision by them, clause 5's test, and
    /// the region. Called from a quad's out-of-line path, so that the common path stays
    /// small where it inlines.
    #[inline(always)]
    pub(crate) fn settle_pending(
        &self,
        ray: &Ray,
        ray_t: Interval,
        window: Option<([DVec2; 2], bool)>,
        pending: Pending,
    ) -> Option<Decided> {
        let Pending {
            hit,
            q_minus_o,
            p,
            c,
            d1,
        } = pending;
        let t = hit.t;
        let parts = self.parts(t, q_minus_o, p, c, d1);
        // Clearly outside first: clause 5's test (`beyond`) would turn none of them into a
        // hit.
        let clearly = window.and_then(|(window, filled)| {
            self.clearly(&parts, &hit, window)
                .filter(|c| matches!(c, Clearly::Outside) || filled)
        });
        if matches!(clearly, Some(Clearly::Outside)) || !beyond(&parts, t, ray_t.min) {
            return None;
        }
        if matches!(clearly, Some(Clearly::Inside)) {
            return Some(Decided::Inside(hit));
        }
        // (Tried: this test, without the division, before the coordinates and the clear
        // decision, so that crossings behind the closest hit so far skip them; slower on
        // the quads scene.)
        // (The region's own reach, grown as `Plane::region` grows it, bit for bit: the quad
        // holds the reported `t` to at least `t - 3` times it.)
        let reach = self.reach(&parts, t);
        if t - 3.0 * (reach * (1.0 + gamma(16))) > ray_t.max {
            return None;
        }
        if !((hit.alpha.abs() < f64::INFINITY) & (hit.beta.abs() < f64::INFINITY)) {
            return None;
        }
        Some(Decided::Region(hit, self.finish(ray, &hit, &parts, reach)))
    }

    /// Whether the region [`Plane::crossing_region`] would compute for the crossing `hit`
    /// lies clearly outside the rectangle `[lo, hi]` of `(alpha, beta)`, or clearly inside
    /// it, decided without the reach's division; `None` where it is near the rectangle's
    /// edges. The region reaches at most
    /// `reach (|w| + gamma(3) d1 s) + world s + gamma(3) |center|` from its centre per
    /// coordinate (`w` its `along`, `s` the coordinate scale: the half-length, then the
    /// radius with the drift over the reach and the rounding of evaluating the segment,
    /// grown by `1 + gamma(16)`). The computed `|w| = |d.(v x w)|` is at most
    /// `(1 + gamma(3)) |d|_1 |v x w|_inf`, and `s`, the computed `|v x w|_1`, at least
    /// `(1 - gamma(2))` of that, and the computed `d1` is within `gamma(2)` of itself: so
    /// `|w| + gamma(3) d1 s <= (1 + gamma(10)) d1 s`, with no dot product. (Loose only where `along` is small, a ray steep to the
    /// plane, whose reach is small too.) And `reach <= height / slack`, where `height` is the
    /// reach's numerator with the tolerance's term at its largest (`tolerance / slack`).
    /// Doubling both terms leaves room for every rounding here and in the region by a
    /// factor near 2, so a crossing this test finds clearly outside (inside) is one the
    /// region's own test finds clear of (wholly within) the rectangle: the test changes no
    /// decision, it only reaches it sooner. With `slack <= 0` (a reach without bound) it
    /// decides nothing; a non-finite centre is never inside.
    #[inline(always)]
    fn clearly(&self, p: &Parts, hit: &PlaneHit, [lo, hi]: [DVec2; 2]) -> Option<Clearly> {
        let slack = p.slack;
        if slack.is_nan() || slack <= 0.0 {
            return None;
        }
        let height = p.numerator + gamma(2) * hit.t.abs() * p.c + self.tolerance;
        let world = p.across + self.frame_reach() + self.tolerance;
        let center = [hit.alpha, hit.beta];
        // Per coordinate: how far the region reaches from its centre, times the slack, and
        // the slack times the centre's distance beyond the rectangle's edges (`outside`),
        // and within them (`inside`).
        let mut inside = true;
        for i in 0..2 {
            let (scale, x) = (self.coordinate_scale[i], center[i]);
            let rate = 2.0 * height * (1.0 + gamma(10)) * p.d1 * scale;
            let fixed = 2.0 * (world * scale + gamma(3) * x.abs());
            if ((lo[i] - x).max(x - hi[i]) - fixed) * slack > rate {
                return Some(Clearly::Outside);
            }
            inside &= ((x - lo[i]).min(hi[i] - x) - fixed) * slack > rate;
        }
        inside.then_some(Clearly::Inside)
    }

    /// `m = |q - o|_1 + |t| |d|_1`, which [`Quick`] bounds the error terms by, and the
    /// slack `c - (gamma(3) + e) |d|_1` (the height gained per unit of `t`, less its error).
    #[inline(always)]
    fn quick_terms(&self, q_minus_o: DVec3, t: f64, c: f64, d1: f64) -> (f64, f64) {
        (l1(q_minus_o) + t.abs() * d1, c - self.quick.slope * d1)
    }

    /// Whether a crossing at `t` is past `max` whatever is decided for it: the reported `t`
    /// is at least `t - 3 reach` (see [`Quad`](crate::Quad)'s pending decision), and the
    /// reach is at most `(height m + tolerance) / slack` ([`Quick`]; the tolerance's term
    /// along the ray is at most `tolerance / slack`). Four for three covers this test's
    /// own rounding. Decides nothing where the slack is not positive (the reach is
    /// unbounded) or `max` is infinite. So a crossing behind the closest hit so far costs
    /// no coordinates.
    #[inline(always)]
    fn clearly_past(&self, t: f64, max: f64, m: f64, slack: f64) -> bool {
        // (`t > max` first: most crossings a search tests come before its first hit.)
        t > max && slack > 0.0 && (t - max) * slack > 4.0 * (self.quick.height * m + self.tolerance)
    }

    /// [`Plane::clearly`] with its terms bounded by multiples of `m = |q - o|_1 + |t| |d|_1`
    /// ([`Quick`]), from `m`, the slack and `d1 = |d|_1` ([`Plane::quick_terms`]): looser,
    /// so it decides fewer crossings, but each one as `clearly` would (every term is at
    /// least `clearly`'s, whose factor of 2 covers the rounding here too), at about half
    /// the cost. Inside also asks, as `beyond` does, that the crossing lie past `min` by
    /// more than twice the rounding of `t` (`height m / slack`).
    #[inline(always)]
    fn clearly_quick(
        &self,
        hit: &PlaneHit,
        m: f64,
        slack: f64,
        d1: f64,
        min: f64,
        [lo, hi]: [DVec2; 2],
    ) -> Option<Clearly> {
        // (A NaN coordinate fails every test below; an infinite one is outside, where
        // `crossing` would reject it too.)
        if slack.is_nan() || slack <= 0.0 {
            return None;
        }
        let reach = self.quick.rate * m + self.quick.fixed;
        // Per coordinate, the distance `delta` of the centre within the rectangle's edges
        // (negative beyond them), from its middle `c` and half-width `h`. `clearly`'s
        // rounding term `2 gamma(3) |x|` is at most `2 gamma(3) (|c| + h + |delta|)`; twice
        // that covers this test's own rounding (of `c`, `h` and `delta`) too. With
        // `slack <= (1 + gamma(10)) d1` the constant part joins the rate.
        let shrink = slack * (1.0 - 4.0 * gamma(3));
        let center = DVec2::new(hit.alpha, hit.beta);
        let (mid, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let delta = (half - (center - mid).abs()) * shrink;
        let fixed = 4.0 * gamma(3) * (1.0 + gamma(10)) * (mid.abs() + half);
        let rate = (reach * self.coordinate_scale + fixed) * d1;
        if delta.cmplt(-rate).any() {
            return Some(Clearly::Outside);
        }
        let beyond =
            min == f64::NEG_INFINITY || (hit.t - min) * slack >= 2.0 * self.quick.height * m;
        (delta.cmpgt(rate).all() && beyond).then_some(Clearly::Inside)
    }

    /// The region of [`Plane::crossing_region`], from `q - o`, the point `p` and `|n.d|` as
    /// computed.
    #[inline(always)]
    fn region_of(
        &self,
        ray: &Ray,
        hit: &PlaneHit,
        q_minus_o: DVec3,
        p: DVec3,
        c: f64,
    ) -> CrossingRegion {
        let parts = self.parts(hit.t, q_minus_o, p, c, l1(ray.direction));
        self.finish(ray, hit, &parts, self.reach(&parts, hit.t))
    }

    /// The [`Parts`] of a crossing, from `q - o`, the point `p`, `c = |n.d|` and
    /// `d1 = |d|_1` as computed.
    #[inline(always)]
    fn parts(&self, t: f64, q_minus_o: DVec3, p: DVec3, c: f64, d1: f64) -> Parts {
        let (a, b, big_p) = (l1(q_minus_o), t.abs() * d1, l1(p));
        let across = gamma(2) * (a + b);
        Parts {
            numerator: gamma(4) * a + gamma(3) * b + self.frame_error * (big_p + across),
            across: across + gamma(3) * big_p,
            slack: c - (gamma(3) + self.frame_error) * d1,
            c,
            d1,
        }
    }

    /// The change of `(alpha, beta)` per unit of `t` along `ray`. A product past f64's
    /// range sums to `inf - inf`: the change is too large to represent, and reported as
    /// infinite (the segment is symmetric, so its sign does not matter), never as NaN.
    #[inline(always)]
    fn along(&self, ray: &Ray) -> DVec2 {
        DVec2::new(
            ray.direction.dot(self.to_alpha),
            ray.direction.dot(self.to_beta),
        )
        .map(|x| if x.is_nan() { f64::INFINITY } else { x })
    }

    /// The reach along the ray, in units of `t` (see [`Plane::crossing_region`]): its
    /// rounding, and the tolerance along the ray.
    #[inline(always)]
    fn reach(&self, p: &Parts, t: f64) -> f64 {
        let slack = p.slack;
        if slack > 0.0 {
            // One division: the tolerance's rate is the slack too, above a slope of 2^-52.
            let inv = 1.0 / slack;
            let tolerance = if slack >= p.d1 * f64::EPSILON {
                self.tolerance * inv
            } else {
                self.tolerance_along(slack, p.d1)
            };
            p.numerator * inv + gamma(2) * t.abs() * (p.c * inv) + tolerance
        } else {
            f64::INFINITY
        }
    }

    /// The region from its reach: the drift over the reach, and the radius.
    #[inline(always)]
    fn finish(&self, ray: &Ray, hit: &PlaneHit, p: &Parts, reach: f64) -> CrossingRegion {
        let drift = if reach < f64::INFINITY {
            reach * gamma(3) * p.d1
        } else {
            f64::INFINITY
        };
        let world = p.across + self.frame_reach() + self.tolerance + drift;
        self.region(hit, self.along(ray), reach, world * self.coordinate_scale)
    }

    /// The tolerance along the ray, in units of `t`: as far as the ray goes while its
    /// height over the plane changes by the tolerance, at `rate` of height per unit of `t`.
    /// Below a slope of 2^-52 (a ray within an ulp's angle of parallel) it stops growing,
    /// so that the rounding of `along` over it stays within the tolerance too.
    #[inline(always)]
    fn tolerance_along(&self, rate: f64, d1: f64) -> f64 {
        self.tolerance / rate.max(d1 * f64::EPSILON)
    }

    /// How far the frame's own error moves the crossing of a point of a shape: `e` times
    /// `|u|_1 + |v|_1` (see [`Plane::crossing_region`]).
    #[inline]
    pub(crate) fn frame_reach(&self) -> f64 {
        self.frame_error * self.extent
    }

    /// A region for the crossing `hit` with bounds `reach` (in units of `t`) and `radius`
    /// (in `alpha` and `beta`), each enlarged by `gamma(16)` for the rounding of its own
    /// evaluation.
    #[inline(always)]
    fn region(&self, hit: &PlaneHit, along: DVec2, reach: f64, radius: DVec2) -> CrossingRegion {
        let grow = 1.0 + gamma(16);
        CrossingRegion {
            center: DVec2::new(hit.alpha, hit.beta),
            along,
            reach: reach * grow,
            radius: radius * grow,
        }
    }

    /// The crossing of `ray` with the plane again, in double-double arithmetic (about 106
    /// bits), with a region of the same meaning as [`Plane::crossing_region`]'s but whose
    /// width no longer depends on how far the ray comes from: for the rare rays that the
    /// `f64` region leaves undecided, close to a shape's edge. `None` where the
    /// arithmetic overflows (coordinates near `f64::MAX`).
    ///
    /// `q - o` is exact as a double-double; the normal is `u x v` from exact products (so
    /// its tilt is of order `u_r^2 / s`, and no longer the `f64` frame's `u_r / s`); `t`,
    /// the point `t d - (q - o)` and its coordinates follow. Every double-double operation
    /// errs by at most `4 u_r^2` of the magnitudes it combines (Hida, Li and Bailey 2001),
    /// and no chain here has more than 64 of them: `K = 256 u_r^2` bounds each step
    /// relative to the magnitudes `a`, `b` and `P` as in [`Plane::crossing_region`]. The
    /// frame's own error `e` (from the `f64` vectors `v x w` and `w x u`) still applies to
    /// `alpha` and `beta`, and their final rounding to `f64` adds `u_r` of themselves.
    ///
    /// Also returns how far from `t` the exact crossing can be by rounding alone (the reach
    /// without the tolerance), which the contract's clause 5 goes by (see [`beyond`]).
    pub(crate) fn refine(&self, ray: &Ray) -> Option<(PlaneHit, CrossingRegion, f64)> {
        let (q, o, d) = (self.q, ray.origin, ray.direction);
        let a = [Dd::diff(q.x, o.x), Dd::diff(q.y, o.y), Dd::diff(q.z, o.z)];
        let (u, v) = (self.u, self.v);
        let cross =
            |a0: f64, b0: f64, a1: f64, b1: f64| Dd::product(a0, b0).add(Dd::product(a1, b1).neg());
        let n = [
            cross(u.y, v.z, u.z, v.y),
            cross(u.z, v.x, u.x, v.z),
            cross(u.x, v.y, u.y, v.x),
        ];
        // Scaled by a power of two (exactly) so that n.(q - o) cannot overflow early.
        let scale = power_of_two_scale(n[0].hi.abs().max(n[1].hi.abs()).max(n[2].hi.abs()));
        let n = n.map(|x| x.mul_f64(scale));
        let num = n[0].mul(a[0]).add(n[1].mul(a[1])).add(n[2].mul(a[2]));
        let den = Dd::dot(n, d);
        let t = num.div(den);
        let p = [
            t.mul_f64(d.x).add(a[0].neg()),
            t.mul_f64(d.y).add(a[1].neg()),
            t.mul_f64(d.z).add(a[2].neg()),
        ];
        let hit = PlaneHit {
            t: t.hi,
            alpha: Dd::dot(p, self.to_alpha).hi,
            beta: Dd::dot(p, self.to_beta).hi,
        };

        let k = 256.0 * UNIT_ROUNDOFF * UNIT_ROUNDOFF;
        let l1 = |x: [Dd; 3]| x[0].hi.abs() + x[1].hi.abs() + x[2].hi.abs();
        let d1 = d.abs().element_sum();
        let (a, b, big_p) = (
            l1(a),
            hit.t.abs() * d1,
            l1(p.map(|x| Dd { hi: x.hi, lo: 0.0 })),
        );
        // The height gained per unit of t is |n.d| / |n|_2; an upper bound of |n|_2 (the
        // low parts are below 2 u_r of the high ones) makes c a lower bound of it, and the
        // f64 region's `c` to within a few u_r: this reach is no larger than that one's
        // (`Quad::hit` relies on it).
        let n2 = sqrt(n[0].hi * n[0].hi + n[1].hi * n[1].hi + n[2].hi * n[2].hi) * (1.0 + gamma(4));
        let c = den.hi.abs() / n2;
        let tilt = k * (1.0 + self.frame_error / gamma(2));
        let across = k * (a + b);
        let slack = c - (k + tilt) * d1;
        let (rounding, reach) = if slack > 0.0 {
            let rounding = (k * (a + b) + tilt * (big_p + across)) / slack + k * hit.t.abs();
            (rounding, rounding + self.tolerance_along(slack, d1))
        } else {
            (f64::INFINITY, f64::INFINITY)
        };
        // `along` in double-double too, then rounded: its error is `u_r` of itself (plus
        // `K` of the magnitudes), so that its drift over the reach stays within the
        // tolerance (see `tolerance_along`).
        let d_dd = [d.x, d.y, d.z].map(|x| Dd { hi: x, lo: 0.0 });
        let along = DVec2::new(
            Dd::dot(d_dd, self.to_alpha).hi,
            Dd::dot(d_dd, self.to_beta).hi,
        );
        let (drift_world, drift) = if reach < f64::INFINITY {
            (reach * k * d1, reach * UNIT_ROUNDOFF * along.abs())
        } else {
            (f64::INFINITY, DVec2::INFINITY)
        };
        let world = across + k * big_p + self.frame_reach() + self.tolerance + drift_world;
        let center = DVec2::new(hit.alpha, hit.beta);
        let radius = world * self.coordinate_scale + UNIT_ROUNDOFF * center.abs() + drift;
        let region = self.region(&hit, along, reach, radius);
        let finite = hit.t.is_finite()
            && hit.alpha.is_finite()
            && hit.beta.is_finite()
            && region.radius.is_finite()
            && !region.reach.is_nan();
        finite.then_some((hit, region, rounding * (1.0 + gamma(16))))
    }
}

/// Whether the exact crossing lies at or beyond `min` whatever the rounding of `t` (the
/// contract's clause 5: a ray spawned from a surface, whose exact crossing is a hair behind
/// its origin, gets a rounded `t` of zero or just above, and must not find it), or whether
/// that cannot be told in `f64` (a reach without bound: `Quad::hit` then asks the refined
/// crossing). The rounding of `t` is at most `height / slack`, for `height` the reach's
/// numerator and its `t` term without the tolerance (which widens shapes against their
/// neighbours' rounding, and is not an uncertainty of this crossing); checked without the
/// division, with a factor 2 for the rounding of the check itself.
#[inline(always)]
fn beyond(p: &Parts, t: f64, min: f64) -> bool {
    if min == f64::NEG_INFINITY || p.slack.is_nan() || p.slack <= 0.0 {
        return true;
    }
    (t - min) * p.slack >= 2.0 * (p.numerator + gamma(2) * t.abs() * p.c)
}

#[cfg(test)]
mod tests {
    use super::{Clearly, Plane, beyond};
    use crate::math::{Stream, l1};
    use crate::{Interval, Ray};
    use glam::{DVec2, DVec3};

    /// A plane coordinate: anywhere around the unit interval, or within `10^-j` of one of
    /// its ends (or of the ends of `[-1, 1]`), on either side.
    fn coordinate(s: &mut Stream) -> f64 {
        if s.uniform() < 0.3 {
            return s.range(-1.5, 1.5);
        }
        let edge = [0.0, 1.0, -1.0][(s.uniform() * 3.0) as usize];
        let side = if s.uniform() < 0.5 { -1.0 } else { 1.0 };
        edge + side * s.power(-17, -1)
    }

    /// How far the region reaches from its centre per coordinate, and whether it lies
    /// wholly within `[lo, hi]` or wholly beyond one of its edges.
    fn region_against(
        plane: &Plane,
        ray: &Ray,
        hit: &super::PlaneHit,
        [lo, hi]: [DVec2; 2],
    ) -> (bool, bool) {
        let region = plane.crossing_region(ray, hit);
        let reach = region.half_length() + region.radius;
        let (low, high) = (region.center - reach, region.center + reach);
        let within = low.cmpge(lo).all() && high.cmple(hi).all();
        let beside = low.cmpgt(hi).any() || high.cmplt(lo).any();
        (within, beside)
    }

    /// The clear decisions before the region (`clearly_quick`, then `clearly`) decide
    /// nothing the region would not: a crossing either finds clearly inside (outside) the
    /// rectangle has its whole region inside it (beside it), and the quick test decides
    /// only what `clearly` decides too, alike. Planes of sizes 1e-3 to 1e3 at offsets up
    /// to 4e10 with edges at any angle, rays aimed at points within 1e-17 to 1e-1 of an
    /// edge (where the decisions' margins are), from any direction or grazing the plane
    /// at slopes down to 1e-15, from near and far, with directions of every ordinary
    /// length. Some decisions must fall near the region's own width, or the test would
    /// not probe the bounds.
    #[test]
    fn clear_decisions_agree_with_the_region() {
        let mut s = Stream(0x0c1e_a4de_c1de_5eed);
        let windows = [[DVec2::ZERO, DVec2::ONE], [-DVec2::ONE, DVec2::ONE]];
        let (mut quick_decided, mut tight_decided, mut close, mut past) = (0, 0, 0, 0);
        for _ in 0..60_000 {
            let size = s.power(-3, 3);
            let offset = [0.0, 1e3, 1e6, 1e9, -3.7e10][(s.uniform() * 5.0) as usize];
            let q = DVec3::splat(offset) + s.vector() * size;
            let (u, v) = (
                s.vector() * size * s.power(-1, 1),
                s.vector() * size * s.power(-1, 1),
            );
            let Ok(plane) = Plane::new(q, u, v) else {
                continue;
            };
            let target = q + coordinate(&mut s) * u + coordinate(&mut s) * v;
            let direction = if s.uniform() < 0.5 {
                s.vector()
            } else {
                let along = s.vector().reject_from(plane.normal());
                along + plane.normal() * along.length() * s.power(-15, -1) * s.range(-1.0, 1.0)
            };
            let distance = size * s.power(-2, 6);
            let origin = target - direction.normalize_or_zero() * distance;
            let ray = Ray::new(origin, direction * s.power(-3, 3));
            let Some(hit) = plane.intersect(&ray, Interval::UNIVERSE) else {
                continue;
            };
            let q_minus_o = plane.q - ray.origin;
            let p = hit.t * ray.direction - q_minus_o;
            let (c, d1) = (plane.normal.dot(ray.direction).abs(), l1(ray.direction));
            let parts = plane.parts(hit.t, q_minus_o, p, c, d1);
            let (m, slack) = plane.quick_terms(q_minus_o, hit.t, c, d1);
            for window in windows {
                let quick = plane.clearly_quick(&hit, m, slack, d1, f64::NEG_INFINITY, window);
                let tight = plane.clearly(&parts, &hit, window);
                let (within, beside) = region_against(&plane, &ray, &hit, window);
                let name = |d: &Option<Clearly>| match d {
                    Some(Clearly::Inside) => "inside",
                    Some(Clearly::Outside) => "outside",
                    None => "undecided",
                };
                let case = || format!("{plane:?} {ray:?} {hit:?} {window:?}");
                for (decision, test) in [(&quick, "quick"), (&tight, "tight")] {
                    match decision {
                        Some(Clearly::Inside) => assert!(within, "{test} inside: {}", case()),
                        Some(Clearly::Outside) => assert!(beside, "{test} outside: {}", case()),
                        None => {}
                    }
                }
                if quick.is_some() {
                    assert_eq!(name(&quick), name(&tight), "quick, tight: {}", case());
                    quick_decided += 1;
                    // Within 64 times the region's reach of an edge: the bound is probed.
                    let region = plane.crossing_region(&ray, &hit);
                    let reach = (region.half_length() + region.radius).max_element();
                    let center = region.center;
                    let margin = (center - window[0])
                        .abs()
                        .min((window[1] - center).abs())
                        .min_element();
                    close += usize::from(margin < 64.0 * reach);
                }
                tight_decided += usize::from(tight.is_some());
            }
            // Inside past `min` only where `beyond` finds it past whatever the rounding.
            for min in [0.0, hit.t * 0.5, hit.t * (1.0 - 1e-12)] {
                if let Some(Clearly::Inside) =
                    plane.clearly_quick(&hit, m, slack, d1, min, windows[0])
                {
                    assert!(beyond(&parts, hit.t, min), "beyond {min}: {ray:?} {hit:?}");
                }
            }
            // Past `max` only where the pending decision finds it past too (`t - 3 reach`,
            // the least `t` it can report), for a `max` on either side of that bound.
            let reach = plane.reach(&parts, hit.t);
            for k in [2.0, 2.9, 3.0, 3.1, 4.0, 4.1, 5.0, 8.0] {
                let max = hit.t - k * reach;
                if plane.clearly_past(hit.t, max, m, slack) {
                    past += 1;
                    assert!(hit.t - 3.0 * reach > max, "past {max}: {ray:?} {hit:?}");
                }
            }
        }
        assert!(
            quick_decided > 20_000 && tight_decided > quick_decided && close > 100 && past > 1000,
            "{quick_decided} {tight_decided} {close} {past}"
        );
    }
}

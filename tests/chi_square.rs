//! Every light sampler draws what its density says: a chi-square goodness-of-fit test (the
//! method of Mitsuba's and pbrt-v4's `chi2` tests) that the directions
//! `PdfHittable::sample_direction` makes from uniform points of `[0, 1)^2` are distributed
//! over solid angle as `PdfHittable::pdf_value` says. It covers rectangles sampled by solid
//! angle and by area, skewed parallelograms, triangles, disks, rings, spheres, a mixture of
//! lights, a light tree, a moved light and lights under scales, shears and mirrors, from near, far, grazing, behind and inside; a negative control
//! shows that it catches a sampler that is off by a little.
//!
//! For one light and one origin: every direction toward the light lies in the cone around
//! the bounding sphere of its box. That cone is cut into cells of equal solid angle; each
//! cell's expected count is `N` times the integral of `pdf_value` over it (by quadrature),
//! its observed count that of `N` samples. Cells expecting fewer than 5 are pooled, and
//! `sum (O - E)^2 / E` must stay under the chi-square quantile at significance 1e-5.

mod support;

use std::f64::consts::TAU;
use std::ops::RangeInclusive;

use hitkit::glam::{DAffine3, DMat3, DQuat, DVec2, DVec3};
use hitkit::{
    Aabb, Disk, Emission, HitRecord, Hittable, Interval, LightTree, Mixture, PdfHittable, Quad,
    Ray, Ring, Sampling, ShadingContext, Sphere, Transformed, Triangle,
};
use support::SplitMix;

/// Samples per light and origin.
const N: usize = 200_000;

/// The cone is cut into `ROWS` rows, equal steps of `x = (1 - cos theta) / (1 - cos
/// theta_max)`, times `COLUMNS` columns, equal steps of `phi`: 800 cells of equal solid
/// angle. A light that fills a fair part of the cone gets a few hundred of them, each
/// expecting a few hundred samples: cells enough to see a sampler wrong in one part of the
/// light, samples enough per cell for the chi-square approximation.
const ROWS: usize = 20;
const COLUMNS: usize = 40;

/// The quadrature of each cell's expected count. Each cell is cut into `K x K` sub-cells,
/// equal steps of `theta` and of `phi`, and each sub-cell's integral is the density at its
/// middle times its exact solid angle (the midpoint rule). Steps of `theta` rather than of
/// `x`, because `x` grows as `theta^2` near the axis: equal steps of `x` would leave the first
/// sub-row's points degrees away from it, and miss a light's edge that passes closer (a
/// grazing light's far edge does).
///
/// Where the density is smooth that is plenty. Where it is not, at the light's edges (a
/// sub-cell whose density is 0 next to one whose density is not) and where it changes by more
/// than the factor `STEEP` between neighbouring sub-cells, the sub-cell is integrated again on
/// `M x M` parts, each at a uniform random point of its own: stratified, so that an edge that
/// runs along the grid (a sphere's outline does) leaves an error of either sign in each part
/// rather than the same one in all. Every refined sub-cell that turns out partly lit also has
/// its neighbours refined, so that a sliver of the light thinner than a sub-cell (a corner of
/// a light seen at a grazing angle) is followed until it is thinner than a part.
///
/// `K` and `M` are the smallest powers of two for which, in every case below, the expected
/// counts agree with those of `2K x 2M`: `sum (E - E')^2 / E'`, what the difference adds to
/// the statistic's mean, is under 0.05 for most cases and 0.46 at most (the two grazing
/// ones), so that no cell's error is more than a fraction of its `sqrt(E)`, against a
/// threshold over `df` of `4.3 sqrt(2 df)`, 45 or more. With `K = 16` the grazing cases
/// reached 3.6, with `M = 4` 10; before the quadrature stepped in `theta`, followed slivers
/// and drew its points at random, they failed by thousands (whole slivers of the light
/// missed). The cost: `800 K^2 = 819_200` density evaluations, and `M^2` more for each of the
/// 4_000 to 14_000 refined sub-cells: about half a second per case in debug.
const K: usize = 32;
const M: usize = 8;
const STEEP: f64 = 1.25;

/// Cells expected to hold fewer samples are pooled into one (the usual rule for the
/// chi-square approximation to hold).
const MIN_EXPECTED: f64 = 5.0;

/// The standard normal quantile at `1 - 1e-5`: the significance of each case. With 32 cases
/// in the file, a correct sampler would fail a run with probability about 3.2e-4 (were the
/// seeds not fixed).
const Z: f64 = 4.264_890_793_922_825;

/// The chi-square quantile for `df` degrees of freedom whose upper tail is that of `Z`, by
/// the Wilson-Hilferty approximation (Wilson and Hilferty 1931, "The distribution of
/// chi-square"): `(chi2 / df)^(1/3)` is nearly normal, with mean `1 - 2 / (9 df)` and
/// variance `2 / (9 df)`. At this tail it overestimates the quantile a little (by 0.8% at
/// `df = 20`, under 0.3% from `df = 50`; the true tail beyond it is then between 8e-6 and
/// 1e-5), so it errs on the side of not failing a correct sampler.
fn threshold(df: usize) -> f64 {
    let k = df as f64;
    let v = 2.0 / (9.0 * k);
    k * (1.0 - v + Z * v.sqrt()).powi(3)
}

/// The cone around the bounding sphere of a light's box, as seen from an origin, and a frame
/// whose `z` is its axis; the whole sphere of directions when the origin is inside that
/// sphere.
struct Cone {
    frame: [DVec3; 3],
    one_minus_cos_max: f64,
}

impl Cone {
    fn around(light: &dyn PdfHittable, origin: DVec3) -> Self {
        let bounds: Aabb = light.bounding_box();
        let centre = 0.5 * (bounds.min() + bounds.max());
        let radius = 0.5 * (bounds.max() - bounds.min()).length();
        let to_centre = centre - origin;
        let z = to_centre.normalize_or(DVec3::Z);
        let (x, y) = z.any_orthonormal_pair();
        let s = radius / to_centre.length();
        // `1 - cos(asin s)`, written so that it does not cancel for far lights (small s).
        let one_minus_cos_max = if s < 1.0 {
            s * s / (1.0 + (1.0 - s * s).sqrt())
        } else {
            2.0
        };
        Self {
            frame: [x, y, z],
            one_minus_cos_max,
        }
    }

    /// The polar angle at `x = (1 - cos theta) / (1 - cos theta_max)`, through
    /// `1 - cos theta = 2 sin^2(theta / 2)`.
    fn theta(&self, x: f64) -> f64 {
        2.0 * (0.5 * x * self.one_minus_cos_max).sqrt().min(1.0).asin()
    }

    /// The unit direction at polar angle `theta` and azimuth `phi`.
    fn direction(&self, theta: f64, phi: f64) -> DVec3 {
        let [ex, ey, ez] = self.frame;
        let sin = theta.sin();
        sin * phi.cos() * ex + sin * phi.sin() * ey + theta.cos() * ez
    }

    /// The cell `direction` falls in, or `None` outside the cone.
    fn cell(&self, direction: DVec3) -> Option<usize> {
        let d = direction.normalize();
        let [ex, ey, ez] = self.frame;
        let (a, b, c) = (d.dot(ex), d.dot(ey), d.dot(ez));
        // `1 - cos theta` as `sin^2 / (1 + cos)` where that does not cancel.
        let one_minus_cos = if c > 0.0 {
            (a * a + b * b) / (1.0 + c)
        } else {
            1.0 - c
        };
        let x = one_minus_cos / self.one_minus_cos_max;
        // A direction toward a corner of the box that is also a point of the light (a
        // rectangle's corner) has `x = 1` to within a few roundings of its angle and of the
        // frame (1e-14 or so); 1e-9 allows for them and is far below a sub-cell.
        if x.is_nan() || x > 1.0 + 1e-9 {
            return None;
        }
        let phi = b.atan2(a).rem_euclid(TAU);
        let row = ((x * ROWS as f64) as usize).min(ROWS - 1);
        let column = ((phi / TAU * COLUMNS as f64) as usize).min(COLUMNS - 1);
        Some(row * COLUMNS + column)
    }

    /// `N` times the integral of the light's density over each cell, and the integral over
    /// the whole cone, by the quadrature described at `K`, on `k x k` sub-cells and `m x m`
    /// parts.
    fn expected(
        &self,
        light: &dyn PdfHittable,
        origin: DVec3,
        k: usize,
        m: usize,
    ) -> (Vec<f64>, f64) {
        let (rows, columns) = (ROWS * k, COLUMNS * k);
        let step = TAU / columns as f64;
        // Sub-row `i` spans `theta` from `bounds[i]` to `bounds[i + 1]`.
        let bounds: Vec<f64> = (0..=rows)
            .map(|i| {
                let (row, part) = (i / k, (i % k) as f64 / k as f64);
                let start = self.theta(row as f64 / ROWS as f64);
                let end = self.theta((row + 1).min(ROWS) as f64 / ROWS as f64);
                start + (end - start) * part
            })
            .collect();
        // The solid angle between polar angles `lo` and `hi`, over `step` of `phi`:
        // `(cos lo - cos hi) step`, written without cancellation.
        let band =
            |lo: f64, hi: f64| 2.0 * (0.5 * (lo + hi)).sin() * (0.5 * (hi - lo)).sin() * step;
        let densities: Vec<f64> = (0..rows * columns)
            .map(|c| {
                let (i, j) = (c / columns, c % columns);
                let theta = 0.5 * (bounds[i] + bounds[i + 1]);
                light.pdf_value(origin, self.direction(theta, step * (j as f64 + 0.5)))
            })
            .collect();
        let mut integrals: Vec<f64> = (0..rows * columns)
            .map(|c| densities[c] * band(bounds[c / columns], bounds[c / columns + 1]))
            .collect();

        // Where the density changes between neighbouring sub-cells: from 0 to not, or by
        // more than `STEEP`. The first sub-row's sub-cells all meet at the cone's axis, and
        // the last's (for the whole sphere) at the opposite pole: each of those rows is one
        // neighbourhood as well.
        let differ = |p: f64, q: f64| (p > 0.0) != (q > 0.0) || p > STEEP * q || q > STEEP * p;
        let uneven = |i: usize| {
            let row = &densities[i * columns..(i + 1) * columns];
            let (min, max) = row.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
            max > STEEP * min
        };
        let poles = [(0, uneven(0)), (rows - 1, uneven(rows - 1))];
        let mut marked = vec![false; rows * columns];
        for i in 0..rows {
            let pole = poles.iter().any(|&(row, uneven)| row == i && uneven);
            let below = (i + 1).min(rows - 1) * columns;
            for j in 0..columns {
                let c = i * columns + j;
                marked[c] |= pole;
                // Each pair of neighbours once: this one and the one to its right, and the
                // three below.
                for other in [
                    i * columns + (j + 1) % columns,
                    below + (j + columns - 1) % columns,
                    below + j,
                    below + (j + 1) % columns,
                ] {
                    if differ(densities[c], densities[other]) {
                        marked[c] = true;
                        marked[other] = true;
                    }
                }
            }
        }

        // The integral over sub-cell `(i, j)` by `m x m` parts, each at a uniform point of its
        // own (from a stream of the sub-cell's own, so the result does not depend on the
        // order of refinement), and how many parts are lit.
        let refine = |i: usize, j: usize| {
            let (start, end) = (bounds[i], bounds[i + 1]);
            let mut rng = SplitMix::new((i * columns + j) as u64);
            let (mut sum, mut lit) = (0.0, 0);
            for a in 0..m {
                let lo = start + (end - start) * a as f64 / m as f64;
                let hi = start + (end - start) * (a + 1) as f64 / m as f64;
                // Uniform in solid angle is uniform in `sin^2(theta / 2) = (1 - cos) / 2`.
                let (s_lo, s_hi) = ((0.5 * lo).sin().powi(2), (0.5 * hi).sin().powi(2));
                let area = band(lo, hi) / m as f64;
                for b in 0..m {
                    let theta = 2.0 * (s_lo + rng.next_f64() * (s_hi - s_lo)).sqrt().asin();
                    let phi = step * (j as f64 + (b as f64 + rng.next_f64()) / m as f64);
                    let pdf = light.pdf_value(origin, self.direction(theta, phi));
                    sum += area * pdf;
                    lit += usize::from(pdf > 0.0);
                }
            }
            (sum, lit)
        };
        let mut queue: Vec<(usize, usize)> = (0..rows * columns)
            .filter(|&c| marked[c])
            .map(|c| (c / columns, c % columns))
            .collect();
        let mut refined = vec![false; rows * columns];
        let mut whole_rows_queued = poles.map(|(_, uneven)| uneven);
        while let Some((i, j)) = queue.pop() {
            if std::mem::replace(&mut refined[i * columns + j], true) {
                continue;
            }
            let (integral, lit) = refine(i, j);
            integrals[i * columns + j] = integral;
            if 0 < lit && lit < m * m {
                for a in i.saturating_sub(1)..=(i + 1).min(rows - 1) {
                    queue.extend([columns - 1, 0, 1].map(|dj| (a, (j + dj) % columns)));
                }
                for (p, &(row, _)) in poles.iter().enumerate() {
                    if row == i && !std::mem::replace(&mut whole_rows_queued[p], true) {
                        queue.extend((0..columns).map(|b| (i, b)));
                    }
                }
            }
        }

        let mut expected = vec![0.0; ROWS * COLUMNS];
        for (c, integral) in integrals.iter().enumerate() {
            let (i, j) = (c / columns, c % columns);
            expected[(i / k) * COLUMNS + j / k] += N as f64 * integral;
        }
        let integral = expected.iter().sum::<f64>() / N as f64;
        (expected, integral)
    }
}

/// The chi-square statistic of `observed` against `expected` counts, and its degrees of
/// freedom, after pooling the cells expected to hold fewer than `MIN_EXPECTED` samples (and,
/// if those together still expect fewer, the next smallest cells) into one.
fn statistic(observed: &[usize], expected: &[f64]) -> (f64, usize) {
    let mut cells: Vec<(f64, f64)> = expected
        .iter()
        .zip(observed)
        .map(|(&e, &o)| (e, o as f64))
        .collect();
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut pooled = cells.iter().take_while(|c| c.0 < MIN_EXPECTED).count();
    let mut pool_expected: f64 = cells[..pooled].iter().map(|c| c.0).sum();
    while pooled > 0 && pool_expected < MIN_EXPECTED && pooled < cells.len() {
        pool_expected += cells[pooled].0;
        pooled += 1;
    }
    let pool_observed: f64 = cells[..pooled].iter().map(|c| c.1).sum();
    let term = |e: f64, o: f64| (o - e) * (o - e) / e;
    let mut chi2: f64 = cells[pooled..].iter().map(|&(e, o)| term(e, o)).sum();
    let mut classes = cells.len() - pooled;
    if pooled > 0 {
        chi2 += term(pool_expected, pool_observed);
        classes += 1;
    }
    (chi2, classes - 1)
}

/// The outcome for one light and origin.
struct Fit {
    statistic: f64,
    df: usize,
    threshold: f64,
    /// The density's integral over the cone.
    integral: f64,
}

/// Draws `N` directions toward `light` from `origin` (the stream `seed`), checks that each
/// has a positive finite density and lies in the cone, and fits their cells' counts to the
/// density's.
fn fit(what: &str, light: &dyn PdfHittable, origin: DVec3, seed: u64) -> Fit {
    let cone = Cone::around(light, origin);
    let (expected, integral) = cone.expected(light, origin, K, M);
    let mut observed = vec![0usize; ROWS * COLUMNS];
    let mut rng = SplitMix::new(seed);
    for _ in 0..N {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        let d = light.sample_direction(origin, u);
        // A sample that the density calls impossible, or outside the cone that holds the
        // light, is a failure by itself, whatever the counts.
        let pdf = light.pdf_value(origin, d);
        assert!(
            pdf > 0.0 && pdf.is_finite(),
            "{what} from {origin}: the sample {d} (u = {u}) has density {pdf}"
        );
        let Some(cell) = cone.cell(d) else {
            panic!("{what} from {origin}: the sample {d} (u = {u}) is outside the cone");
        };
        observed[cell] += 1;
    }
    let (statistic, df) = statistic(&observed, &expected);
    Fit {
        statistic,
        df,
        threshold: threshold(df),
        integral,
    }
}

/// One light seen from one origin.
struct Case {
    what: &'static str,
    light: Box<dyn PdfHittable>,
    origin: DVec3,
}

fn case(what: &'static str, light: impl PdfHittable + 'static, origin: DVec3) -> Case {
    Case {
        what,
        light: Box::new(light),
        origin,
    }
}

/// Fits every case (each with its own stream, from `seed` on), and fails listing all those
/// that do not fit: a statistic over the threshold, or a density whose integral over the
/// cone is not 1.
///
/// The integral's tolerance: were it off by `e`, every expected count would be off by the
/// fraction `e`, which adds about `e^2 N` to the statistic; the tolerance `1 / sqrt(N)` keeps
/// that under one. (The integrals here are within 5e-4 of 1. A density off by more would fail
/// the statistic too; this check names the cause: a light not wholly inside its cone, or a
/// quadrature too coarse for it.)
fn assert_samplers_follow_their_densities(cases: Vec<Case>, seed: u64) {
    let tolerance = 1.0 / (N as f64).sqrt();
    let mut failures = Vec::new();
    for (i, case) in cases.into_iter().enumerate() {
        let Case {
            what,
            light,
            origin,
        } = case;
        let fit = fit(what, light.as_ref(), origin, seed + i as u64);
        if !(fit.statistic <= fit.threshold && (fit.integral - 1.0).abs() <= tolerance) {
            failures.push(format!(
                "{what}, from {origin}: chi-square {:.1} with {} degrees of freedom \
                 (threshold {:.1}); density integral over the cone {:.6} (tolerance {tolerance:.1e})",
                fit.statistic, fit.df, fit.threshold, fit.integral
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A unit square in the plane z = 0, centred on the origin, facing +z.
fn square() -> Quad {
    Quad::new(DVec3::new(-0.5, -0.5, 0.0), DVec3::X, DVec3::Y).unwrap()
}

/// A parallelogram whose edges are not perpendicular: area sampled from everywhere.
fn skewed() -> Quad {
    Quad::new(
        DVec3::new(-0.6, -0.4, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.4, 0.9, 0.0),
    )
    .unwrap()
}

/// An oblique frame (no edge along an axis): corner or centre `Q`, edges or semi-axes `U`
/// and `V`, perpendicular (exactly: every product in `U . V` is exact), so that the
/// parallelogram on it is a rectangle.
const Q: DVec3 = DVec3::new(0.3, -0.2, 1.0);
const U: DVec3 = DVec3::new(1.5, 0.25, -0.5);
const V: DVec3 = DVec3::new(0.25, 1.5, 1.5);

fn normal() -> DVec3 {
    U.cross(V).normalize()
}

/// The solid angle from `origin` of the convex polygon with `corners` (in order): Van
/// Oosterom and Strackee's formula for each triangle of a fan. It says which sampler a case
/// reaches.
fn solid_angle(corners: &[DVec3], origin: DVec3) -> f64 {
    let triangle = |a: DVec3, b: DVec3, c: DVec3| {
        let (a, b, c) = (a - origin, b - origin, c - origin);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c)).abs();
        let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * numerator.atan2(denominator)
    };
    corners
        .windows(2)
        .skip(1)
        .map(|pair| triangle(corners[0], pair[0], pair[1]))
        .sum()
}

fn rectangle_solid_angle(quad: &Quad, origin: DVec3) -> f64 {
    let p = quad.plane();
    solid_angle(
        &[p.q(), p.q() + p.u(), p.q() + p.u() + p.v(), p.q() + p.v()],
        origin,
    )
}

/// The solid angles between which a rectangle or triangle is sampled by solid angle
/// (src/spherical.rs).
const SPHERICAL: RangeInclusive<f64> = 3e-4..=6.22;

fn rectangles_sampled_by_solid_angle() -> Vec<Case> {
    let origins = [
        ("square, 0.05 over its centre", DVec3::new(0.0, 0.0, 0.05)),
        (
            "square, 0.5 over a point off centre",
            DVec3::new(0.4, -0.3, 0.5),
        ),
        ("square, 3 over a point off it", DVec3::new(1.5, 0.8, 3.0)),
        // 0.01 over its plane, 0.25 outside an edge: the light is a band from 0.4 to 2.3
        // degrees under the horizon, 1e-4 radians thin at its corners.
        ("square, grazing", DVec3::new(0.3, -0.75, 0.01)),
        // The other side: the quad is two-sided for sampling.
        ("square, from behind", DVec3::new(0.2, 0.1, -0.4)),
    ];
    let mut cases = Vec::new();
    for (what, origin) in origins {
        let omega = rectangle_solid_angle(&square(), origin);
        assert!(SPHERICAL.contains(&omega), "{what}: solid angle {omega}");
        cases.push(case(what, square(), origin));
    }
    // A longer rectangle on the oblique frame, and the same moved by a generic rotation:
    // the moved light is sampled in its own space.
    assert_eq!(U.dot(V), 0.0);
    let rectangle = Quad::new(Q, U, V).unwrap();
    let near = Q + 0.5 * (U + V) + 0.4 * normal() + 0.3 * U;
    assert!(SPHERICAL.contains(&rectangle_solid_angle(&rectangle, near)));
    let rotation = DQuat::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 0.7);
    let translation = DVec3::new(-3.0, 5.0, 2.5);
    let moved = Transformed::new(rectangle, rotation, translation).unwrap();
    cases.push(case("oblique rectangle, near", rectangle, near));
    cases.push(case(
        "oblique rectangle, rotated and moved, near",
        moved,
        rotation * near + translation,
    ));
    cases
}

fn quads_sampled_by_area() -> Vec<Case> {
    // Far enough for a rectangle's solid angle to be under 3e-4.
    let far = DVec3::new(3.0, -2.0, 100.0);
    let omega = rectangle_solid_angle(&square(), far);
    assert!(omega < *SPHERICAL.start(), "solid angle {omega}");
    vec![
        case("square, 100 away", square(), far),
        case(
            "skewed parallelogram, near",
            skewed(),
            DVec3::new(0.1, 0.2, 0.3),
        ),
        case("skewed parallelogram, far", skewed(), far),
        // 0.02 over its plane, 0.1 outside an edge.
        case(
            "skewed parallelogram, grazing",
            skewed(),
            DVec3::new(0.2, -0.5, 0.02),
        ),
        case(
            "skewed parallelogram, from behind",
            skewed(),
            DVec3::new(-0.1, 0.3, -0.5),
        ),
    ]
}

fn triangles_disks_and_rings() -> Vec<Case> {
    let triangle = || Quad::with_interior(Q, U, V, Triangle).unwrap();
    let disk = || Quad::with_interior(Q, U, V, Disk).unwrap();
    let ring = || Quad::with_interior(Q, U, V, Ring::new(0.6).unwrap()).unwrap();
    let (n, along) = (normal(), U.normalize());
    // Over a point of the shape a little off its centre; and far, off to one side.
    let centroid = Q + (U + V) / 3.0;
    let grazing = Q + 0.6 * (U + V) + 0.02 * n;
    // The triangle is sampled by solid angle from every origin here but the far one.
    for origin in [
        centroid + 0.3 * n + 0.2 * along,
        centroid - 0.5 * n,
        grazing,
    ] {
        let omega = solid_angle(&[Q, Q + U, Q + V], origin);
        assert!(
            SPHERICAL.contains(&omega),
            "triangle from {origin}: {omega}"
        );
    }
    vec![
        case(
            "triangle, near",
            triangle(),
            centroid + 0.3 * n + 0.2 * along,
        ),
        case(
            "triangle, far",
            triangle(),
            centroid + 60.0 * n + 20.0 * along,
        ),
        case("triangle, from behind", triangle(), centroid - 0.5 * n),
        // 0.02 over its plane, outside its long edge.
        case("triangle, grazing", triangle(), grazing),
        case(
            "triangle sampled by area, near",
            triangle().with_sampling(Sampling::Area),
            centroid + 0.3 * n + 0.2 * along,
        ),
        case("disk, near", disk(), Q + 0.4 * n + 0.3 * along),
        case("disk, far", disk(), Q + 60.0 * n - 20.0 * along),
        // Over the hole.
        case("ring, near", ring(), Q + 0.3 * n + 0.2 * along),
        case("ring, far", ring(), Q - 60.0 * n + 20.0 * along),
    ]
}

fn spheres() -> Vec<Case> {
    let (centre, radius) = (DVec3::new(1.0, -0.5, 2.0), 0.7);
    let sphere = || Sphere::new(centre, radius).unwrap();
    let out = DVec3::new(0.3, 0.9, -0.4).normalize();
    vec![
        case(
            "sphere, 1.05 radii from its centre",
            sphere(),
            centre + 1.05 * radius * out,
        ),
        case(
            "sphere, 100 radii from its centre",
            sphere(),
            centre - 100.0 * radius * out,
        ),
        // Inside, the density is over the whole sphere of directions (1 / 4 pi), and so is
        // the cone.
        case("sphere, from inside", sphere(), centre + 0.4 * radius * out),
    ]
}

/// `support::four_lights` (a square, sampled by solid angle from both origins
/// here, a disk, a triangle and a sphere) as one light, from among them and from outside.
fn mixtures() -> Vec<Case> {
    let lights = support::four_lights;
    let square = Quad::new(DVec3::new(-1.0, 2.0, -1.0), DVec3::X, DVec3::Z).unwrap();
    let (among, outside) = (DVec3::new(0.2, 0.3, -0.1), DVec3::new(4.0, 3.0, 5.0));
    for origin in [among, outside] {
        assert!(SPHERICAL.contains(&rectangle_solid_angle(&square, origin)));
    }
    let weighted = Mixture::new(lights(), &[4.0, 1.0, 0.0, 3.0]).unwrap();
    vec![
        case("mixture, from among the lights", lights(), among),
        case("mixture, from outside", lights(), outside),
        case(
            "mixture weighted 4:1:0:3, from among the lights",
            weighted,
            among,
        ),
    ]
}

#[test]
fn rectangles_sampled_by_solid_angle_draw_what_their_density_says() {
    assert_samplers_follow_their_densities(rectangles_sampled_by_solid_angle(), 100);
}

#[test]
fn quads_sampled_by_area_draw_what_their_density_says() {
    assert_samplers_follow_their_densities(quads_sampled_by_area(), 200);
}

#[test]
fn triangles_disks_and_rings_draw_what_their_density_says() {
    assert_samplers_follow_their_densities(triangles_disks_and_rings(), 300);
}

#[test]
fn spheres_draw_what_their_density_says_from_near_far_and_inside() {
    assert_samplers_follow_their_densities(spheres(), 400);
}

/// Lights under affine maps (`Transformed::affine`): the object is sampled in its own
/// space, and its density carried to the world by the Jacobian between the spheres of
/// directions; wrong by a power of the scale, or with the scale on the wrong side, these
/// fail by orders of magnitude.
fn affine_lights() -> Vec<Case> {
    let turn = DMat3::from_quat(DQuat::from_axis_angle(
        DVec3::new(1.0, -2.0, 0.5).normalize(),
        0.7,
    ));
    let other = DMat3::from_quat(DQuat::from_axis_angle(
        DVec3::new(0.2, 0.4, -1.0).normalize(),
        2.1,
    ));
    let map = |scales: DVec3, at: DVec3| {
        DAffine3::from_mat3_translation(turn * DMat3::from_diagonal(scales) * other, at)
    };
    let at = DVec3::new(-3.0, 5.0, 2.5);
    // A rectangle stretched 8:1 along a skewed pair of axes (a shear), from over it.
    let stretched = map(DVec3::new(2.0, 0.25, 1.0), at);
    let rectangle = Transformed::affine(Quad::new(Q, U, V).unwrap(), stretched).unwrap();
    let over = stretched.transform_point3(Q + 0.5 * (U + V) + 0.4 * normal());
    // A ball stretched into an ellipsoid 1:4:10 and a mirrored one, from near, far and
    // inside.
    let ball = || Sphere::new(DVec3::ZERO, 1.0).unwrap();
    let ellipsoid = map(DVec3::new(0.3, 1.2, 3.0), at);
    let mirrored = map(DVec3::new(-0.5, 1.5, 0.8), at);
    let out = DVec3::new(0.3, 0.9, -0.4).normalize();
    // A disk mirrored and flattened, seen at a slant.
    let disk = Quad::with_interior(Q, U, V, Disk).unwrap();
    let flattened = map(DVec3::new(1.0, -0.2, 1.5), at);
    let slant = flattened.transform_point3(Q + 0.3 * U + 0.5 * normal());
    vec![
        case(
            "rectangle stretched 8:1 and sheared, from over it",
            rectangle,
            over,
        ),
        case(
            "ellipsoid 1:4:10, near",
            Transformed::affine(ball(), ellipsoid).unwrap(),
            ellipsoid.transform_point3(1.2 * out),
        ),
        case(
            "ellipsoid 1:4:10, far",
            Transformed::affine(ball(), ellipsoid).unwrap(),
            ellipsoid.transform_point3(-40.0 * out),
        ),
        case(
            "ellipsoid 1:4:10, from inside",
            Transformed::affine(ball(), ellipsoid).unwrap(),
            ellipsoid.transform_point3(0.5 * out),
        ),
        case(
            "mirrored ellipsoid, near",
            Transformed::affine(ball(), mirrored).unwrap(),
            mirrored.transform_point3(1.5 * out),
        ),
        case(
            "disk mirrored and flattened, at a slant",
            Transformed::affine(disk, flattened).unwrap(),
            slant,
        ),
    ]
}

#[test]
fn lights_under_scales_shears_and_mirrors_draw_what_their_density_says() {
    assert_samplers_follow_their_densities(affine_lights(), 650);
}

#[test]
fn a_mixture_of_lights_draws_what_its_density_says() {
    assert_samplers_follow_their_densities(mixtures(), 500);
}

/// The four lights in a light tree (each light's emission as its shape has it: the
/// square facing down, the disk and the triangle both ways, the sphere everywhere), of
/// powers far apart, one of them 0: the walk's choices vary with the origin, so from each
/// origin the density must follow them, and with a normal (either side) the cosine at the
/// surface weighs them too.
fn light_trees() -> Vec<Case> {
    let tree = || {
        let emission = [
            Emission::OneSide(DVec3::NEG_Y),
            Emission::BothSides(DVec3::X),
            Emission::BothSides(DVec3::Y),
            Emission::Everywhere,
        ];
        LightTree::new(support::four_lights(), &[4.0, 100.0, 0.0, 0.5], &emission).unwrap()
    };
    let (among, outside) = (DVec3::new(0.2, 0.3, -0.1), DVec3::new(4.0, 3.0, 5.0));
    let below = DVec3::new(-0.5, 1.0, -0.5);
    vec![
        case("light tree, from among the lights", tree(), among),
        case("light tree, from outside", tree(), outside),
        case("light tree, under the square", tree(), below),
        case(
            "light tree seen from a surface facing up, from among the lights",
            Seen(tree(), DVec3::Y),
            among,
        ),
        case(
            "light tree seen from a tilted surface, from outside",
            Seen(tree(), DVec3::new(-1.0, -0.2, -1.0)),
            outside,
        ),
    ]
}

/// A light seen from a surface facing the given normal: sampled by
/// [`PdfHittable::sample_light`] (the zero vector where it gives no sample) with its
/// density [`PdfHittable::light_pdf`], from a context at the origin asked.
struct Seen<L>(L, DVec3);

impl<L: PdfHittable> Hittable for Seen<L> {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.0.hit(ray, ray_t)
    }

    fn bounding_box(&self) -> Aabb {
        self.0.bounding_box()
    }
}

impl<L: PdfHittable> PdfHittable for Seen<L> {
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.0
            .light_pdf(&ShadingContext::on_surface(origin, self.1), direction)
    }

    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        let at = ShadingContext::on_surface(origin, self.1);
        self.0
            .sample_light(&at, u)
            .map_or(DVec3::ZERO, |s| s.direction)
    }
}

#[test]
fn a_light_tree_draws_what_its_density_says() {
    assert_samplers_follow_their_densities(light_trees(), 700);
}

/// A sampler with a small bug: the square's, fed `u.x^1.05` for `u.x`, while its density
/// stays the square's. In `u.x` the warp has density `a u^(a - 1)`, `a = 1 / 1.05`, which
/// crosses 1 at `u* = a^(1 / (1 - a)) = 0.359`: it moves `u*^a - u* = 1.8%` of the samples,
/// and changes the density by at most 5% for `u.x` above 0.13.
struct Warped(Quad);

impl Hittable for Warped {
    fn hit(&self, ray: &Ray, ray_t: Interval) -> Option<HitRecord> {
        self.0.hit(ray, ray_t)
    }

    fn bounding_box(&self) -> Aabb {
        self.0.bounding_box()
    }
}

impl PdfHittable for Warped {
    fn pdf_value(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.0.pdf_value(origin, direction)
    }

    fn sample_direction(&self, origin: DVec3, u: DVec2) -> DVec3 {
        self.0
            .sample_direction(origin, DVec2::new(u.x.powf(1.05), u.y))
    }
}

/// The negative control: the test has power. The warp's chi-square divergence from uniform
/// is `a^2 / (2a - 1) - 1 = 0.25%`, so over cells that resolve it the statistic's mean grows
/// by about `N` times that, 500, while the threshold is 76 over `df` (112 here). Measured
/// over six streams: 474 to 620, 2.5 to 3.3 times the threshold.
#[test]
fn a_sampler_that_misplaces_two_percent_of_its_samples_fails() {
    let origin = DVec3::new(0.4, -0.3, 0.5);
    let fit = fit("warped square", &Warped(square()), origin, 600);
    assert!(
        fit.statistic > fit.threshold,
        "a warped square from {origin}: chi-square {:.1} with {} degrees of freedom, under the \
         threshold {:.1}",
        fit.statistic,
        fit.df,
        fit.threshold
    );
}

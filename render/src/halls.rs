//! Halls of many lamps for judging a light sampler: lamps as quads with their powers and
//! sides, shading points on the floor, each lamp's exact irradiance there (Lambert's
//! polygon formula), and the variance of a sampler's choice of lamp against it. The light
//! tree's test and the `--halls` bench of the peers comparison share them.

use core::f64::consts::PI;

use hitkit::glam::DVec3;
use hitkit::{Emission, Hittable, LightTree, Quad, ShadingContext};

use crate::pbrt_lights::PbrtLightBvh;
use crate::workloads::SplitMix;

/// The kinds of hall: which lamps, where, facing where.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hall {
    /// A 10:1 hall, 4 high, its ceiling a grid of equal square lamps facing down.
    Ceiling,
    /// The same ceiling, lamps of sizes from 0.05 to 0.5 (power as area), placed at
    /// random in their cells.
    Sizes,
    /// Lamps on the ceiling and on all four walls, facing into the room.
    Room,
    /// Panels hanging from the ceiling, turned to within 10 degrees of upright: seen
    /// nearly edge on from the floor.
    EdgeOn,
    /// Ten rooms of 10 x 10 along the hall, walls between them, lamps on every room's four
    /// walls facing into it (an inner wall carries lamps on both faces): seen from points
    /// on the walls ([`points`]), where the lamps of the rooms beyond lie behind the wall.
    Walls,
}

impl Hall {
    pub const ALL: [Hall; 5] = [
        Hall::Ceiling,
        Hall::Sizes,
        Hall::Room,
        Hall::EdgeOn,
        Hall::Walls,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Hall::Ceiling => "ceiling",
            Hall::Sizes => "sizes",
            Hall::Room => "room",
            Hall::EdgeOn => "edge on",
            Hall::Walls => "walls",
        }
    }
}

/// The hall's length (x), width (z) and height (y) at scale 1.
const LENGTH: f64 = 100.0;
const WIDTH: f64 = 10.0;
const HEIGHT: f64 = 4.0;

/// A hall's lamps (one-sided quads), their powers and the side each emits on.
pub struct Lamps {
    pub quads: Vec<Quad>,
    pub powers: Vec<f64>,
    pub emission: Vec<Emission>,
    /// Each lamp's unit normal (the side it emits on).
    pub normals: Vec<DVec3>,
    /// Each lamp's corners, in order around it.
    pub corners: Vec<[DVec3; 4]>,
}

impl Lamps {
    fn push(&mut self, corner: DVec3, u: DVec3, v: DVec3, radiance: f64) {
        let quad = Quad::new(corner, u, v).expect("a lamp of some area");
        let normal = u.cross(v).normalize();
        self.powers.push(PI * radiance * u.cross(v).length());
        self.emission.push(Emission::OneSide(normal));
        self.normals.push(normal);
        self.corners
            .push([corner, corner + u, corner + u + v, corner + v]);
        self.quads.push(quad);
    }

    /// Lamp `i`'s radiance.
    pub fn radiance(&self, i: usize) -> f64 {
        self.powers[i] / (PI * self.quads[i].area())
    }

    /// hitkit's light tree over the lamps, each of its side.
    pub fn tree(&self) -> LightTree<Quad> {
        LightTree::new(self.quads.clone(), &self.powers, &self.emission).expect("valid lamps")
    }

    /// pbrt-v4's BVH light sampler over the lamps.
    pub fn pbrt(&self) -> PbrtLightBvh {
        let boxes: Vec<_> = self
            .quads
            .iter()
            .map(|q| (q.bounding_box().min(), q.bounding_box().max()))
            .collect();
        PbrtLightBvh::new(&boxes, &self.powers, &self.normals)
    }
}

/// About `n` lamps of a hall of kind `kind`, every length times `scale`; the same for every
/// seed.
pub fn lamps(kind: Hall, n: usize, scale: f64, seed: u64) -> Lamps {
    let mut rng = SplitMix::new(seed);
    let mut lamps = Lamps {
        quads: Vec::new(),
        powers: Vec::new(),
        emission: Vec::new(),
        normals: Vec::new(),
        corners: Vec::new(),
    };
    // A grid of `across` by `along` cells over the ceiling, `along = 10 across` for a
    // square cell.
    let grid = |count: usize| {
        let across = ((count as f64 / 10.0).sqrt().round() as usize).max(1);
        (across, (count / across).max(1))
    };
    let ceiling = HEIGHT * scale;
    match kind {
        Hall::Ceiling | Hall::Sizes | Hall::EdgeOn => {
            let (across, along) = grid(n);
            let (dx, dz) = (LENGTH / along as f64, WIDTH / across as f64);
            for i in 0..along {
                for j in 0..across {
                    let centre = DVec3::new((i as f64 + 0.5) * dx, 0.0, (j as f64 + 0.5) * dz);
                    match kind {
                        Hall::Ceiling => {
                            let s = 0.2 * dx.min(dz);
                            let c = (centre - DVec3::new(0.5 * s, 0.0, 0.5 * s)) * scale;
                            let (u, v) = (DVec3::X * s * scale, DVec3::Z * s * scale);
                            lamps.push(c + DVec3::Y * ceiling, u, v, 1.0);
                        }
                        Hall::Sizes => {
                            let cell = dx.min(dz);
                            let s = cell * (0.05 + 0.45 * rng.next_f64());
                            let slack = cell - s;
                            let at = centre
                                + DVec3::new(
                                    (rng.next_f64() - 0.5) * slack,
                                    0.0,
                                    (rng.next_f64() - 0.5) * slack,
                                )
                                - DVec3::new(0.5 * s, 0.0, 0.5 * s);
                            let (u, v) = (DVec3::X * s * scale, DVec3::Z * s * scale);
                            lamps.push(at * scale + DVec3::Y * ceiling, u, v, 1.0);
                        }
                        _ => {
                            // Upright, then tipped by up to 10 degrees about x, turned
                            // about y at random.
                            let s = 0.5 * dx.min(dz);
                            let turn = core::f64::consts::TAU * rng.next_f64();
                            let tip = (rng.next_f64() * 10.0).to_radians();
                            let across_dir = DVec3::new(turn.cos(), 0.0, turn.sin());
                            let down = DVec3::new(0.0, -tip.cos(), 0.0)
                                + across_dir.cross(DVec3::Y) * tip.sin();
                            let (u, v) = (across_dir * s * scale, down * s * scale);
                            let top = centre * scale + DVec3::Y * (ceiling - 0.1 * scale);
                            // Facing either way along its normal at random.
                            let (u, v) = if rng.next_f64() < 0.5 { (u, v) } else { (v, u) };
                            lamps.push(top, u, v, 1.0);
                        }
                    }
                }
            }
        }
        Hall::Room => {
            // Half on the ceiling, half on the walls by their lengths, in a band from 1 to
            // 3 high.
            let (across, along) = grid(n / 2);
            let (dx, dz) = (LENGTH / along as f64, WIDTH / across as f64);
            for i in 0..along {
                for j in 0..across {
                    let s = 0.2 * dx.min(dz);
                    let c = DVec3::new((i as f64 + 0.4) * dx, 0.0, (j as f64 + 0.4) * dz);
                    let (u, v) = (DVec3::X * s * scale, DVec3::Z * s * scale);
                    lamps.push(c * scale + DVec3::Y * ceiling, u, v, 1.0);
                }
            }
            let walls = n - lamps.quads.len();
            let perimeter = 2.0 * (LENGTH + WIDTH);
            let step = perimeter / walls as f64;
            for k in 0..walls {
                let along = (k as f64 + 0.5) * step;
                let y = 1.0 + 2.0 * rng.next_f64();
                let s = 0.3 * step.min(1.0);
                // Walk the walls: z = 0 (facing +z), x = LENGTH (-x), z = WIDTH (-z), x = 0.
                let (at, u, v) = if along < LENGTH {
                    (DVec3::new(along, y, 0.0), DVec3::X, DVec3::Y)
                } else if along < LENGTH + WIDTH {
                    (DVec3::new(LENGTH, y, along - LENGTH), DVec3::Z, DVec3::Y)
                } else if along < 2.0 * LENGTH + WIDTH {
                    let x = LENGTH - (along - LENGTH - WIDTH);
                    (DVec3::new(x, y, WIDTH), DVec3::NEG_X, DVec3::Y)
                } else {
                    let z = WIDTH - (along - 2.0 * LENGTH - WIDTH);
                    (DVec3::new(0.0, y, z), DVec3::NEG_Z, DVec3::Y)
                };
                lamps.push(at * scale, u * s * scale, v * s * scale, 1.0);
            }
        }
        Hall::Walls => {
            // Each wall of each room a row of lamps 0.5 in from its ends, in a band from 1
            // to 3 high; `u x v` faces into the room.
            let per_wall = (n / (4 * ROOMS)).max(1);
            let s = 0.3 * (9.0 / per_wall as f64).min(1.0);
            for r in 0..ROOMS {
                let (x0, x1) = (ROOM * r as f64, ROOM * (r + 1) as f64);
                for wall in 0..4 {
                    for k in 0..per_wall {
                        let along = 0.5 + 9.0 * (k as f64 + 0.5) / per_wall as f64;
                        let y = 1.0 + 2.0 * rng.next_f64();
                        let (at, u) = match wall {
                            0 => (DVec3::new(x0 + along, y, 0.0), DVec3::X),
                            1 => (DVec3::new(x1, y, along), DVec3::Z),
                            2 => (DVec3::new(x0 + along, y, WIDTH), DVec3::NEG_X),
                            _ => (DVec3::new(x0, y, along), DVec3::NEG_Z),
                        };
                        lamps.push(at * scale, u * s * scale, DVec3::Y * s * scale, 1.0);
                    }
                }
            }
        }
    }
    lamps
}

/// The rooms of [`Hall::Walls`], and their side.
const ROOMS: usize = 10;
const ROOM: f64 = 10.0;

/// `n` shading points of a hall at `scale`: on its floor ([`floor_points`]), or, for
/// [`Hall::Walls`], on its rooms' walls, facing into their room, 0.5 in from a wall's
/// ends and from the floor and ceiling; the same for every seed.
pub fn points(hall: Hall, n: usize, scale: f64, seed: u64) -> Vec<ShadingContext> {
    if hall != Hall::Walls {
        return floor_points(n, scale, seed);
    }
    let mut rng = SplitMix::new(seed ^ 0x3a11);
    (0..n)
        .map(|_| {
            let room = ((rng.next_f64() * ROOMS as f64) as usize).min(ROOMS - 1);
            let (x0, x1) = (ROOM * room as f64, ROOM * (room + 1) as f64);
            let along = 0.5 + 9.0 * rng.next_f64();
            let y = 0.5 + (HEIGHT - 1.0) * rng.next_f64();
            let (p, normal) = match (rng.next_f64() * 4.0) as usize {
                0 => (DVec3::new(x0 + along, y, 0.0), DVec3::Z),
                1 => (DVec3::new(x1, y, along), DVec3::NEG_X),
                2 => (DVec3::new(x0 + along, y, WIDTH), DVec3::NEG_Z),
                _ => (DVec3::new(x0, y, along), DVec3::X),
            };
            ShadingContext::on_surface(p * scale, normal)
        })
        .collect()
}

/// `n` shading points on the floor of a hall at `scale` (facing up), away from the walls
/// by half a unit; the same for every seed.
pub fn floor_points(n: usize, scale: f64, seed: u64) -> Vec<ShadingContext> {
    let mut rng = SplitMix::new(seed ^ 0x5eed);
    (0..n)
        .map(|_| {
            let x = 0.5 + (LENGTH - 1.0) * rng.next_f64();
            let z = 0.5 + (WIDTH - 1.0) * rng.next_f64();
            ShadingContext::on_surface(DVec3::new(x, 0.0, z) * scale, DVec3::Y)
        })
        .collect()
}

/// The irradiance lamp `i` sends to a surface at `at` (facing its normal, one side), by
/// Lambert's formula for a polygon of uniform radiance: `L / 2` times the sum over its
/// edges of the angle each subtends times the cosine between the receiver's normal and the
/// normal of the plane through the point and the edge. Every lamp of [`lamps`] lies
/// wholly above every [`points`] point's horizon, or (on the walls) wholly on or below it,
/// where it sends nothing: the formula holds unclipped.
pub fn irradiance(lamps: &Lamps, i: usize, at: &ShadingContext) -> f64 {
    let (p, n) = (at.point, at.normal.expect("a point on a surface"));
    let corners = lamps.corners[i];
    let q = corners[0];
    // One-sided: nothing where the point lies behind the lamp, or the lamp behind (or in
    // the plane of) the receiver.
    if (p - q).dot(lamps.normals[i]) <= 0.0 || corners.iter().all(|c| n.dot(*c - p) <= 0.0) {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..4 {
        let (a, b) = (
            (corners[k] - p).normalize(),
            (corners[(k + 1) % 4] - p).normalize(),
        );
        let cross = a.cross(b);
        let angle = cross.length().atan2(a.dot(b));
        if let Some(c) = cross.try_normalize() {
            sum += angle * c.dot(n);
        }
    }
    0.5 * lamps.radiance(i) * sum.abs()
}

/// The variance of a sampler's choice of lamp from `at`, relative to the square of the
/// total: `sum f_i^2 / p_i / F^2 - 1` for each lamp's irradiance `f_i` (its sum `F`) and
/// the probability `p_i` the sampler picks it with; 0 for a choice in proportion to the
/// irradiance, infinite where a lamp that lights the point is never picked. `None` where
/// no lamp lights the point.
pub fn choice_variance(
    lamps: &Lamps,
    at: &ShadingContext,
    probability: impl Fn(usize) -> f64,
) -> Option<f64> {
    let (mut total, mut second) = (0.0, 0.0);
    for i in 0..lamps.quads.len() {
        let f = irradiance(lamps, i, at);
        if f > 0.0 {
            total += f;
            second += f * f / probability(i);
        }
    }
    (total > 0.0).then(|| second / (total * total) - 1.0)
}

/// The mean of [`choice_variance`] over `points` (those no lamp lights left out), for a
/// sampler whose probability of lamp `i` from a point is `probability`.
pub fn mean_choice_variance(
    lamps: &Lamps,
    points: &[ShadingContext],
    probability: impl Fn(&ShadingContext, usize) -> f64,
) -> f64 {
    let v: Vec<f64> = points
        .iter()
        .filter_map(|at| choice_variance(lamps, at, |i| probability(at, i)))
        .collect();
    v.iter().sum::<f64>() / v.len() as f64
}

//! Seeds: inputs written as the bytes the targets read, so that fuzzing starts from the
//! hard cases the tests hold (shared edges and corners of quads and meshes, grazing and
//! far rays, scenes at 1e9, mirrored and stretched instances, lights seen from near their
//! corners) rather than from nothing. `examples/seeds.rs` writes them to `fuzz/seeds/`.
//!
//! Each value is written as `arbitrary`'s derived decoding reads it back: integers little
//! endian, a `bool` as a byte, a sequence as a `1` byte before each element and a `0` after
//! the last, an enum's variant as a `u32` that picks it, and every number as
//! [`Num`](crate::Num)'s tag 0 and its bits (exact). `tests` below decode what is written
//! and compare.

use hitkit::glam::DVec3;

use crate::{Crowd, LightInput, MeshInput, Num, Op, RaySpec, Spec, TreeInput, UpdateInput, V};

/// A value as the bytes `arbitrary` decodes it from.
pub trait Seed {
    fn write(&self, out: &mut Vec<u8>);

    fn bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        self.write(&mut out);
        out
    }
}

/// The `u32` with which a derived enum of `count` variants picks `index`:
/// `(u32 * count) >> 32 == index`.
fn variant(index: u32, count: u32, out: &mut Vec<u8>) {
    let pick = ((u64::from(index) << 32).div_ceil(u64::from(count))) as u32;
    out.extend(pick.to_le_bytes());
}

impl Seed for Num {
    fn write(&self, out: &mut Vec<u8>) {
        out.push(0);
        out.extend(self.0.to_bits().to_le_bytes());
    }
}

impl Seed for V {
    fn write(&self, out: &mut Vec<u8>) {
        self.0.write(out);
        self.1.write(out);
        self.2.write(out);
    }
}

impl Seed for bool {
    fn write(&self, out: &mut Vec<u8>) {
        out.push(u8::from(*self));
    }
}

impl Seed for u8 {
    fn write(&self, out: &mut Vec<u8>) {
        out.push(*self);
    }
}

impl Seed for u16 {
    fn write(&self, out: &mut Vec<u8>) {
        out.extend(self.to_le_bytes());
    }
}

impl<T: Seed, const N: usize> Seed for [T; N] {
    fn write(&self, out: &mut Vec<u8>) {
        self.iter().for_each(|x| x.write(out));
    }
}

impl<A: Seed, B: Seed> Seed for (A, B) {
    fn write(&self, out: &mut Vec<u8>) {
        self.0.write(out);
        self.1.write(out);
    }
}

impl<T: Seed> Seed for Vec<T> {
    fn write(&self, out: &mut Vec<u8>) {
        for x in self {
            out.push(1);
            x.write(out);
        }
        out.push(0);
    }
}

impl<T: Seed> Seed for Option<T> {
    fn write(&self, out: &mut Vec<u8>) {
        self.is_some().write(out);
        if let Some(x) = self {
            x.write(out);
        }
    }
}

impl Seed for RaySpec {
    fn write(&self, out: &mut Vec<u8>) {
        self.origin.write(out);
        self.direction.write(out);
        self.bounded.write(out);
        self.min.write(out);
        self.max.write(out);
    }
}

impl Seed for Spec {
    fn write(&self, out: &mut Vec<u8>) {
        match self {
            Spec::Quad {
                q,
                u,
                v,
                interior,
                inner,
            } => {
                variant(0, 4, out);
                (*q, *u).write(out);
                v.write(out);
                interior.write(out);
                inner.write(out);
            }
            Spec::Sphere { centre, radius } => {
                variant(1, 4, out);
                (*centre, *radius).write(out);
            }
            Spec::Cuboid { a, b } => {
                variant(2, 4, out);
                (*a, *b).write(out);
            }
            Spec::Mapped {
                q,
                u,
                v,
                columns,
                offset,
            } => {
                variant(3, 4, out);
                (*q, *u).write(out);
                v.write(out);
                columns.write(out);
                offset.write(out);
            }
        }
    }
}

impl Seed for Op {
    fn write(&self, out: &mut Vec<u8>) {
        match self {
            Op::Insert(c, r) => {
                variant(0, 5, out);
                (*c, *r).write(out);
            }
            Op::Remove(k) => {
                variant(1, 5, out);
                k.write(out);
            }
            Op::Move(d) => {
                variant(2, 5, out);
                d.write(out);
            }
            Op::Optimize(share) => {
                variant(3, 5, out);
                share.write(out);
            }
            Op::Rebuild => variant(4, 5, out),
        }
    }
}

impl Seed for Crowd {
    fn write(&self, out: &mut Vec<u8>) {
        self.count.write(out);
        self.shrink.write(out);
        self.turn.write(out);
        (self.centre, self.along).write(out);
        self.aim.write(out);
    }
}

impl Seed for TreeInput {
    fn write(&self, out: &mut Vec<u8>) {
        self.shapes.write(out);
        self.rays.write(out);
        self.crowd.write(out);
    }
}

impl Seed for MeshInput {
    fn write(&self, out: &mut Vec<u8>) {
        self.vertices.write(out);
        self.faces.write(out);
        self.moved.write(out);
        self.rays.write(out);
        self.crowd.write(out);
    }
}

impl Seed for UpdateInput {
    fn write(&self, out: &mut Vec<u8>) {
        self.start.write(out);
        self.ops.write(out);
        self.rays.write(out);
        self.crowd.write(out);
    }
}

impl Seed for LightInput {
    fn write(&self, out: &mut Vec<u8>) {
        self.light.write(out);
        self.origin.write(out);
        self.normal.write(out);
        self.samples.write(out);
    }
}

/// A number, exactly.
pub fn num(x: f64) -> Num {
    Num(x)
}

/// A vector, exactly.
pub fn v(p: DVec3) -> V {
    V(Num(p.x), Num(p.y), Num(p.z))
}

/// A ray over `[0, inf)`.
pub fn ray(origin: DVec3, direction: DVec3) -> RaySpec {
    RaySpec {
        origin: v(origin),
        direction: v(direction),
        bounded: false,
        min: Num(0.0),
        max: Num(f64::INFINITY),
    }
}

#[cfg(test)]
mod tests {
    use arbitrary::{Arbitrary, Unstructured};

    use super::*;

    /// What is written decodes as the value written (by `Debug`, which prints every number
    /// exactly).
    fn round_trip<'a, T: Seed + Arbitrary<'a> + core::fmt::Debug>(value: &T, bytes: &'a [u8]) {
        let back = T::arbitrary_take_rest(Unstructured::new(bytes)).unwrap();
        assert_eq!(format!("{back:?}"), format!("{value:?}"));
    }

    #[test]
    fn seeds_decode_as_written() {
        let tree = TreeInput {
            shapes: vec![
                Spec::Quad {
                    q: v(DVec3::new(1e9 + 0.3, -2.5, 7.0)),
                    u: v(DVec3::X),
                    v: v(DVec3::Y * 3.0),
                    interior: 3,
                    inner: num(0.25),
                },
                Spec::Sphere {
                    centre: v(DVec3::ZERO),
                    radius: num(-1.0),
                },
                Spec::Cuboid {
                    a: v(DVec3::ONE),
                    b: v(DVec3::NAN),
                },
                Spec::Mapped {
                    q: v(DVec3::ZERO),
                    u: v(DVec3::X),
                    v: v(DVec3::Z),
                    columns: [v(DVec3::X), v(DVec3::Y * 1e-3), v(-DVec3::Z)],
                    offset: v(DVec3::splat(5.0)),
                },
            ],
            rays: vec![ray(DVec3::ZERO, DVec3::ONE), ray(DVec3::ONE, DVec3::NEG_Y)],
            crowd: Some(Crowd {
                count: 700,
                shrink: 3,
                turn: 255,
                centre: v(DVec3::ONE),
                along: v(DVec3::Z * 1e-3),
                aim: true,
            }),
        };
        round_trip(&tree, &tree.bytes());
        let update = UpdateInput {
            start: vec![(v(DVec3::ONE), num(0.5))],
            ops: vec![
                Op::Insert(v(DVec3::ZERO), num(1.0)),
                Op::Remove(7),
                Op::Move(v(DVec3::X)),
                Op::Optimize(200),
                Op::Rebuild,
            ],
            rays: vec![ray(DVec3::Z, -DVec3::Z)],
            crowd: None,
        };
        round_trip(&update, &update.bytes());
        let mesh = MeshInput {
            vertices: vec![v(DVec3::X), v(DVec3::Y)],
            faces: vec![[0, 1, 255]],
            moved: vec![v(DVec3::Z)],
            rays: vec![ray(DVec3::ZERO, DVec3::X)],
            crowd: Some(Crowd {
                count: 0,
                shrink: 0,
                turn: 0,
                centre: v(DVec3::ZERO),
                along: v(DVec3::ZERO),
                aim: false,
            }),
        };
        round_trip(&mesh, &mesh.bytes());
        let light = LightInput {
            light: Spec::Sphere {
                centre: v(DVec3::ONE),
                radius: num(2.0),
            },
            origin: v(DVec3::ZERO),
            normal: Some(v(DVec3::Y)),
            samples: vec![(0, 0), (u16::MAX, 3)],
        };
        round_trip(&light, &light.bytes());
    }
}

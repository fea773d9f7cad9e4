//! Writes `fuzz/seeds/<target>/<case>`: the hard cases of hitkit's tests as the targets'
//! inputs (`cargo run --manifest-path fuzz/Cargo.toml --example seeds`). Each is decoded
//! again before it is written, to the value it was built from.

use std::fs;
use std::path::Path;

use arbitrary::{Arbitrary, Unstructured};
use hitkit::glam::{DMat3, DVec3};
use hitkit_fuzz::seed::{Seed, num, ray, v};
use hitkit_fuzz::{Crowd, LightInput, MeshInput, Op, RaySpec, Spec, TreeInput, UpdateInput};

/// An offset that rounds every corner built from it (not a power of two), and a size.
const FAR: f64 = 1.0e9 + 0.3;
const SIZE: f64 = 1.7;

fn write<T: Seed + for<'a> Arbitrary<'a> + core::fmt::Debug>(dir: &Path, name: &str, value: &T) {
    let bytes = value.bytes();
    let back = T::arbitrary_take_rest(Unstructured::new(&bytes)).expect("decodes");
    assert_eq!(format!("{back:?}"), format!("{value:?}"), "{name}");
    fs::create_dir_all(dir).unwrap();
    fs::write(dir.join(name), &bytes).unwrap();
}

/// The corners of a box of side `size` at `offset`, turned by `turn` (rounded one by one,
/// as a scene built in world space rounds them).
fn corners(offset: DVec3, size: f64, turn: DMat3) -> [DVec3; 8] {
    core::array::from_fn(|i| {
        let c = DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        offset + turn * (size * c)
    })
}

/// The six faces of the box of `corners` as quads (`q`, `u`, `v` from corner differences).
fn faces(c: &[DVec3; 8]) -> Vec<Spec> {
    [
        (0, 1, 2),
        (4, 6, 5),
        (0, 4, 1),
        (2, 3, 6),
        (0, 2, 4),
        (1, 5, 3),
    ]
    .iter()
    .map(|&(q, a, b)| Spec::Quad {
        q: v(c[q]),
        u: v(c[a] - c[q]),
        v: v(c[b] - c[q]),
        interior: 0,
        inner: num(0.0),
    })
    .collect()
}

/// Rays at the box's edges and corners, from outside and from its middle, and one grazing
/// a face.
fn rays_at(c: &[DVec3; 8]) -> Vec<RaySpec> {
    let middle = 0.5 * (c[0] + c[7]);
    let outside = middle + 3.0 * (c[7] - c[0]);
    let mut rays = Vec::new();
    for target in [
        c[0],
        c[7],
        0.5 * (c[0] + c[1]),
        0.5 * (c[1] + c[3]),
        0.5 * (c[0] + c[3]),
    ] {
        rays.push(ray(outside, target - outside));
        rays.push(ray(middle, target - middle));
    }
    rays.push(ray(c[0] - (c[1] - c[0]), c[1] - c[0]));
    rays
}

fn turn() -> DMat3 {
    DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7)
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds");
    let tree = root.join("tree");
    for (name, offset, size, turn) in [
        ("box-at-origin", DVec3::ZERO, 1.0, DMat3::IDENTITY),
        ("box-far", DVec3::splat(FAR), SIZE, DMat3::IDENTITY),
        ("box-turned-far", DVec3::splat(FAR), SIZE, turn()),
        ("box-tiny-far", DVec3::splat(1.7e12 + 0.1), 1.3e-3, turn()),
        ("box-huge", DVec3::splat(-3.3e9), 1.3e6, turn()),
    ] {
        let c = corners(offset, size, turn);
        let mut shapes = faces(&c);
        shapes.push(Spec::Sphere {
            centre: v(0.5 * (c[0] + c[7])),
            radius: num(0.25 * size),
        });
        shapes.push(Spec::Cuboid {
            a: v(c[0]),
            b: v(c[0] + DVec3::splat(0.5 * size)),
        });
        let rays = rays_at(&c);
        write(
            &tree,
            name,
            &TreeInput {
                shapes,
                rays,
                crowd: None,
            },
        );
    }
    // Disks, rings and triangles, grazed; and instances stretched and mirrored.
    let mut shapes = Vec::new();
    for (k, interior) in [1u8, 2, 3].into_iter().enumerate() {
        shapes.push(Spec::Quad {
            q: v(DVec3::new(3.0 * k as f64, 0.0, 0.0)),
            u: v(DVec3::X),
            v: v(DVec3::Y),
            interior,
            inner: num(0.5),
        });
    }
    for (k, columns) in [
        [DVec3::X * -1.0, DVec3::Y * 8.0, DVec3::Z * 0.125],
        [DVec3::new(1.0, 1.0, 0.0), DVec3::Y, DVec3::Z * 1e-3],
    ]
    .into_iter()
    .enumerate()
    {
        shapes.push(Spec::Mapped {
            q: v(DVec3::ZERO),
            u: v(DVec3::X),
            v: v(DVec3::Z),
            columns: columns.map(v),
            offset: v(DVec3::new(0.0, 5.0 + 3.0 * k as f64, FAR)),
        });
    }
    let rays = vec![
        ray(DVec3::new(-1.0, 0.5, 1e-12), DVec3::new(1.0, 0.0, -1e-12)),
        ray(DVec3::new(1.0, 1.0, 1.0), -DVec3::ONE),
        ray(DVec3::new(6.5, 0.5, 1.0), -DVec3::Z),
        ray(DVec3::new(0.5, 5.0, FAR + 1.0), -DVec3::Z),
    ];
    write(
        &tree,
        "interiors-and-instances",
        &TreeInput {
            shapes,
            rays,
            crowd: None,
        },
    );

    // A closed mesh (a box of twelve triangles) sharing every edge, and a fan sharing a
    // vertex; rays through its corners and edges; moved by a little.
    let mesh = root.join("mesh");
    for (name, offset, turn) in [
        ("box-mesh", DVec3::ZERO, DMat3::IDENTITY),
        ("box-mesh-turned-far", DVec3::splat(1.1e6 + 0.3), turn()),
    ] {
        let c = corners(offset, SIZE, turn);
        let faces: Vec<[u8; 3]> = [
            [0, 1, 3],
            [0, 3, 2],
            [4, 6, 7],
            [4, 7, 5],
            [0, 4, 5],
            [0, 5, 1],
            [2, 3, 7],
            [2, 7, 6],
            [0, 2, 6],
            [0, 6, 4],
            [1, 5, 7],
            [1, 7, 3],
        ]
        .to_vec();
        let input = MeshInput {
            vertices: c.iter().map(|&p| v(p)).collect(),
            faces,
            moved: (0..8).map(|i| v(DVec3::splat(1e-3 * i as f64))).collect(),
            rays: rays_at(&c),
            crowd: None,
        };
        write(&mesh, name, &input);
    }
    let fan: Vec<DVec3> = std::iter::once(DVec3::ZERO)
        .chain((0..8).map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 8.0;
            DVec3::new(a.cos(), a.sin(), 0.0)
        }))
        .collect();
    write(
        &mesh,
        "fan",
        &MeshInput {
            vertices: fan.iter().map(|&p| v(p)).collect(),
            faces: (1..=8u8).map(|k| [0, k, k % 8 + 1]).collect(),
            moved: vec![v(DVec3::Z * 0.25)],
            rays: vec![
                ray(DVec3::Z, -DVec3::Z),
                ray(DVec3::new(0.5, 0.0, 1.0), -DVec3::Z),
            ],
            crowd: None,
        },
    );

    // A row of balls changed every way.
    let update = root.join("update");
    let start: Vec<_> = (0..40)
        .map(|i| (v(DVec3::new(i as f64, 0.0, 0.0)), num(0.4)))
        .collect();
    let ops = vec![
        Op::Remove(3),
        Op::Insert(v(DVec3::new(3.0, 0.0, 0.0)), num(0.4)),
        Op::Move(v(DVec3::Y * 5.0)),
        Op::Optimize(64),
        Op::Remove(40),
        Op::Move(v(DVec3::Y * -5.0)),
        Op::Rebuild,
        Op::Insert(v(DVec3::new(FAR, 0.0, 0.0)), num(1e-3)),
    ];
    let rays = (0..8)
        .map(|i| ray(DVec3::new(i as f64 * 5.0, 2.0, 0.0), -DVec3::Y))
        .chain([ray(DVec3::new(-1.0, 0.0, 0.0), DVec3::X)])
        .collect();
    write(
        &update,
        "row",
        &UpdateInput {
            start,
            ops,
            rays,
            crowd: None,
        },
    );
    crowds(&root);

    // Lights seen from near and far, from beside a corner, from inside a sphere and from
    // within rounding of a plane; every corner of the square.
    let light = root.join("light");
    let corners_of_square = vec![(0, 0), (0, u16::MAX), (u16::MAX, 0), (u16::MAX, u16::MAX)];
    let square = |interior: u8| Spec::Quad {
        q: v(DVec3::new(-1.0, 1.0, -1.0)),
        u: v(DVec3::X * 2.0),
        v: v(DVec3::Z * 2.0),
        interior,
        inner: num(0.5),
    };
    for (name, spec, origin) in [
        ("square-near", square(0), DVec3::new(0.3, 0.0, 0.2)),
        ("square-far", square(0), DVec3::new(0.0, -1e6, 0.0)),
        (
            "triangle-corner",
            square(1),
            DVec3::new(-1.0, 1.0, -1.0) + 1e-9,
        ),
        ("disk-edge-on", square(2), DVec3::new(3.0, 1.0, 0.0)),
        ("ring-near", square(3), DVec3::new(0.0, 0.99, 0.0)),
        (
            "sphere-inside",
            Spec::Sphere {
                centre: v(DVec3::ZERO),
                radius: num(2.0),
            },
            DVec3::new(0.5, 0.0, 0.0),
        ),
        (
            "sphere-grazing",
            Spec::Sphere {
                centre: v(DVec3::splat(FAR)),
                radius: num(SIZE),
            },
            DVec3::splat(FAR) + DVec3::new(SIZE, 0.0, 0.0) + 1e-6,
        ),
        (
            "mapped-stretched",
            Spec::Mapped {
                q: v(DVec3::ZERO),
                u: v(DVec3::X),
                v: v(DVec3::Z),
                columns: [
                    v(DVec3::X * 8.0),
                    v(DVec3::Y),
                    v(DVec3::new(0.0, 1.0, 0.125)),
                ],
                offset: v(DVec3::new(0.0, 3.0, 0.0)),
            },
            DVec3::ZERO,
        ),
    ] {
        let input = LightInput {
            light: spec,
            origin: v(origin),
            normal: Some(v(DVec3::Y)),
            samples: corners_of_square.clone(),
        };
        write(&light, name, &input);
    }
}

/// Crowds, the walks' worst case: every child of every node entered, level after level.
/// Coincident copies and nested shells of a quad and a ball, strands along a line, a fan of
/// slivers meeting at a point, and nested balls inserted one by one; rays aimed at where
/// they meet, from every side.
fn crowds(root: &Path) {
    let crowd = |count: u16, shrink: u8, turn: u8, along: DVec3| Crowd {
        count,
        shrink,
        turn,
        centre: v(DVec3::new(0.25, 0.5, 0.0)),
        along: v(along),
        aim: true,
    };
    let around: Vec<RaySpec> = (0..12)
        .map(|k| {
            let a = k as f64 * 0.55;
            let from = 4.0 * DVec3::new(a.cos() * a.sin(), a.sin(), a.cos());
            ray(from, -from)
        })
        .collect();
    let shapes = vec![
        Spec::Quad {
            q: v(DVec3::new(-0.5, 0.0, -0.5)),
            u: v(DVec3::new(1.5, 0.25, 0.0)),
            v: v(DVec3::new(0.0, 0.25, 1.0)),
            interior: 0,
            inner: num(0.0),
        },
        Spec::Sphere {
            centre: v(DVec3::new(0.25, 0.5, 0.0)),
            radius: num(0.75),
        },
    ];
    let tree = root.join("tree");
    for (name, crowd) in [
        ("crowd-coincident", crowd(1023, 0, 0, DVec3::ZERO)),
        ("crowd-nested", crowd(1023, 200, 0, DVec3::ZERO)),
        (
            "crowd-strands",
            crowd(1023, 0, 64, DVec3::new(0.0, 0.0, 10.0)),
        ),
    ] {
        let input = TreeInput {
            shapes: shapes.clone(),
            rays: around.clone(),
            crowd: Some(crowd),
        };
        write(&tree, name, &input);
    }
    // A sliver from the crowd's point, turned about the z axis once round: a fan of 1,024.
    let mesh = MeshInput {
        vertices: [
            DVec3::new(0.25, 0.5, 0.0),
            DVec3::new(1.25, 0.5, 3.0),
            DVec3::new(1.26, 0.52, 3.0),
        ]
        .map(v)
        .to_vec(),
        faces: vec![[0, 1, 2]],
        moved: vec![v(DVec3::ZERO)],
        rays: around.clone(),
        crowd: Some(crowd(1023, 0, 255, DVec3::ZERO)),
    };
    write(&root.join("mesh"), "crowd-fan", &mesh);
    let update = UpdateInput {
        start: vec![(v(DVec3::new(0.25, 0.5, 0.0)), num(2.0))],
        ops: vec![Op::Optimize(80), Op::Remove(5)],
        rays: around,
        crowd: Some(crowd(511, 250, 0, DVec3::ZERO)),
    };
    write(&root.join("update"), "crowd-nested-inserts", &update);
}

//! A `TriangleMesh` of arbitrary vertices and faces (bad ones an error, never a panic)
//! answers every arbitrary ray as the loop over its faces: the same face, the same `t`;
//! `occluded` as whether the loop finds one; and after `set_vertices`, as a mesh built
//! anew from the moved vertices. With a crowd, copies of the mesh about one point or along
//! one line (coincident faces, nested shells, fans of slivers), and rays aimed there.

#![no_main]

use hitkit::glam::DVec3;
use hitkit::{Hittable, Interval, Ray, TriangleMesh};
use hitkit_fuzz::{MeshInput, check_record, closest, rays};
use libfuzzer_sys::fuzz_target;

/// The mesh's answer and the loop's over its faces agree on every ray.
fn agree(mesh: &TriangleMesh, rays: &[(Ray, Interval)]) {
    // In the caller's numbering, which ties go by.
    let mut faces: Vec<_> = mesh.faces().collect();
    faces.sort_by_key(|f| f.index());
    let list: Vec<&dyn Hittable> = faces.iter().map(|f| f as &dyn Hittable).collect();
    for &(ray, ray_t) in rays {
        let expected = closest(&list, &ray, ray_t);
        let found = mesh.hit(&ray, ray_t);
        assert_eq!(
            found.map(|h| (h.primitive, h.t.to_bits())),
            expected.map(|(i, h)| (Some(faces[i].index()), h.t.to_bits())),
            "the mesh and the loop over its faces disagree on {ray:?} over {ray_t:?}"
        );
        assert_eq!(
            mesh.occluded(&ray, ray_t),
            expected.is_some(),
            "occluded on {ray:?}"
        );
        if let Some(hit) = found {
            check_record(&hit, ray_t, "mesh");
        }
    }
}

/// Faces in all, at most, where a crowd copies them.
const CROWD_FACES: usize = 4096;

fuzz_target!(|input: MeshInput| {
    let mut vertices: Vec<DVec3> = input.vertices.iter().map(|v| v.get()).collect();
    let n = vertices.len().max(1) as u32;
    // Indices mostly in range (a face out of range is an error to report, once in a while).
    let mut faces: Vec<[u32; 3]> = input
        .faces
        .iter()
        .map(|f| f.map(|k| if k == 255 { u32::MAX } else { u32::from(k) % n }))
        .collect();
    if let Some(crowd) = &input.crowd
        && !faces.is_empty()
    {
        // Copies of the whole mesh about the crowd's point and along its line (a face with
        // a corner at the point, turned, makes a fan of slivers meeting there).
        let (base, first) = (vertices.clone(), faces.clone());
        for i in 1..crowd.count().min(CROWD_FACES / first.len()) {
            let map = crowd.map(i);
            let shift = (i * base.len()) as u32;
            vertices.extend(base.iter().map(|&p| map.transform_point3(p)));
            faces.extend(first.iter().map(|f| f.map(|k| k.saturating_add(shift))));
        }
    }
    let rays = rays(&input.rays, input.crowd.as_ref());
    let Ok(mut mesh) = TriangleMesh::new(&vertices, &faces) else {
        return;
    };
    agree(&mesh, &rays);
    // The same count of moved vertices (any other count is an error).
    let moved: Vec<DVec3> = vertices
        .iter()
        .zip(input.moved.iter().cycle())
        .map(|(p, d)| *p + d.get())
        .collect();
    if moved.len() != vertices.len() {
        return;
    }
    match (mesh.set_vertices(&moved), TriangleMesh::new(&moved, &faces)) {
        (Ok(()), Ok(rebuilt)) => {
            agree(&mesh, &rays);
            for &(ray, ray_t) in &rays {
                assert_eq!(
                    mesh.hit(&ray, ray_t).map(|h| (h.primitive, h.t.to_bits())),
                    rebuilt
                        .hit(&ray, ray_t)
                        .map(|h| (h.primitive, h.t.to_bits())),
                    "updated in place and rebuilt disagree on {ray:?}"
                );
            }
        }
        (Err(_), Err(_)) => {}
        (a, b) => panic!("set_vertices {a:?} but a new mesh {:?}", b.map(|_| ())),
    }
});

//! Embree 3 (the system's library, through the `embree3` crate) in the triad: the ceiling.
//! `rtcIntersect1` and `rtcOccluded1` on its own `f32` triangles, medium build quality,
//! robust mode off. Built only with the `embree` feature (`apt-get install libembree-dev`).

use std::sync::Arc;
use std::sync::atomic::{AtomicIsize, Ordering::Relaxed};

use embree3::{
    BufferUsage, BuildQuality, Device, Format, GeometryKind, IntersectContext, Ray as ERay, RayHit,
    Scene as EScene,
};
use hitkit::Ray;

use crate::Hit;
use crate::library::{Library, ftz_daz};

/// A scene built in Embree, and the bytes its device held after the build.
pub struct Embree<'a> {
    // (The scene before the device: it is released first.)
    scene: EScene<'static>,
    _device: Device,
    position: &'a [usize],
    /// What Embree's memory monitor counted after the build.
    pub bytes: isize,
}

impl<'a> Embree<'a> {
    /// The mesh `vertices`/`faces` in Embree. Making a device turns FTZ/DAZ on (the
    /// `embree3` crate does, as Embree recommends); the register is put back as it was, so
    /// that every library is timed in the same mode.
    pub fn new(
        vertices: &[hitkit::glam::DVec3],
        faces: &[[u32; 3]],
        position: &'a [usize],
    ) -> Self {
        let old = ftz_daz(false);
        let device = Device::new().expect("an Embree device");
        ftz_daz(old & 0x8040 != 0);
        let bytes = Arc::new(AtomicIsize::new(0));
        let counter = Arc::clone(&bytes);
        // Embree reports an allocation before it happens and a release after.
        device.set_memory_monitor_function(move |b, _| {
            counter.fetch_add(b, Relaxed);
            true
        });
        let mut scene = device.create_scene().expect("an Embree scene");
        scene.set_build_quality(BuildQuality::MEDIUM);
        let mut geometry = device
            .create_geometry(GeometryKind::TRIANGLE)
            .expect("an Embree triangle geometry");
        geometry
            .set_new_buffer::<[f32; 3]>(BufferUsage::VERTEX, 0, Format::FLOAT3, 12, vertices.len())
            .expect("a vertex buffer")
            .copy_from_slice(
                &vertices
                    .iter()
                    .map(|v| v.as_vec3().to_array())
                    .collect::<Vec<_>>(),
            );
        geometry
            .set_new_buffer::<[u32; 3]>(BufferUsage::INDEX, 0, Format::UINT3, 12, faces.len())
            .expect("an index buffer")
            .copy_from_slice(faces);
        let geometry = geometry.commit();
        scene.attach_geometry(&geometry);
        scene.commit();
        let bytes = bytes.load(Relaxed);
        Self {
            scene,
            _device: device,
            position,
            bytes,
        }
    }

    /// The ray in `f32`, starting at obvhs's `t = 1e-4` (`OBVHS_T_MIN`): Embree has no
    /// `spawn_ray`, and from `t = 0` its bounce and shadow rays find the surface they leave
    /// (on the bunny, 26,030 of 56,809 bounces, at `--side 500`).
    fn ray(ray: &Ray, t_max: f32) -> ERay {
        ERay::segment(
            ray.origin.as_vec3().to_array(),
            ray.direction.as_vec3().to_array(),
            crate::triad::OBVHS_T_MIN,
            t_max,
        )
    }
}

impl Library for Embree<'_> {
    fn name(&self) -> String {
        "Embree 3.13 (f32, medium, not robust)".into()
    }
    fn closest(&self, ray: &Ray) -> Hit {
        let mut hit = RayHit::from(Self::ray(ray, f32::INFINITY));
        self.scene
            .intersect(&mut IntersectContext::incoherent(), &mut hit);
        hit.hit.is_valid().then(|| {
            (
                self.position[hit.hit.primID as usize],
                f64::from(hit.ray.tfar),
            )
        })
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.scene.occluded(
            &mut IntersectContext::incoherent(),
            &mut Self::ray(ray, 1.0),
        )
    }
    fn count(&self, _: &Ray, _: bool) -> Option<(u32, u32)> {
        None
    }
}

//! The third stage: the scene's nodes walked from their roots, each mesh placed under its
//! node's transform composed with its parents' (and at each of its
//! `EXT_mesh_gpu_instancing` instances), each camera where its node puts it.

use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec;
use std::vec::Vec;

use glam::{DAffine3, DMat4, DQuat, DVec3};
use gltf::accessor::{DataType, Dimensions};

use super::accessors::check_accessor;
use super::{GltfCamera, GltfInstance, GltfMesh, GltfPunctual, LeftOut, Projection};
use crate::load::{LoadError, LoadErrorKind};
use crate::{GeometryError, Transformed};

/// What the walk places: instances, cameras and lights.
type Placed = (Vec<GltfInstance>, Vec<GltfCamera>, Vec<GltfPunctual>);

/// The instances, cameras and lights of scene `scene` (the file's default scene, else its
/// first, where `None`), in the order a depth-first walk in the file's order meets them;
/// the lights' materials numbered from `first_light`.
pub(super) fn place(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    (meshes, placed): (&[GltfMesh], &[Vec<Option<usize>>]),
    first_light: usize,
    scene: Option<gltf::Scene>,
    path: &Path,
    left_out: &mut Vec<LeftOut>,
) -> Result<Placed, LoadError> {
    let (mut instances, mut cameras, mut punctual) = (Vec::new(), Vec::new(), Vec::new());
    let Some(scene) = scene else {
        return Ok((instances, cameras, punctual));
    };
    // A node met twice (a cycle, or two parents, which glTF forbids) is an error rather
    // than a walk without end.
    let mut stack: Vec<(gltf::Node, DMat4)> = scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    stack.reverse();
    let mut seen = vec![false; document.nodes().count()];
    while let Some((node, parent)) = stack.pop() {
        if core::mem::replace(&mut seen[node.index()], true) {
            let what = format!(
                "node {} is reached twice in the scene's hierarchy",
                node.index()
            );
            return Err(LoadError::new(path, LoadErrorKind::Parse(what)));
        }
        let name = node
            .name()
            .map_or_else(|| format!("node {}", node.index()), ToString::to_string);
        let local = match local_transform(&node) {
            Ok(local) => local,
            Err(error) => {
                // Not a rotation: nothing under the node has a place (its children are
                // left out with it, named by it).
                left_out.push(LeftOut::Node { node: name, error });
                continue;
            }
        };
        let world = parent * local;
        if let Some(camera) = node.camera() {
            cameras.push(camera_at(&camera, name.clone(), world));
        }
        if let Some(light) = node.light() {
            let id =
                crate::MaterialId(u32::try_from(first_light + punctual.len()).unwrap_or(u32::MAX));
            match super::lights::punctual_at(&light, name.clone(), world, id) {
                Ok(light) => punctual.push(light),
                Err(error) => left_out.push(LeftOut::Light {
                    node: name.clone(),
                    error,
                }),
            }
        }
        if let Some(mesh) = node.mesh() {
            // `EXT_mesh_gpu_instancing`: the node's mesh at each instance's place, under
            // the node's transform; each instance named by its number after `#`.
            let locals = match node.extension_value("EXT_mesh_gpu_instancing") {
                None => vec![(name.clone(), DMat4::IDENTITY)],
                Some(value) => gpu_instances(value, document, buffers)
                    .map_err(|(accessor, problem)| {
                        LoadError::new(
                            path,
                            LoadErrorKind::Malformed {
                                mesh: format!("{name} (EXT_mesh_gpu_instancing)"),
                                accessor,
                                problem,
                            },
                        )
                    })?
                    .into_iter()
                    .enumerate()
                    .map(|(k, local)| (format!("{name}#{k}"), local))
                    .collect(),
            };
            for (name, local) in locals {
                let transform = DAffine3::from_mat4(world * local);
                let places = placed[mesh.index()].iter().flatten();
                // A transform that places nothing (a zero scale hides a part), or moves
                // a primitive past f64's range: the node is left out, named, rather
                // than failing `transformed`.
                let refused = places
                    .clone()
                    .find_map(|&m| Transformed::affine(meshes[m].mesh.clone(), transform).err());
                match refused {
                    Some(error) => left_out.push(LeftOut::Node { node: name, error }),
                    None => instances.extend(places.map(|&m| GltfInstance {
                        node: name.clone(),
                        mesh: m,
                        transform,
                    })),
                }
            }
        }
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok((instances, cameras, punctual))
}

/// A node's transform, parent from node: its matrix, or `T * R * S` of its translation,
/// rotation and scale in `f64`, the rotation normalized; an error for a rotation that is no
/// unit quaternion to within what `f32` storage and an exporter's rounding leave (a
/// squared length off 1 by more than 1e-3: a zero quaternion, say), or that is not finite.
fn local_transform(node: &gltf::Node) -> Result<DMat4, GeometryError> {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            Ok(DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from))))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let turn = DQuat::from_array(rotation.map(f64::from));
            let length = turn.length_squared();
            if !((1.0 - 1e-3)..=(1.0 + 1e-3)).contains(&length) {
                return Err(GeometryError::InvalidParameter {
                    what: "node rotation's squared length",
                    value: length,
                    domain: "a unit quaternion: 1 (to within 1e-3)",
                });
            }
            Ok(DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                turn.normalize(),
                DVec3::from_array(translation.map(f64::from)),
            ))
        }
    }
}

/// A camera of node `name`, whose transform composed with its parents' is `world`.
fn camera_at(camera: &gltf::Camera, name: String, world: DMat4) -> GltfCamera {
    GltfCamera {
        node: name,
        transform: DAffine3::from_mat4(world),
        projection: match camera.projection() {
            gltf::camera::Projection::Perspective(p) => Projection::Perspective {
                yfov: f64::from(p.yfov()),
                aspect_ratio: p.aspect_ratio().map(f64::from),
            },
            gltf::camera::Projection::Orthographic(o) => Projection::Orthographic {
                xmag: f64::from(o.xmag()),
                ymag: f64::from(o.ymag()),
            },
        },
    }
}

/// The places of a node's `EXT_mesh_gpu_instancing` instances (its `value`): each
/// `T * R * S` of its `TRANSLATION`, `ROTATION` and `SCALE` (each optional, all of one
/// count), in the node's space. The accessor and what is wrong where they cannot be read.
fn gpu_instances(
    value: &gltf::json::Value,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<DMat4>, (usize, String)> {
    use gltf::accessor::Iter;
    let get = |b: gltf::Buffer| buffers.get(b.index()).map(|d| &d.0[..]);
    let named = |key: &str| -> Result<Option<gltf::Accessor>, (usize, String)> {
        let Some(index) = value.get("attributes").and_then(|a| a.get(key)) else {
            return Ok(None);
        };
        let index = index
            .as_u64()
            .map_or(usize::MAX, |i| usize::try_from(i).unwrap_or(usize::MAX));
        document
            .accessors()
            .nth(index)
            .map(Some)
            .ok_or_else(|| (index, format!("no such accessor for {key}")))
    };
    let (translation, rotation, scale) =
        (named("TRANSLATION")?, named("ROTATION")?, named("SCALE")?);
    let vec3 = [(Dimensions::Vec3, DataType::F32)];
    let quaternion = [
        (Dimensions::Vec4, DataType::F32),
        (Dimensions::Vec4, DataType::I8),
        (Dimensions::Vec4, DataType::I16),
    ];
    let mut count = None;
    for (accessor, allowed) in [
        (&translation, &vec3[..]),
        (&rotation, &quaternion[..]),
        (&scale, &vec3[..]),
    ] {
        if let Some(a) = accessor {
            check_accessor(a, allowed, buffers).map_err(|p| (a.index(), p))?;
            if *count.get_or_insert(a.count()) != a.count() {
                return Err((
                    a.index(),
                    format!(
                        "{} instances, where another attribute has {}",
                        a.count(),
                        count.unwrap_or(0)
                    ),
                ));
            }
        }
    }
    let Some(count) = count else {
        // No attribute (glTF asks at least one): the node's one place.
        return Ok(vec![DMat4::IDENTITY]);
    };
    let vectors = |a: &Option<gltf::Accessor>, default: DVec3| -> Vec<DVec3> {
        a.clone()
            .and_then(|a| Iter::<[f32; 3]>::new(a, get))
            .map_or_else(
                || vec![default; count],
                |it| it.map(|v| DVec3::from_array(v.map(f64::from))).collect(),
            )
    };
    let translations = vectors(&translation, DVec3::ZERO);
    let scales = vectors(&scale, DVec3::ONE);
    let rotations: Vec<glam::DQuat> = match rotation {
        None => vec![glam::DQuat::IDENTITY; count],
        Some(a) => {
            use gltf::animation::util::Rotations;
            let read = match a.data_type() {
                DataType::I8 => Iter::new(a, get).map(Rotations::I8),
                DataType::I16 => Iter::new(a, get).map(Rotations::I16),
                _ => Iter::new(a, get).map(Rotations::F32),
            };
            read.map(|r| {
                r.into_f32()
                    .map(|q| {
                        let q = glam::DQuat::from_array(q.map(f64::from));
                        // A zero quaternion (no rotation at all) stays one, which glam
                        // turns as the identity.
                        if q.length_squared() > 0.0 {
                            q.normalize()
                        } else {
                            q
                        }
                    })
                    .collect()
            })
            .unwrap_or_default()
        }
    };
    Ok((0..count)
        .map(|k| {
            let at = |v: &[DVec3], default| v.get(k).copied().unwrap_or(default);
            let turn = rotations.get(k).copied().unwrap_or(glam::DQuat::IDENTITY);
            DMat4::from_translation(at(&translations, DVec3::ZERO))
                * DMat4::from_quat(turn)
                * DMat4::from_scale(at(&scales, DVec3::ONE))
        })
        .collect())
}

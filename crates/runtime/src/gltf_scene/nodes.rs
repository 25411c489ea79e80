//! The scene's node trees (glTF §3.5): the meshes, cameras and `KHR_lights_punctual`
//! lights they place, in world space.

use super::error::GltfError;
use super::model::{GltfCamera, GltfLight, GltfMaterial, GltfPrimitive, GltfProjection, LightKind};
use super::primitive::Primitives;
use crate::error::Result;
use std::path::Path;

/// The deepest node level followed (a deeper tree is refused).
const MAX_DEPTH: usize = 64;

/// What the default scene's node trees place.
pub(super) struct Placed {
    /// The primitives (triangle, line and point lists), in world space.
    pub(super) primitives: Vec<GltfPrimitive>,
    /// The cameras, in node order.
    pub(super) cameras: Vec<GltfCamera>,
    /// The lights, in node order.
    pub(super) lights: Vec<GltfLight>,
    /// What the primitives' reader noted (a Draco stream that fell back to its uncompressed
    /// accessors), one line each.
    pub(super) notes: Vec<String>,
}

/// Walks the default scene's (or the first scene's) node trees, or every root node when the
/// file has no scene, reading each mesh's primitives from `buffers` (`materials` are the
/// document's, the default one last); `draco_required`: the file lists
/// `KHR_draco_mesh_compression` in `extensionsRequired` (no uncompressed fallback).
pub(super) fn place(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    path: &Path,
    materials: &[GltfMaterial],
    draco_required: bool,
) -> Result<Placed> {
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            doc.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    let identity: [[f32; 4]; 4] =
        std::array::from_fn(|c| std::array::from_fn(|r| if r == c { 1.0 } else { 0.0 }));
    let mut stack: Vec<(gltf::Node, [[f32; 4]; 4], usize)> =
        roots.into_iter().map(|n| (n, identity, 0)).collect();
    let mut primitives = Vec::new();
    let mut cameras = Vec::new();
    let mut lights = Vec::new();
    let quantized = doc.extensions_used().any(|e| e == "KHR_mesh_quantization");
    let mut reader = Primitives::new(doc, path, buffers, materials, quantized, draco_required);
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err(GltfError::TooDeep {
                node: node.index(),
                max_depth: MAX_DEPTH,
            }
            .at(path));
        }
        let world = mat_mul(&parent, &node.transform().matrix());
        if !world.iter().flatten().all(|x| x.is_finite()) {
            return Err(GltfError::NodeTransform { node: node.index() }.at(path));
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
        }
        if let Some(camera) = node.camera() {
            cameras.push((node.index(), gltf_camera(path, &camera, world)?));
        }
        if let Some(light) = node_light(path, &node, world)? {
            lights.push((node.index(), light));
        }
        let Some(mesh) = node.mesh() else { continue };
        for prim in mesh.primitives() {
            primitives.push(reader.read(&mesh, &prim, &world)?);
        }
    }
    cameras.sort_by_key(|(node, _)| *node);
    lights.sort_by_key(|(node, _)| *node);
    Ok(Placed {
        primitives,
        cameras: cameras.into_iter().map(|(_, c)| c).collect(),
        lights: lights.into_iter().map(|(_, l)| l).collect(),
        notes: reader.notes,
    })
}

/// The product a b of column-major 4 × 4 matrices.
fn mat_mul(a: &[[f32; 4]; 4], b: &[[f32; 4]; 4]) -> [[f32; 4]; 4] {
    // Column-major: (a b)[c][r] = Σ_k a[k][r] b[c][k].
    std::array::from_fn(|c| std::array::from_fn(|r| (0..4).map(|k| a[k][r] * b[c][k]).sum()))
}

/// The `KHR_lights_punctual` light a node places, checked (finite, non-negative colour and
/// intensity; cone angles 0 ≤ inner < outer ≤ π/2).
fn node_light(path: &Path, node: &gltf::Node, world: [[f32; 4]; 4]) -> Result<Option<GltfLight>> {
    // The document was validated (gltf::Document::from_json): the light index exists.
    let Some(light) = node.light() else {
        return Ok(None);
    };
    let index = light.index();
    let name = light
        .name()
        .map_or_else(|| format!("light {index}"), str::to_string);
    let bad = |what: String| {
        GltfError::Light {
            node: node.index(),
            light: index,
            name: name.clone(),
            what,
        }
        .at(path)
    };
    let (colour, intensity) = (light.color(), light.intensity());
    if !colour
        .iter()
        .chain([&intensity])
        .all(|x| x.is_finite() && *x >= 0.0)
    {
        return Err(bad(format!(
            "colour {colour:?}, intensity {intensity} (expected finite, ≥ 0)"
        )));
    }
    let range = light.range();
    if range.is_some_and(|r| !(r > 0.0 && r.is_finite())) {
        return Err(bad(format!(
            "range {} (expected a positive number)",
            range.unwrap_or_default()
        )));
    }
    let kind = match light.kind() {
        gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
        gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            let ok = inner_cone_angle >= 0.0
                && inner_cone_angle < outer_cone_angle
                && outer_cone_angle <= std::f32::consts::FRAC_PI_2;
            if !ok {
                return Err(bad(format!(
                    "cone angles {inner_cone_angle}, {outer_cone_angle} rad (expected 0 ≤ inner < outer ≤ π/2)"
                )));
            }
            LightKind::Spot {
                inner_cone_rad: inner_cone_angle,
                outer_cone_rad: outer_cone_angle,
            }
        }
    };
    let z = [world[2][0], world[2][1], world[2][2]];
    let len = (z[0] * z[0] + z[1] * z[1] + z[2] * z[2]).sqrt();
    if !(len > 1e-12 && len.is_finite()) {
        return Err(bad("its node's z axis is zero".to_string()));
    }
    Ok(Some(GltfLight {
        name,
        kind,
        colour,
        intensity,
        position: [world[3][0], world[3][1], world[3][2]],
        direction: z.map(|c| -c / len),
        range,
    }))
}

/// A node's camera, checked: finite positive planes and field of view (§3.10.2–3).
fn gltf_camera(path: &Path, camera: &gltf::Camera, world: [[f32; 4]; 4]) -> Result<GltfCamera> {
    let name = camera
        .name()
        .map_or_else(|| format!("camera {}", camera.index()), str::to_string);
    let positive = |x: f32| x.is_finite() && x > 0.0;
    let bad = |what: String| {
        GltfError::Camera {
            camera: camera.index(),
            name: name.clone(),
            what,
        }
        .at(path)
    };
    let projection = match camera.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let (yfov_rad, znear, zfar) = (p.yfov(), p.znear(), p.zfar());
            if !(positive(yfov_rad) && yfov_rad < std::f32::consts::PI) {
                return Err(bad(format!(
                    "yfov {yfov_rad} rad (expected between 0 and π)"
                )));
            }
            if !positive(znear) || zfar.is_some_and(|f| !(f.is_finite() && f > znear)) {
                return Err(bad(format!("znear {znear}, zfar {zfar:?}")));
            }
            GltfProjection::Perspective {
                yfov_rad,
                znear,
                zfar,
            }
        }
        gltf::camera::Projection::Orthographic(o) => {
            let (xmag, ymag, znear, zfar) = (o.xmag(), o.ymag(), o.znear(), o.zfar());
            if !(xmag.is_finite() && xmag != 0.0 && ymag.is_finite() && ymag != 0.0) {
                return Err(bad(format!("xmag {xmag}, ymag {ymag}")));
            }
            if !(znear.is_finite() && znear >= 0.0 && zfar.is_finite() && zfar > znear) {
                return Err(bad(format!("znear {znear}, zfar {zfar}")));
            }
            GltfProjection::Orthographic {
                xmag: xmag.abs(),
                ymag: ymag.abs(),
                znear,
                zfar,
            }
        }
    };
    Ok(GltfCamera {
        name,
        world,
        projection,
    })
}

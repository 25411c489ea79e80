//! The lights a glTF scene is drawn with (`KHR_lights_punctual`).

use crate::gltf_scene::{GltfScene, LightKind};
use crate::render::{Light, MAX_PUNCTUAL_LIGHTS, PunctualKind, PunctualLight};

/// The lights the mesh renderer draws `scene` with, and a note when they are not all of the
/// file's lighting. As the glTF Sample Viewer does by default, a file without
/// `KHR_lights_punctual` lights is lit by the environment alone (the directional light's
/// intensity is 0). A file's lights are drawn as they are, at every shading point
/// ([`PunctualLight`]: position, cone, range and r² falloff of the specification), up to
/// [`MAX_PUNCTUAL_LIGHTS`]: beyond that, the brightest at the centre of the scene's bounds
/// (colour × intensity × falloff there), with a note naming how many are left out.
pub fn scene_lights(scene: &GltfScene) -> (Light, Vec<PunctualLight>, Option<String>) {
    let off = Light {
        intensity: 0.0,
        ..Light::default()
    };
    let (lo, hi) = scene.bounds();
    let centre: [f32; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let mut lights: Vec<(f32, PunctualLight)> = scene
        .lights
        .iter()
        .map(|light| {
            let punctual = PunctualLight {
                kind: match light.kind {
                    LightKind::Directional => PunctualKind::Directional,
                    LightKind::Point => PunctualKind::Point,
                    LightKind::Spot {
                        inner_cone_rad,
                        outer_cone_rad,
                    } => PunctualKind::Spot {
                        inner_cone_rad,
                        outer_cone_rad,
                    },
                },
                position: light.position,
                direction: light.direction,
                colour: light.colour,
                intensity: light.intensity,
                range: light.range,
            };
            (brightness_at(&punctual, centre), punctual)
        })
        .collect();
    let note = (lights.len() > MAX_PUNCTUAL_LIGHTS).then(|| {
        format!(
            "KHR_lights_punctual: {} lights; the {MAX_PUNCTUAL_LIGHTS} brightest at the scene's centre are drawn",
            lights.len()
        )
    });
    if lights.len() > MAX_PUNCTUAL_LIGHTS {
        // Brightest first; a stable sort keeps the file's order among equals.
        lights.sort_by(|a, b| b.0.total_cmp(&a.0));
        lights.truncate(MAX_PUNCTUAL_LIGHTS);
    }
    (off, lights.into_iter().map(|(_, l)| l).collect(), note)
}

/// The irradiance (summed over colour channels) `light` gives at `point` facing it: its
/// ranking when a file has more lights than are drawn.
fn brightness_at(light: &PunctualLight, point: [f32; 3]) -> f32 {
    let colour = light.colour.iter().sum::<f32>() * light.intensity;
    let value = match light.kind {
        PunctualKind::Directional => colour,
        PunctualKind::Point | PunctualKind::Spot { .. } => {
            let d: [f32; 3] = std::array::from_fn(|k| point[k] - light.position[k]);
            let r2 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).max(1e-12);
            let window = light.range.map_or(1.0, |range| {
                (1.0 - (r2 / (range * range)).powi(2)).clamp(0.0, 1.0)
            });
            let cone = match light.kind {
                PunctualKind::Spot {
                    inner_cone_rad,
                    outer_cone_rad,
                } => {
                    let r = r2.sqrt();
                    let cos_angle = (0..3).map(|k| d[k] / r * light.direction[k]).sum::<f32>();
                    let (cos_inner, cos_outer) = (inner_cone_rad.cos(), outer_cone_rad.cos());
                    let t = ((cos_angle - cos_outer) / (cos_inner - cos_outer).max(1e-3))
                        .clamp(0.0, 1.0);
                    t * t
                }
                _ => 1.0,
            };
            colour * window * window * cone / r2
        }
    };
    if value.is_finite() { value } else { 0.0 }
}

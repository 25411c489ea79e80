//! The scene the examples share: a row of film spheres sweeping thickness, lights, and
//! (when a path is given) a glTF asset such as Khronos' IridescenceSuzanne.
#![allow(dead_code)]

use bevy::prelude::*;
use bevy_nacre::{FilmThickness, NacreFilm, NacreMaterial};

/// Spheres in the row.
pub const ROW: usize = 7;
/// Thickness of the last sphere's film, nm (the first has none).
pub const THICKNESS_MAX_NM: f32 = 700.0;

/// Spawns the sphere row (film index 1.8 on a black glazed dielectric, 0 … 700 nm left to
/// right) centred at `centre`.
pub fn spawn_sphere_row(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<NacreMaterial>,
    centre: Vec3,
) {
    let mesh = meshes.add(Sphere::new(0.45).mesh().uv(64, 32));
    for i in 0..ROW {
        let d = THICKNESS_MAX_NM * i as f32 / (ROW - 1) as f32;
        commands.spawn((
            Mesh3d(mesh.clone()),
            MeshMaterial3d(materials.add(NacreMaterial {
                base: StandardMaterial {
                    base_color: Color::BLACK,
                    perceptual_roughness: 0.25,
                    ..default()
                },
                extension: NacreFilm {
                    film_ior: 1.8,
                    thickness: FilmThickness::Gltf {
                        min_nm: d,
                        max_nm: d,
                    },
                    weight: 1.0,
                    ..default()
                },
            })),
            Transform::from_translation(centre + Vec3::X * (i as f32 - (ROW - 1) as f32 / 2.0)),
        ));
    }
}

/// A white ambient light (Bevy's ambient term has the split-sum specular, so the film shows
/// over the whole sphere) and a directional light for highlights.
pub fn spawn_lights(commands: &mut Commands) {
    commands.insert_resource(GlobalAmbientLight {
        color: Color::WHITE,
        brightness: 2500.0,
        ..default()
    });
    commands.spawn((
        DirectionalLight {
            illuminance: 2000.0,
            ..default()
        },
        Transform::from_xyz(2.0, 4.0, 6.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

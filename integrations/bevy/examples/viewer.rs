//! Interactive: a window with an orbit camera (drag with the left mouse button, scroll to
//! zoom), the sphere row sweeping thickness, and a glTF asset — by default Khronos'
//! IridescenceSuzanne from `../shared/gltf-samples` (see `../shared/DATA.md`).
//!
//! ```text
//! cargo run --release --features viewer --example viewer -- [ASSET.gltf]
//! ```

use bevy::gltf::GltfAssetLabel;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;
use bevy::world_serialization::WorldAssetRoot;
use bevy_nacre::{NacreMaterial, NacrePlugin};
use std::path::PathBuf;

#[path = "common/scene.rs"]
mod scene;

#[derive(Component)]
struct Orbit {
    yaw: f32,
    pitch: f32,
    distance: f32,
}

#[derive(Resource)]
struct Asset(Option<String>);

fn main() {
    let asset = std::env::args().nth(1).map(PathBuf::from).or_else(|| {
        let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/gltf-samples/IridescenceSuzanne/glTF/IridescenceSuzanne.gltf");
        p.is_file().then_some(p)
    });
    let root = asset
        .as_ref()
        .and_then(|a| a.parent())
        .map(|p| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()))
        .unwrap_or_else(|| PathBuf::from("."));
    let file = asset
        .as_ref()
        .and_then(|a| a.file_name())
        .map(|f| f.to_string_lossy().into_owned());
    if file.is_none() {
        eprintln!("no glTF asset given and ../shared/gltf-samples not found: spheres only");
    }
    App::new()
        .add_plugins(DefaultPlugins.set(AssetPlugin {
            file_path: root.to_string_lossy().into_owned(),
            ..default()
        }))
        .add_plugins(NacrePlugin)
        .insert_resource(Asset(file))
        .add_systems(Startup, setup)
        .add_systems(Update, orbit)
        .run();
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<NacreMaterial>>,
    asset_server: Res<AssetServer>,
    asset: Res<Asset>,
) {
    scene::spawn_lights(&mut commands);
    scene::spawn_sphere_row(&mut commands, &mut meshes, &mut materials, Vec3::Y * -1.6);
    if let Some(file) = &asset.0 {
        commands.spawn((
            WorldAssetRoot(asset_server.load(GltfAssetLabel::Scene(0).from_asset(file.clone()))),
            Transform::from_xyz(0.0, 0.6, 0.0),
        ));
    }
    commands.spawn((
        Camera3d::default(),
        Orbit {
            yaw: 0.0,
            pitch: 0.1,
            distance: 7.5,
        },
        Transform::default(),
    ));
}

fn orbit(
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    mut cameras: Query<(&mut Orbit, &mut Transform)>,
) {
    for (mut o, mut t) in &mut cameras {
        if buttons.pressed(MouseButton::Left) {
            o.yaw -= motion.delta.x * 0.005;
            o.pitch = (o.pitch + motion.delta.y * 0.005).clamp(-1.5, 1.5);
        }
        o.distance = (o.distance * (1.0 - scroll.delta.y * 0.1)).clamp(1.0, 50.0);
        let eye = Quat::from_euler(EulerRot::YXZ, o.yaw, -o.pitch, 0.0) * Vec3::Z * o.distance;
        *t = Transform::from_translation(eye).looking_at(Vec3::ZERO, Vec3::Y);
    }
}

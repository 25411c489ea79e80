//! Renders without a window: the sphere row (and, given its path, a glTF asset beside it)
//! to a PNG file.
//!
//! ```text
//! cargo run --release --example headless -- OUT.png [ASSET.gltf]
//! ```
//!
//! Vulkan (`WGPU_BACKEND` is honoured by Bevy; Mesa's lavapipe works without a GPU).

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::ecs::system::RunSystemOnce;
use bevy::gltf::GltfAssetLabel;
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::world_serialization::{WorldAsset, WorldAssetRoot};
use bevy_nacre::NacreMaterial;
use std::path::PathBuf;

#[path = "common/headless.rs"]
mod headless;
#[path = "common/scene.rs"]
mod scene;

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(out) = args.next().map(PathBuf::from) else {
        eprintln!("usage: headless OUT.png [ASSET.gltf]");
        std::process::exit(2);
    };
    let asset = args.next().map(PathBuf::from);
    let (width, height) = if asset.is_some() {
        (800, 400)
    } else {
        (700, 100)
    };
    // Assets are read relative to the glTF's folder (the row needs no files).
    let root = asset
        .as_ref()
        .and_then(|a| a.parent())
        .map(|p| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()))
        .unwrap_or_else(|| PathBuf::from("."));

    let mut app = headless::headless_app(&root, RenderPlugin::default());

    let world = app.world_mut();
    let image = world
        .resource_mut::<Assets<Image>>()
        .add(Image::new_target_texture(
            width,
            height,
            TextureFormat::Rgba8UnormSrgb,
            None,
        ));
    let mut scene_handle = None;
    let row_y = if asset.is_some() { -1.6 } else { 0.0 };
    world
        .run_system_once(
            move |mut commands: Commands,
                  mut meshes: ResMut<Assets<Mesh>>,
                  mut materials: ResMut<Assets<NacreMaterial>>| {
                scene::spawn_lights(&mut commands);
                scene::spawn_sphere_row(
                    &mut commands,
                    &mut meshes,
                    &mut materials,
                    Vec3::Y * row_y,
                );
            },
        )
        .expect("setting up the scene");
    if let Some(asset) = &asset {
        let file = asset.file_name().unwrap().to_string_lossy().into_owned();
        let handle: Handle<WorldAsset> = world
            .resource::<AssetServer>()
            .load(GltfAssetLabel::Scene(0).from_asset(file));
        world.spawn((
            WorldAssetRoot(handle.clone()),
            Transform::from_xyz(0.0, 0.6, 0.0),
        ));
        scene_handle = Some(handle);
    }
    let (projection, eye) = if asset.is_some() {
        (Projection::default(), Vec3::new(0.0, 0.0, 7.5))
    } else {
        (
            Projection::Orthographic(OrthographicProjection {
                scaling_mode: bevy::camera::ScalingMode::FixedHorizontal {
                    viewport_width: scene::ROW as f32,
                },
                ..OrthographicProjection::default_3d()
            }),
            Vec3::new(0.0, 0.0, 5.0),
        )
    };
    world.spawn((
        Camera3d::default(),
        RenderTarget::Image(image.clone().into()),
        Tonemapping::None,
        projection,
        Transform::from_translation(eye).looking_at(Vec3::ZERO, Vec3::Y),
    ));

    if let Some(handle) = &scene_handle {
        for _ in 0..5000 {
            app.update();
            if app
                .world()
                .resource::<AssetServer>()
                .is_loaded_with_dependencies(handle)
            {
                break;
            }
        }
    }
    for _ in 0..10 {
        app.update();
    }
    app.world_mut()
        .spawn(Screenshot::image(image))
        .observe(save_to_disk(out.clone()));
    for _ in 0..10 {
        app.update();
    }
    eprintln!("wrote {}", out.display());
}

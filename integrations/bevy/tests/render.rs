//! Headless renders through the plugin (Vulkan; Mesa's lavapipe in CI): a row of film
//! spheres sweeping thickness shows the film's colours (hue structure as the golden tests
//! check it), and the same row without the film does not; Khronos' IridescenceSuzanne and
//! sphere grids load through the glTF hook with their iridescence and render in colour.

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::gltf::GltfAssetLabel;
use bevy::prelude::*;
use bevy::world_serialization::{WorldAsset, WorldAssetRoot};
use bevy_nacre::{FilmThickness, NacreFilm, NacreMaterial};

mod support;
use support::{capture, colourfulness, headless_app, repo_root, run_until, samples, target, write_png};

const ROW: usize = 7;
const THICKNESS_MAX_NM: f32 = 1100.0;

fn lights(world: &mut World) {
    world.insert_resource(GlobalAmbientLight {
        color: Color::WHITE,
        brightness: 6000.0,
        ..default()
    });
    world.spawn((
        DirectionalLight {
            illuminance: 3000.0,
            ..default()
        },
        Transform::from_xyz(2.0, 4.0, 6.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

/// A row of spheres on a black glazed base, film index 1.8, thickness 0 … 1100 nm left to
/// right, film weight `weight`; the picture, `width` × `height`.
fn sphere_row(weight: f32, width: u32, height: u32) -> Vec<u8> {
    let mut app = headless_app(&repo_root());
    let image = target(&mut app, width, height);
    let world = app.world_mut();
    let mesh = world.resource_mut::<Assets<Mesh>>().add(Sphere::new(0.45).mesh().uv(48, 24));
    for i in 0..ROW {
        let d = THICKNESS_MAX_NM * i as f32 / (ROW - 1) as f32;
        let material = world.resource_mut::<Assets<NacreMaterial>>().add(NacreMaterial {
            base: StandardMaterial {
                base_color: Color::BLACK,
                perceptual_roughness: 0.25,
                ..default()
            },
            extension: NacreFilm {
                film_ior: 1.8,
                thickness: FilmThickness::Gltf { min_nm: d, max_nm: d },
                weight,
                ..default()
            },
        });
        world.spawn((
            Mesh3d(mesh.clone()),
            MeshMaterial3d(material),
            Transform::from_xyz(i as f32 - (ROW - 1) as f32 / 2.0, 0.0, 0.0),
        ));
    }
    lights(world);
    world.spawn((
        Camera3d::default(),
        RenderTarget::Image(image.clone().into()),
        Tonemapping::None,
        Projection::Orthographic(OrthographicProjection {
            scaling_mode: bevy::camera::ScalingMode::FixedHorizontal {
                viewport_width: ROW as f32,
            },
            ..OrthographicProjection::default_3d()
        }),
        Transform::from_xyz(0.0, 0.0, 5.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    capture(&mut app, &image, 10)
}

#[test]
fn a_sphere_row_shows_the_film_colours() {
    let (w, h) = (560, 80);
    let film = sphere_row(1.0, w, h);
    write_png("bevy-sphere-row.png", w, h, &film);
    let (count, sectors) = colourfulness(&film);
    eprintln!("film: {count} saturated pixels over {sectors} hue sectors of 30°");
    assert!(count >= 2000, "{count} saturated pixels");
    assert!(sectors >= 5, "hues in {sectors} sectors");
    // The film's colour changes with thickness: the spheres' mean hues differ.
    let bare = sphere_row(0.0, w, h);
    let (count_bare, sectors_bare) = colourfulness(&bare);
    eprintln!("no film: {count_bare} saturated pixels over {sectors_bare} sectors");
    assert!(count_bare * 20 < count, "the bare spheres are colourful: {count_bare}");
}

/// Loads `file` (under `dir`) as a scene, waits for it, and checks that the glTF hook gave
/// `min_films` or more meshes a `NacreMaterial`; the picture.
fn render_gltf(dir: &std::path::Path, file: &str, eye: Vec3, min_films: usize) -> Vec<u8> {
    let (w, h) = (240, 180);
    let mut app = headless_app(dir);
    let image = target(&mut app, w, h);
    let scene: Handle<WorldAsset> = app
        .world()
        .resource::<AssetServer>()
        .load(GltfAssetLabel::Scene(0).from_asset(file.to_owned()));
    app.world_mut().spawn(WorldAssetRoot(scene.clone()));
    lights(app.world_mut());
    app.world_mut().spawn((
        Camera3d::default(),
        RenderTarget::Image(image.clone().into()),
        Tonemapping::None,
        Transform::from_translation(eye).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let loaded = run_until(&mut app, 2000, |world| {
        world
            .resource::<AssetServer>()
            .is_loaded_with_dependencies(&scene)
    });
    assert!(loaded, "{file} did not load");
    let films = run_until(&mut app, 50, |world| {
        world
            .query::<&MeshMaterial3d<NacreMaterial>>()
            .iter(world)
            .count()
            >= min_films
    });
    let mut q = app.world_mut().query::<&MeshMaterial3d<NacreMaterial>>();
    let n = q.iter(app.world()).count();
    assert!(films, "{file}: {n} meshes with a NacreMaterial, expected ≥ {min_films}");
    eprintln!("{file}: {n} meshes with a NacreMaterial");
    let pixels = capture(&mut app, &image, 10);
    write_png(&format!("bevy-{file}.png"), w, h, &pixels);
    pixels
}

#[test]
fn iridescence_suzanne_loads_with_its_films() {
    let Some(dir) = samples() else { return };
    let pixels = render_gltf(
        &dir.join("IridescenceSuzanne/glTF"),
        "IridescenceSuzanne.gltf",
        Vec3::new(0.0, 0.5, 4.0),
        1,
    );
    let (count, sectors) = colourfulness(&pixels);
    eprintln!("IridescenceSuzanne: {count} saturated pixels over {sectors} hue sectors");
    assert!(count >= 200 && sectors >= 3, "{count} pixels, {sectors} sectors");
}

#[test]
fn sphere_grids_load_with_their_films() {
    let Some(dir) = samples() else { return };
    for name in ["IridescenceMetallicSpheres", "IridescenceDielectricSpheres"] {
        let pixels = render_gltf(
            &dir.join(name).join("glTF"),
            &format!("{name}.gltf"),
            Vec3::new(0.0, 0.0, 30.0),
            100,
        );
        let (count, sectors) = colourfulness(&pixels);
        eprintln!("{name}: {count} saturated pixels over {sectors} hue sectors");
        assert!(count >= 200 && sectors >= 3, "{name}: {count} pixels, {sectors} sectors");
    }
}

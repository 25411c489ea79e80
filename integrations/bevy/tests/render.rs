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
use support::{
    capture, colourfulness, headless_app, repo_root, run_until, samples, target, write_png,
};

const ROW: usize = 7;
const THICKNESS_MAX_NM: f32 = 700.0;

/// White ambient light of `brightness` cd/m² and a directional light of `brightness` lux.
fn lights(world: &mut World, brightness: f32) {
    world.insert_resource(GlobalAmbientLight {
        color: Color::WHITE,
        brightness,
        ..default()
    });
    world.spawn((
        DirectionalLight {
            illuminance: brightness,
            ..default()
        },
        Transform::from_xyz(2.0, 4.0, 6.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

/// A row of spheres on a black glazed base, film index 1.8, thickness 0 … 700 nm left to
/// right, film weight `weight`; the picture, `width` × `height`.
fn sphere_row(weight: f32, width: u32, height: u32) -> Vec<u8> {
    let mut app = headless_app(&repo_root());
    let image = target(&mut app, width, height);
    let world = app.world_mut();
    let mesh = world
        .resource_mut::<Assets<Mesh>>()
        .add(Sphere::new(0.45).mesh().uv(48, 24));
    for i in 0..ROW {
        let d = THICKNESS_MAX_NM * i as f32 / (ROW - 1) as f32;
        let material = world
            .resource_mut::<Assets<NacreMaterial>>()
            .add(NacreMaterial {
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
    lights(world, 2500.0);
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

/// Linear value of an sRGB byte.
fn linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Hue (degrees) and saturation of a linear RGB colour.
fn hue_saturation(rgb: [f64; 3]) -> (f64, f64) {
    let p = rgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
    let (h, s, _) = support::hsv(&[p[0], p[1], p[2], 255]);
    (h, s)
}

#[test]
fn a_sphere_row_shows_the_film_colours() {
    let (w, h) = (560, 80);
    let film = sphere_row(1.0, w, h);
    write_png("bevy-sphere-row.png", w, h, &film);
    let (count, sectors) = colourfulness(&film);
    eprintln!("film: {count} saturated pixels over {sectors} hue sectors of 30°");
    assert!(count >= 1000, "{count} saturated pixels");
    assert!(sectors >= 3, "hues in {sectors} sectors");

    // At each sphere's centre (n·v = 1) Bevy's ambient specular is F₀ A + B with the
    // material's F₀ = nacre's film colour at normal incidence: a scaled colour plus grey,
    // whose hue is the film's. Compare with the CPU lookup (`nacre color --method
    // lut:film-dielectric`) wherever the film colour is saturated enough to have a hue.
    let path = repo_root().join("tables/baked/film-dielectric.json");
    let manifest = nacre_format::Manifest::read(&path).unwrap();
    let axes = manifest.film_lut().cloned().unwrap();
    let table = manifest.load_table(&path, "reflectance").unwrap().unwrap();
    let mut compared = 0;
    for i in 0..ROW {
        let d = f64::from(THICKNESS_MAX_NM) * i as f64 / (ROW - 1) as f64;
        let cpu = nacre_format::film_lut::FilmLut::lookup(&axes, &table, 1.0, d, 1.8);
        let (cpu_hue, cpu_s) = hue_saturation(cpu);
        let x = ((i as f64 + 0.5) * f64::from(w) / ROW as f64) as usize;
        let y = (h / 2) as usize;
        let p = &film[4 * (y * w as usize + x)..][..4];
        let (gpu_hue, gpu_s) = hue_saturation([p[0], p[1], p[2]].map(linear));
        let diff = (gpu_hue - cpu_hue)
            .abs()
            .min(360.0 - (gpu_hue - cpu_hue).abs());
        eprintln!(
            "d = {d:.0} nm: CPU hue {cpu_hue:.0}° (s {cpu_s:.2}), Bevy {gpu_hue:.0}° (s {gpu_s:.2})"
        );
        if cpu_s > 0.2 {
            compared += 1;
            assert!(
                diff <= 20.0,
                "d = {d} nm: hue {gpu_hue:.0}° against nacre's {cpu_hue:.0}°"
            );
        }
    }
    assert!(
        compared >= 3,
        "{compared} spheres with a saturated film colour"
    );

    // Without the film (weight 0) the spheres are grey.
    let bare = sphere_row(0.0, w, h);
    let (count_bare, _) = colourfulness(&bare);
    eprintln!("no film: {count_bare} saturated pixels");
    assert!(
        count_bare * 20 < count,
        "the bare spheres are colourful: {count_bare}"
    );
}

/// Loads `file` (under `dir`) as a scene, waits for it, and checks that the glTF hook gave
/// `min_films` or more meshes a `NacreMaterial`; the picture.
fn render_gltf(
    dir: &std::path::Path,
    file: &str,
    eye: Vec3,
    min_films: usize,
    brightness: f32,
) -> Vec<u8> {
    let (w, h) = (240, 180);
    let mut app = headless_app(dir);
    let image = target(&mut app, w, h);
    let scene: Handle<WorldAsset> = app
        .world()
        .resource::<AssetServer>()
        .load(GltfAssetLabel::Scene(0).from_asset(file.to_owned()));
    app.world_mut().spawn(WorldAssetRoot(scene.clone()));
    lights(app.world_mut(), brightness);
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
    assert!(
        films,
        "{file}: {n} meshes with a NacreMaterial, expected ≥ {min_films}"
    );
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
        Vec3::new(0.0, 1.0, 8.0),
        3,
        2500.0,
    );
    let (count, sectors) = colourfulness(&pixels);
    eprintln!("IridescenceSuzanne: {count} saturated pixels over {sectors} hue sectors");
    assert!(
        count >= 200 && sectors >= 3,
        "{count} pixels, {sectors} sectors"
    );
}

#[test]
fn sphere_grids_load_with_their_films() {
    let Some(dir) = samples() else { return };
    // Every sphere (7 × 7 × 7) gets its film through the hook.
    let metallic = render_gltf(
        &dir.join("IridescenceMetallicSpheres/glTF"),
        "IridescenceMetallicSpheres.gltf",
        Vec3::new(0.0, 0.0, 45.0),
        343,
        400.0,
    );
    let (count, sectors) = colourfulness(&metallic);
    eprintln!("IridescenceMetallicSpheres: {count} saturated pixels over {sectors} hue sectors");
    assert!(
        count >= 500 && sectors >= 6,
        "{count} pixels, {sectors} sectors"
    );
    // The dielectric grid's white diffuse bases outshine their films under this light: the
    // films are checked by the hook's count only.
    render_gltf(
        &dir.join("IridescenceDielectricSpheres/glTF"),
        "IridescenceDielectricSpheres.gltf",
        Vec3::new(0.0, 0.0, 45.0),
        343,
        400.0,
    );
}

#[test]
fn a_table_loads_as_an_asset_and_binds_to_materials() {
    let mut app = headless_app(&repo_root());
    let soap: Handle<bevy_nacre::NacreTable> = app
        .world()
        .resource::<AssetServer>()
        .load("tables/baked/soap-film.json");
    let material = app
        .world_mut()
        .resource_mut::<Assets<NacreMaterial>>()
        .add(NacreMaterial {
            base: StandardMaterial::default(),
            extension: NacreFilm {
                lut_table: soap.clone(),
                ..default()
            },
        });
    let loaded = run_until(&mut app, 500, |world| {
        world
            .resource::<AssetServer>()
            .is_loaded_with_dependencies(&soap)
    });
    assert!(loaded, "soap-film.json did not load");
    run_until(&mut app, 3, |_| false);
    let world = app.world();
    let table = world
        .resource::<Assets<bevy_nacre::NacreTable>>()
        .get(&soap)
        .unwrap();
    assert_eq!(table.name, "soap-film");
    let bevy_nacre::tables::NacreTableAxes::FilmLut(axes) = table.axes else {
        panic!("soap-film is a film-lut table");
    };
    assert_eq!(axes.has_transmittance, 1);
    assert!(table.transmittance.is_some());
    // The material now samples soap-film's textures with soap-film's axes.
    let m = world
        .resource::<Assets<NacreMaterial>>()
        .get(&material)
        .unwrap();
    assert_eq!(m.extension.lut_reflectance.as_ref(), Some(&table.texture));
    assert_eq!(m.extension.lut_axes, axes);
}

//! Headless renders through the plugin (Vulkan; Mesa's lavapipe in CI): a row of film
//! spheres sweeping thickness shows the film's colours (hue structure as the golden tests
//! check it), and the same row without the film does not; Khronos' IridescenceSuzanne and
//! sphere grids load through the glTF hook with their iridescence and render in colour.

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::gltf::GltfAssetLabel;
use bevy::math::DVec3;
use bevy::prelude::*;
use bevy::world_serialization::{WorldAsset, WorldAssetRoot};
use bevy_nacre::{FilmTechnique, FilmThickness, NacreFilm, NacreMaterial};
use nacre_optics::C64;
use nacre_optics::fourier::{FilmOnBase, Harmonics};

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

/// Perceptual roughness of the lobe test's quads and Bevy's α = r_p² (r_p ≥ 0.089).
const LOBE_PERCEPTUAL_ROUGHNESS: f64 = 0.6;
/// Film of the lobe test: index 1.8, 400 nm, on the film-lut table's base (index 1.5).
const LOBE_FILM_IOR: f64 = 1.8;
const LOBE_THICKNESS_NM: f64 = 400.0;
/// Directional light's illuminance (lux) and its angle to the view direction.
const LOBE_LUX: f64 = 10.0;
const LOBE_LIGHT_DEG: f64 = 60.0;
/// Point light: luminous intensity (cd), distance from the middle quad, range (m).
const LOBE_POINT_CD: f64 = 100.0;
const LOBE_POINT_DISTANCE: f64 = 4.0;
const LOBE_POINT_RANGE: f64 = 20.0;
/// Uniform environment map's radiance (cd/m²).
const LOBE_ENVIRONMENT_NITS: f64 = 1.0;

/// The light of the lobe test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LobeLight {
    /// One directional light.
    Directional,
    /// One point light (no radius), through Bevy's clusters.
    Point,
    /// One spot light where the point light is, aimed at the middle quad, every quad inside
    /// its inner cone (so the same light as `Point`, through the spot branch).
    Spot,
    /// A uniform environment map (Bevy's `EnvironmentMapLight::solid_color`), no light.
    Environment,
}
/// Quad normals' angles to the view direction, about the vertical axis (30°: the mirror
/// configuration n = h of the 60° light).
const LOBE_QUADS_DEG: [f64; 5] = [0.0, 15.0, 30.0, 45.0, 55.0];

/// GGX normal distribution D(α, n·h) (Walter et al. 2007).
fn ggx_d(alpha: f64, n_dot_h: f64) -> f64 {
    let k = alpha / (1.0 - n_dot_h * n_dot_h + (n_dot_h * alpha).powi(2));
    k * k / std::f64::consts::PI
}

/// Height-correlated Smith visibility V = G / (4 n·v n·l) (Heitz 2014).
fn smith_v(alpha: f64, n_dot_v: f64, n_dot_l: f64) -> f64 {
    let a2 = alpha * alpha;
    let lv = n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt();
    let ll = n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
    0.5 / (lv + ll)
}

/// Flat film quads facing an orthographic camera at known angles, lit by one directional
/// light, no ambient or environment light, black base (no diffuse): each quad's centre pixel
/// is its specular radiance, read as linear floats (HDR, no tone mapping, no dithering) and
/// compared with the CPU: exposure × E × D V R_f(v·h) × (Bevy's multiple-scattering factor)
/// × n·l, R_f from `film`, nacre's CPU colour of `technique` (on `base`). The previous
/// material (Schlick with an F₀ that matches R_f only at the mirror configuration) is
/// computed too and must miss off the mirror.
fn specular_lobe(
    technique: FilmTechnique,
    base: C64,
    light: LobeLight,
    film: impl Fn(f64) -> [f64; 3],
) {
    let point = matches!(light, LobeLight::Point | LobeLight::Spot);
    use bevy::core_pipeline::tonemapping::DebandDither;
    use bevy::render::render_resource::TextureFormat;

    let n = LOBE_QUADS_DEG.len();
    let (w, h) = (50 * n as u32, 50);
    let mut app = headless_app(&repo_root());
    let image = app
        .world_mut()
        .resource_mut::<Assets<Image>>()
        .add(Image::new_target_texture(
            w,
            h,
            TextureFormat::Rgba32Float,
            None,
        ));
    let world = app.world_mut();
    let mesh = world
        .resource_mut::<Assets<Mesh>>()
        .add(Rectangle::new(0.8, 0.8));
    let material = world
        .resource_mut::<Assets<NacreMaterial>>()
        .add(lobe_material(technique, base));
    for (i, phi) in LOBE_QUADS_DEG.iter().enumerate() {
        world.spawn((
            Mesh3d(mesh.clone()),
            MeshMaterial3d(material.clone()),
            Transform::from_xyz(i as f32 - (n - 1) as f32 / 2.0, 0.0, 0.0)
                .with_rotation(Quat::from_rotation_y((*phi as f32).to_radians())),
        ));
    }
    world.insert_resource(GlobalAmbientLight {
        color: Color::WHITE,
        brightness: 0.0,
        ..default()
    });
    // The directional light at LOBE_LIGHT_DEG to the view; the point light LOBE_POINT_DISTANCE
    // from the middle quad in that direction (its mirror configuration).
    let beta = LOBE_LIGHT_DEG.to_radians();
    let to_light = DVec3::new(beta.sin(), 0.0, beta.cos());
    let point_at = to_light * LOBE_POINT_DISTANCE;
    if light == LobeLight::Spot {
        world.spawn((
            SpotLight {
                intensity: (LOBE_POINT_CD * 4.0 * std::f64::consts::PI) as f32,
                range: LOBE_POINT_RANGE as f32,
                radius: 0.0,
                inner_angle: 1.2,
                outer_angle: 1.4,
                ..default()
            },
            Transform::from_translation(point_at.as_vec3()).looking_at(Vec3::ZERO, Vec3::Y),
        ));
    } else if point {
        world.spawn((
            PointLight {
                intensity: (LOBE_POINT_CD * 4.0 * std::f64::consts::PI) as f32,
                range: LOBE_POINT_RANGE as f32,
                radius: 0.0,
                ..default()
            },
            Transform::from_translation(point_at.as_vec3()),
        ));
    } else if light == LobeLight::Directional {
        world.spawn((
            DirectionalLight {
                illuminance: LOBE_LUX as f32,
                ..default()
            },
            Transform::default().looking_to(-to_light.as_vec3(), Vec3::Y),
        ));
    }
    let exposure = bevy::camera::Exposure { ev100: 0.0 };
    let environment = (light == LobeLight::Environment).then(|| {
        let mut images = world.resource_mut::<Assets<Image>>();
        let mut map = EnvironmentMapLight::solid_color(&mut images, Color::WHITE);
        map.intensity = LOBE_ENVIRONMENT_NITS as f32;
        map
    });
    let mut camera = world.spawn((
        Camera3d::default(),
        bevy::camera::Hdr,
        exposure,
        RenderTarget::Image(image.clone().into()),
        Tonemapping::None,
        DebandDither::Disabled,
        Projection::Orthographic(OrthographicProjection {
            scaling_mode: bevy::camera::ScalingMode::FixedHorizontal {
                viewport_width: n as f32,
            },
            ..OrthographicProjection::default_3d()
        }),
        Transform::from_xyz(0.0, 0.0, 5.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    if let Some(map) = environment {
        camera.insert(map);
    }
    let bytes = capture(&mut app, &image, 10);
    assert_eq!(bytes.len(), 16 * (w * h) as usize, "an Rgba32Float picture");
    let pixel = |x: usize, y: usize| -> [f64; 3] {
        let p = &bytes[16 * (y * w as usize + x)..];
        std::array::from_fn(|c| {
            f64::from(f32::from_le_bytes(p[4 * c..4 * c + 4].try_into().unwrap()))
        })
    };

    let rp = LOBE_PERCEPTUAL_ROUGHNESS;
    let alpha = rp * rp;
    // Bevy's F_AB polynomial (Karis 2014) sums to A + B = 1 − 0.55 r_p wherever its B is above
    // its 5×10⁻⁵ floor (true for r_p = 0.6 at every n·v): the multiple-scattering factor is
    // 1 + F₀ (1/(A + B) − 1).
    let multiscatter = |f0: f64| 1.0 + f0 * (1.0 / (1.0 - 0.55 * rp) - 1.0);
    // Bevy's HDR target is Rgba16Float (relative steps of 2⁻¹¹); the film-lut lookup is the
    // CPU's to 5×10⁻⁷ (probe.rs).
    let tolerance = |cpu: f64| 3e-3 * cpu + 1e-4;
    let mut worst: f64 = 0.0;
    let v = DVec3::Z;
    let kind = format!("{light:?}");
    for (i, phi) in LOBE_QUADS_DEG.iter().enumerate() {
        let phi = phi.to_radians();
        let normal = DVec3::new(phi.sin(), 0.0, phi.cos());
        // The world point seen at the centre of pixel (50 i + 25, 25): 0.01 right of and below
        // the quad's centre, on its plane.
        let (px, py) = (50 * i + 25, 25);
        let x = (px as f64 + 0.5) / f64::from(w) * n as f64 - n as f64 / 2.0;
        let y = (f64::from(h) / 2.0 - (py as f64 + 0.5)) * n as f64 / f64::from(w);
        let centre_x = i as f64 - (n - 1) as f64 / 2.0;
        let z = -normal.x * (x - centre_x) / normal.z;
        let p = DVec3::new(x, y, z);
        // Light direction and illuminance E (lux) at p: Bevy's point light has
        // I = Φ/4π cd and the range falloff (1 − (d²/r²)²)² (saturated) over d².
        let (l, illuminance) = if point {
            let to = point_at - p;
            let d2 = to.length_squared();
            let falloff = (1.0 - (d2 / LOBE_POINT_RANGE.powi(2)).powi(2)).clamp(0.0, 1.0);
            (to.normalize(), LOBE_POINT_CD * falloff * falloff / d2)
        } else {
            (to_light, LOBE_LUX)
        };
        if light == LobeLight::Environment {
            // Split sum: R_f(μ) (A + B) times the environment's radiance.
            let gpu = pixel(px, py);
            let r_mu = film(normal.dot(v));
            for c in 0..3 {
                let cpu = f64::from(exposure.exposure())
                    * LOBE_ENVIRONMENT_NITS
                    * r_mu[c]
                    * (1.0 - 0.55 * rp);
                eprintln!(
                    "{technique:?}, environment, quad {:.0}°, channel {c}: Bevy {:.5}, CPU {cpu:.5} (|Δ| {:.1e})",
                    phi.to_degrees(),
                    gpu[c],
                    (gpu[c] - cpu).abs()
                );
                assert!(
                    (gpu[c] - cpu).abs() <= tolerance(cpu),
                    "environment, quad {:.0}° channel {c}: Bevy {} against {cpu}",
                    phi.to_degrees(),
                    gpu[c]
                );
                worst = worst.max((gpu[c] - cpu).abs() / cpu);
            }
            continue;
        }
        let half = (l + v).normalize();
        let (n_dot_v, n_dot_l, n_dot_h, v_dot_h) =
            (normal.dot(v), normal.dot(l), normal.dot(half), v.dot(half));
        let scale = f64::from(exposure.exposure()) * illuminance;
        let dv = ggx_d(alpha, n_dot_h) * smith_v(alpha, n_dot_v, n_dot_l) * n_dot_l * scale;
        let r_mu = film(n_dot_v);
        let r_vh = film(v_dot_h);
        let gpu = pixel(px, py);
        // The previous material: F₀ = (R_f(μ) − x)/(1 − x), Bevy's Schlick at v·h with
        // f₉₀ = saturate(16.5 ΣF₀).
        let x = (1.0 - n_dot_v).powi(5).min(0.99);
        let f0_old = r_mu.map(|r| ((r - x) / (1.0 - x)).max(0.0));
        let f90 = (16.5 * f0_old.iter().sum::<f64>()).clamp(0.0, 1.0);
        // Within 2° of the mirror configuration n = h the two agree.
        let mirror = n_dot_h > 2f64.to_radians().cos();
        let mut old_missed = false;
        for c in 0..3 {
            let cpu = dv * r_vh[c] * multiscatter(r_mu[c]);
            let f_old = f0_old[c] + (f90 - f0_old[c]) * (1.0 - v_dot_h).powi(5);
            let old = dv * f_old * multiscatter(f0_old[c]);
            eprintln!(
                "{technique:?}, {kind} light, quad {:.0}° (n·h {n_dot_h:.4}), channel {c}: Bevy {:.5}, CPU {cpu:.5} (|Δ| {:.1e}), F₀-inversion {old:.5} (|Δ| {:.1e})",
                phi.to_degrees(),
                gpu[c],
                (gpu[c] - cpu).abs(),
                (old - cpu).abs(),
            );
            assert!(
                (gpu[c] - cpu).abs() <= tolerance(cpu),
                "{kind} light, quad {:.0}° channel {c}: Bevy {} against the film lobe's {cpu}",
                phi.to_degrees(),
                gpu[c]
            );
            worst = worst.max((gpu[c] - cpu).abs() / cpu);
            old_missed |= (old - cpu).abs() > 10.0 * tolerance(cpu);
        }
        // Off the mirror configuration the previous material misses by more than ten
        // tolerances: the test tells the two apart.
        assert!(
            mirror || old_missed,
            "{kind} light, quad {:.0}°: the F₀-inversion is within the tolerance",
            phi.to_degrees()
        );
    }
    eprintln!("{technique:?}, {kind} light: largest relative difference Bevy − CPU {worst:.1e}");
}

/// The table events seen by [`record_table_events`].
#[derive(Resource, Default)]
struct TableEvents(Vec<AssetEvent<bevy_nacre::NacreTable>>);

fn record_table_events(
    mut reader: bevy::ecs::message::MessageReader<AssetEvent<bevy_nacre::NacreTable>>,
    mut seen: ResMut<TableEvents>,
) {
    seen.0.extend(reader.read().cloned());
}

/// Copies table `name` of `tables/baked` (manifest and KTX2 files) into `dir`, the manifest
/// as `as_name`.
fn copy_table(name: &str, dir: &std::path::Path, as_name: &str) {
    let baked = repo_root().join("tables/baked");
    std::fs::copy(baked.join(format!("{name}.json")), dir.join(as_name)).unwrap();
    for part in ["reflectance", "transmittance"] {
        let file = format!("{name}.{part}.ktx2");
        std::fs::copy(baked.join(&file), dir.join(&file)).unwrap();
    }
}

/// A re-baked table reaches the materials: a table loaded from a directory is rewritten (the
/// manifest and its KTX2 files replaced by another table's) and reloaded through the asset
/// server (`AssetServer::reload`, what Bevy's `file_watcher` calls on a change: the watcher
/// itself is not built for the tests, see README), which sends `AssetEvent::Modified`; the
/// asset then has the new axes, and a material using it is bound to the new textures.
#[test]
fn a_rewritten_table_reloads_into_its_materials() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bevy-table-reload");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    copy_table("soap-film", &dir, "table.json");
    let mut app = headless_app(&dir);
    app.init_resource::<TableEvents>()
        .add_systems(Update, record_table_events);
    let handle: Handle<bevy_nacre::NacreTable> =
        app.world().resource::<AssetServer>().load("table.json");
    let material = app
        .world_mut()
        .resource_mut::<Assets<NacreMaterial>>()
        .add(NacreMaterial {
            base: StandardMaterial::default(),
            extension: NacreFilm {
                lut_table: handle.clone(),
                ..default()
            },
        });
    let loaded = run_until(&mut app, 500, |world| {
        world
            .resource::<AssetServer>()
            .is_loaded_with_dependencies(&handle)
    });
    assert!(loaded, "table.json did not load");
    let axes = |world: &World| match world
        .resource::<Assets<bevy_nacre::NacreTable>>()
        .get(&handle)
        .unwrap()
        .axes
    {
        bevy_nacre::tables::NacreTableAxes::FilmLut(a) => a,
        _ => panic!("a film-lut table"),
    };
    let before = axes(app.world());

    copy_table("oil-slick", &dir, "table.json");
    app.world_mut().resource_mut::<TableEvents>().0.clear();
    app.world().resource::<AssetServer>().reload("table.json");
    let id = handle.id();
    let modified = run_until(&mut app, 500, |world| {
        world
            .resource::<TableEvents>()
            .0
            .contains(&AssetEvent::Modified { id })
    });
    assert!(modified, "no AssetEvent::Modified after the reload");
    run_until(&mut app, 3, |_| false);
    let world = app.world();
    let after = axes(world);
    let table = world
        .resource::<Assets<bevy_nacre::NacreTable>>()
        .get(&handle)
        .unwrap();
    eprintln!(
        "film index axis {}–{} → {}–{}",
        before.ior_min, before.ior_max, after.ior_min, after.ior_max
    );
    assert_eq!(table.name, "oil-slick");
    assert_ne!(before, after, "the axes did not change");
    let m = world
        .resource::<Assets<NacreMaterial>>()
        .get(&material)
        .unwrap();
    assert_eq!(m.extension.lut_axes, after);
    assert_eq!(m.extension.lut_reflectance.as_ref(), Some(&table.texture));
}

#[test]
fn the_specular_lobe_has_the_film_at_v_dot_h() {
    // film_lut on its table's base (index 1.5): `nacre color --method lut:film-dielectric`.
    let path = repo_root().join("tables/baked/film-dielectric.json");
    let manifest = nacre_format::Manifest::read(&path).unwrap();
    let axes = manifest.film_lut().cloned().unwrap();
    let table = manifest.load_table(&path, "reflectance").unwrap().unwrap();
    let film = |cos| {
        nacre_format::film_lut::FilmLut::lookup(
            &axes,
            &table,
            cos,
            LOBE_THICKNESS_NM,
            LOBE_FILM_IOR,
        )
    };
    for light in [
        LobeLight::Directional,
        LobeLight::Point,
        LobeLight::Spot,
        LobeLight::Environment,
    ] {
        specular_lobe(FilmTechnique::Lut, C64::new(1.5, 0.0), light, film);
    }
}

#[test]
fn the_specular_lobe_has_the_film_at_v_dot_h_on_a_metal() {
    // film_fourier on a metal base (n = 0.27 + 2.9i): `nacre color --method fourier:auto`.
    let path = repo_root().join("tables/baked/fourier-srgb.json");
    let manifest = nacre_format::Manifest::read(&path).unwrap();
    let fourier = manifest.load_fourier(&path).unwrap();
    let colorimeter = manifest.colorimeter(&path).unwrap();
    let base = C64::new(0.27, 2.9);
    let film = FilmOnBase {
        n_ambient: 1.0,
        n_film: LOBE_FILM_IOR,
        base: [base; 3],
    };
    specular_lobe(
        FilmTechnique::Fourier,
        base,
        LobeLight::Directional,
        |cos| {
            film.fourier_colour_with(
                &colorimeter,
                cos,
                LOBE_THICKNESS_NM,
                Harmonics::Auto,
                0.0,
                false,
                |mu, s| fourier.sample(mu, s),
            )
            .expect("a film of index 1.8 in air")
            .colour
        },
    );
}

/// `nacre color --method lut:film-dielectric` for the lobe tests' film (index 1.8, 400 nm):
/// R_f(cos θ) from the film-lut table on its base (index 1.5).
fn lobe_film_lut() -> impl Fn(f64) -> [f64; 3] {
    let path = repo_root().join("tables/baked/film-dielectric.json");
    let manifest = nacre_format::Manifest::read(&path).unwrap();
    let axes = manifest.film_lut().cloned().unwrap();
    let table = manifest.load_table(&path, "reflectance").unwrap().unwrap();
    move |cos| {
        nacre_format::film_lut::FilmLut::lookup(
            &axes,
            &table,
            cos,
            LOBE_THICKNESS_NM,
            LOBE_FILM_IOR,
        )
    }
}

/// The lobe tests' film material: black base (no diffuse), roughness
/// `LOBE_PERCEPTUAL_ROUGHNESS`, film index 1.8, 400 nm, with `technique` on `base`.
fn lobe_material(technique: FilmTechnique, base: C64) -> NacreMaterial {
    NacreMaterial {
        base: StandardMaterial {
            base_color: Color::BLACK,
            perceptual_roughness: LOBE_PERCEPTUAL_ROUGHNESS as f32,
            ..default()
        },
        extension: NacreFilm {
            technique,
            base_ior: Vec3::splat(base.re as f32),
            base_kappa: Vec3::splat(base.im as f32),
            film_ior: LOBE_FILM_IOR as f32,
            thickness: FilmThickness::Gltf {
                min_nm: LOBE_THICKNESS_NM as f32,
                max_nm: LOBE_THICKNESS_NM as f32,
            },
            weight: 1.0,
            ..default()
        },
    }
}

/// [`lobe_material`] with `film_lut` on the default base (1.5, the film-lut table's).
fn lobe_film_material() -> NacreMaterial {
    lobe_material(FilmTechnique::Lut, C64::new(1.5, 0.0))
}

/// The film's specular radiance on the CPU where the film's normal `normal` faces the view
/// direction `v` (unit vectors towards the viewer and, `l`, the light), under
/// `illuminance` (lux, before exposure): exposure × E × D V R_f(v·h) × n·l × Bevy's
/// multiple-scattering factor 1 + R_f(n·v) (1/(A + B) − 1), A + B = 1 − 0.55 r_p (Bevy's
/// F_AB at r_p = 0.6, see `specular_lobe`).
fn lobe_radiance(
    film: &impl Fn(f64) -> [f64; 3],
    normal: DVec3,
    v: DVec3,
    l: DVec3,
    illuminance: f64,
) -> [f64; 3] {
    let rp = LOBE_PERCEPTUAL_ROUGHNESS;
    let alpha = rp * rp;
    let half = (l + v).normalize();
    let (n_dot_v, n_dot_l, n_dot_h, v_dot_h) =
        (normal.dot(v), normal.dot(l), normal.dot(half), v.dot(half));
    if n_dot_l <= 0.0 {
        return [0.0; 3];
    }
    let exposure = f64::from(bevy::camera::Exposure { ev100: 0.0 }.exposure());
    let dv = ggx_d(alpha, n_dot_h) * smith_v(alpha, n_dot_v, n_dot_l) * n_dot_l;
    let (r_mu, r_vh) = (film(n_dot_v), film(v_dot_h));
    std::array::from_fn(|c| {
        exposure * illuminance * dv * r_vh[c] * (1.0 + r_mu[c] * (1.0 / (1.0 - 0.55 * rp) - 1.0))
    })
}

/// Pictures of the plane z = 0 through an orthographic camera on the z axis looking down −z,
/// `width_m` metres across `width` pixels (`height` pixels high): HDR, no tone mapping, no
/// dithering, exposure ev100 = 0, read back as linear floats; no ambient light.
struct PlaneView {
    width: u32,
    height: u32,
    width_m: f64,
}

impl PlaneView {
    /// A headless app with the camera and an Rgba32Float target; the scene is the caller's.
    fn app(&self) -> (App, Handle<Image>) {
        use bevy::core_pipeline::tonemapping::DebandDither;
        use bevy::render::render_resource::TextureFormat;
        let mut app = headless_app(&repo_root());
        let image = app
            .world_mut()
            .resource_mut::<Assets<Image>>()
            .add(Image::new_target_texture(
                self.width,
                self.height,
                TextureFormat::Rgba32Float,
                None,
            ));
        let world = app.world_mut();
        world.insert_resource(GlobalAmbientLight {
            color: Color::WHITE,
            brightness: 0.0,
            ..default()
        });
        world.spawn((
            Camera3d::default(),
            bevy::camera::Hdr,
            bevy::camera::Exposure { ev100: 0.0 },
            RenderTarget::Image(image.clone().into()),
            Tonemapping::None,
            DebandDither::Disabled,
            Projection::Orthographic(OrthographicProjection {
                scaling_mode: bevy::camera::ScalingMode::FixedHorizontal {
                    viewport_width: self.width_m as f32,
                },
                ..OrthographicProjection::default_3d()
            }),
            Transform::from_xyz(0.0, 0.0, 5.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        (app, image)
    }

    /// Renders and reads back: linear RGB per pixel, row by row.
    fn render(&self, app: &mut App, image: &Handle<Image>) -> Vec<[f64; 3]> {
        let bytes = capture(app, image, 10);
        assert_eq!(
            bytes.len(),
            16 * (self.width * self.height) as usize,
            "an Rgba32Float picture"
        );
        bytes
            .chunks_exact(16)
            .map(|p| {
                std::array::from_fn(|c| {
                    f64::from(f32::from_le_bytes(p[4 * c..4 * c + 4].try_into().unwrap()))
                })
            })
            .collect()
    }

    /// The point of the plane z = 0 seen at the centre of pixel (`px`, `py`).
    fn point(&self, px: usize, py: usize) -> DVec3 {
        let m_per_px = self.width_m / f64::from(self.width);
        DVec3::new(
            (px as f64 + 0.5) * m_per_px - self.width_m / 2.0,
            (f64::from(self.height) / 2.0 - (py as f64 + 0.5)) * m_per_px,
            0.0,
        )
    }
}

/// Bevy's spot cone at `p` for a spot at `position` aimed along `axis` (unit) with cone
/// angles `inner`, `outer` (rad): t = saturate(cos ψ s + o), s = 1/(cos inner − cos outer),
/// o = −cos outer · s, ψ the angle between the axis and p − position; the light is scaled
/// by t² (Filament's spot attenuation, as `bevy_pbr`'s `spot_light`).
fn spot_cone(position: DVec3, axis: DVec3, inner: f64, outer: f64, p: DVec3) -> f64 {
    let scale = 1.0 / (inner.cos() - outer.cos()).max(1e-4);
    let t = ((p - position).normalize().dot(axis) * scale - outer.cos() * scale).clamp(0.0, 1.0);
    t * t
}

/// A spot light's cone edge crosses a flat film and, beside it, a flat `StandardMaterial`:
/// the film's specular is cut where Bevy's own lit area is. Two pictures of the same scene,
/// under the spot light and under a point light in its place (same intensity): their ratio
/// at every pixel of a row crossing the cone's edge on both quads is the CPU's cone factor
/// t² (`spot_cone`), to 0.3 % — for `StandardMaterial` (which checks the CPU's cone against
/// Bevy's) and for the film (whose lobe has its own spot code). The spot points down
/// (its axis's y < 0, stored as a flag) and sideways, so the axis's packing is exercised; a
/// film without the cone (ratio 1), with t in place of t² or the axis's y sign lost misses
/// by more than ten tolerances.
#[test]
fn the_film_lobe_is_cut_by_spot_cones() {
    let view = PlaneView {
        width: 400,
        height: 80,
        width_m: 5.0,
    };
    let position = DVec3::new(0.0, 1.8, 2.5);
    let aim = DVec3::new(0.25, 0.0, 0.0);
    let axis = (aim - position).normalize();
    let (inner, outer) = (0.25, 0.45);
    let intensity_lm = (LOBE_POINT_CD * 4.0 * std::f64::consts::PI) as f32;
    // Film quad on the left, StandardMaterial (white diffuse) on the right.
    const QUAD_HALF_WIDTH: f64 = 1.2;
    let quads = [(-1.25f64, true), (1.25, false)];
    let render = |spot: bool| {
        let (mut app, image) = view.app();
        let world = app.world_mut();
        let mesh = world
            .resource_mut::<Assets<Mesh>>()
            .add(Rectangle::new(2.0 * QUAD_HALF_WIDTH as f32, 0.9));
        let film = world
            .resource_mut::<Assets<NacreMaterial>>()
            .add(lobe_film_material());
        let standard = world
            .resource_mut::<Assets<StandardMaterial>>()
            .add(StandardMaterial {
                base_color: Color::WHITE,
                perceptual_roughness: LOBE_PERCEPTUAL_ROUGHNESS as f32,
                ..default()
            });
        for (x, is_film) in quads {
            let mut quad = world.spawn((
                Mesh3d(mesh.clone()),
                Transform::from_xyz(x as f32, 0.0, 0.0),
            ));
            if is_film {
                quad.insert(MeshMaterial3d(film.clone()));
            } else {
                quad.insert(MeshMaterial3d(standard.clone()));
            }
        }
        let transform =
            Transform::from_translation(position.as_vec3()).looking_at(aim.as_vec3(), Vec3::Y);
        if spot {
            world.spawn((
                SpotLight {
                    intensity: intensity_lm,
                    range: LOBE_POINT_RANGE as f32,
                    radius: 0.0,
                    inner_angle: inner as f32,
                    outer_angle: outer as f32,
                    ..default()
                },
                transform,
            ));
        } else {
            world.spawn((
                PointLight {
                    intensity: intensity_lm,
                    range: LOBE_POINT_RANGE as f32,
                    radius: 0.0,
                    ..default()
                },
                transform,
            ));
        }
        view.render(&mut app, &image)
    };
    let (spot, point) = (render(true), render(false));

    let py = view.height as usize / 2;
    let tolerance = |point: f64| 3e-3 * point + 1e-5;
    for (centre, is_film) in quads {
        let name = if is_film { "film" } else { "StandardMaterial" };
        let (mut dark, mut edge, mut full) = (0, 0, 0);
        let mut worst: f64 = 0.0;
        for px in 0..view.width as usize {
            let p = view.point(px, py);
            if (p.x - centre).abs() > QUAD_HALF_WIDTH - 0.05 {
                continue;
            }
            let cone = spot_cone(position, axis, inner, outer, p);
            let (s, q) = (
                spot[py * view.width as usize + px],
                point[py * view.width as usize + px],
            );
            if cone == 0.0 {
                dark += 1;
            } else if cone == 1.0 {
                full += 1;
            } else if (0.05..0.95).contains(&cone) {
                edge += 1;
            }
            for c in 0..3 {
                assert!(
                    q[c] > 1e-3,
                    "{name} at x = {:.3}: {} under the point light",
                    p.x,
                    q[c]
                );
                let diff = (s[c] - cone * q[c]).abs();
                assert!(
                    diff <= tolerance(q[c]),
                    "{name} at x = {:.3}, channel {c}: spot {} against t² = {cone:.4} × point {} = {}",
                    p.x,
                    s[c],
                    q[c],
                    cone * q[c]
                );
                worst = worst.max(diff / q[c]);
            }
        }
        eprintln!(
            "{name}: {dark} pixels outside the cone, {edge} on its edge (0.05 < t² < 0.95), {full} inside; largest |spot − t² point|/point {worst:.1e}"
        );
        // The row crosses the cone's edge on both quads.
        assert!(
            dark >= 10 && edge >= 20 && full >= 10,
            "{name}: {dark} dark, {edge} edge, {full} full pixels"
        );
    }
}

/// The light of the shadow test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ShadowLight {
    Point,
    Spot,
    Directional,
}

/// Whether the segment from `from` along `direction` (t in [0, `t_max`]) meets the
/// axis-aligned box `centre` ± `half` (slab test).
fn ray_hits_box(from: DVec3, direction: DVec3, t_max: f64, centre: DVec3, half: f64) -> bool {
    let (mut t0, mut t1) = (0.0f64, t_max);
    for k in 0..3 {
        let (lo, hi) = (centre[k] - half, centre[k] + half);
        if direction[k].abs() < 1e-12 {
            if from[k] < lo || from[k] > hi {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo - from[k]) / direction[k], (hi - from[k]) / direction[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1
}

/// A cube between a shadow-casting light and a flat film: the film's specular vanishes in
/// the cube's shadow and is the unshadowed lobe elsewhere. One picture per light (point:
/// `fetch_point_shadow`, spot: `fetch_spot_shadow`, directional: `fetch_directional_shadow`);
/// along a row crossing the shadow each pixel is classified on the CPU by casting its ray to
/// the light against the cube shrunk and grown by 3 cm (so the shadow map's filtering and
/// biases at the edge are left out): in the shadow the film is below 1 % of the CPU's
/// unshadowed lobe (`lobe_radiance`, which is ≥ 0.01 there), outside it within the lobe
/// tests' 0.3 % + 10⁻⁴. A film lobe that ignored the shadow maps would keep its full value in
/// the shadow.
fn film_shadow(light: ShadowLight) {
    let view = PlaneView {
        width: 400,
        height: 60,
        width_m: 4.0,
    };
    let film = lobe_film_lut();
    let position = DVec3::new(1.5, 0.0, 2.0);
    let to_light = position.normalize();
    let (cube_centre, cube_half) = (DVec3::new(0.9, 0.0, 1.2), 0.2);
    let (inner, outer) = (0.7, 0.9);
    let (mut app, image) = view.app();
    let world = app.world_mut();
    let plane = world
        .resource_mut::<Assets<Mesh>>()
        .add(Rectangle::new(view.width_m as f32, 1.0));
    let material = world
        .resource_mut::<Assets<NacreMaterial>>()
        .add(lobe_film_material());
    world.spawn((
        Mesh3d(plane),
        MeshMaterial3d(material),
        Transform::default(),
    ));
    let cube = world
        .resource_mut::<Assets<Mesh>>()
        .add(Cuboid::from_length(2.0 * cube_half as f32));
    let grey = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial::default());
    world.spawn((
        Mesh3d(cube),
        MeshMaterial3d(grey),
        Transform::from_translation(cube_centre.as_vec3()),
    ));
    let at_light = Transform::from_translation(position.as_vec3()).looking_at(Vec3::ZERO, Vec3::Y);
    let intensity_lm = (LOBE_POINT_CD * 4.0 * std::f64::consts::PI) as f32;
    match light {
        ShadowLight::Point => {
            world.spawn((
                PointLight {
                    intensity: intensity_lm,
                    range: LOBE_POINT_RANGE as f32,
                    radius: 0.0,
                    shadow_maps_enabled: true,
                    ..default()
                },
                at_light,
            ));
        }
        ShadowLight::Spot => {
            world.spawn((
                SpotLight {
                    intensity: intensity_lm,
                    range: LOBE_POINT_RANGE as f32,
                    radius: 0.0,
                    inner_angle: inner as f32,
                    outer_angle: outer as f32,
                    shadow_maps_enabled: true,
                    ..default()
                },
                at_light,
            ));
        }
        ShadowLight::Directional => {
            world.spawn((
                DirectionalLight {
                    illuminance: LOBE_LUX as f32,
                    shadow_maps_enabled: true,
                    ..default()
                },
                // One cascade over the whole scene (the camera is 5 m from the film).
                bevy::light::CascadeShadowConfigBuilder {
                    num_cascades: 1,
                    maximum_distance: 10.0,
                    first_cascade_far_bound: 10.0,
                    ..default()
                }
                .build(),
                at_light,
            ));
        }
    }
    let pixels = view.render(&mut app, &image);

    let py = view.height as usize / 2;
    let v = DVec3::Z;
    let normal = DVec3::Z;
    let (mut shadowed, mut lit) = (0, 0);
    let mut worst: f64 = 0.0;
    let mut darkest: f64 = 0.0;
    for px in 0..view.width as usize {
        let p = view.point(px, py);
        // Skip where the camera sees the cube rather than the film.
        if ray_hits_box(p, v, 10.0, cube_centre, cube_half + 0.02) || p.x.abs() > 1.9 {
            continue;
        }
        let (l, distance, illuminance) = match light {
            ShadowLight::Directional => (to_light, 100.0, LOBE_LUX),
            ShadowLight::Point | ShadowLight::Spot => {
                let to = position - p;
                let d2 = to.length_squared();
                let falloff = (1.0 - (d2 / LOBE_POINT_RANGE.powi(2)).powi(2)).clamp(0.0, 1.0);
                let cone = if light == ShadowLight::Spot {
                    spot_cone(position, -position.normalize(), inner, outer, p)
                } else {
                    1.0
                };
                (
                    to.normalize(),
                    d2.sqrt(),
                    LOBE_POINT_CD * falloff * falloff / d2 * cone,
                )
            }
        };
        let inside = ray_hits_box(p, l, distance, cube_centre, cube_half - 0.03);
        let outside = !ray_hits_box(p, l, distance, cube_centre, cube_half + 0.03);
        let cpu = lobe_radiance(&film, normal, v, l, illuminance);
        let gpu = pixels[py * view.width as usize + px];
        for c in 0..3 {
            if inside {
                assert!(
                    cpu[c] >= 0.01,
                    "{light:?}: the unshadowed lobe at x = {:.3} is {} (too faint to tell)",
                    p.x,
                    cpu[c]
                );
                assert!(
                    gpu[c] <= 0.01 * cpu[c],
                    "{light:?} light, x = {:.3} (in the cube's shadow), channel {c}: the film's specular is {} against {} unshadowed",
                    p.x,
                    gpu[c],
                    cpu[c]
                );
                darkest = darkest.max(gpu[c] / cpu[c]);
            } else if outside {
                assert!(
                    (gpu[c] - cpu[c]).abs() <= 3e-3 * cpu[c] + 1e-4,
                    "{light:?} light, x = {:.3} (lit), channel {c}: Bevy {} against the lobe's {}",
                    p.x,
                    gpu[c],
                    cpu[c]
                );
                if cpu[c] > 0.0 {
                    worst = worst.max((gpu[c] - cpu[c]).abs() / cpu[c]);
                }
            }
        }
        shadowed += usize::from(inside);
        lit += usize::from(outside);
    }
    eprintln!(
        "{light:?} light: {shadowed} shadowed pixels (largest film/unshadowed {darkest:.1e}), {lit} lit pixels (largest relative difference to the lobe {worst:.1e})"
    );
    assert!(
        shadowed >= 20 && lit >= 100,
        "{light:?}: {shadowed} shadowed and {lit} lit pixels on the row"
    );
}

#[test]
fn the_film_lobe_is_shadowed_by_point_lights() {
    film_shadow(ShadowLight::Point);
}

#[test]
fn the_film_lobe_is_shadowed_by_spot_lights() {
    film_shadow(ShadowLight::Spot);
}

#[test]
fn the_film_lobe_is_shadowed_by_directional_lights() {
    film_shadow(ShadowLight::Directional);
}

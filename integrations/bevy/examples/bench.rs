//! Frame time of the film material against `StandardMaterial` in the same Bevy scene: a grid
//! of spheres filling a headless 1280 × 720 target, rendered with `StandardMaterial`, with
//! `NacreMaterial` on `film_lut`, on `film_fourier` and on `film_stack` (the default
//! two-film stack, `bevy_nacre::material::default_stack`, its top film d across the grid);
//! each frame waits for the GPU. Prints
//! milliseconds per frame (median of the timed frames) and the ratios. A benchmark, not a
//! test: the figures go to BENCHMARKS.md.
//!
//! ```text
//! cargo run --release --example bench [-- FRAMES]
//! ```

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::ecs::system::RunSystemOnce;
use bevy::prelude::*;
use bevy::render::render_resource::{PollType, TextureFormat};
use bevy::render::renderer::RenderDevice;
use bevy::render::{RenderApp, RenderPlugin};
use bevy_nacre::{FilmTechnique, FilmThickness, NacreFilm, NacreMaterial};
use std::path::Path;
use std::time::Instant;

#[path = "common/headless.rs"]
mod headless;
#[path = "common/scene.rs"]
mod scene;

const GRID: usize = 12;
const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;

#[derive(Clone, Copy, Debug)]
enum Kind {
    Standard,
    Film(FilmTechnique),
}

fn base() -> StandardMaterial {
    StandardMaterial {
        base_color: Color::BLACK,
        perceptual_roughness: 0.25,
        ..default()
    }
}

/// Median milliseconds per frame of `frames` frames after 10 warm-up frames.
fn time_scene(kind: Kind, frames: usize) -> f64 {
    // Pipelines compile before the first frame that needs them: the warm-up frames then
    // render the scene (compiled asynchronously, a large material shader on lavapipe can
    // still be compiling when the timed frames start, which then time an empty scene).
    let mut app = headless::headless_app(
        Path::new("assets"),
        RenderPlugin {
            synchronous_pipeline_compilation: true,
            ..default()
        },
    );
    app.world_mut()
        .run_system_once(
            move |mut commands: Commands,
                  mut meshes: ResMut<Assets<Mesh>>,
                  mut images: ResMut<Assets<Image>>,
                  mut standard: ResMut<Assets<StandardMaterial>>,
                  mut films: ResMut<Assets<NacreMaterial>>| {
                scene::spawn_lights(&mut commands);
                let mesh = meshes.add(Sphere::new(0.45).mesh().uv(64, 32));
                for i in 0..GRID * GRID {
                    let (x, y) = ((i % GRID) as f32, (i / GRID) as f32);
                    let at = Transform::from_xyz(
                        x - (GRID - 1) as f32 / 2.0,
                        y - (GRID - 1) as f32 / 2.0,
                        0.0,
                    );
                    let d = 1100.0 * i as f32 / (GRID * GRID) as f32;
                    let mut entity = commands.spawn((Mesh3d(mesh.clone()), at));
                    match kind {
                        Kind::Standard => {
                            entity.insert(MeshMaterial3d(standard.add(base())));
                        }
                        Kind::Film(technique) => {
                            entity.insert(MeshMaterial3d(films.add(NacreMaterial {
                                base: base(),
                                extension: NacreFilm {
                                    technique,
                                    film_ior: 1.8,
                                    thickness: FilmThickness::Gltf {
                                        min_nm: d,
                                        max_nm: d,
                                    },
                                    weight: 1.0,
                                    ..default()
                                },
                            })));
                        }
                    }
                }
                let target = images.add(Image::new_target_texture(
                    WIDTH,
                    HEIGHT,
                    TextureFormat::Rgba8UnormSrgb,
                    None,
                ));
                commands.spawn((
                    Camera3d::default(),
                    RenderTarget::Image(target.into()),
                    Tonemapping::None,
                    Projection::Orthographic(OrthographicProjection {
                        scaling_mode: bevy::camera::ScalingMode::FixedVertical {
                            viewport_height: GRID as f32,
                        },
                        ..OrthographicProjection::default_3d()
                    }),
                    Transform::from_xyz(0.0, 0.0, 10.0).looking_at(Vec3::ZERO, Vec3::Y),
                ));
            },
        )
        .expect("setting up the scene");
    let wait = |app: &App| {
        app.get_sub_app(RenderApp)
            .expect("a renderer")
            .world()
            .resource::<RenderDevice>()
            .poll(PollType::Wait {
                submission_index: None,
                timeout: None,
            })
            .expect("waiting for the GPU");
    };
    for _ in 0..10 {
        app.update();
        wait(&app);
    }
    let mut ms: Vec<f64> = (0..frames)
        .map(|_| {
            let t = Instant::now();
            app.update();
            wait(&app);
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    ms[ms.len() / 2]
}

fn main() {
    let frames: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(30);
    let standard = time_scene(Kind::Standard, frames);
    println!(
        "StandardMaterial: {standard:.2} ms/frame ({GRID}×{GRID} spheres, {WIDTH}×{HEIGHT}, median of {frames})"
    );
    for technique in [
        FilmTechnique::Lut,
        FilmTechnique::Fourier,
        FilmTechnique::Stack,
    ] {
        let film = time_scene(Kind::Film(technique), frames);
        println!(
            "NacreMaterial ({technique:?}): {film:.2} ms/frame, {:.2}× StandardMaterial",
            film / standard
        );
    }
}

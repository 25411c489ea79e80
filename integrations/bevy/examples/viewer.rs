//! Interactive: a window with an orbit camera (drag with the left mouse button, scroll to
//! zoom), the sphere row sweeping thickness, and a glTF asset — by default Khronos'
//! IridescenceSuzanne from `../shared/gltf-samples` (see `../shared/DATA.md`).
//!
//! ```text
//! cargo run --release --features viewer --example viewer -- [ASSET.gltf] [--frames N] [--screenshot PATH]
//! ```
//!
//! `--frames N` runs without a user: it exits by itself after N frames, counted from the
//! frame where the glTF asset (if any) has loaded, with pipelines compiled before the first
//! frame that draws them, so that frame N shows the whole scene; `--screenshot PATH` saves
//! the window's picture at that frame (PNG) before exiting (N = 10 when only `--screenshot`
//! is given). `tests/viewer.rs` runs it that way under Xvfb.

use bevy::gltf::GltfAssetLabel;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::winit::WinitSettings;
use bevy::world_serialization::{WorldAsset, WorldAssetRoot};
use bevy_nacre::{NacreMaterial, NacrePlugin};
use std::path::PathBuf;

#[path = "common/scene.rs"]
pub mod scene;

/// The camera's orbit about the origin.
#[derive(Component, Clone, Copy, Debug)]
pub struct Orbit {
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
}

/// The camera's starting orbit.
pub const START: Orbit = Orbit {
    yaw: 0.0,
    pitch: 0.1,
    distance: 7.5,
};

/// Where the sphere row's centre is.
pub const ROW_CENTRE: Vec3 = Vec3::new(0.0, -1.6, 0.0);

impl Orbit {
    /// The camera's transform: at `distance` from the origin, turned by `yaw` about the
    /// vertical and raised by `pitch`, looking at the origin.
    pub fn transform(&self) -> Transform {
        let eye =
            Quat::from_euler(EulerRot::YXZ, self.yaw, -self.pitch, 0.0) * Vec3::Z * self.distance;
        Transform::from_translation(eye).looking_at(Vec3::ZERO, Vec3::Y)
    }
}

/// The command line: `[ASSET.gltf] [--frames N] [--screenshot PATH]`.
#[derive(Debug, Default, PartialEq)]
pub struct Options {
    /// The glTF asset shown above the sphere row.
    pub asset: Option<PathBuf>,
    /// Exit by itself after this many frames (counted once the asset has loaded).
    pub frames: Option<u32>,
    /// Save the window's picture (PNG) at the last frame.
    pub screenshot: Option<PathBuf>,
}

/// Frames after which a `--screenshot` run without `--frames` exits.
pub const DEFAULT_SCREENSHOT_FRAMES: u32 = 10;

impl Options {
    /// Parses the arguments after the program's name; the message names the flag at fault.
    pub fn parse(args: impl IntoIterator<Item = String>) -> Result<Self, String> {
        let mut options = Options::default();
        let mut args = args.into_iter();
        while let Some(arg) = args.next() {
            match arg.as_str() {
                "--frames" => {
                    let value = args.next().ok_or("--frames needs a number of frames")?;
                    let frames = value
                        .parse::<u32>()
                        .ok()
                        .filter(|&n| n > 0)
                        .ok_or(format!("--frames {value}: not a whole number above 0"))?;
                    options.frames = Some(frames);
                }
                "--screenshot" => {
                    let value = args.next().ok_or("--screenshot needs a file path")?;
                    options.screenshot = Some(PathBuf::from(value));
                }
                flag if flag.starts_with("--") => return Err(format!("unknown flag {flag}")),
                _ if options.asset.is_some() => {
                    return Err(format!("a second asset {arg}: the viewer shows one"));
                }
                _ => options.asset = Some(PathBuf::from(arg)),
            }
        }
        if options.screenshot.is_some() && options.frames.is_none() {
            options.frames = Some(DEFAULT_SCREENSHOT_FRAMES);
        }
        Ok(options)
    }
}

/// The glTF asset to show: its file name and the scene's handle once loading started.
#[derive(Resource)]
struct Asset {
    file: Option<String>,
    scene: Option<Handle<WorldAsset>>,
}

/// A run without a user (`--frames`): frames still to draw, where the screenshot goes.
#[derive(Resource)]
struct Auto {
    frames: u32,
    screenshot: Option<PathBuf>,
    /// Frames run since the start (a bound on waiting for the asset and the screenshot).
    elapsed: u32,
    /// The screenshot was asked for.
    requested: bool,
}

/// Frames a `--frames` run waits for its asset, and for its screenshot, before failing.
const WAIT_FRAMES: u32 = 3000;

fn main() -> AppExit {
    match Options::parse(std::env::args().skip(1)) {
        Ok(options) => run(options),
        Err(message) => {
            eprintln!("viewer: {message}");
            eprintln!("usage: viewer [ASSET.gltf] [--frames N] [--screenshot PATH]");
            AppExit::from_code(2)
        }
    }
}

/// Runs the viewer until its window closes (or, with `--frames`, by itself).
pub fn run(options: Options) -> AppExit {
    let asset = options.asset.or_else(|| {
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
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(AssetPlugin {
                file_path: root.to_string_lossy().into_owned(),
                ..default()
            })
            .set(WindowPlugin {
                primary_window: Some(Window {
                    title: "bevy_nacre viewer".into(),
                    ..default()
                }),
                ..default()
            })
            .set(RenderPlugin {
                // Without a user, pipelines compile before the frame that draws them, so
                // the counted frames show the whole scene.
                synchronous_pipeline_compilation: options.frames.is_some(),
                ..default()
            }),
    )
    .add_plugins(NacrePlugin)
    .insert_resource(Asset { file, scene: None })
    .add_systems(Startup, setup)
    .add_systems(Update, orbit);
    if let Some(frames) = options.frames {
        // Frames keep coming whether or not the window has the focus (Xvfb has no window
        // manager to give it).
        app.insert_resource(WinitSettings::continuous())
            .insert_resource(Auto {
                frames,
                screenshot: options.screenshot,
                elapsed: 0,
                requested: false,
            })
            .add_systems(Update, auto_exit);
    }
    app.run()
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<NacreMaterial>>,
    asset_server: Res<AssetServer>,
    mut asset: ResMut<Asset>,
) {
    scene::spawn_lights(&mut commands);
    scene::spawn_sphere_row(&mut commands, &mut meshes, &mut materials, ROW_CENTRE);
    if let Some(file) = asset.file.clone() {
        let scene = asset_server.load(GltfAssetLabel::Scene(0).from_asset(file));
        commands.spawn((
            WorldAssetRoot(scene.clone()),
            Transform::from_xyz(0.0, 0.6, 0.0),
        ));
        asset.scene = Some(scene);
    }
    commands.spawn((Camera3d::default(), START, START.transform()));
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
        *t = o.transform();
    }
}

/// `--frames`: counts the frames once the asset has loaded; at the last one asks for the
/// screenshot (whose observer saves it and exits) or exits. Fails (exit status 1) when the
/// asset does not load or the screenshot does not come back within [`WAIT_FRAMES`].
fn auto_exit(
    mut commands: Commands,
    mut auto: ResMut<Auto>,
    asset: Res<Asset>,
    asset_server: Res<AssetServer>,
    mut exit: MessageWriter<AppExit>,
) {
    auto.elapsed += 1;
    if auto.elapsed > WAIT_FRAMES + auto.frames {
        error!(
            "viewer: {} after {} frames",
            if auto.requested {
                "no screenshot"
            } else {
                "the asset has not loaded"
            },
            auto.elapsed
        );
        exit.write(AppExit::error());
        return;
    }
    if let Some(scene) = &asset.scene {
        if asset_server.load_state(scene).is_failed() {
            error!("viewer: {:?} did not load", asset.file);
            exit.write(AppExit::error());
            return;
        }
        if !asset_server.is_loaded_with_dependencies(scene) {
            return;
        }
    }
    if auto.requested {
        return;
    }
    auto.frames -= 1;
    if auto.frames > 0 {
        return;
    }
    let Some(path) = auto.screenshot.clone() else {
        exit.write(AppExit::Success);
        return;
    };
    auto.requested = true;
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
            let saved = captured
                .image
                .clone()
                .try_into_dynamic()
                .map_err(|e| e.to_string())
                .and_then(|image| image.to_rgb8().save(&path).map_err(|e| e.to_string()));
            match saved {
                Ok(()) => {
                    info!("viewer: screenshot saved to {}", path.display());
                    exit.write(AppExit::Success);
                }
                Err(e) => {
                    error!("viewer: cannot save the screenshot {}: {e}", path.display());
                    exit.write(AppExit::error());
                }
            }
        },
    );
}

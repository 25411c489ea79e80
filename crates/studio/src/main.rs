//! `nacre-studio`: the studio in a native window (eframe, wgpu). The view renders through
//! the window's own device: the runtime's `GpuContext` wraps eframe's adapter, device and
//! queue.
//!
//! `--screenshot PATH --frames N` draws N frames, saves the window's picture as a PNG
//! (atomically) and exits: for tests under Xvfb and for the README's pictures.

use clap::Parser;
use eframe::egui;
use eframe::egui_wgpu::{WgpuConfiguration, WgpuSetup, WgpuSetupCreateNew};
use nacre_format::atomic::write_atomic;
use nacre_format::materials::{MaterialDb, set_database};
use nacre_runtime::{GpuContext, Technique};
use nacre_studio::material_db;
use nacre_studio::view::Lighting;
use nacre_studio::{StackDoc, Studio, View};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// nacre studio: design a thin-film stack by eye, live on the runtime's renderer.
#[derive(Parser)]
#[command(name = "nacre-studio", version)]
struct Args {
    /// Start from this stack recipe (the TOML `nacre color --recipe` reads) instead of the
    /// last session's stack.
    #[arg(long, value_name = "FILE.toml")]
    recipe: Option<PathBuf>,
    /// The session file: the stack, saved as a recipe on every change and restored on
    /// start [default: $XDG_STATE_HOME/nacre/studio-session.toml, else
    /// ~/.local/state/nacre/studio-session.toml; none with --screenshot].
    #[arg(long, value_name = "FILE.toml", conflicts_with = "no_session")]
    session: Option<PathBuf>,
    /// Neither restore nor save a session.
    #[arg(long)]
    no_session: bool,
    /// Draw --frames frames, save the window's picture to this PNG and exit.
    #[arg(long, value_name = "FILE.png")]
    screenshot: Option<PathBuf>,
    /// Frames to draw before --screenshot (1 to 10000).
    #[arg(long, value_name = "N", default_value_t = 5)]
    frames: u64,
    /// Window size, logical pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1440x900")]
    window: String,
    /// The view's picture size, pixels, WIDTHxHEIGHT [default: the space the window leaves].
    #[arg(long, value_name = "WxH")]
    view_size: Option<String>,
    /// Technique: stack, spectral, fourier or lut.
    #[arg(long, default_value = "stack")]
    technique: String,
    /// Lighting: studio (the bundled environment and its sun) or uniform (a white sky);
    /// --env replaces both.
    #[arg(long, default_value = "studio")]
    lighting: String,
    /// Light the view with this equirectangular environment (OpenEXR or Radiance HDR,
    /// linear; PNG or JPEG, sRGB; row 0 = zenith), as `nacre render --env`.
    #[arg(long, value_name = "FILE")]
    env: Option<PathBuf>,
    /// A thickness map (PNG or JPEG, grey or colour) in place of the procedural one, as
    /// `nacre render --thickness-map`.
    #[arg(long, value_name = "FILE.png")]
    thickness_map: Option<PathBuf>,
    /// Where `lut` keeps the tables it bakes for stacks the bundled table does not hold
    /// [default: $XDG_CACHE_HOME/nacre/studio-luts, else ~/.cache/nacre/studio-luts].
    #[arg(long, value_name = "DIR", conflicts_with = "no_lut_cache")]
    lut_cache: Option<PathBuf>,
    /// Bake no stack tables: `lut` draws every stack with the bundled film-dielectric table
    /// (its ambient and base), as before.
    #[arg(long)]
    no_lut_cache: bool,
    /// Turn the camera by a degree every frame (every frame is drawn anew) and print the
    /// mean frame time at exit: the frame-time benchmark.
    #[arg(long)]
    spin: bool,
}

/// A bad flag: the message names it; exit status 2.
fn bad(flag: &str, message: impl std::fmt::Display) -> ! {
    eprintln!("error: {flag}: {message}");
    std::process::exit(2);
}

/// The default session file (`--session`), if a home or state folder is known.
fn default_session() -> Option<PathBuf> {
    Some(
        nacre_studio::folders::user_folder("XDG_STATE_HOME", ".local/state")?
            .join("nacre")
            .join("studio-session.toml"),
    )
}

fn size(flag: &str, text: &str) -> [u32; 2] {
    let parsed = text
        .split_once('x')
        .and_then(|(w, h)| Some([w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?]));
    match parsed {
        Some([w, h]) if (64..=8192).contains(&w) && (64..=8192).contains(&h) => [w, h],
        _ => bad(
            flag,
            format!("`{text}` (expected WIDTHxHEIGHT, 64 to 8192 each)"),
        ),
    }
}

struct App {
    studio: Studio,
    started: Instant,
    first_picture: Option<f64>,
    frames: u64,
    screenshot: Option<PathBuf>,
    wanted_frames: u64,
    requested: bool,
    shot: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
    exit_code: Arc<Mutex<i32>>,
    spin: bool,
    /// Per drawn frame: its seconds and its render pass's.
    spin_seconds: Vec<(f64, f64)>,
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let drawn = self.studio.frames_drawn;
        if self.spin {
            self.studio.settings.orbit.drag(2.5, 0.0);
        }
        self.studio.ui(ui);
        if self.studio.frames_drawn > drawn {
            if self.first_picture.is_none() {
                let t = self.started.elapsed().as_secs_f64();
                self.first_picture = Some(t);
                eprintln!("first picture after {t:.2} s");
            }
            // A stack's lut table baking in the background: the frames draw `stack`.
            if let Some(f) = &self.studio.frame
                && self.studio.live_lut.progress().is_none()
            {
                self.spin_seconds.push((f.seconds, f.image.gpu_seconds));
            }
        }
        self.frames += 1;
        let ctx = ui.ctx().clone();
        if self.spin || self.screenshot.is_some() {
            ctx.request_repaint();
        }
        let Some(path) = self.screenshot.clone() else {
            return;
        };
        let taken = self.shot.lock().unwrap_or_else(|e| e.into_inner()).take();
        if let Some(image) = taken {
            let [w, h] = image.size;
            let rgba: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
            let saved = image::RgbaImage::from_raw(w as u32, h as u32, rgba)
                .ok_or_else(|| "the screenshot's size and pixels disagree".to_string())
                .and_then(|img| {
                    // The window is opaque: RGB, adaptive row filters and the best
                    // compression keep the README's pictures small (1280 × 800: 280 KB
                    // against 437 KB as RGBA at the default settings).
                    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
                    let rgb = image::DynamicImage::ImageRgba8(img).to_rgb8();
                    let mut png = Vec::new();
                    rgb.write_with_encoder(PngEncoder::new_with_quality(
                        &mut png,
                        CompressionType::Best,
                        FilterType::Adaptive,
                    ))
                    .map_err(|e| e.to_string())?;
                    write_atomic(&path, |out| out.write_all(&png)).map_err(|e| e.to_string())
                });
            match saved {
                Ok(()) => eprintln!(
                    "saved {} ({w}x{h}) after {} frames",
                    path.display(),
                    self.frames
                ),
                Err(e) => {
                    eprintln!("error: --screenshot {}: {e}", path.display());
                    *self.exit_code.lock().unwrap_or_else(|e| e.into_inner()) = 2;
                }
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        }
        // With `lut` on a stack that needs its own table: once the table is drawn.
        let ready = self.studio.frame.is_some()
            && self.studio.curves_current()
            && self.studio.live_lut.progress().is_none();
        if !self.requested
            && self.frames >= self.wanted_frames
            && (ready || self.studio.view_error.is_some())
        {
            self.requested = true;
            let slot = Arc::clone(&self.shot);
            let waker = ctx.clone();
            ctx.request_screenshot(move |image| {
                *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(image);
                waker.request_repaint();
            });
        }
    }

    fn on_exit(&mut self) {
        self.studio.save_session();
        if self.spin && !self.spin_seconds.is_empty() {
            // The first frame compiles the pipeline: left out.
            let s = &self.spin_seconds[1.min(self.spin_seconds.len() - 1)..];
            let mean = |k: usize| {
                s.iter()
                    .map(|f| if k == 0 { f.0 } else { f.1 })
                    .sum::<f64>()
                    / s.len() as f64
            };
            let frame = self.studio.frame.as_ref();
            eprintln!(
                "view frames: {} at {}x{} ({}), mean {:.2} ms (render pass {:.2} ms; the rest: uniforms, environment upload, readback, texture upload)",
                s.len(),
                frame.map_or(0, |f| f.image.width),
                frame.map_or(0, |f| f.image.height),
                self.studio.settings.technique.name(),
                mean(0) * 1e3,
                mean(1) * 1e3
            );
        }
    }
}

fn main() {
    let started = Instant::now();
    let args = Args::parse();
    if !(1..=10000).contains(&args.frames) {
        bad("--frames", format!("{} (expected 1 to 10000)", args.frames));
    }
    let window = size("--window", &args.window);
    let view_size = args.view_size.as_deref().map(|t| size("--view-size", t));
    let technique = Technique::from_name(&args.technique).unwrap_or_else(|| {
        bad(
            "--technique",
            format!(
                "`{}` (expected stack, spectral, fourier or lut)",
                args.technique
            ),
        )
    });
    let lighting = match args.lighting.as_str() {
        "studio" => Lighting::Studio,
        "uniform" => Lighting::Uniform,
        other => bad(
            "--lighting",
            format!("`{other}` (expected studio or uniform)"),
        ),
    };
    // The material database `shelf/book/page` materials are read from (recipes, the
    // session, the browser): NACRE_MATERIAL_DB, else ../shared beside the repository.
    let db_origin = if std::env::var_os(material_db::DB_ENV).is_some_and(|v| !v.is_empty()) {
        material_db::DB_ENV
    } else {
        "the shared material database folder"
    };
    set_database(material_db::default_folder().map(|d| MaterialDb::new(d, db_origin)));
    // Read the recipe before opening the window: bad input fails fast.
    let doc = match &args.recipe {
        Some(path) => {
            let doc = StackDoc::read_recipe(path).unwrap_or_else(|e| bad("--recipe", e));
            if let Err(e) = doc.build() {
                bad("--recipe", e);
            }
            doc
        }
        None => StackDoc::default(),
    };
    if let Some(path) = &args.env
        && let Err(e) = nacre_runtime::render::EnvironmentMap::load(path)
    {
        bad("--env", e);
    }
    if let Some(path) = &args.thickness_map
        && let Err(e) = nacre_runtime::render::ThicknessMap::load(path)
    {
        bad("--thickness-map", e);
    }
    let lut_cache = if args.no_lut_cache {
        None
    } else {
        args.lut_cache
            .clone()
            .or_else(nacre_studio::live_lut::default_folder)
    };
    if let Some(dir) = &lut_cache
        && dir.is_file()
    {
        bad(
            "--lut-cache",
            format!("{} is a file, not a folder", dir.display()),
        );
    }
    if let Some(path) = &args.screenshot
        && path.is_dir()
    {
        bad("--screenshot", format!("{} is a folder", path.display()));
    }
    let session = if args.no_session {
        None
    } else if args.session.is_some() {
        args.session.clone()
    } else if args.screenshot.is_some() {
        // A screenshot draws what its flags say, never a session's stack.
        None
    } else {
        default_session()
    };
    if let Some(path) = &session {
        if path.is_dir() {
            bad("--session", format!("{} is a folder", path.display()));
        }
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
            && let Err(e) = std::fs::create_dir_all(dir)
        {
            bad("--session", format!("{}: {e}", dir.display()));
        }
    }
    let from_recipe = args.recipe.is_some();
    let exit_code = Arc::new(Mutex::new(0));
    let setup = WgpuSetupCreateNew {
        device_descriptor: Arc::new(|adapter| wgpu::DeviceDescriptor {
            label: Some("nacre studio"),
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: adapter.limits(),
            ..Default::default()
        }),
        ..WgpuSetupCreateNew::without_display_handle()
    };
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("nacre studio")
            .with_inner_size([window[0] as f32, window[1] as f32]),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: WgpuConfiguration {
            wgpu_setup: WgpuSetup::CreateNew(setup),
            ..Default::default()
        },
        ..Default::default()
    };
    let code = Arc::clone(&exit_code);
    let (env, thickness_map) = (args.env.clone(), args.thickness_map.clone());
    let result = eframe::run_native(
        "nacre studio",
        options,
        Box::new(move |cc| {
            let view = match &cc.wgpu_render_state {
                Some(rs) => View::new(GpuContext::from_parts(
                    rs.adapter.clone(),
                    rs.device.clone(),
                    rs.queue.clone(),
                ))
                .map_err(|e| e.to_string()),
                None => Err("eframe started without wgpu".to_string()),
            };
            let size = view_size.unwrap_or([800, 600]);
            let mut studio = match session {
                Some(path) if !from_recipe => Studio::with_session(view, doc, size, path),
                Some(path) => {
                    let mut s = Studio::new(view, doc, size);
                    s.session_path = Some(path);
                    s
                }
                None => Studio::new(view, doc, size),
            };
            studio.follow_panel = view_size.is_none();
            studio.settings.technique = technique;
            studio.settings.lighting = lighting;
            studio.live_lut.folder = lut_cache;
            if let Some(path) = &env {
                studio.environment_error = studio.open_environment(path).err();
            }
            if let Some(path) = &thickness_map {
                studio.thickness_map_error = studio.open_thickness_map(path).err();
            }
            Ok(Box::new(App {
                studio,
                started,
                first_picture: None,
                frames: 0,
                screenshot: args.screenshot.clone(),
                wanted_frames: args.frames,
                requested: false,
                shot: Arc::new(Mutex::new(None)),
                exit_code: code,
                spin: args.spin,
                spin_seconds: Vec::new(),
            }))
        }),
    );
    if let Err(e) = result {
        eprintln!("error: nacre studio could not start: {e}");
        std::process::exit(1);
    }
    let code = *exit_code.lock().unwrap_or_else(|e| e.into_inner());
    std::process::exit(code);
}

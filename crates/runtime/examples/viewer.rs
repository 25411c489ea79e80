//! Interactive viewer: the `nacre render` scenes in a window, with an orbit camera.
//!
//! ```sh
//! cargo run --release -p nacre-runtime --example viewer --features viewer
//! ```
//!
//! Keys: `1` film_lut, `2` film_fourier, `3` film_spectral; `S` next scene (sphere, bubble,
//! plane); `+`/`-` exposure; `H`/`J` fewer/more Fourier harmonics; `Esc` quits. Drag with
//! the left mouse button to orbit, scroll to zoom. The window title shows the technique,
//! the scene and the frame time.
//!
//! Frames are rendered with [`Renderer::render_with`] into an offscreen target, read back
//! and written to the swap-chain image (a simple path that works on every adapter,
//! software ones included); a host engine instead binds the technique's group 1 and the
//! material's groups in its own passes.

use nacre_format::set::resolve_table;
use nacre_runtime::bindings::TechniqueOptions;
use nacre_runtime::render::{
    EnvironmentMap, Renderer, SceneKind, SceneOptions, ThicknessMap, procedural_thickness_map,
};
use nacre_runtime::{GpuContext, TableSet, Technique};
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Orbit camera around the scene's default target.
struct Orbit {
    yaw: f32,
    pitch: f32,
    distance: f32,
}

struct State {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: GpuContext,
    scene: SceneKind,
    technique: Technique,
    tables: TableSet,
    renderer: Renderer,
    environment: EnvironmentMap,
    thickness: ThicknessMap,
    options: SceneOptions,
    orbit: Orbit,
    dragging: Option<(f64, f64)>,
    cursor: (f64, f64),
}

fn load_tables(ctx: &GpuContext, scene: SceneKind) -> Result<TableSet, String> {
    let lut = match scene {
        SceneKind::Sphere => "film-dielectric",
        SceneKind::Bubble => "soap-film",
        SceneKind::Plane => "oil-slick",
    };
    let mut tables = TableSet::default();
    for name in [lut, "fourier-srgb"] {
        tables
            .add(ctx, &resolve_table(name))
            .map_err(|e| e.to_string())?;
    }
    Ok(tables)
}

fn orbit_of(options: &SceneOptions) -> Orbit {
    let c = options.camera;
    let d = [
        c.eye[0] - c.target[0],
        c.eye[1] - c.target[1],
        c.eye[2] - c.target[2],
    ];
    let distance = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    Orbit {
        yaw: d[0].atan2(d[2]),
        pitch: (d[1] / distance).asin(),
        distance,
    }
}

impl State {
    fn new(window: Arc<Window>, instance: wgpu::Instance) -> Result<State, String> {
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| e.to_string())?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| e.to_string())?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("nacre viewer"),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| e.to_string())?;
        let ctx = GpuContext::from_parts(adapter, device, queue);
        let size = window.inner_size();
        let caps = surface.get_capabilities(&ctx.adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| {
                matches!(
                    f,
                    wgpu::TextureFormat::Rgba8UnormSrgb | wgpu::TextureFormat::Bgra8UnormSrgb
                )
            })
            .ok_or("the surface offers no 8-bit sRGB format")?;
        if !caps.usages.contains(wgpu::TextureUsages::COPY_DST) {
            return Err("the surface cannot be a copy destination".into());
        }
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::COPY_DST,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: Default::default(),
        };
        surface.configure(&ctx.device, &config);
        let scene = SceneKind::Sphere;
        let technique = Technique::Lut;
        let tables = load_tables(&ctx, scene)?;
        let mut options = SceneOptions::new(scene);
        options.fit_to_tables(&tables).map_err(|e| e.to_string())?;
        let renderer = Renderer::new(&ctx, &tables, technique, &options.technique_options())
            .map_err(|e| e.to_string())?;
        Ok(State {
            window,
            surface,
            config,
            orbit: orbit_of(&options),
            ctx,
            scene,
            technique,
            tables,
            renderer,
            environment: EnvironmentMap::default_map().map_err(|e| e.to_string())?,
            thickness: procedural_thickness_map(512),
            options,
            dragging: None,
            cursor: (0.0, 0.0),
        })
    }

    fn rebuild(&mut self) -> Result<(), String> {
        let options: TechniqueOptions = self.options.technique_options();
        self.renderer = Renderer::new(&self.ctx, &self.tables, self.technique, &options)
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    fn set_scene(&mut self, scene: SceneKind) -> Result<(), String> {
        self.scene = scene;
        self.tables = load_tables(&self.ctx, scene)?;
        let exposure = self.options.exposure_ev;
        self.options = SceneOptions::new(scene);
        self.options.exposure_ev = exposure;
        self.options
            .fit_to_tables(&self.tables)
            .map_err(|e| e.to_string())?;
        self.orbit = orbit_of(&self.options);
        self.rebuild()
    }

    fn draw(&mut self) -> Result<(), String> {
        let o = &self.orbit;
        let target = self.options.camera.target;
        self.options.camera.eye = [
            target[0] + o.distance * o.pitch.cos() * o.yaw.sin(),
            target[1] + o.distance * o.pitch.sin(),
            target[2] + o.distance * o.pitch.cos() * o.yaw.cos(),
        ];
        self.options.width = self.config.width;
        self.options.height = self.config.height;
        let start = Instant::now();
        let image = self
            .renderer
            .render_with(
                &self.ctx,
                &self.tables,
                &self.options,
                &self.environment,
                &self.thickness,
            )
            .map_err(|e| e.to_string())?;
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            _ => {
                self.surface.configure(&self.ctx.device, &self.config);
                return Ok(());
            }
        };
        let mut pixels = image.pixels;
        if self.config.format == wgpu::TextureFormat::Bgra8UnormSrgb {
            for p in pixels.chunks_exact_mut(4) {
                p.swap(0, 2);
            }
        }
        self.ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &frame.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &pixels,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * image.width),
                rows_per_image: Some(image.height),
            },
            wgpu::Extent3d {
                width: image.width,
                height: image.height,
                depth_or_array_layers: 1,
            },
        );
        self.ctx.queue.submit([]);
        self.ctx.queue.present(frame);
        self.window.set_title(&format!(
            "nacre — {} — {} — {:.0} ms (1 lut, 2 fourier, 3 spectral, S scene, +/- exposure)",
            self.technique.name(),
            self.scene.name(),
            start.elapsed().as_secs_f64() * 1e3
        ));
        Ok(())
    }
}

#[derive(Default)]
struct App {
    state: Option<State>,
    error: Option<String>,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title("nacre")
            .with_inner_size(winit::dpi::LogicalSize::new(960.0, 640.0));
        let result = event_loop
            .create_window(attributes)
            .map_err(|e| e.to_string())
            .and_then(|w| {
                let instance = wgpu::Instance::new(
                    wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
                        event_loop.owned_display_handle(),
                    )),
                );
                State::new(Arc::new(w), instance)
            });
        match result {
            Ok(state) => {
                state.window.request_redraw();
                self.state = Some(state);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(state) = self.state.as_mut() else {
            return;
        };
        let mut redraw = false;
        let result: Result<(), String> = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                state.config.width = size.width.max(1);
                state.config.height = size.height.max(1);
                state.surface.configure(&state.ctx.device, &state.config);
                redraw = true;
                Ok(())
            }
            WindowEvent::RedrawRequested => state.draw(),
            WindowEvent::CursorMoved { position, .. } => {
                state.cursor = (position.x, position.y);
                if let Some((x, y)) = state.dragging {
                    state.orbit.yaw -= ((position.x - x) * 0.01) as f32;
                    state.orbit.pitch =
                        (state.orbit.pitch + ((position.y - y) * 0.01) as f32).clamp(-1.5, 1.5);
                    state.dragging = Some((position.x, position.y));
                    redraw = true;
                }
                Ok(())
            }
            WindowEvent::MouseInput {
                state: pressed,
                button: MouseButton::Left,
                ..
            } => {
                state.dragging = (pressed == ElementState::Pressed).then_some(state.cursor);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                state.orbit.distance = (state.orbit.distance * 0.9f32.powf(lines)).clamp(0.5, 50.0);
                redraw = true;
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                redraw = true;
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => {
                        event_loop.exit();
                        Ok(())
                    }
                    Key::Character(c) => match c {
                        "1" | "2" | "3" => {
                            state.technique = match c {
                                "1" => Technique::Lut,
                                "2" => Technique::Fourier,
                                _ => Technique::Spectral,
                            };
                            state.rebuild()
                        }
                        "s" | "S" => {
                            let next = match state.scene {
                                SceneKind::Sphere => SceneKind::Bubble,
                                SceneKind::Bubble => SceneKind::Plane,
                                SceneKind::Plane => SceneKind::Sphere,
                            };
                            state.set_scene(next)
                        }
                        "+" | "=" => {
                            state.options.exposure_ev += 0.25;
                            Ok(())
                        }
                        "-" => {
                            state.options.exposure_ev -= 0.25;
                            Ok(())
                        }
                        "h" | "j" => {
                            let m = state.options.harmonics;
                            state.options.harmonics = if c == "h" {
                                m.saturating_sub(1).max(1)
                            } else {
                                m + 1
                            };
                            state.rebuild()
                        }
                        _ => Ok(()),
                    },
                    _ => Ok(()),
                }
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.error = Some(e);
            event_loop.exit();
        } else if redraw {
            state.window.request_redraw();
        }
    }
}

fn main() -> std::process::ExitCode {
    let event_loop = match EventLoop::new() {
        Ok(l) => l,
        Err(e) => {
            eprintln!("viewer: no display: {e}");
            return std::process::ExitCode::from(2);
        }
    };
    let mut app = App::default();
    if let Err(e) = event_loop.run_app(&mut app) {
        eprintln!("viewer: {e}");
        return std::process::ExitCode::from(2);
    }
    match app.error {
        Some(e) => {
            eprintln!("viewer: {e}");
            std::process::ExitCode::from(2)
        }
        None => std::process::ExitCode::SUCCESS,
    }
}

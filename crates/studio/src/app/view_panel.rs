//! The live view's panel: technique, scene, lighting and camera controls, the picture
//! (redrawn only when the stack or the settings changed), the glTF model (open, drop, close)
//! and the ΔE2000 map against the exact technique with its colour scale.

use super::{SCENES, Studio, TECHNIQUES};
use crate::compare::{REFERENCE, delta_e, scale_colour};
use crate::view::{Lighting, Orbit};
use eframe::egui;
use egui::{Color32, RichText, TextureOptions};
use nacre_runtime::render::SceneKind;
use std::path::{Path, PathBuf};

/// The thickness map's channels, as the menus name them.
const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// A scene's menu name.
fn scene_name(scene: SceneKind) -> &'static str {
    match scene {
        SceneKind::Sphere => "sphere",
        SceneKind::Bubble => "bubble",
        SceneKind::Plane => "plane",
    }
}

impl Studio {
    /// Opens the glTF file at `path` (`.gltf` or `.glb`) as the view's model: the stack's
    /// top film goes on its materials and the orbit starts at the fitted camera's
    /// direction. A file that does not load leaves the view as it was.
    pub fn open_model(&mut self, path: &Path) -> Result<(), String> {
        let view = self
            .view
            .as_mut()
            .map_err(|e| format!("no live view: {e}"))?;
        view.load_model(path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.settings.model = Some(path.to_path_buf());
        self.settings.orbit.yaw_deg = 0.0;
        self.settings.orbit.pitch_deg = nacre_runtime::mesh::DEFAULT_PITCH_DEG as f32;
        self.model_path = path.display().to_string();
        Ok(())
    }

    /// Back to the analytic scene.
    pub fn close_model(&mut self) {
        if self.settings.model.take().is_some() {
            self.settings.orbit = Orbit::for_scene(self.settings.scene);
        }
    }

    /// Opens the environment file at `path` (OpenEXR, Radiance HDR, PNG or JPEG) and lights
    /// the view with it ([`Lighting::File`]). A file that does not load leaves the view as
    /// it was.
    pub fn open_environment(&mut self, path: &Path) -> Result<(), String> {
        let view = self
            .view
            .as_mut()
            .map_err(|e| format!("no live view: {e}"))?;
        view.load_environment(path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.settings.environment = Some(path.to_path_buf());
        self.settings.lighting = Lighting::File;
        self.environment_path = path.display().to_string();
        Ok(())
    }

    /// Opens the thickness map at `path` (PNG or JPEG, grey or colour) in place of the
    /// procedural one. A file that does not load leaves the view as it was.
    pub fn open_thickness_map(&mut self, path: &Path) -> Result<(), String> {
        let view = self
            .view
            .as_mut()
            .map_err(|e| format!("no live view: {e}"))?;
        let colour = view
            .load_thickness_map(path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.settings.thickness_map = Some(path.to_path_buf());
        self.thickness_map_colour = colour;
        self.thickness_map_path = path.display().to_string();
        Ok(())
    }

    /// Opens what is dropped on the window: the first `.gltf`/`.glb` file as the model, the
    /// first `.exr`/`.hdr` file as the environment, the first `.png`/`.jpg`/`.jpeg` file as
    /// the thickness map.
    pub(super) fn take_dropped_model(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        let has = |exts: &[&str], p: &Path| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| exts.iter().any(|x| e.eq_ignore_ascii_case(x)))
        };
        if let Some(path) = dropped.iter().find(|p| is_gltf(p)) {
            self.model_error = self.open_model(path).err();
        }
        if let Some(path) = dropped.iter().find(|p| has(&["exr", "hdr"], p)) {
            self.environment_error = self.open_environment(path).err();
        }
        if let Some(path) = dropped.iter().find(|p| has(&["png", "jpg", "jpeg"], p)) {
            self.thickness_map_error = self.open_thickness_map(path).err();
        }
    }

    /// The environment file and thickness map rows.
    fn files_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            if let Some(path) = file_field(
                ui,
                "Environment file",
                &mut self.environment_path,
                "an equirectangular .exr or .hdr (linear), or .png/.jpg (sRGB), row 0 at the zenith (or drop one on the window)",
                "Open environment",
            ) {
                self.environment_error = self.open_environment(&path).err();
            }
            error_label(ui, &self.environment_error);
        });
        ui.horizontal_wrapped(|ui| {
            if let Some(path) = file_field(
                ui,
                "Thickness map",
                &mut self.thickness_map_path,
                "a .png or .jpg: grey g maps film 1 to d + r(2g − 1); a colour map's G and B can drive the lower films under `stack`",
                "Open thickness map",
            ) {
                self.thickness_map_error = self.open_thickness_map(&path).err();
            }
            if ui
                .add_enabled(
                    self.settings.thickness_map.is_some(),
                    egui::Button::new("Procedural map"),
                )
                .clicked()
            {
                self.settings.thickness_map = None;
            }
            error_label(ui, &self.thickness_map_error);
        });
        let films = self.good.0.films.len();
        if self.thickness_map_colour && self.settings.thickness_map.is_some() && films > 1 {
            ui.horizontal_wrapped(|ui| {
                let channels = &mut self.settings.film_channels;
                channels.resize(films, 0);
                for (k, channel) in channels.iter_mut().enumerate().skip(1) {
                    egui::ComboBox::from_label(format!("Film {} follows", k + 1))
                        .selected_text(CHANNELS[*channel])
                        .show_ui(ui, |ui| {
                            for (c, name) in CHANNELS.iter().enumerate() {
                                ui.selectable_value(channel, c, *name);
                            }
                        });
                }
            });
        }
    }

    /// The `lut` technique's table: the stack's own while it bakes (progress) or when its
    /// bake failed.
    fn live_lut_ui(&mut self, ui: &mut egui::Ui) {
        if self.settings.technique != nacre_runtime::Technique::Lut || self.settings.model.is_some()
        {
            return;
        }
        if let Some((done, total)) = self.live_lut.progress() {
            ui.horizontal(|ui| {
                ui.label("lut table of this stack");
                ui.add(
                    egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                        .desired_width(160.0)
                        .show_percentage(),
                );
            });
            ui.ctx()
                .request_repaint_after(std::time::Duration::from_millis(50));
        }
        if let Some(e) = self.live_lut.error() {
            ui.label(
                RichText::new(format!("the lut table of this stack did not bake: {e}"))
                    .color(Color32::LIGHT_RED),
            );
        }
    }

    /// Sets [`crate::view::ViewSettings::lut_key`] for this frame ([`crate::live_lut`]).
    fn update_live_lut(&mut self) {
        let lut = self.settings.technique == nacre_runtime::Technique::Lut
            && self.settings.model.is_none();
        let state = match (&mut self.view, lut) {
            (Ok(view), true) => self.live_lut.update(view, &self.good.0, &self.good.1),
            _ => crate::live_lut::LutState {
                key: None,
                loaded: false,
            },
        };
        self.settings.lut_key = state.key;
        if state.loaded {
            self.drawn = None;
        }
    }

    pub(super) fn view_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            let s = &mut self.settings;
            egui::ComboBox::from_label("Technique")
                .selected_text(s.technique.name())
                .show_ui(ui, |ui| {
                    for t in TECHNIQUES {
                        ui.selectable_value(&mut s.technique, t, t.name());
                    }
                });
            let scene = s.scene;
            egui::ComboBox::from_label("Scene")
                .selected_text(scene_name(scene))
                .show_ui(ui, |ui| {
                    for k in SCENES {
                        ui.selectable_value(&mut s.scene, k, scene_name(k));
                    }
                });
            if s.scene != scene {
                s.orbit = Orbit::for_scene(s.scene);
            }
            egui::ComboBox::from_label("Lighting")
                .selected_text(s.lighting.name())
                .show_ui(ui, |ui| {
                    for l in Lighting::ALL {
                        ui.selectable_value(&mut s.lighting, l, l.name());
                    }
                });
            ui.checkbox(
                &mut self.compare,
                format!("ΔE2000 against {}", REFERENCE.name()),
            );
            if self.compare {
                ui.add(
                    egui::Slider::new(&mut self.delta_e_max, 0.5..=20.0)
                        .logarithmic(true)
                        .text("ΔE scale max"),
                );
            }
        });
        ui.horizontal_wrapped(|ui| {
            let s = &mut self.settings;
            ui.add(egui::Slider::new(&mut s.exposure_ev, -4.0..=4.0).text("Exposure (EV)"));
            ui.add(
                egui::Slider::new(&mut s.roughness_alpha, 0.001..=1.0)
                    .logarithmic(true)
                    .text("Roughness α"),
            );
        });
        ui.horizontal_wrapped(|ui| {
            if let Some(path) = file_field(
                ui,
                "Model file",
                &mut self.model_path,
                "a .gltf or .glb file (or drop one on the window)",
                "Open model",
            ) {
                self.model_error = self.open_model(&path).err();
            }
            if ui
                .add_enabled(
                    self.settings.model.is_some(),
                    egui::Button::new("Close model"),
                )
                .clicked()
            {
                self.close_model();
            }
            ui.checkbox(&mut self.settings.film_on_all, "Film on every material");
            error_label(ui, &self.model_error);
        });
        self.files_ui(ui);
        self.update_live_lut();
        self.live_lut_ui(ui);
        if self.follow_panel {
            let ppp = ui.ctx().pixels_per_point();
            let avail = ui.available_size() * ppp;
            // Multiples of 16 pixels, so that a resize re-renders only now and then.
            let snap = |v: f32| ((v as u32) / 16 * 16).clamp(64, 4096);
            let (width, below) = if self.compare {
                (avail.x / 2.0 - 8.0 * ppp, 84.0 * ppp)
            } else {
                (avail.x, 24.0 * ppp)
            };
            self.settings.size = [snap(width), snap(avail.y - below)];
        }
        self.draw_if_needed(ui.ctx());
        if let Some(e) = &self.view_error {
            ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
        }
        if let Some(frame) = &self.frame {
            for note in &frame.notes {
                ui.label(RichText::new(format!("note: {note}")).weak());
            }
        }
        if let Some(texture) = &self.texture {
            let ppp = ui.ctx().pixels_per_point();
            let [w, h] = texture.size();
            let size = egui::vec2(w as f32, h as f32) / ppp;
            let response = ui
                .horizontal(|ui| {
                    let response = ui.add(
                        egui::Image::from_texture((texture.id(), size))
                            .sense(egui::Sense::click_and_drag())
                            .alt_text("Live view"),
                    );
                    if self.compare
                        && let Some((map, _)) = &self.delta_e_texture
                    {
                        let [w, h] = map.size();
                        ui.add(
                            egui::Image::from_texture((
                                map.id(),
                                egui::vec2(w as f32, h as f32) / ppp,
                            ))
                            .alt_text("ΔE2000 map"),
                        );
                    }
                    response
                })
                .inner;
            if response.dragged() {
                let d = response.drag_delta();
                self.settings.orbit.drag(d.x, d.y);
            }
            if self.compare {
                self.delta_e_legend(ui);
            }
            if let Some(frame) = &self.frame {
                ui.label(
                    RichText::new(format!(
                        "{}×{} · {} · frame {:.1} ms",
                        frame.image.width,
                        frame.image.height,
                        self.view.as_ref().map_or(String::new(), |v| v.describe()),
                        frame.seconds * 1e3
                    ))
                    .weak(),
                );
            }
        }
    }

    /// Draws a new frame when the stack or the settings changed since the last one.
    pub(super) fn draw_if_needed(&mut self, ctx: &egui::Context) {
        let key = (self.settings.clone(), self.good.0.clone(), self.compare);
        if self.drawn.as_ref() == Some(&key) {
            self.update_delta_e_texture(ctx);
            return;
        }
        let view = match &mut self.view {
            Ok(v) => v,
            Err(e) => {
                self.view_error = Some(format!("no live view: {e}"));
                return;
            }
        };
        self.drawn = Some(key);
        match view.render(&self.settings, &self.good.0, &self.good.1) {
            Ok(frame) => {
                let img = &frame.image;
                let picture = egui::ColorImage::from_rgba_unmultiplied(
                    [img.width as usize, img.height as usize],
                    &img.pixels,
                );
                match &mut self.texture {
                    Some(t) => t.set(picture, TextureOptions::LINEAR),
                    None => {
                        self.texture =
                            Some(ctx.load_texture("live view", picture, TextureOptions::LINEAR));
                    }
                }
                self.frame = Some(frame);
                self.view_error = None;
                self.frames_drawn += 1;
            }
            Err(e) => {
                self.view_error = Some(e.to_string());
                return;
            }
        }
        self.delta_e = None;
        self.reference = None;
        if !self.compare {
            return;
        }
        let mut settings = self.settings.clone();
        settings.technique = REFERENCE;
        match view.render(&settings, &self.good.0, &self.good.1) {
            Ok(reference) => {
                self.delta_e = self
                    .frame
                    .as_ref()
                    .and_then(|f| delta_e(&f.image, &reference.image));
                self.reference = Some(reference);
            }
            Err(e) => {
                self.view_error = Some(format!("the {} reference: {e}", REFERENCE.name()));
            }
        }
        self.delta_e_texture = None;
        self.update_delta_e_texture(ctx);
    }

    /// Paints the ΔE2000 map's texture when the map or the scale changed.
    pub(super) fn update_delta_e_texture(&mut self, ctx: &egui::Context) {
        let Some(d) = &self.delta_e else {
            self.delta_e_texture = None;
            return;
        };
        if self
            .delta_e_texture
            .as_ref()
            .is_some_and(|(_, max)| *max == self.delta_e_max)
        {
            return;
        }
        let picture = egui::ColorImage::from_rgba_unmultiplied(
            [d.width as usize, d.height as usize],
            &d.map_rgba(self.delta_e_max),
        );
        match &mut self.delta_e_texture {
            Some((t, max)) => {
                t.set(picture, TextureOptions::NEAREST);
                *max = self.delta_e_max;
            }
            None => {
                self.delta_e_texture = Some((
                    ctx.load_texture("ΔE2000 map", picture, TextureOptions::NEAREST),
                    self.delta_e_max,
                ));
            }
        }
    }

    /// The ΔE2000 map's colour scale and statistics.
    pub(super) fn delta_e_legend(&self, ui: &mut egui::Ui) {
        let Some(d) = &self.delta_e else {
            return;
        };
        ui.horizontal(|ui| {
            ui.label("ΔE2000 0");
            let (rect, _) = ui.allocate_exact_size(egui::vec2(200.0, 14.0), egui::Sense::hover());
            let steps = 64;
            for k in 0..steps {
                let t = k as f32 / (steps - 1) as f32;
                let [r, g, b] = scale_colour(t * self.delta_e_max, self.delta_e_max);
                let x = rect.left() + rect.width() * k as f32 / steps as f32;
                ui.painter().rect_filled(
                    egui::Rect::from_min_max(
                        egui::pos2(x, rect.top()),
                        egui::pos2(x + rect.width() / steps as f32 + 0.5, rect.bottom()),
                    ),
                    0.0,
                    Color32::from_rgb(r, g, b),
                );
            }
            ui.label(format!("≥ {:.1}", self.delta_e_max));
        });
        ui.label(format!(
            "ΔE2000 {} against {}: mean {:.2}, p95 {:.2}, max {:.2} over the picture; {} pixels differ (mean {:.2}, p95 {:.2})",
            self.settings.technique.name(),
            REFERENCE.name(),
            d.mean,
            d.p95,
            d.max,
            d.differing,
            d.mean_differing,
            d.p95_differing
        ));
    }
}

/// A path field labelled `label` (its accessible name) with `hover` help, and its `button`:
/// the path typed when the button is clicked.
fn file_field(
    ui: &mut egui::Ui,
    label: &str,
    path: &mut String,
    hover: &str,
    button: &str,
) -> Option<PathBuf> {
    let label = ui.label(label);
    ui.add(egui::TextEdit::singleline(path).desired_width(220.0))
        .labelled_by(label.id)
        .on_hover_text(hover);
    ui.button(button)
        .clicked()
        .then(|| PathBuf::from(path.trim()))
}

/// An error beside a field, in red, when there is one.
fn error_label(ui: &mut egui::Ui, error: &Option<String>) {
    if let Some(e) = error {
        ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
    }
}

/// Whether `path` names a glTF file (`.gltf` or `.glb`, any case).
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

//! The studio's window: the stack editor (left), the live view (centre) and the plots
//! (right). [`Studio::ui`] draws it all into any [`egui::Ui`], so the same code runs in the
//! native window (`main.rs`, eframe) and in the UI tests (`egui_kittest`).
//!
//! An entry is applied when the stack it makes builds ([`StackDoc::build`], the CLI's
//! parser); otherwise the error is shown beside the stack and the view, the plots and the
//! exports keep the last stack that built.

use crate::bake::{BakeJob, BakeOutcome, BakeSettings};
use crate::compare::{DEFAULT_SCALE_MAX, DeltaE, REFERENCE, delta_e, scale_colour};
use crate::curves::{CurveWorker, Curves};
use crate::doc::{Film, History, MAX_FILMS, PRESETS, SLIDER_MAX_NM, StackDoc};
use crate::view::{Frame, Lighting, View, ViewSettings};
use eframe::egui;
use egui::{Color32, RichText, TextureHandle, TextureOptions};
use nacre_format::atomic::write_atomic;
use nacre_optics::Stack;
use nacre_runtime::Technique;
use nacre_runtime::render::SceneKind;
use std::path::{Path, PathBuf};

/// The techniques the view offers.
pub const TECHNIQUES: [Technique; 4] = [
    Technique::Stack,
    Technique::Spectral,
    Technique::Fourier,
    Technique::Lut,
];

/// The scenes the view offers.
pub const SCENES: [SceneKind; 3] = [SceneKind::Sphere, SceneKind::Bubble, SceneKind::Plane];

/// A scene's menu name.
fn scene_name(scene: SceneKind) -> &'static str {
    match scene {
        SceneKind::Sphere => "sphere",
        SceneKind::Bubble => "bubble",
        SceneKind::Plane => "plane",
    }
}

/// The studio's state.
pub struct Studio {
    /// The stack as edited (may not build).
    pub doc: StackDoc,
    /// The stack at the last undo step.
    committed: StackDoc,
    /// Undo and redo.
    pub history: History,
    /// The last stack that built, and its optics.
    good: (StackDoc, Stack),
    /// Why the edited stack does not build.
    pub stack_error: Option<String>,
    /// The typed thickness of each film, and its error.
    thickness_text: Vec<(String, Option<String>)>,
    /// What the view draws besides the stack.
    pub settings: ViewSettings,
    /// Whether the picture's size follows the window (the native window; tests fix it).
    pub follow_panel: bool,
    view: Result<View, String>,
    texture: Option<TextureHandle>,
    /// The last frame drawn.
    pub frame: Option<Frame>,
    /// Why the last frame failed.
    pub view_error: Option<String>,
    drawn: Option<(ViewSettings, StackDoc, bool)>,
    /// Frames drawn since the start.
    pub frames_drawn: u64,
    worker: CurveWorker,
    /// The plots' data, and its request.
    pub curves: Option<Curves>,
    /// Why the plots' data failed.
    pub curves_error: Option<String>,
    asked: Option<(StackDoc, f64, u64)>,
    /// The spectra's incidence angle, degrees.
    pub spectrum_angle_deg: f64,
    /// Where the recipe is saved or opened.
    pub recipe_path: String,
    /// Where the picture is saved.
    pub picture_path: String,
    /// The glTF file the model field names.
    pub model_path: String,
    /// Why the last model did not open.
    pub model_error: Option<String>,
    /// The last export's outcome.
    pub status: Option<Result<String, String>>,
    /// What the export panel bakes.
    pub bake: BakeSettings,
    /// The bake running, if any.
    pub bake_job: Option<BakeJob>,
    /// How the last bake ended (or why it did not start).
    pub bake_status: Option<Result<String, String>>,
    /// Times the studio was drawn (every UI frame, whether the view redrew or not).
    pub ui_frames: u64,
    /// Whether the view shows the ΔE2000 map against the exact technique beside the picture.
    pub compare: bool,
    /// The top of the ΔE2000 colour scale.
    pub delta_e_max: f32,
    /// The last comparison: the ΔE2000 map of the picture against [`REFERENCE`]'s.
    pub delta_e: Option<DeltaE>,
    /// The reference picture of the last comparison.
    pub reference: Option<Frame>,
    delta_e_texture: Option<(TextureHandle, f32)>,
    /// Where the session (the stack, as a recipe) is saved on every committed change and
    /// restored from on start; None: no session.
    pub session_path: Option<PathBuf>,
    /// The stack the session file holds (nothing is written until the stack differs).
    saved_session: Option<StackDoc>,
    /// Why the session could not be restored or saved, if it could not.
    pub session_error: Option<String>,
}

impl Studio {
    /// A studio drawing with `view` (its error is shown in place of the picture) at `size`.
    pub fn new(view: Result<View, String>, doc: StackDoc, size: [u32; 2]) -> Studio {
        let (doc, stack) = match doc.build() {
            Ok(stack) => (doc, stack),
            Err(_) => {
                let d = StackDoc::default();
                let s = d.build().expect("the default preset builds");
                (d, s)
            }
        };
        Studio {
            committed: doc.clone(),
            thickness_text: texts(&doc),
            good: (doc.clone(), stack),
            doc,
            history: History::default(),
            stack_error: None,
            settings: ViewSettings::new(size),
            follow_panel: false,
            view,
            texture: None,
            frame: None,
            view_error: None,
            drawn: None,
            frames_drawn: 0,
            worker: CurveWorker::new(),
            curves: None,
            curves_error: None,
            asked: None,
            spectrum_angle_deg: 0.0,
            recipe_path: "stack.toml".into(),
            picture_path: "studio.png".into(),
            model_path: String::new(),
            model_error: None,
            status: None,
            bake: BakeSettings::default(),
            bake_job: None,
            bake_status: None,
            ui_frames: 0,
            compare: false,
            delta_e_max: DEFAULT_SCALE_MAX,
            delta_e: None,
            reference: None,
            delta_e_texture: None,
            session_path: None,
            saved_session: None,
            session_error: None,
        }
    }

    /// A studio whose session lives at `path`: the stack it holds is restored (a missing
    /// file starts from `doc`; an unreadable one too, its error shown and the file left as
    /// it is until the stack changes), and every committed change is written back
    /// atomically as a recipe ([`StackDoc::write_recipe`]).
    pub fn with_session(
        view: Result<View, String>,
        doc: StackDoc,
        size: [u32; 2],
        path: PathBuf,
    ) -> Studio {
        let (doc, error) = match restore_session(&path) {
            Ok(Some(restored)) => (restored, None),
            Ok(None) => (doc, None),
            Err(e) => (doc, Some(e)),
        };
        let mut studio = Studio::new(view, doc, size);
        studio.saved_session = Some(studio.good.0.clone());
        studio.session_path = Some(path);
        studio.session_error = error;
        studio
    }

    /// Writes the session file when the committed stack builds and differs from what it
    /// holds (called every frame once the edits are committed, and on exit).
    pub fn save_session(&mut self) {
        let Some(path) = &self.session_path else {
            return;
        };
        if self.stack_error.is_some()
            || self.doc != self.committed
            || self.saved_session.as_ref() == Some(&self.good.0)
        {
            return;
        }
        match self.good.0.write_recipe(path) {
            Ok(()) => {
                self.saved_session = Some(self.good.0.clone());
                self.session_error = None;
            }
            Err(e) => {
                // Tried once per stack: the error stays shown until the next change.
                self.saved_session = Some(self.good.0.clone());
                self.session_error = Some(format!("session {}: {e}", path.display()));
            }
        }
    }

    /// The last stack that built (what the view and the plots show).
    pub fn stack(&self) -> &(StackDoc, Stack) {
        &self.good
    }

    /// Replaces the stack (a preset, a recipe), as one undo step.
    pub fn set_doc(&mut self, doc: StackDoc) {
        self.commit();
        self.history.record(self.doc.clone());
        self.doc = doc;
        self.committed = self.doc.clone();
        self.thickness_text = texts(&self.doc);
    }

    /// Records the edits since the last step as one undo step.
    fn commit(&mut self) {
        if self.doc != self.committed {
            self.history.record(self.committed.clone());
            self.committed = self.doc.clone();
        }
    }

    /// Undoes the last step.
    pub fn undo(&mut self) {
        self.commit();
        if let Some(d) = self.history.undo(&self.doc) {
            self.doc = d;
            self.committed = self.doc.clone();
            self.thickness_text = texts(&self.doc);
        }
    }

    /// Redoes the last undone step.
    pub fn redo(&mut self) {
        if let Some(d) = self.history.redo(&self.doc) {
            self.doc = d;
            self.committed = self.doc.clone();
            self.thickness_text = texts(&self.doc);
        }
    }

    /// Builds the edited stack: applies it when it builds, else keeps the error.
    fn apply(&mut self) {
        if self.doc == self.good.0 {
            self.stack_error = None;
            return;
        }
        match self.doc.build() {
            Ok(stack) => {
                self.good = (self.doc.clone(), stack);
                self.stack_error = None;
            }
            Err(e) => self.stack_error = Some(e.to_string()),
        }
    }

    /// Writes the stack as a recipe to `path` (atomically); refused while an entry is in
    /// error, so that the file always holds what the fields show.
    pub fn export_recipe(&mut self, path: &Path) -> Result<(), String> {
        if let Some(e) = &self.stack_error {
            return Err(format!("the stack has an error, fix it first: {e}"));
        }
        self.good
            .0
            .write_recipe(path)
            .map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Opens a recipe (the CLI's reader) as the new stack.
    pub fn open_recipe(&mut self, path: &Path) -> Result<(), String> {
        let doc = StackDoc::read_recipe(path).map_err(|e| e.to_string())?;
        doc.build().map_err(|e| e.to_string())?;
        self.set_doc(doc);
        Ok(())
    }

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
            self.settings.orbit = crate::view::Orbit::for_scene(self.settings.scene);
        }
    }

    /// Opens the first `.gltf`/`.glb` file dropped on the window, if any.
    fn take_dropped_model(&mut self, ctx: &egui::Context) {
        let dropped = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .find(|p| is_gltf(p))
        });
        if let Some(path) = dropped {
            self.model_error = self.open_model(&path).err();
        }
    }

    /// Writes the view's last picture as a PNG to `path` (atomically).
    pub fn save_picture(&self, path: &Path) -> Result<(), String> {
        let frame = self.frame.as_ref().ok_or("no picture drawn yet")?;
        let png = frame.image.encode_png().map_err(|e| e.to_string())?;
        write_atomic(path, |w| w.write_all(&png)).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Draws the whole studio into `ui` (and the view's frame when anything changed).
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        self.ui_frames += 1;
        self.shortcuts(ui.ctx());
        self.take_dropped_model(ui.ctx());
        egui::Panel::top("studio toolbar").show(ui, |ui| self.toolbar(ui));
        egui::Panel::bottom("studio export").show(ui, |ui| self.export_panel(ui));
        egui::Panel::left("studio stack")
            .default_size(330.0)
            .resizable(true)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.stack_editor(ui));
            });
        self.apply();
        if !ui.ctx().input(|i| i.pointer.any_down()) && ui.ctx().memory(|m| m.focused().is_none()) {
            self.commit();
            self.save_session();
        }
        self.poll_curves();
        egui::Panel::right("studio plots")
            .default_size(360.0)
            .resizable(true)
            .show(ui, |ui| self.plots(ui));
        egui::CentralPanel::default().show(ui, |ui| self.view_ui(ui));
    }

    fn shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.memory(|m| m.focused().is_some()) {
            return;
        }
        let (undo, redo) = ctx.input_mut(|i| {
            let redo = i.consume_key(
                egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
                egui::Key::Z,
            ) || i.consume_key(egui::Modifiers::COMMAND, egui::Key::Y);
            (i.consume_key(egui::Modifiers::COMMAND, egui::Key::Z), redo)
        });
        if undo {
            self.undo();
        }
        if redo {
            self.redo();
        }
    }

    fn toolbar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.menu_button("Presets", |ui| {
                for p in PRESETS {
                    if ui.button(p.name).on_hover_text(p.description).clicked() {
                        self.set_doc(p.doc());
                        ui.close();
                    }
                }
            });
            if ui
                .add_enabled(
                    self.history.can_undo() || self.doc != self.committed,
                    egui::Button::new("Undo"),
                )
                .clicked()
            {
                self.undo();
            }
            if ui
                .add_enabled(self.history.can_redo(), egui::Button::new("Redo"))
                .clicked()
            {
                self.redo();
            }
            ui.separator();
            let label = ui.label("Recipe file");
            ui.add(egui::TextEdit::singleline(&mut self.recipe_path).desired_width(140.0))
                .labelled_by(label.id);
            if ui.button("Save recipe").clicked() {
                let path = self.recipe_path.clone();
                self.status = Some(
                    self.export_recipe(Path::new(&path))
                        .map(|()| format!("saved {path}")),
                );
            }
            if ui.button("Open recipe").clicked() {
                let path = self.recipe_path.clone();
                self.status = Some(
                    self.open_recipe(Path::new(&path))
                        .map(|()| format!("opened {path}")),
                );
            }
            ui.separator();
            let label = ui.label("Picture file");
            ui.add(egui::TextEdit::singleline(&mut self.picture_path).desired_width(120.0))
                .labelled_by(label.id);
            if ui.button("Save picture").clicked() {
                let path = self.picture_path.clone();
                self.status = Some(
                    self.save_picture(Path::new(&path))
                        .map(|()| format!("saved {path}")),
                );
            }
            match &self.status {
                Some(Ok(text)) => {
                    ui.label(text);
                }
                Some(Err(text)) => {
                    ui.label(RichText::new(text).color(Color32::LIGHT_RED));
                }
                None => {}
            }
        });
    }

    /// Starts baking the last stack that built into [`Studio::bake`]'s folder (refused while
    /// an entry is in error or a bake runs).
    pub fn start_bake(&mut self) {
        if self.bake_job.is_some() {
            return;
        }
        self.bake_status = Some(match &self.stack_error {
            Some(e) => Err(format!("the stack has an error, fix it first: {e}")),
            None => match BakeJob::start(&self.good.0, &self.bake) {
                Ok(job) => {
                    self.bake_job = Some(job);
                    Ok("baking…".into())
                }
                Err(e) => Err(e),
            },
        });
    }

    /// Whether a bake is running.
    pub fn baking(&self) -> bool {
        self.bake_job.is_some()
    }

    /// Takes a finished bake's outcome.
    fn poll_bake(&mut self) {
        let Some(job) = &mut self.bake_job else {
            return;
        };
        let Some(outcome) = job.poll() else {
            return;
        };
        self.bake_status = Some(match outcome {
            BakeOutcome::Baked(path) => Ok(format!("baked {}", path.display())),
            BakeOutcome::Cancelled => {
                Err(format!("bake of {} cancelled: nothing written", job.name))
            }
            BakeOutcome::Failed(e) => Err(format!("bake failed: {e}")),
        });
        self.bake_job = None;
    }

    /// The export panel: a table set baked from the stack, with its progress and a cancel
    /// button.
    fn export_panel(&mut self, ui: &mut egui::Ui) {
        self.poll_bake();
        ui.horizontal_wrapped(|ui| {
            ui.strong("Export");
            let running = self.bake_job.is_some();
            ui.add_enabled_ui(!running, |ui| {
                let b = &mut self.bake;
                let label = ui.label("Table folder");
                ui.add(egui::TextEdit::singleline(&mut b.folder).desired_width(160.0))
                    .labelled_by(label.id);
                let label = ui.label("Table name");
                ui.add(egui::TextEdit::singleline(&mut b.name).desired_width(110.0))
                    .labelled_by(label.id);
                for (text, value, max) in [
                    ("cos θ texels", &mut b.cos_theta_count, 256),
                    ("thickness texels", &mut b.opd_count, 2048),
                    ("index texels", &mut b.film_ior_count, 128),
                ] {
                    let label = ui.label(text);
                    ui.add(egui::DragValue::new(value).range(2..=max))
                        .labelled_by(label.id);
                }
            });
            if ui
                .add_enabled(!running, egui::Button::new("Bake tables"))
                .clicked()
            {
                self.start_bake();
            }
            if let Some(job) = &self.bake_job {
                let (done, total) = job.progress();
                ui.add(
                    egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                        .desired_width(180.0)
                        .text(format!("{done}/{total} rows")),
                );
                if ui
                    .add_enabled(!job.cancelling(), egui::Button::new("Cancel bake"))
                    .clicked()
                {
                    job.cancel();
                }
                // Keep drawing while the thread works: the bar moves and the outcome shows.
                ui.ctx()
                    .request_repaint_after(std::time::Duration::from_millis(50));
            }
            match &self.bake_status {
                Some(Ok(text)) => {
                    ui.label(text);
                }
                Some(Err(text)) => {
                    ui.label(RichText::new(text).color(Color32::LIGHT_RED));
                }
                None => {}
            }
        });
    }

    fn stack_editor(&mut self, ui: &mut egui::Ui) {
        ui.heading("Stack");
        material_field(ui, "Ambient", &mut self.doc.ambient);
        ui.separator();
        let mut remove = None;
        let mut swap = None;
        let count = self.doc.films.len();
        self.thickness_text.resize(count, (String::new(), None));
        for j in 0..count {
            let n = j + 1;
            ui.label(RichText::new(format!("Film {n}")).strong());
            material_field(
                ui,
                &format!("Film {n} material"),
                &mut self.doc.films[j].material,
            );
            let film = &mut self.doc.films[j];
            let (text, error) = &mut self.thickness_text[j];
            ui.horizontal(|ui| {
                let label = ui.label(format!("Film {n} thickness (nm)"));
                let typed = ui
                    .add(egui::TextEdit::singleline(text).desired_width(70.0))
                    .labelled_by(label.id);
                let slider = ui.add(
                    egui::Slider::new(&mut film.thickness_nm, 0.0..=SLIDER_MAX_NM)
                        .clamping(egui::SliderClamping::Never)
                        .show_value(false),
                );
                slider.widget_info(|| {
                    egui::WidgetInfo::slider(
                        true,
                        film.thickness_nm,
                        format!("Film {n} thickness slider"),
                    )
                });
                if slider.changed() {
                    *text = format_nm(film.thickness_nm);
                    *error = None;
                } else if typed.changed() {
                    match nacre_bake::commands::grid::parse_thickness_nm(
                        format!("studio film {n} thickness"),
                        text,
                    ) {
                        Ok(d) => {
                            film.thickness_nm = d;
                            *error = None;
                        }
                        Err(e) => *error = Some(e.to_string()),
                    }
                } else if !typed.has_focus() && error.is_none() {
                    *text = format_nm(film.thickness_nm);
                }
            });
            if let Some(e) = error {
                ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
            }
            ui.add(
                egui::Slider::new(&mut film.relative_nm, 0.0..=300.0)
                    .text(format!("Film {n} relative (nm)")),
            );
            ui.horizontal(|ui| {
                if ui.small_button("Remove").clicked() {
                    remove = Some(j);
                }
                if j > 0 && ui.small_button("Up").clicked() {
                    swap = Some(j - 1);
                }
                if j + 1 < count && ui.small_button("Down").clicked() {
                    swap = Some(j);
                }
            });
            ui.separator();
        }
        if let Some(j) = remove {
            self.doc.films.remove(j);
            self.thickness_text.remove(j);
        }
        if let Some(j) = swap {
            self.doc.films.swap(j, j + 1);
            self.thickness_text.swap(j, j + 1);
        }
        if ui
            .add_enabled(count < MAX_FILMS, egui::Button::new("Add film"))
            .clicked()
        {
            let film = Film::new("1.45", 100.0);
            self.thickness_text
                .push((format_nm(film.thickness_nm), None));
            self.doc.films.push(film);
        }
        ui.separator();
        material_field(ui, "Base", &mut self.doc.substrate);
        ui.separator();
        if let Some(e) = &self.session_error {
            ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
        }
        if let Some(e) = &self.stack_error {
            ui.label(RichText::new(format!("Not applied: {e}")).color(Color32::LIGHT_RED));
        } else {
            ui.label("Materials: numbers (1.45, 0.27+2.9i), bundled names (bk7, mgf2, tio2, water, oil, au, ag, cu, al, cr, si), or files (.yml, .csv).");
        }
    }

    fn view_ui(&mut self, ui: &mut egui::Ui) {
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
                s.orbit = crate::view::Orbit::for_scene(s.scene);
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
            let label = ui.label("Model file");
            ui.add(egui::TextEdit::singleline(&mut self.model_path).desired_width(220.0))
                .labelled_by(label.id)
                .on_hover_text("a .gltf or .glb file (or drop one on the window)");
            if ui.button("Open model").clicked() {
                let path = PathBuf::from(self.model_path.trim());
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
            if let Some(e) = &self.model_error {
                ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
            }
        });
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
    fn draw_if_needed(&mut self, ctx: &egui::Context) {
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
    fn update_delta_e_texture(&mut self, ctx: &egui::Context) {
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
    fn delta_e_legend(&self, ui: &mut egui::Ui) {
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

    /// Asks the worker for the current stack's curves when they are stale; takes its answer.
    fn poll_curves(&mut self) {
        if let Some((id, out)) = self.worker.take()
            && id == self.worker.last_request()
        {
            match out {
                Ok(c) => {
                    self.curves = Some(c);
                    self.curves_error = None;
                }
                Err(e) => self.curves_error = Some(e),
            }
        }
        let stale = match &self.asked {
            Some((doc, angle, _)) => *doc != self.good.0 || *angle != self.spectrum_angle_deg,
            None => true,
        };
        if stale {
            let id = self
                .worker
                .ask(self.good.1.clone(), self.spectrum_angle_deg);
            self.asked = Some((self.good.0.clone(), self.spectrum_angle_deg, id));
        }
    }

    /// Whether the plots show the current stack.
    pub fn curves_current(&self) -> bool {
        match (&self.curves, &self.asked) {
            (Some(c), Some((doc, angle, _))) => {
                *doc == self.good.0 && c.angle_deg == *angle && *angle == self.spectrum_angle_deg
            }
            _ => false,
        }
    }

    fn plots(&mut self, ui: &mut egui::Ui) {
        use egui_plot::{Legend, Line, Plot, PlotPoints};
        ui.heading("Spectra");
        ui.add(
            egui::Slider::new(&mut self.spectrum_angle_deg, 0.0..=89.0).text("Spectrum angle (°)"),
        );
        if let Some(e) = &self.curves_error {
            ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
        }
        let Some(c) = &self.curves else {
            ui.label("computing…");
            ui.ctx().request_repaint();
            return;
        };
        if !self.curves_current() {
            ui.ctx().request_repaint();
        }
        let series = |values: &[f64]| -> PlotPoints<'static> {
            c.wavelengths_nm
                .iter()
                .zip(values)
                .map(|(&x, &y)| [x, y])
                .collect()
        };
        let colours = [
            Color32::from_rgb(90, 160, 255),
            Color32::from_rgb(255, 140, 60),
            Color32::from_gray(230),
        ];
        for (title, values, names) in [
            ("Reflectance", &c.reflectance, ["R s", "R p", "R"]),
            ("Transmittance", &c.transmittance, ["T s", "T p", "T"]),
        ] {
            ui.label(format!("{title} at {:.0}°", c.angle_deg));
            Plot::new(title)
                .height(150.0)
                .legend(Legend::default())
                .include_y(0.0)
                .include_y(1.0)
                .x_axis_label("wavelength (nm)")
                .allow_scroll(false)
                .show(ui, |p| {
                    for k in 0..3 {
                        p.line(
                            Line::new(names[k], series(&values[k]))
                                .color(colours[k])
                                .width(if k == 2 { 2.0 } else { 1.2 }),
                        );
                    }
                });
        }
        ui.label("Exact colour against angle, 0° to 89°");
        let (rect, _) =
            ui.allocate_exact_size(egui::vec2(ui.available_width(), 28.0), egui::Sense::hover());
        let n = c.colour_by_angle.len().max(1);
        let w = rect.width() / n as f32;
        for (k, rgb) in c.colour_by_angle.iter().enumerate() {
            let x = rect.left() + w * k as f32;
            let r = egui::Rect::from_min_max(
                egui::pos2(x, rect.top()),
                egui::pos2(x + w + 0.5, rect.bottom()),
            );
            ui.painter().rect_filled(r, 0.0, srgb8(*rgb));
        }
    }
}

/// Whether `path` names a glTF file (`.gltf` or `.glb`, any case).
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// The stack a session file holds: None when there is no file; an error (its message)
/// when it cannot be read or does not build.
pub fn restore_session(path: &Path) -> Result<Option<StackDoc>, String> {
    if !path.exists() {
        return Ok(None);
    }
    let doc = StackDoc::read_recipe(path).map_err(|e| format!("session not restored: {e}"))?;
    doc.build()
        .map_err(|e| format!("session not restored: {}: {e}", path.display()))?;
    Ok(Some(doc))
}

/// The thickness texts of `doc`'s films.
fn texts(doc: &StackDoc) -> Vec<(String, Option<String>)> {
    doc.films
        .iter()
        .map(|f| (format_nm(f.thickness_nm), None))
        .collect()
}

/// A thickness as typed: up to two decimals, no trailing zeros.
pub fn format_nm(d: f64) -> String {
    let t = format!("{d:.2}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A labelled single-line material entry.
fn material_field(ui: &mut egui::Ui, label: &str, text: &mut String) {
    ui.horizontal(|ui| {
        let l = ui.label(label);
        ui.add(egui::TextEdit::singleline(text).desired_width(150.0))
            .labelled_by(l.id);
    });
}

/// Linear sRGB → an 8-bit sRGB-encoded colour (clipped to [0, 1]; IEC 61966-2-1).
pub fn srgb8(rgb: [f64; 3]) -> Color32 {
    let e = |c: f64| {
        let c = c.clamp(0.0, 1.0);
        let v = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (v * 255.0).round() as u8
    };
    Color32::from_rgb(e(rgb[0]), e(rgb[1]), e(rgb[2]))
}

//! The studio's window: the stack editor (left), the live view (centre) and the plots
//! (right). [`Studio::ui`] draws it all into any [`egui::Ui`], so the same code runs in the
//! native window (`main.rs`, eframe) and in the UI tests (`egui_kittest`).
//!
//! Each panel is its own file: `stack_editor.rs` (left), `view_panel.rs` (centre: the
//! picture, the model, the ΔE2000 map), `material_browser.rs` (under the stack), `plots.rs` (right, the "Plots" tab), `fit.rs` (right, the "Fit" tab), `export.rs` (bottom: the table
//! bake and the engine export). This file holds the state they share, undo, the session, the recipe and the
//! toolbar.
//!
//! An entry is applied when the stack it makes builds ([`StackDoc::build`], the CLI's
//! parser); otherwise the error is shown beside the stack and the view, the plots and the
//! exports keep the last stack that built.

mod export;
mod fit;
mod material_browser;
mod plots;
mod stack_editor;
mod view_panel;

pub use fit::{FitPanel, FreeText, TargetText, hex, parse_hex};
pub use material_browser::{MAX_RESULTS, MaterialBrowser, MaterialTarget};
pub use plots::{BY_ANGLE, BY_THICKNESS, CHROMATICITY, FAMILY_R, FAMILY_T, PlotReadout};
pub use view_panel::is_gltf;

use crate::bake::{BakeJob, BakeSettings};
use crate::compare::{DEFAULT_SCALE_MAX, DeltaE};
use crate::curves::{CurveWorker, Curves};
use crate::doc::{History, PRESETS, StackDoc};
use crate::engine::{EngineExport, EngineJob};
use crate::live_lut::LiveLut;
use crate::view::{Frame, View, ViewSettings};
use eframe::egui;
use egui::{Color32, RichText, TextureHandle};
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
    /// The environment file the field names.
    pub environment_path: String,
    /// Why the last environment file did not open.
    pub environment_error: Option<String>,
    /// The thickness map file the field names.
    pub thickness_map_path: String,
    /// Why the last thickness map did not open.
    pub thickness_map_error: Option<String>,
    /// Whether the loaded thickness map is a colour map (channels for the lower films).
    pub thickness_map_colour: bool,
    /// `lut` on stacks the bundled table does not hold: their own tables, baked in the
    /// background ([`crate::live_lut`]).
    pub live_lut: LiveLut,
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
    /// The material database browser.
    pub materials: MaterialBrowser,
    /// The last engine export prepared (the closest glTF film, the stack JSON, snippets).
    pub engine: Option<EngineExport>,
    /// The engine export being prepared, if any.
    pub engine_job: Option<EngineJob>,
    /// How the last engine export or write went.
    pub engine_status: Option<Result<String, String>>,
    /// What the pointer last read on a plot.
    pub plot_readout: Option<PlotReadout>,
    /// The fit panel (the right panel's "Fit" tab).
    pub fit: FitPanel,
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
            environment_path: String::new(),
            environment_error: None,
            thickness_map_path: String::new(),
            thickness_map_error: None,
            thickness_map_colour: false,
            live_lut: LiveLut::new(None),
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
            materials: MaterialBrowser::default(),
            engine: None,
            engine_job: None,
            engine_status: None,
            plot_readout: None,
            fit: FitPanel::default(),
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
        egui::Panel::bottom("studio export").show(ui, |ui| {
            self.export_panel(ui);
            self.engine_panel(ui);
        });
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
            .show(ui, |ui| self.side_panel(ui));
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
            status_label(ui, &self.status);
        });
    }
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

/// An outcome's line: the text, in red when it is an error; nothing before the first.
fn status_label(ui: &mut egui::Ui, status: &Option<Result<String, String>>) {
    match status {
        Some(Ok(text)) => {
            ui.label(text);
        }
        Some(Err(text)) => {
            ui.label(RichText::new(text).color(Color32::LIGHT_RED));
        }
        None => {}
    }
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
    let [r, g, b] = rgb.map(crate::fit::linear_to_srgb);
    Color32::from_rgb(r, g, b)
}

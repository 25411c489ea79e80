//! The fit panel (the right panel's "Fit" tab, beside "Plots"): which parameters of the
//! current stack are free and over which ranges; colour targets per angle (a colour picker,
//! a hex code, or a pixel of an image); the colour design run in the background
//! ([`crate::fit::FitJob`]) with its progress and a cancel button; the solutions, best first,
//! with their ΔE2000 per target and swatches, each applied to the stack as one undo step;
//! and a measured spectrum fitted the same way, plotted against the fit.
//!
//! Every number is typed as text and read when a fit starts: a bad entry (a bound that is
//! not a number, an inverted range, no target, an unreadable file) is shown in red naming
//! the field or the file, and nothing starts or changes.

use super::{Studio, status_label};
use crate::curves::exact_colours;
use crate::doc::StackDoc;
use crate::fit::{
    ColourResult, DEFAULT_INDEX_RANGE, FitJob, FitOutcome, FitResult, FreeFilm, SampleImage,
    SpectrumResult, TargetEntry, describe_value, linear_to_srgb,
};
use eframe::egui;
use egui::{Color32, RichText, TextureHandle};
use nacre_bake::commands::fit_spectrum::Spectrum;
use nacre_optics::fit::Quantity;
use std::path::Path;

/// One film's free parameters as typed.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeText {
    /// Whether the thickness is free.
    pub thickness_free: bool,
    /// The thickness bounds, nm, as typed.
    pub thickness_nm: [String; 2],
    /// Whether the index is free.
    pub index_free: bool,
    /// The index bounds as typed.
    pub index: [String; 2],
}

impl FreeText {
    /// The defaults of [`FreeFilm::for_film`].
    pub fn for_film(thickness_nm: f64) -> FreeText {
        let f = FreeFilm::for_film(thickness_nm);
        FreeText {
            thickness_free: f.thickness_free,
            thickness_nm: f.thickness_nm.map(|v| format!("{v}")),
            index_free: f.index_free,
            index: f.index.map(|v| format!("{v}")),
        }
    }

    /// The bounds read, errors naming film `n`'s field (only the free ones are read).
    fn read(&self, n: usize) -> Result<FreeFilm, String> {
        let bounds = |free: bool, texts: &[String; 2], what: &str| -> Result<[f64; 2], String> {
            if !free {
                return Ok([0.0, 0.0]);
            }
            Ok([
                number(&format!("film {n} {what} min"), &texts[0])?,
                number(&format!("film {n} {what} max"), &texts[1])?,
            ])
        };
        Ok(FreeFilm {
            thickness_free: self.thickness_free,
            thickness_nm: bounds(self.thickness_free, &self.thickness_nm, "thickness")?,
            index_free: self.index_free,
            index: if self.index_free {
                bounds(true, &self.index, "index")?
            } else {
                DEFAULT_INDEX_RANGE
            },
        })
    }
}

/// One colour target as typed.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetText {
    /// The angle, degrees, as typed.
    pub angle_deg: String,
    /// The colour, 8-bit sRGB (the picker's and the image's).
    pub srgb: [u8; 3],
    /// The colour as a hex code (`#rrggbb`), as typed.
    pub hex: String,
    /// The weight, as typed.
    pub weight: String,
}

impl TargetText {
    /// A target at `angle_deg` of colour `srgb`, weight 1.
    pub fn new(angle_deg: f64, srgb: [u8; 3]) -> TargetText {
        TargetText {
            angle_deg: format!("{angle_deg}"),
            srgb,
            hex: hex(srgb),
            weight: "1".into(),
        }
    }

    fn read(&self, k: usize) -> Result<TargetEntry, String> {
        let srgb = parse_hex(&self.hex)
            .ok_or_else(|| format!("target {k} colour `{}` is not #rrggbb", self.hex.trim()))?;
        Ok(TargetEntry {
            angle_deg: number(&format!("target {k} angle"), &self.angle_deg)?,
            srgb,
            weight: number(&format!("target {k} weight"), &self.weight)?,
        })
    }
}

/// `#rrggbb`.
pub fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// `#rrggbb` or `rrggbb` → the colour.
pub fn parse_hex(text: &str) -> Option<[u8; 3]> {
    let t = text.trim();
    let t = t.strip_prefix('#').unwrap_or(t);
    if t.len() != 6 || !t.is_ascii() {
        return None;
    }
    let c = |i: usize| u8::from_str_radix(&t[i..i + 2], 16).ok();
    Some([c(0)?, c(2)?, c(4)?])
}

/// A typed number: finite, or an error naming `what`.
fn number(what: &str, text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("{what} `{}` is not a number", text.trim())),
    }
}

/// The fit panel's state.
pub struct FitPanel {
    /// Whether the right panel shows the fit (else the plots).
    pub open: bool,
    /// Per film of the stack: its free parameters.
    pub free: Vec<FreeText>,
    /// The colour targets.
    pub targets: Vec<TargetText>,
    /// The target a click on the image sets (0-based).
    pub sample_into: usize,
    /// The colour of reflected or transmitted light.
    pub quantity: Quantity,
    /// Most distinct solutions.
    pub solutions: usize,
    /// The image file field.
    pub image_path: String,
    /// The image colours are sampled from.
    pub image: Option<SampleImage>,
    texture: Option<TextureHandle>,
    /// The spectrum file field.
    pub spectrum_path: String,
    /// The spectra loaded (a wide file or a folder holds several).
    pub spectra: Vec<Spectrum>,
    /// The one shown and fitted (0-based).
    pub spectrum_index: usize,
    /// The fit running, if any.
    pub job: Option<FitJob>,
    /// The last colour design.
    pub colour: Option<ColourResult>,
    /// The last spectrum fit.
    pub spectrum: Option<SpectrumResult>,
    /// Why the last action was refused (a field, a file), or None.
    pub error: Option<String>,
    /// How the last fit or apply went.
    pub status: Option<Result<String, String>>,
}

impl Default for FitPanel {
    /// Three targets at 0°, 30° and 60°, reflected colour, three solutions.
    fn default() -> Self {
        FitPanel {
            open: false,
            free: Vec::new(),
            targets: vec![
                TargetText::new(0.0, [200, 150, 60]),
                TargetText::new(30.0, [170, 140, 90]),
                TargetText::new(60.0, [120, 130, 150]),
            ],
            sample_into: 0,
            quantity: Quantity::Reflectance,
            solutions: 3,
            image_path: String::new(),
            image: None,
            texture: None,
            spectrum_path: String::new(),
            spectra: Vec::new(),
            spectrum_index: 0,
            job: None,
            colour: None,
            spectrum: None,
            error: None,
            status: None,
        }
    }
}

impl FitPanel {
    /// One free-parameter row per film of `doc` (rows kept; new films get the defaults).
    fn sync(&mut self, doc: &StackDoc) {
        if self.free.len() > doc.films.len() {
            self.free.truncate(doc.films.len());
        }
        for f in &doc.films[self.free.len()..] {
            self.free.push(FreeText::for_film(f.thickness_nm));
        }
    }

    fn read_free(&self) -> Result<Vec<FreeFilm>, String> {
        self.free
            .iter()
            .enumerate()
            .map(|(j, f)| f.read(j + 1))
            .collect()
    }

    fn read_targets(&self) -> Result<Vec<TargetEntry>, String> {
        self.targets
            .iter()
            .enumerate()
            .map(|(k, t)| t.read(k + 1))
            .collect()
    }
}

impl Studio {
    /// The right panel: the "Plots" and "Fit" tabs. The fit's outcome is taken whichever
    /// shows.
    pub(super) fn side_panel(&mut self, ui: &mut egui::Ui) {
        self.poll_fit();
        if self.fit.job.is_some() {
            // Keep drawing while the fit works, whichever tab shows: the bar moves and the
            // outcome shows.
            ui.ctx()
                .request_repaint_after(std::time::Duration::from_millis(50));
        }
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.fit.open, false, "Plots");
            ui.selectable_value(&mut self.fit.open, true, "Fit");
        });
        ui.separator();
        if self.fit.open {
            egui::ScrollArea::vertical()
                .id_salt("studio fit scroll")
                .show(ui, |ui| self.fit_panel(ui));
        } else {
            self.plots(ui);
        }
    }

    /// Whether a fit is running.
    pub fn fitting(&self) -> bool {
        self.fit.job.is_some()
    }

    fn stack_for_fit(&self) -> Result<StackDoc, String> {
        match &self.stack_error {
            Some(e) => Err(format!("the stack has an error, fix it first: {e}")),
            None => Ok(self.good.0.clone()),
        }
    }

    /// Starts the colour design of the current stack for the targets (refused, with the
    /// reason in [`FitPanel::error`], when an entry is bad or a fit runs).
    pub fn start_colour_fit(&mut self) {
        if self.fit.job.is_some() {
            return;
        }
        let started = self.stack_for_fit().and_then(|doc| {
            let free = self.fit.read_free()?;
            let targets = self.fit.read_targets()?;
            FitJob::colour(&doc, &free, &targets, self.fit.quantity, self.fit.solutions)
        });
        self.started(started);
    }

    /// Starts fitting the current stack to the loaded spectrum.
    pub fn start_spectrum_fit(&mut self) {
        if self.fit.job.is_some() {
            return;
        }
        let started = self.stack_for_fit().and_then(|doc| {
            let spectrum = self
                .fit
                .spectra
                .get(self.fit.spectrum_index)
                .cloned()
                .ok_or("no spectrum loaded: load a spectrum file first")?;
            let free = self.fit.read_free()?;
            FitJob::spectrum(&doc, &free, spectrum)
        });
        self.started(started);
    }

    fn started(&mut self, started: Result<FitJob, String>) {
        match started {
            Ok(job) => {
                self.fit.status = Some(Ok(format!("{}…", job.what)));
                self.fit.error = None;
                self.fit.job = Some(job);
            }
            Err(e) => self.fit.error = Some(e),
        }
    }

    /// Takes a finished fit's outcome.
    fn poll_fit(&mut self) {
        let Some(job) = &mut self.fit.job else {
            return;
        };
        let Some(outcome) = job.poll() else {
            return;
        };
        let what = job.what;
        self.fit.job = None;
        self.fit.status = Some(match outcome {
            FitOutcome::Done(result) => match result {
                FitResult::Colour(c) => {
                    let line = format!(
                        "colour design: {} solution(s) in {:.1} s ({} samples, {} polishes)",
                        c.design.solutions.len(),
                        c.seconds,
                        c.design.samples,
                        c.design.starts
                    );
                    self.fit.colour = Some(*c);
                    Ok(line)
                }
                FitResult::Spectrum(s) => {
                    let line = format!(
                        "spectrum fit in {:.1} s ({} start(s) of the global search)",
                        s.seconds, s.outcome.fit.starts
                    );
                    self.fit.spectrum = Some(*s);
                    Ok(line)
                }
            },
            FitOutcome::Cancelled => Err(format!("{what} cancelled: the stack is unchanged")),
            FitOutcome::Failed(e) => Err(format!("{what} failed: {e}")),
        });
    }

    /// Applies colour solution `k` (0-based) to the stack, as one undo step.
    pub fn apply_colour_solution(&mut self, k: usize) {
        if let Some(c) = &self.fit.colour
            && k < c.design.solutions.len()
        {
            let doc = c.doc(k);
            self.set_doc(doc);
            self.fit.status = Some(Ok(format!("applied solution {}", k + 1)));
        }
    }

    /// Applies the fitted spectrum's stack, as one undo step.
    pub fn apply_spectrum_fit(&mut self) {
        if let Some(s) = &self.fit.spectrum {
            let doc = s.fitted_doc();
            self.set_doc(doc);
            self.fit.status = Some(Ok("applied the fitted stack".into()));
        }
    }

    /// Loads the image of the image field to sample colours from.
    pub fn load_fit_image(&mut self) {
        match SampleImage::load(Path::new(self.fit.image_path.trim())) {
            Ok(image) => {
                self.fit.image = Some(image);
                self.fit.texture = None;
                self.fit.error = None;
            }
            Err(e) => self.fit.error = Some(format!("image not loaded: {e}")),
        }
    }

    /// Loads the spectrum file of the spectrum field.
    pub fn load_fit_spectrum(&mut self) {
        match crate::fit::load_spectra(Path::new(self.fit.spectrum_path.trim())) {
            Ok(spectra) => {
                self.fit.spectra = spectra;
                self.fit.spectrum_index = 0;
                self.fit.spectrum = None;
                self.fit.error = None;
            }
            Err(e) => self.fit.error = Some(format!("spectrum not loaded: {e}")),
        }
    }

    /// Sets every target's colour to the current stack's exact colour at its angle.
    fn targets_from_stack(&mut self) {
        let angles: Result<Vec<f64>, String> = self
            .fit
            .targets
            .iter()
            .enumerate()
            .map(|(k, t)| number(&format!("target {} angle", k + 1), &t.angle_deg))
            .collect();
        let colours = angles.and_then(|a| {
            if a.iter().any(|v| v.abs() >= 90.0) {
                return Err("target angles must lie strictly between -90 and 90".into());
            }
            exact_colours(&self.good.1, &a).map_err(|e| e.to_string())
        });
        match colours {
            Ok(colours) => {
                for (t, rgb) in self.fit.targets.iter_mut().zip(colours) {
                    t.srgb = rgb.map(linear_to_srgb);
                    t.hex = hex(t.srgb);
                }
                self.fit.error = None;
            }
            Err(e) => self.fit.error = Some(e),
        }
    }

    fn fit_panel(&mut self, ui: &mut egui::Ui) {
        self.fit.sync(&self.good.0);
        let running = self.fit.job.is_some();
        ui.heading("Fit");
        ui.add_enabled_ui(!running, |ui| {
            self.free_rows(ui);
            ui.separator();
            self.target_rows(ui);
        });
        ui.separator();
        ui.horizontal_wrapped(|ui| {
            if ui
                .add_enabled(!running, egui::Button::new("Run fit"))
                .on_hover_text(
                    "design the free parameters for the colour targets (nacre fit color)",
                )
                .clicked()
            {
                self.start_colour_fit();
            }
            if let Some(job) = &self.fit.job {
                let (done, total) = job.progress();
                let fraction = if total == 0 {
                    0.0
                } else {
                    done as f32 / total as f32
                };
                ui.add(
                    egui::ProgressBar::new(fraction)
                        .desired_width(140.0)
                        .text(format!("{}: {done}/{total} steps", job.what)),
                );
                if ui
                    .add_enabled(!job.cancelling(), egui::Button::new("Cancel fit"))
                    .clicked()
                {
                    job.cancel();
                }
            }
        });
        if let Some(e) = &self.fit.error {
            ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
        }
        status_label(ui, &self.fit.status);
        self.colour_solutions(ui);
        ui.separator();
        self.image_sampler(ui);
        ui.separator();
        self.spectrum_section(ui);
    }

    fn free_rows(&mut self, ui: &mut egui::Ui) {
        ui.strong("Free parameters");
        for (j, f) in self.fit.free.iter_mut().enumerate() {
            let n = j + 1;
            let material = self.good.0.films[j].material.trim().to_string();
            ui.label(format!(
                "Film {n} ({material}, {} nm)",
                super::format_nm(self.good.0.films[j].thickness_nm)
            ));
            for (what, free, texts, unit) in [
                (
                    "thickness",
                    &mut f.thickness_free,
                    &mut f.thickness_nm,
                    "nm",
                ),
                ("index", &mut f.index_free, &mut f.index, ""),
            ] {
                ui.horizontal_wrapped(|ui| {
                    let check = ui.checkbox(free, format!("{what} free"));
                    check.widget_info(|| {
                        egui::WidgetInfo::selected(
                            egui::Role::CheckBox,
                            true,
                            *free,
                            format!("Film {n} {what} free"),
                        )
                    });
                    ui.add_enabled_ui(*free, |ui| {
                        for (k, (end, shown)) in [("min", "from"), ("max", "to")].iter().enumerate()
                        {
                            ui.label(*shown);
                            ui.add(egui::TextEdit::singleline(&mut texts[k]).desired_width(50.0))
                                .widget_info(|| {
                                    egui::WidgetInfo::labeled(
                                        egui::Role::TextInput,
                                        true,
                                        format!("Film {n} {what} {end}"),
                                    )
                                });
                        }
                        ui.label(unit);
                    });
                });
            }
        }
        if ui
            .small_button("Reset ranges")
            .on_hover_text("every film's thickness free over ±50 %, indices fixed")
            .clicked()
        {
            self.fit.free.clear();
        }
    }

    fn target_rows(&mut self, ui: &mut egui::Ui) {
        ui.strong("Colour targets");
        ui.horizontal(|ui| {
            ui.radio_value(
                &mut self.fit.quantity,
                Quantity::Reflectance,
                "Reflected colour",
            );
            ui.radio_value(
                &mut self.fit.quantity,
                Quantity::Transmittance,
                "Transmitted colour",
            );
        });
        let mut remove = None;
        let count = self.fit.targets.len();
        for (k, t) in self.fit.targets.iter_mut().enumerate() {
            let n = k + 1;
            ui.horizontal_wrapped(|ui| {
                ui.radio_value(&mut self.fit.sample_into, k, format!("Target {n}"))
                    .on_hover_text("a click on the image sets this target's colour");
                let label = ui.label("angle (°)");
                ui.add(egui::TextEdit::singleline(&mut t.angle_deg).desired_width(36.0))
                    .labelled_by(label.id)
                    .widget_info(|| {
                        egui::WidgetInfo::labeled(
                            egui::Role::TextInput,
                            true,
                            format!("Target {n} angle"),
                        )
                    });
                if egui::color_picker::color_edit_button_srgb(ui, &mut t.srgb).changed() {
                    t.hex = hex(t.srgb);
                }
                let typed = ui.add(egui::TextEdit::singleline(&mut t.hex).desired_width(70.0));
                typed.widget_info(|| {
                    egui::WidgetInfo::labeled(
                        egui::Role::TextInput,
                        true,
                        format!("Target {n} colour"),
                    )
                });
                if typed.changed()
                    && let Some(c) = parse_hex(&t.hex)
                {
                    t.srgb = c;
                }
                let label = ui.label("weight");
                ui.add(egui::TextEdit::singleline(&mut t.weight).desired_width(28.0))
                    .labelled_by(label.id)
                    .widget_info(|| {
                        egui::WidgetInfo::labeled(
                            egui::Role::TextInput,
                            true,
                            format!("Target {n} weight"),
                        )
                    });
                let button = ui
                    .small_button("Remove")
                    .on_hover_text("remove this target");
                button.widget_info(|| {
                    egui::WidgetInfo::labeled(
                        egui::Role::Button,
                        true,
                        format!("Remove target {n}"),
                    )
                });
                if button.clicked() {
                    remove = Some(k);
                }
            });
        }
        if let Some(k) = remove {
            self.fit.targets.remove(k);
            if self.fit.sample_into >= self.fit.targets.len() {
                self.fit.sample_into = self.fit.targets.len().saturating_sub(1);
            }
        }
        ui.horizontal_wrapped(|ui| {
            if ui.button("Add target").clicked() {
                let angle = self
                    .fit
                    .targets
                    .last()
                    .and_then(|t| t.angle_deg.trim().parse::<f64>().ok())
                    .map_or(0.0, |a| (a + 15.0).min(85.0));
                let colour = self.fit.targets.last().map_or([128; 3], |t| t.srgb);
                self.fit.targets.push(TargetText::new(angle, colour));
            }
            if ui
                .add_enabled(count > 0, egui::Button::new("Targets from the stack"))
                .on_hover_text(
                    "each target's colour set to the current stack's exact colour at its angle",
                )
                .clicked()
            {
                self.targets_from_stack();
            }
            let label = ui.label("Solutions");
            ui.add(egui::DragValue::new(&mut self.fit.solutions).range(1..=10))
                .labelled_by(label.id);
        });
    }

    fn colour_solutions(&mut self, ui: &mut egui::Ui) {
        let Some(c) = &self.fit.colour else {
            return;
        };
        let mut apply = None;
        ui.strong("Solutions, best first");
        for (k, s) in c.design.solutions.iter().enumerate() {
            let values: Vec<String> = c
                .template
                .free()
                .iter()
                .zip(&s.x)
                .map(|(f, &v)| describe_value(f, v))
                .collect();
            ui.label(format!(
                "Solution {}: {} — ΔE2000 mean {:.2}, max {:.2}",
                k + 1,
                values.join(", "),
                s.mean(&c.rows),
                s.max()
            ));
            ui.horizontal_wrapped(|ui| {
                for (i, row) in c.rows.iter().enumerate() {
                    swatch_pair(
                        ui,
                        row.colour,
                        s.colour[i],
                        &format!("{}°: ΔE {:.2}", row.angle_deg, s.delta_e[i]),
                    );
                }
            });
            if ui.button(format!("Apply solution {}", k + 1)).clicked() {
                apply = Some(k);
            }
        }
        if let Some(k) = apply {
            self.apply_colour_solution(k);
        }
    }

    fn image_sampler(&mut self, ui: &mut egui::Ui) {
        ui.strong("Sample colours from an image");
        ui.horizontal_wrapped(|ui| {
            let label = ui.label("Image file");
            ui.add(egui::TextEdit::singleline(&mut self.fit.image_path).desired_width(150.0))
                .labelled_by(label.id);
            if ui.button("Load image").clicked() {
                self.load_fit_image();
            }
        });
        let Some(image) = &self.fit.image else {
            return;
        };
        let texture = self.fit.texture.get_or_insert_with(|| {
            ui.ctx().load_texture(
                "fit sample image",
                egui::ColorImage::from_rgba_unmultiplied(
                    [image.width as usize, image.height as usize],
                    &image.rgba,
                ),
                egui::TextureOptions::NEAREST,
            )
        });
        let width = ui.available_width().min(320.0);
        let size = egui::vec2(width, width * image.height as f32 / image.width as f32);
        ui.label(format!(
            "{} ({}×{}): click a point to set target {}'s colour",
            image.path.display(),
            image.width,
            image.height,
            self.fit.sample_into + 1
        ));
        let response = ui.add(
            egui::Image::from_texture((texture.id(), size))
                .sense(egui::Sense::click())
                .alt_text("Sample image"),
        );
        if response.clicked()
            && let Some(pos) = response.interact_pointer_pos()
        {
            let r = response.rect;
            let u = ((pos.x - r.left()) / r.width()).clamp(0.0, 1.0);
            let v = ((pos.y - r.top()) / r.height()).clamp(0.0, 1.0);
            let x = ((u * image.width as f32) as u32).min(image.width - 1);
            let y = ((v * image.height as f32) as u32).min(image.height - 1);
            let colour = image.sample(x, y);
            let k = self.fit.sample_into;
            if let Some(t) = self.fit.targets.get_mut(k) {
                t.srgb = colour;
                t.hex = hex(colour);
                self.fit.status = Some(Ok(format!(
                    "target {} set to {} from pixel ({x}, {y})",
                    k + 1,
                    t.hex
                )));
            }
        }
    }

    fn spectrum_section(&mut self, ui: &mut egui::Ui) {
        use egui_plot::{Legend, Line, Plot, PlotPoints, Points};
        ui.strong("Measured spectrum");
        let running = self.fit.job.is_some();
        ui.horizontal_wrapped(|ui| {
            let label = ui.label("Spectrum file");
            ui.add(egui::TextEdit::singleline(&mut self.fit.spectrum_path).desired_width(150.0))
                .labelled_by(label.id);
            if ui
                .add_enabled(!running, egui::Button::new("Load spectrum"))
                .on_hover_text("CSV: wavelength_nm and R or T, optionally angle_deg and sigma (nacre fit spectrum's format)")
                .clicked()
            {
                self.load_fit_spectrum();
            }
        });
        if self.fit.spectra.len() > 1 {
            let spectra = &self.fit.spectra;
            let index = &mut self.fit.spectrum_index;
            egui::ComboBox::from_label("Spectrum")
                .selected_text(spectra.get(*index).map_or("", |s| s.name.as_str()))
                .show_ui(ui, |ui| {
                    for (i, s) in spectra.iter().enumerate() {
                        ui.selectable_value(index, i, s.name.as_str());
                    }
                });
        }
        let Some(spectrum) = self.fit.spectra.get(self.fit.spectrum_index) else {
            return;
        };
        let letter = match spectrum.quantity {
            Quantity::Reflectance => "R",
            Quantity::Transmittance => "T",
        };
        ui.label(format!(
            "{}: {} points of {letter}{}",
            spectrum.name,
            spectrum.points.len(),
            if self.fit.spectra.len() > 1 {
                format!(
                    " (spectrum {} of {})",
                    self.fit.spectrum_index + 1,
                    self.fit.spectra.len()
                )
            } else {
                String::new()
            }
        ));
        let start = ui
            .add_enabled(!running, egui::Button::new("Fit spectrum"))
            .on_hover_text("fit the free parameters to the spectrum (nacre fit spectrum)")
            .clicked();
        let fitted = self
            .fit
            .spectrum
            .as_ref()
            .filter(|s| s.outcome.name == spectrum.name);
        let mut apply = false;
        if let Some(s) = fitted {
            let values: Vec<String> = s
                .template
                .free()
                .iter()
                .zip(s.outcome.fit.x.iter().zip(&s.outcome.fit.sigma))
                .map(|(f, (&x, sigma))| format!("{} ± {sigma:.2}", describe_value(f, x)))
                .collect();
            ui.label(format!(
                "Fitted: {}; residual RMS {:.2e}",
                values.join(", "),
                s.outcome.fit.rms
            ));
            for w in &s.warnings {
                ui.label(RichText::new(format!("warning: {w}")).color(Color32::YELLOW));
            }
            apply = ui.button("Apply fitted stack").clicked();
        }
        // Measured points and, once fitted, the fitted curve (the first angle's run).
        let measured: PlotPoints<'static> = spectrum
            .points
            .iter()
            .map(|p| [p.wavelength_nm, p.value])
            .collect();
        let curve: Option<PlotPoints<'static>> = fitted.map(|s| {
            s.outcome
                .points
                .iter()
                .zip(&s.outcome.fit.fitted)
                .map(|(p, &f)| [p.wavelength_nm, f])
                .collect()
        });
        Plot::new("Fit spectrum")
            .height(160.0)
            .legend(Legend::default())
            .include_y(0.0)
            .x_axis_label("wavelength (nm)")
            .allow_scroll(false)
            .show(ui, |p| {
                p.points(
                    Points::new(format!("measured {letter}"), measured)
                        .radius(1.5)
                        .color(Color32::from_gray(220)),
                );
                if let Some(curve) = curve {
                    p.line(
                        Line::new(format!("fitted {letter}"), curve)
                            .color(Color32::from_rgb(255, 140, 60))
                            .width(1.5),
                    );
                }
            });
        if apply {
            self.apply_spectrum_fit();
        }
        if start {
            self.start_spectrum_fit();
        }
    }
}

/// A target swatch over an achieved one (linear output-space colours), captioned.
fn swatch_pair(ui: &mut egui::Ui, target: [f64; 3], achieved: [f64; 3], caption: &str) {
    ui.vertical(|ui| {
        let (rect, _) = ui.allocate_exact_size(egui::vec2(54.0, 36.0), egui::Sense::hover());
        let top = egui::Rect::from_min_max(rect.min, egui::pos2(rect.right(), rect.center().y));
        let bottom = egui::Rect::from_min_max(egui::pos2(rect.left(), rect.center().y), rect.max);
        ui.painter().rect_filled(top, 0.0, super::srgb8(target));
        ui.painter()
            .rect_filled(bottom, 0.0, super::srgb8(achieved));
        ui.label(RichText::new(caption).small());
    });
}

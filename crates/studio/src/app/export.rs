//! The export panel: the stack's `film-lut` table set baked on a background thread
//! ([`crate::bake`]), with its progress bar and a cancel button; and the engine export
//! ([`crate::engine`]): the closest glTF film, the stack JSON and the Bevy and three.js
//! snippets, shown and written into the same folder under the same name.

use super::{Studio, status_label};
use crate::bake::{BakeJob, BakeOutcome};
use crate::engine::EngineJob;
use eframe::egui;
use egui::RichText;
use std::path::Path;

impl Studio {
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
    pub(super) fn poll_bake(&mut self) {
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
    pub(super) fn export_panel(&mut self, ui: &mut egui::Ui) {
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
            status_label(ui, &self.bake_status);
        });
    }

    /// Starts preparing the engine export of the last stack that built (refused while an
    /// entry is in error; one at a time).
    pub fn start_engine_export(&mut self) {
        if self.engine_job.is_some() {
            return;
        }
        if let Some(e) = &self.stack_error {
            self.engine_status = Some(Err(format!("the stack has an error, fix it first: {e}")));
            return;
        }
        self.engine_job = Some(EngineJob::start(
            self.good.0.clone(),
            self.bake.name.clone(),
        ));
        self.engine_status = Some(Ok("fitting the closest glTF film…".into()));
    }

    /// Whether the engine export is being prepared.
    pub fn engine_running(&self) -> bool {
        self.engine_job.is_some()
    }

    fn poll_engine(&mut self) {
        let Some(outcome) = self.engine_job.as_mut().and_then(EngineJob::poll) else {
            return;
        };
        self.engine_job = None;
        self.engine_status = Some(match outcome {
            Ok(export) => {
                let summary = export.summary();
                self.engine = Some(export);
                Ok(summary)
            }
            Err(e) => Err(format!("engine export failed: {e}")),
        });
    }

    /// Writes the engine export's four files into the table folder under the table name
    /// (refused when the stack changed since the export was prepared).
    pub fn write_engine_files(&mut self) {
        self.engine_status = Some(match &self.engine {
            None => Err("prepare the engine export first".into()),
            Some(e) if e.doc != self.good.0 => {
                Err("the stack changed since the export: prepare it again".into())
            }
            Some(e) => e
                .write(Path::new(self.bake.folder.trim()), self.bake.name.trim())
                .map(|files| {
                    format!(
                        "wrote {}",
                        files
                            .iter()
                            .map(|f| f.display().to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                }),
        });
    }

    /// The engine export's row of the export panel and its snippets.
    pub(super) fn engine_panel(&mut self, ui: &mut egui::Ui) {
        self.poll_engine();
        ui.horizontal_wrapped(|ui| {
            ui.strong("Engines");
            let running = self.engine_job.is_some();
            if ui
                .add_enabled(!running, egui::Button::new("Prepare engine export"))
                .on_hover_text("the closest KHR_materials_iridescence film (nacre fit gltf), the stack JSON (nacre export) and Bevy and three.js snippets")
                .clicked()
            {
                self.start_engine_export();
            }
            if running {
                ui.spinner();
                ui.ctx()
                    .request_repaint_after(std::time::Duration::from_millis(50));
            }
            let ready = self.engine.as_ref().is_some_and(|e| e.doc == self.good.0);
            if ui
                .add_enabled(ready && !running, egui::Button::new("Write engine files"))
                .on_hover_text("NAME.material.json, NAME.stack.json, NAME.bevy.rs, NAME.three.js into the table folder")
                .clicked()
            {
                self.write_engine_files();
            }
            status_label(ui, &self.engine_status);
        });
        let Some(export) = &self.engine else {
            return;
        };
        egui::CollapsingHeader::new("Engine snippets")
            .default_open(false)
            .show(ui, |ui| {
                egui::ScrollArea::vertical()
                    .id_salt("engine snippets")
                    .max_height(260.0)
                    .show(ui, |ui| {
                        let material =
                            serde_json::to_string_pretty(&export.material).unwrap_or_default();
                        for (title, text) in [
                            (
                                "glTF material (KHR_materials_iridescence)",
                                material.as_str(),
                            ),
                            ("Bevy (bevy_nacre)", export.bevy.as_str()),
                            ("three.js (@nacre/three)", export.three.as_str()),
                        ] {
                            ui.strong(title);
                            ui.label(RichText::new(text).monospace());
                        }
                    });
            });
    }
}

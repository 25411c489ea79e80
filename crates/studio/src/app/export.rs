//! The export panel: the stack's `film-lut` table set baked on a background thread
//! ([`crate::bake`]), with its progress bar and a cancel button.

use super::Studio;
use crate::bake::{BakeJob, BakeOutcome};
use eframe::egui;
use egui::{Color32, RichText};

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
}

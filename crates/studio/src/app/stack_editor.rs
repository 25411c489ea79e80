//! The stack editor: ambient, films (material, thickness typed or slid, relative
//! thickness, order) and base.

use super::{Studio, format_nm, material_field};
use crate::doc::{Film, MAX_FILMS, SLIDER_MAX_NM};
use eframe::egui;
use egui::{Color32, RichText};

impl Studio {
    pub(super) fn stack_editor(&mut self, ui: &mut egui::Ui) {
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
        self.material_browser(ui);
        ui.separator();
        if let Some(e) = &self.session_error {
            ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
        }
        if let Some(e) = &self.stack_error {
            ui.label(RichText::new(format!("Not applied: {e}")).color(Color32::LIGHT_RED));
        } else {
            ui.label("Materials: numbers (1.45, 0.27+2.9i), bundled names (bk7, mgf2, tio2, water, oil, au, ag, cu, al, cr, si), files (.yml, .csv), or refractiveindex.info pages (main/Au/Johnson) from the material database.");
        }
    }
}

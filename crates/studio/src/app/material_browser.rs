//! The material database browser, under the stack editor: the local refractiveindex.info
//! database's folder, a search over its catalog's pages (shelf, book, page and title), and
//! the layer a picked page goes to (the ambient, a film or the base), as the material
//! `shelf/book/page`.

use super::Studio;
use crate::material_db::{Catalog, default_folder};
use eframe::egui;
use egui::{Color32, RichText};
use nacre_format::materials::database;
use std::path::PathBuf;

/// At most this many search results are listed (the count says how many match).
pub const MAX_RESULTS: usize = 60;

/// Where a picked page goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialTarget {
    /// The medium above the stack.
    Ambient,
    /// Film `j` (0: the top film).
    Film(usize),
    /// The base below the stack.
    Base,
}

/// The browser's state.
#[derive(Debug)]
pub struct MaterialBrowser {
    /// The database folder as typed.
    pub folder: String,
    /// The search text.
    pub query: String,
    /// Where a picked page goes.
    pub target: MaterialTarget,
    /// The database opened, if any.
    pub catalog: Option<Catalog>,
    /// Why the folder did not open.
    pub error: Option<String>,
    /// Whether the folder as typed has been tried (the first draw opens it).
    tried: bool,
}

impl Default for MaterialBrowser {
    /// The folder the stack's parser already reads (set by `main.rs` from
    /// `NACRE_MATERIAL_DB` or `../shared`), else [`default_folder`], else empty.
    fn default() -> Self {
        let folder = database()
            .map(|db| db.dir)
            .or_else(default_folder)
            .map(|d| d.display().to_string())
            .unwrap_or_default();
        MaterialBrowser {
            folder,
            query: String::new(),
            target: MaterialTarget::Film(0),
            catalog: None,
            error: None,
            tried: false,
        }
    }
}

impl MaterialBrowser {
    /// Opens the database at the typed folder; on failure the previous one stays.
    pub fn open(&mut self) {
        self.tried = true;
        let folder = self.folder.trim();
        if folder.is_empty() {
            self.error = Some(
                "no database folder: type the path of a refractiveindex.info-database clone".into(),
            );
            return;
        }
        match Catalog::open(&PathBuf::from(folder)) {
            Ok(c) => {
                self.catalog = Some(c);
                self.error = None;
            }
            Err(e) => self.error = Some(e),
        }
    }
}

impl Studio {
    /// Sets the browser's target layer's material to the database page `spec`
    /// (`shelf/book/page`) and makes the browser's database the one the stack reads; the
    /// stack applies it on this frame (or shows why it does not build).
    pub fn pick_material(&mut self, spec: &str) {
        if let Some(c) = &self.materials.catalog {
            c.make_current();
        }
        let slot = match self.materials.target {
            MaterialTarget::Ambient => &mut self.doc.ambient,
            MaterialTarget::Film(j) => match self.doc.films.get_mut(j) {
                Some(f) => &mut f.material,
                None => return,
            },
            MaterialTarget::Base => &mut self.doc.substrate,
        };
        *slot = spec.to_string();
    }

    pub(super) fn material_browser(&mut self, ui: &mut egui::Ui) {
        egui::CollapsingHeader::new("Material database")
            .default_open(true)
            .show(ui, |ui| self.material_browser_body(ui));
    }

    fn material_browser_body(&mut self, ui: &mut egui::Ui) {
        let b = &mut self.materials;
        if !b.tried && !b.folder.trim().is_empty() {
            b.open();
        }
        ui.horizontal(|ui| {
            let label = ui.label("Database folder");
            ui.add(egui::TextEdit::singleline(&mut b.folder).desired_width(170.0))
                .labelled_by(label.id)
                .on_hover_text("a clone of refractiveindex.info-database (NACRE_MATERIAL_DB)");
            if ui.button("Open database").clicked() {
                b.open();
            }
        });
        if let Some(e) = &b.error {
            ui.label(RichText::new(e.as_str()).color(Color32::LIGHT_RED));
        }
        // The films may have been removed since the target was chosen.
        if let MaterialTarget::Film(j) = b.target
            && j >= self.doc.films.len()
        {
            b.target = MaterialTarget::Base;
        }
        ui.horizontal_wrapped(|ui| {
            ui.label("Apply to");
            ui.selectable_value(&mut b.target, MaterialTarget::Ambient, "ambient");
            for j in 0..self.doc.films.len() {
                ui.selectable_value(
                    &mut b.target,
                    MaterialTarget::Film(j),
                    format!("film {}", j + 1),
                );
            }
            ui.selectable_value(&mut b.target, MaterialTarget::Base, "base");
        });
        let Some(catalog) = &b.catalog else {
            return;
        };
        ui.horizontal(|ui| {
            let label = ui.label("Search materials");
            ui.add(
                egui::TextEdit::singleline(&mut b.query)
                    .desired_width(170.0)
                    .hint_text("e.g. Au Johnson, SiO2, glass BK7"),
            )
            .labelled_by(label.id);
        });
        let (found, total) = catalog.search(&b.query, MAX_RESULTS);
        ui.label(
            RichText::new(format!(
                "{total} of {} pages match{}",
                catalog.pages.len(),
                if total > found.len() {
                    format!(" (the first {} listed)", found.len())
                } else {
                    String::new()
                }
            ))
            .weak(),
        );
        let mut picked = None;
        egui::ScrollArea::vertical()
            .id_salt("material search results")
            .max_height(220.0)
            .show(ui, |ui| {
                for page in found {
                    let spec = page.spec();
                    if ui
                        .selectable_label(false, spec.as_str())
                        .on_hover_text(&page.name)
                        .clicked()
                    {
                        picked = Some(spec);
                    }
                }
            });
        if let Some(spec) = picked {
            self.pick_material(&spec);
        }
    }
}

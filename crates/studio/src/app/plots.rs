//! The plots: reflectance and transmittance spectra at one angle and the exact colour
//! against angle, computed by [`crate::curves`]' worker thread.

use super::{Studio, srgb8};
use eframe::egui;
use egui::{Color32, RichText};

impl Studio {
    /// Asks the worker for the current stack's curves when they are stale; takes its answer.
    pub(super) fn poll_curves(&mut self) {
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

    pub(super) fn plots(&mut self, ui: &mut egui::Ui) {
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

//! The plots: reflectance and transmittance spectra at one angle and at a family of angles,
//! the exact colour against angle and against film 1's thickness, and the chromaticity
//! trajectories (CIE xy), computed by [`crate::curves`]' worker thread. Hovering a plot
//! reads the data point nearest the pointer ([`PlotReadout`]).

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
        use crate::curves::{FAMILY_ANGLES_DEG, THICKNESS_SWEEP_NM};
        use egui_plot::{HoverPosition, Legend, Line, Plot, PlotPoints, Points};
        use std::cell::RefCell;
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
        // What the pointer reads, set by the plot it hovers (kept for the tests).
        let hovered: RefCell<Option<PlotReadout>> = RefCell::new(None);
        let reader = |plot: &'static str, text: fn(&str, usize, f64, f64) -> String| {
            let hovered = &hovered;
            move |h: &HoverPosition<'_>| -> Option<String> {
                let HoverPosition::NearDataPoint {
                    plot_name,
                    position,
                    index,
                } = h
                else {
                    return None;
                };
                let t = text(plot_name, *index, position.x, position.y);
                *hovered.borrow_mut() = Some(PlotReadout {
                    plot,
                    series: plot_name.to_string(),
                    index: *index,
                    x: position.x,
                    y: position.y,
                    text: t.clone(),
                });
                Some(t)
            }
        };
        // A spectrum's axes: R or T from 0 to 1 against wavelength, no scroll zoom.
        let spectrum_plot = |id: &'static str| {
            Plot::new(id)
                .height(120.0)
                .legend(Legend::default())
                .include_y(0.0)
                .include_y(1.0)
                .x_axis_label("wavelength (nm)")
                .allow_scroll(false)
        };
        let spectrum_text =
            |name: &str, _: usize, x: f64, y: f64| format!("{name} at {x:.0} nm: {y:.4}");
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
            Color32::from_rgb(120, 220, 120),
        ];
        egui::ScrollArea::vertical()
            .id_salt("studio plots scroll")
            .show(ui, |ui| {
                for (title, values, names) in [
                    ("Reflectance", &c.reflectance, ["R s", "R p", "R"]),
                    ("Transmittance", &c.transmittance, ["T s", "T p", "T"]),
                ] {
                    ui.label(format!("{title} at {:.0}°", c.angle_deg));
                    spectrum_plot(title)
                        .label_formatter(reader(title, spectrum_text))
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
                let angles = FAMILY_ANGLES_DEG
                    .iter()
                    .map(|a| format!("{a:.0}°"))
                    .collect::<Vec<_>>()
                    .join(", ");
                for (title, plot, values, letter) in [
                    ("Reflectance family", FAMILY_R, &c.family_reflectance, "R"),
                    (
                        "Transmittance family",
                        FAMILY_T,
                        &c.family_transmittance,
                        "T",
                    ),
                ] {
                    ui.label(format!("{letter} (unpolarised) at {angles}"));
                    spectrum_plot(title)
                        .label_formatter(reader(plot, spectrum_text))
                        .show(ui, |p| {
                            for (k, v) in values.iter().enumerate() {
                                p.line(
                                    Line::new(
                                        format!("{letter} {:.0}°", FAMILY_ANGLES_DEG[k]),
                                        series(v),
                                    )
                                    .color(colours[k % colours.len()])
                                    .width(1.5),
                                );
                            }
                        });
                }
                ui.label("Exact colour against angle, 0° to 89°");
                colour_strip(ui, &c.colour_by_angle);
                if !c.colour_by_thickness.is_empty() {
                    let (lo, hi, _) = THICKNESS_SWEEP_NM;
                    ui.label(format!(
                        "Exact colour at 0° against film 1's thickness, {lo:.0} to {hi:.0} nm"
                    ));
                    colour_strip(ui, &c.colour_by_thickness);
                }
                ui.label("Chromaticity (CIE 1931 xy) as the angle and film 1's thickness vary");
                let thicknesses = c.thicknesses_nm.clone();
                Plot::new("Chromaticity")
                    .height(200.0)
                    .data_aspect(1.0)
                    .legend(Legend::default())
                    .include_x(0.2)
                    .include_x(0.45)
                    .include_y(0.2)
                    .include_y(0.45)
                    .x_axis_label("x")
                    .y_axis_label("y")
                    .allow_scroll(false)
                    .label_formatter(reader(CHROMATICITY, chromaticity_text))
                    .show(ui, |p| {
                        let line = |xy: &[[f64; 2]]| -> PlotPoints<'static> {
                            xy.iter().copied().collect()
                        };
                        p.line(
                            Line::new(BY_ANGLE, line(&c.xy_by_angle))
                                .color(colours[0])
                                .width(1.5),
                        );
                        if !thicknesses.is_empty() {
                            p.line(
                                Line::new(BY_THICKNESS, line(&c.xy_by_thickness))
                                    .color(colours[1])
                                    .width(1.2),
                            );
                        }
                        p.points(
                            Points::new("D65 white", vec![[0.3127, 0.3290]])
                                .radius(3.0)
                                .color(Color32::WHITE),
                        );
                    });
            });
        self.plot_readout = hovered.into_inner().or(self.plot_readout.take());
    }
}

/// The reflectance family plot's name in [`PlotReadout::plot`].
pub const FAMILY_R: &str = "Reflectance family";
/// The transmittance family plot's name.
pub const FAMILY_T: &str = "Transmittance family";
/// The chromaticity plot's name.
pub const CHROMATICITY: &str = "Chromaticity";
/// The chromaticity plot's trajectory over angle (0° to 89°, one point a degree).
pub const BY_ANGLE: &str = "xy against angle";
/// Its trajectory over film 1's thickness (at 0°, the points of
/// [`crate::curves::THICKNESS_SWEEP_NM`]).
pub const BY_THICKNESS: &str = "xy against thickness";

/// What the pointer last read on a plot: the plot, the series and the data point nearest
/// the pointer (its index in the series and its coordinates), and the text shown.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotReadout {
    /// The plot ("Reflectance", "Transmittance", [`FAMILY_R`], [`FAMILY_T`],
    /// [`CHROMATICITY`]).
    pub plot: &'static str,
    /// The series' name ("R 30°", [`BY_ANGLE`], …).
    pub series: String,
    /// The point's index in its series.
    pub index: usize,
    /// Its x (wavelength, nm; or chromaticity x).
    pub x: f64,
    /// Its y (R or T; or chromaticity y).
    pub y: f64,
    /// The text the hover label shows.
    pub text: String,
}

/// The chromaticity plot's hover text: the angle or the thickness the point stands for.
fn chromaticity_text(series: &str, index: usize, x: f64, y: f64) -> String {
    let (lo, _, step) = crate::curves::THICKNESS_SWEEP_NM;
    match series {
        BY_ANGLE => format!("{index}°: x {x:.4}, y {y:.4}"),
        BY_THICKNESS => format!(
            "film 1 {:.0} nm: x {x:.4}, y {y:.4}",
            lo + step * index as f64
        ),
        _ => format!("{series}: x {x:.4}, y {y:.4}"),
    }
}

/// A strip of colours (linear sRGB), left to right, the panel's width.
fn colour_strip(ui: &mut egui::Ui, colours: &[[f64; 3]]) {
    let (rect, _) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 24.0), egui::Sense::hover());
    let n = colours.len().max(1);
    let w = rect.width() / n as f32;
    for (k, rgb) in colours.iter().enumerate() {
        let x = rect.left() + w * k as f32;
        let r = egui::Rect::from_min_max(
            egui::pos2(x, rect.top()),
            egui::pos2(x + w + 0.5, rect.bottom()),
        );
        ui.painter().rect_filled(r, 0.0, srgb8(*rgb));
    }
}

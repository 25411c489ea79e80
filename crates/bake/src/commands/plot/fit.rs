//! The picture of a spectrum fit (`nacre fit spectrum --plot`): the measured values against
//! the fitted ones, and the residuals below.

use super::{
    Chart2d, DrawResult, Figure, ImageFormat, Line, MAX_CURVES, Solid, draw_line, draw_side_legend,
    fmt_tick, nice_ceiling, palette,
};
use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One incidence angle's points of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct FitCurve {
    /// Incidence angle, degrees.
    pub angle_deg: f64,
    /// Vacuum wavelengths, nm, in the data's order.
    pub wavelengths_nm: Vec<f64>,
    /// The measured values.
    pub measured: Vec<f64>,
    /// The fitted values a(ν) M + b(ν).
    pub fitted: Vec<f64>,
}

/// A fit: top panel the measured values (dots) and the fitted curve (line), one colour
/// per angle (Tableau 10); bottom panel the residuals, measured − fitted, on a scale
/// symmetric about zero.
#[derive(Clone, Debug)]
pub struct FitPlot {
    /// Title (the data file and the fitted values).
    pub title: String,
    /// The quantity's name on the y axis (`reflectance`, `transmittance`).
    pub quantity: String,
    /// The curves, one per angle (at most [`MAX_CURVES`]).
    pub curves: Vec<FitCurve>,
}

impl FitPlot {
    /// Groups `points` (angle, wavelength, measured, fitted) by angle in the order the
    /// angles first appear; errors when there is nothing to draw or more than
    /// [`MAX_CURVES`] angles.
    pub fn new(title: String, quantity: &str, points: &[(f64, f64, f64, f64)]) -> Result<Self> {
        let mut curves: Vec<FitCurve> = Vec::new();
        for &(angle_deg, wl, measured, fitted) in points {
            let at = match curves
                .iter()
                .position(|c| c.angle_deg.to_bits() == angle_deg.to_bits())
            {
                Some(at) => at,
                None => {
                    curves.push(FitCurve {
                        angle_deg,
                        wavelengths_nm: Vec::new(),
                        measured: Vec::new(),
                        fitted: Vec::new(),
                    });
                    curves.len() - 1
                }
            };
            let c = &mut curves[at];
            c.wavelengths_nm.push(wl);
            c.measured.push(measured);
            c.fitted.push(fitted);
        }
        if curves.is_empty() {
            return Err(Error::invalid(
                "nacre fit spectrum --plot",
                "nothing to draw",
            ));
        }
        if curves.len() > MAX_CURVES {
            return Err(Error::invalid(
                "nacre fit spectrum --plot",
                format!(
                    "the data hold {} angles: a fit plot shows at most {MAX_CURVES}",
                    curves.len()
                ),
            ));
        }
        Ok(FitPlot {
            title,
            quantity: quantity.into(),
            curves,
        })
    }

    fn wavelength_range(&self) -> (f64, f64) {
        let all = self.curves.iter().flat_map(|c| c.wavelengths_nm.iter());
        let (a, b) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
        if b > a { (a, b) } else { (a - 1.0, b + 1.0) }
    }
}

/// `colour` 45 % over white: the measured points under the fitted line.
fn pale(colour: RGBColor) -> RGBColor {
    let mix = |c: u8| (255.0 - 0.45 * (255.0 - c as f64)).round() as u8;
    RGBColor(mix(colour.0), mix(colour.1), mix(colour.2))
}

/// A panel's chart with the house mesh.
fn panel<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    x: (f64, f64),
    y: (f64, f64),
    y_desc: &str,
) -> std::result::Result<Chart2d<'a, DB>, plotters::drawing::DrawingAreaErrorKind<DB::ErrorType>> {
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_right(170)
        .x_label_area_size(46)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    chart
        .configure_mesh()
        .x_desc("vacuum wavelength λ (nm)")
        .y_desc(y_desc)
        .x_label_formatter(&fmt_tick)
        .y_label_formatter(&fmt_tick)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .bold_line_style(BLACK.mix(0.15))
        .light_line_style(BLACK.mix(0.04))
        .draw()?;
    Ok(chart)
}

impl Figure for FitPlot {
    fn size(&self) -> (u32, u32) {
        (1200, 80 + 440 + 260)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 20))?;
        let (_, h) = area.dim_in_pixel();
        let (top, bottom) = area.split_vertically(h as i32 * 440 / 700);
        let (wl0, wl1) = self.wavelength_range();
        let finite = |v: &&f64| v.is_finite();
        // Values: from 0 (or below, for a negative offset) to a round value above the data.
        let values = self
            .curves
            .iter()
            .flat_map(|c| c.measured.iter().chain(&c.fitted));
        let (lo, hi) = values
            .filter(finite)
            .fold((0.0f64, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
        let y1 = nice_ceiling((hi * 1.05).max(1e-3));
        let y0 = if lo < 0.0 {
            -nice_ceiling(-lo * 1.05)
        } else {
            0.0
        };
        let mut chart = panel(&top, (wl0, wl1), (y0, y1), &self.quantity)?;
        let mut entries = Vec::new();
        for (i, c) in self.curves.iter().enumerate() {
            let colour = palette(i);
            chart.draw_series(
                c.wavelengths_nm
                    .iter()
                    .zip(&c.measured)
                    .filter(|(_, v)| v.is_finite() && **v >= y0 && **v <= y1)
                    .map(|(&w, &v)| Circle::new((w, v), 2, pale(colour).filled())),
            )?;
            let line = Line {
                colour,
                width: 2,
                dash: Solid,
            };
            let points: Vec<Option<(f64, f64)>> = c
                .wavelengths_nm
                .iter()
                .zip(&c.fitted)
                .map(|(&w, &v)| Some((w, v)))
                .collect();
            draw_line(&mut chart, &points, [wl0, wl1, y0, y1], line, None)?;
            entries.push((format!("fit at {}°", c.angle_deg), line));
            entries.push((
                format!("measured at {}°", c.angle_deg),
                Line {
                    colour: pale(colour),
                    width: 4,
                    dash: super::Dotted,
                },
            ));
        }
        let (w, _) = top.dim_in_pixel();
        draw_side_legend(&top, (w as i32 - 160, 14), &entries)?;
        // Residuals, symmetric about zero.
        let largest = self
            .curves
            .iter()
            .flat_map(|c| c.measured.iter().zip(&c.fitted).map(|(m, f)| (m - f).abs()))
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        let r1 = nice_ceiling((largest * 1.1).max(1e-6));
        let mut chart = panel(&bottom, (wl0, wl1), (-r1, r1), "measured − fitted")?;
        chart.draw_series(LineSeries::new(
            [(wl0, 0.0), (wl1, 0.0)],
            BLACK.mix(0.5).stroke_width(1),
        ))?;
        for (i, c) in self.curves.iter().enumerate() {
            let points: Vec<Option<(f64, f64)>> = c
                .wavelengths_nm
                .iter()
                .zip(c.measured.iter().zip(&c.fitted))
                .map(|(&w, (m, f))| Some((w, m - f)))
                .collect();
            let line = Line {
                colour: palette(i),
                width: 1,
                dash: Solid,
            };
            draw_line(&mut chart, &points, [wl0, wl1, -r1, r1], line, None)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::plot::render;

    fn plot() -> FitPlot {
        let points: Vec<(f64, f64, f64, f64)> = (0..50)
            .flat_map(|i| {
                let wl = 400.0 + 8.0 * i as f64;
                let fit = 0.1 + 0.05 * (wl / 20.0).sin();
                [
                    (0.0, wl, fit + 0.002, fit),
                    (45.0, wl, fit - 0.001, fit + 0.01),
                ]
            })
            .collect();
        FitPlot::new("fit".into(), "reflectance", &points).unwrap()
    }

    #[test]
    fn groups_points_by_angle() {
        let p = plot();
        assert_eq!(p.curves.len(), 2);
        assert_eq!(p.curves[1].angle_deg, 45.0);
        assert_eq!(p.curves[0].wavelengths_nm.len(), 50);
        assert!(FitPlot::new("x".into(), "reflectance", &[]).is_err());
        let many: Vec<_> = (0..=MAX_CURVES)
            .map(|a| (a as f64, 500.0, 0.1, 0.1))
            .collect();
        assert!(FitPlot::new("x".into(), "reflectance", &many).is_err());
    }

    #[test]
    fn renders_png_and_svg() {
        let png = render(&plot(), ImageFormat::Png).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        let svg = String::from_utf8(render(&plot(), ImageFormat::Svg).unwrap()).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("measured − fitted"));
        assert!(svg.contains("fit at 45°"));
    }
}

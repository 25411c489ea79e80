//! The CIE 1931 xy diagram with gamuts and a film's colour trajectory ([`ChromaticityPlot`]).

use super::*;
use nacre_optics::elementary;

/// A film's colour trajectory by one method: the chromaticity at each parameter value.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// The method, as given (`spectral`, `fourier:3`, …).
    pub label: String,
    /// (x, y) per parameter value; None for black.
    pub xy: Vec<Option<[f64; 2]>>,
}

/// Parses `--gamut srgb,p3,rec2020,acescg` (any subset, in any order).
pub fn parse_gamuts(text: &str) -> Result<Vec<RgbSpace>> {
    let mut out = Vec::new();
    for item in text.split(',') {
        let s: RgbSpace = item.trim().parse().map_err(|_| Error::value(Param::Gamut, text, format!(
                "unknown gamut `{}`: expected any of srgb, p3, rec2020, acescg, separated by commas",
                item.trim()
            )))?;
        if !out.contains(&s) {
            out.push(s);
        }
    }
    Ok(out)
}

/// The CIE 1931 (or 1964) xy chromaticity diagram: the spectral locus (x̄, ȳ, z̄ of the
/// bundled colour-matching functions, 360–830 nm, labelled in nm) closed by the purple
/// line, its inside painted approximately in colour (each chromaticity at the largest
/// luminance sRGB holds after clipping negative channels, lightened), the gamut triangles
/// of the chosen RGB spaces, the white point, and a film's colour trajectories by several
/// methods (the `spectral` reference thick and black), with a marker every
/// `marker_step` of the parameter (labelled on the first trajectory).
#[derive(Clone, Debug)]
pub struct ChromaticityPlot {
    /// Title.
    pub title: String,
    /// The observer whose locus is drawn.
    pub observer: Observer,
    /// The white point (x, y) and its label.
    pub white: ([f64; 2], String),
    /// Gamut triangles to draw.
    pub gamuts: Vec<RgbSpace>,
    /// The parameter along the trajectories (thickness, nm, or angle, degrees).
    pub parameter: Vec<f64>,
    /// Its unit, appended to marker labels (` nm`, `°`).
    pub parameter_unit: String,
    /// Markers where the parameter is a multiple of this step.
    pub marker_step: f64,
    /// The trajectories, one per method.
    pub trajectories: Vec<Trajectory>,
    /// Paint the inside of the locus.
    pub fill: bool,
}

impl ChromaticityPlot {
    /// A round marker step for `parameter`: about a tenth of its span.
    pub fn default_marker_step(parameter: &[f64]) -> f64 {
        let (lo, hi) = parameter
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        if hi > lo {
            nice_step((hi - lo) / 10.0)
        } else {
            1.0
        }
    }
}

/// The spectral locus of `observer`, (x, y) every nm from 360 to 830 nm.
pub(super) fn spectral_locus(observer: Observer) -> Vec<(f64, [f64; 2])> {
    observer
        .cmf()
        .xyz_bar()
        .iter()
        .enumerate()
        .filter_map(|(i, xyz)| {
            let s = xyz[0] + xyz[1] + xyz[2];
            (s > 0.0).then(|| {
                (
                    nacre_optics::colour::spectral_wavelength_nm(i),
                    xyz_to_xy(*xyz),
                )
            })
        })
        .collect()
}

/// The x intervals where the horizontal line at `y` is inside `polygon` (even-odd rule).
pub(super) fn scanline(polygon: &[[f64; 2]], y: f64) -> Vec<(f64, f64)> {
    let mut xs: Vec<f64> = Vec::new();
    for k in 0..polygon.len() {
        let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
        if (a[1] <= y) != (b[1] <= y) {
            xs.push(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
        }
    }
    xs.sort_by(f64::total_cmp);
    xs.chunks_exact(2).map(|p| (p[0], p[1])).collect()
}

/// The approximate colour of chromaticity `xy` for the locus fill: linear sRGB of
/// (x/y, 1, (1 − x − y)/y) with negative channels clipped, scaled so that the largest is
/// 1, encoded, and mixed half-way towards white so that lines on top stay visible.
pub(super) fn locus_fill_colour(xy: [f64; 2]) -> RGBColor {
    let m = RgbSpace::Srgb.xyz_to_rgb_matrix();
    let xyz = xy_to_xyz(xy);
    let rgb: [f64; 3] =
        std::array::from_fn(|r| (m[r][0] * xyz[0] + m[r][1] * xyz[1] + m[r][2] * xyz[2]).max(0.0));
    let max = rgb.iter().copied().fold(0.0, f64::max);
    let rgb = if max > 0.0 {
        rgb.map(|v| v / max)
    } else {
        [1.0; 3]
    };
    let [r, g, b] = rgb.map(|v| ((0.5 * srgb_encode(v) + 0.5) * 255.0).round() as u8);
    RGBColor(r, g, b)
}

fn gamut_style(space: RgbSpace) -> (Dash, &'static str) {
    match space {
        RgbSpace::Srgb => (Solid, "sRGB gamut"),
        RgbSpace::DisplayP3 => (Dashed, "Display P3 gamut"),
        RgbSpace::Rec2020 => (Dotted, "Rec. 2020 gamut"),
        RgbSpace::AcesCg => (Dashed, "ACEScg (AP1) gamut"),
    }
}

impl Figure for ChromaticityPlot {
    fn size(&self) -> (u32, u32) {
        (960, 1040)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 16))?;
        let bounds = [0.0, 0.8, 0.0, 0.9];
        let mut chart = ChartBuilder::on(&area)
            .margin(16)
            .margin_right(30)
            .x_label_area_size(46)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..0.8, 0.0..0.9)?;
        chart
            .configure_mesh()
            .x_desc("x")
            .y_desc("y")
            .x_labels(9)
            .y_labels(10)
            .x_label_formatter(&fmt_tick)
            .y_label_formatter(&fmt_tick)
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .bold_line_style(BLACK.mix(0.12))
            .light_line_style(BLACK.mix(0.0))
            .draw()?;
        let locus = spectral_locus(self.observer);
        let polygon: Vec<[f64; 2]> = locus.iter().map(|(_, xy)| *xy).collect();
        if self.fill {
            let step: f64 = if format.fine() { 0.002 } else { 0.01 };
            let mut cells = Vec::new();
            let rows = (0.9 / step).round() as usize;
            for k in 0..rows {
                let y = (k as f64 + 0.5) * step;
                for (xa, xb) in scanline(&polygon, y) {
                    let i0 = (xa / step).ceil() as i64;
                    let i1 = (xb / step).floor() as i64;
                    // Cells whose centre lies inside, each a step wide.
                    for i in i0..i1.max(i0) {
                        let x = (i as f64 + 0.5) * step;
                        if x < xa || x > xb {
                            continue;
                        }
                        cells.push(Rectangle::new(
                            [
                                (x - step / 2.0, y - step / 2.0),
                                (x + step / 2.0, y + step / 2.0),
                            ],
                            locus_fill_colour([x, y]).filled(),
                        ));
                    }
                }
            }
            chart.draw_series(cells)?;
        }
        // The locus and the purple line.
        let mut closed: Vec<Option<(f64, f64)>> =
            polygon.iter().map(|p| Some((p[0], p[1]))).collect();
        closed.push(closed[0]);
        draw_line(
            &mut chart,
            &closed,
            bounds,
            Line {
                colour: RGBColor(40, 40, 40),
                width: 2,
                dash: Solid,
            },
            Some(format!("spectral locus (CIE {})", self.observer)),
        )?;
        let white = self.white.0;
        for wl in [
            380.0, 460.0, 470.0, 480.0, 490.0, 500.0, 510.0, 520.0, 540.0, 560.0, 580.0, 600.0,
            620.0, 700.0,
        ] {
            let Some((_, xy)) = locus.iter().find(|(w, _)| (*w - wl).abs() < 0.5) else {
                continue;
            };
            let (dx, dy) = (xy[0] - white[0], xy[1] - white[1]);
            let norm = elementary::hypot(dx, dy).max(1e-9);
            let at = (xy[0] + 0.032 * dx / norm, xy[1] + 0.032 * dy / norm);
            chart.draw_series([Circle::new((xy[0], xy[1]), 3, BLACK.filled())])?;
            chart.draw_series([Text::new(
                format!("{wl}"),
                at,
                ("sans-serif", 13)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            )])?;
        }
        for &space in &self.gamuts {
            let (dash, label) = gamut_style(space);
            let p = space.primaries_xy();
            let tri: Vec<Option<(f64, f64)>> = [p[0], p[1], p[2], p[0]]
                .iter()
                .map(|q| Some((q[0], q[1])))
                .collect();
            draw_line(
                &mut chart,
                &tri,
                bounds,
                Line {
                    colour: RGBColor(90, 90, 90),
                    width: 2,
                    dash,
                },
                Some(label.into()),
            )?;
        }
        // Trajectories: the reference first (thick, black), the others on top of it.
        let mut colour_index = 0;
        let lines: Vec<Line> = self
            .trajectories
            .iter()
            .map(|t| {
                if t.label == "spectral" {
                    Line {
                        colour: BLACK,
                        width: 4,
                        dash: Solid,
                    }
                } else {
                    colour_index += 1;
                    Line {
                        colour: palette(colour_index - 1),
                        width: 2,
                        dash: Solid,
                    }
                }
            })
            .collect();
        for (t, line) in self.trajectories.iter().zip(&lines) {
            let points: Vec<Option<(f64, f64)>> =
                t.xy.iter().map(|p| p.map(|p| (p[0], p[1]))).collect();
            draw_line(&mut chart, &points, bounds, *line, Some(t.label.clone()))?;
        }
        let inside = |p: [f64; 2]| p[0] >= 0.0 && p[0] <= 0.8 && p[1] >= 0.0 && p[1] <= 0.9;
        // Marker labels (first trajectory only) skip markers too close to a labelled one.
        let mut labelled: Vec<(i32, i32)> = vec![chart.backend_coord(&(white[0], white[1]))];
        for (k, t) in self.trajectories.iter().enumerate() {
            for (v, p) in self.parameter.iter().zip(&t.xy) {
                let Some(p) = p else { continue };
                let r = v / self.marker_step;
                if (r - r.round()).abs() > 1e-6 || !inside(*p) {
                    continue;
                }
                chart.draw_series([Circle::new(
                    (p[0], p[1]),
                    if k == 0 { 4 } else { 3 },
                    lines[k].colour.filled(),
                )])?;
                let px = chart.backend_coord(&(p[0], p[1]));
                let free = labelled
                    .iter()
                    .all(|q| (q.0 - px.0).pow(2) + (q.1 - px.1).pow(2) > 34 * 34);
                if k == 0 && free {
                    labelled.push(px);
                    chart.draw_series([EmptyElement::at((p[0], p[1]))
                        + Text::new(
                            format!("{v}{}", self.parameter_unit),
                            (7, -14),
                            ("sans-serif", 12).into_font().color(&BLACK),
                        )])?;
                }
            }
        }
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), u32>>())?
            .label(format!(
                "markers every {}{}",
                fmt_tick(&self.marker_step),
                self.parameter_unit
            ))
            .legend(|(x, y)| Circle::new((x + 12, y), 4, BLACK.filled()));
        chart.draw_series([Cross::new((white[0], white[1]), 7, BLACK.stroke_width(2))])?;
        chart.draw_series([EmptyElement::at((white[0], white[1]))
            + Text::new(
                self.white.1.clone(),
                (-10, 10),
                ("sans-serif", 13)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Right, VPos::Top)),
            )])?;
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 14)?;
        Ok(())
    }
}

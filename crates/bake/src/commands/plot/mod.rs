//! `nacre plot`: pictures of spectra, chromaticities, colour charts and baked tables, as PNG
//! or SVG ([`ImageFormat`], chosen by the output file's extension).
//!
//! Every picture is a [`Figure`]: plain data plus a `draw` function generic over the
//! plotters backend. [`render`] draws it into memory (an RGB buffer encoded with the `png`
//! crate, or an SVG string) and [`write_figure`] writes the bytes atomically, so a failed
//! run never leaves a partial image and never touches an existing one.
//!
//! | figure | shows |
//! |---|---|
//! | [`SpectrumPlot`] | R, T, A (and the s/p parts) against vacuum wavelength, one colour per angle |
//! | [`ChromaticityPlot`] | the CIE 1931 xy diagram: spectral locus, purple line, gamut triangles, white point, and a film's colour trajectory by several methods |
//! | [`FitPlot`] | a spectrum fit: measured values against the fitted curve, residuals below |
//! | [`ChartPlot`] | a swatch chart: film thickness rows × angle (or film index) columns |
//! | [`DesignPlot`] | a colour design (`nacre fit color --plot`): target swatches over the designed stacks', per angle |
//! | [`FilmLutPlot`] | a `film-lut` table: cos θ × optical path difference images at fixed film indices |
//! | [`FourierPlot`] | a `fourier` table: Re and Im of each channel's stored envelope against μ, one line per mip level |
//!
//! # Colour conventions
//!
//! * **Swatches and table images** show a colour as sRGB: the linear colour of its
//!   colorimeter (a perfect reflector = (1, 1, 1) in RGB, Y = 1 in XYZ) is converted to
//!   linear sRGB under the same observer with a Bradford adaptation from its illuminant to
//!   D65 ([`DisplayConverter`]), multiplied by the exposure, **clipped per channel to
//!   [0, 1]** — an out-of-gamut colour keeps its in-gamut channels, so its hue may shift
//!   slightly and over-exposed colours flatten towards white — and encoded with the sRGB
//!   transfer function (IEC 61966-2-1, [`srgb_encode`]), 8 bits per channel. A film
//!   reflecting a few per cent therefore looks dark, as it does in front of a black
//!   background; raise the exposure to see its hues.
//! * **Chromaticities** are CIE (x, y) = (X, Y)/(X + Y + Z) of the colour's XYZ under its
//!   colorimeter's illuminant ([`chromaticity`]); black (X + Y + Z ≤ 10⁻¹²) has none and
//!   breaks a line. Methods that can leave the spectral locus (`rgb3`, `samples:N`, whose
//!   colours can have negative channels) are drawn where they land, clipped to the
//!   diagram's frame.
//! * **Lines** take the Tableau 10 categorical palette in order; the `spectral` reference
//!   is drawn thick and black. Line style tells polarisation (solid: unpolarised,
//!   dashed: s, dotted: p) or gamut (sRGB solid, Display P3 dashed, Rec. 2020 dotted).

use crate::commands::color::{LoadedLut, Quantity};
use crate::commands::grid::parse_range;
use crate::error::{Error, Param, Result};
use nacre_format::Manifest;
use nacre_format::atomic::write_atomic;
use nacre_format::film_lut::{FilmLut, FilmLutAxes, MIN_COS_THETA};
use nacre_format::fourier::FourierTable;
use nacre_format::set::{default_baked_dir, resolve_table};
use nacre_format::table_io::Table3;
use nacre_optics::Stack;
use nacre_optics::colour::{Colorimeter, Observer, OutputSpace, RgbSpace, xy_to_xyz, xyz_to_xy};
use nacre_optics::elementary;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::drawing::DrawingAreaErrorKind;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Most curves (angles) one spectrum plot draws, so that colours and legend stay readable.
pub const MAX_CURVES: usize = 10;

/// Most points of one chromaticity trajectory.
pub const MAX_TRAJECTORY_POINTS: usize = 100_000;

/// Most rows and columns of a swatch chart.
pub const MAX_CHART_CELLS: (usize, usize) = (400, 40);

/// Most film-index slices of a table plot.
pub const MAX_SLICES: usize = 8;

/// The font every figure uses (registered as `sans-serif`).
static FONT: &[u8] = include_bytes!("../../../../../tables/fonts/DejaVuSans.ttf");

/// What a figure's `draw` returns: plotters' error of the backend in use.
pub type DrawResult<DB> =
    std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

type Chart2d<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

// ---------------------------------------------------------------------------------------
// Formats, rendering, writing
// ---------------------------------------------------------------------------------------

/// The image format, chosen by the output file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.png`: 8-bit RGB, drawn with plotters' bitmap backend and encoded with `png`.
    Png,
    /// `.svg`: vector lines and text (heat maps and swatches as rectangles, coarser than
    /// in PNG to keep files small).
    Svg,
}

impl ImageFormat {
    /// The format of `path` (`.png` or `.svg`, any case); anything else is an error naming
    /// `-o/--output`.
    pub fn from_path(path: &Path) -> Result<Self> {
        Self::from_path_of(Param::Output, path)
    }

    /// [`ImageFormat::from_path`] for the file of input `param`.
    pub fn from_path_of(param: Param, path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("svg") => Ok(ImageFormat::Svg),
            _ => Err(Error::value(
                param,
                path.display().to_string(),
                "the image format follows the extension: expected a file name ending in .png or .svg",
            )),
        }
    }

    /// Cells per unit of detail: heat maps and fills are drawn this much finer in PNG.
    fn fine(self) -> bool {
        self == ImageFormat::Png
    }
}

/// A picture: data plus a drawing function for any plotters backend.
pub trait Figure {
    /// Image size in pixels (width, height).
    fn size(&self) -> (u32, u32);
    /// Draws the figure on `root` (already filled white).
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> DrawResult<DB>;
}

/// Renders `figure` into memory: the bytes of a PNG file or of an SVG document.
pub fn render(figure: &impl Figure, format: ImageFormat) -> Result<Vec<u8>> {
    // Registering twice is harmless; a failure only means no text.
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let (w, h) = figure.size();
    let err = |e: String| Error::invalid("nacre plot", format!("drawing the plot failed: {e}"));
    match format {
        ImageFormat::Png => {
            let mut buf = vec![0u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
                figure.draw(&root, format).map_err(|e| err(e.to_string()))?;
                root.present().map_err(|e| err(e.to_string()))?;
            }
            let mut out = Vec::new();
            {
                use image::ImageEncoder;
                image::codecs::png::PngEncoder::new_with_quality(
                    &mut out,
                    image::codecs::png::CompressionType::Default,
                    image::codecs::png::FilterType::Adaptive,
                )
                .write_image(&buf, w, h, image::ExtendedColorType::Rgb8)
                .map_err(|e| err(e.to_string()))?;
            }
            Ok(out)
        }
        ImageFormat::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
                figure.draw(&root, format).map_err(|e| err(e.to_string()))?;
                root.present().map_err(|e| err(e.to_string()))?;
            }
            Ok(svg.into_bytes())
        }
    }
}

/// Renders `figure` in the format of `path`'s extension and writes it atomically.
pub fn write_figure(path: &Path, figure: &impl Figure) -> Result<()> {
    let format = ImageFormat::from_path(path)?;
    let bytes = render(figure, format)?;
    Ok(write_atomic(path, |w| w.write_all(&bytes))?)
}

// ---------------------------------------------------------------------------------------
// Colour helpers
// ---------------------------------------------------------------------------------------

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, after clipping it to
/// [0, 1]: 12.92 v for v ≤ 0.0031308, else 1.055 v^(1/2.4) − 0.055.
pub fn srgb_encode(linear: f64) -> f64 {
    let v = if linear.is_finite() {
        linear.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * elementary::powf(v, 1.0 / 2.4) - 0.055
    }
}

/// 8-bit sRGB of a linear sRGB colour (clipped per channel, then encoded).
pub fn srgb8(linear: [f64; 3]) -> RGBColor {
    let [r, g, b] = linear.map(|v| (srgb_encode(v) * 255.0).round() as u8);
    RGBColor(r, g, b)
}

/// Converts colours of one colorimeter to linear sRGB (D65) for display: through XYZ,
/// with a Bradford adaptation from the colorimeter's illuminant to D65 and the same
/// observer ([`Colorimeter::new`]); the identity for a 1931/D65/sRGB colorimeter.
#[derive(Clone, Debug)]
pub struct DisplayConverter {
    from: Colorimeter,
    to: Colorimeter,
}

impl DisplayConverter {
    /// A converter from the output space of `from`.
    pub fn new(from: &Colorimeter) -> Self {
        let to = Colorimeter::new(
            from.observer(),
            from.illuminant(),
            OutputSpace::Rgb(RgbSpace::Srgb),
        );
        DisplayConverter {
            from: from.clone(),
            to,
        }
    }

    /// Linear sRGB of a colour in the source colorimeter's output space.
    pub fn linear_srgb(&self, colour: [f64; 3]) -> [f64; 3] {
        if self.from.space() == OutputSpace::Rgb(RgbSpace::Srgb) {
            return colour;
        }
        self.to.output_from_xyz(self.from.xyz_from_output(colour))
    }
}

/// CIE (x, y) of a colour in `colorimeter`'s output space, or None for black
/// (X + Y + Z ≤ 10⁻¹²) and non-finite values.
pub fn chromaticity(colour: [f64; 3], colorimeter: &Colorimeter) -> Option<[f64; 2]> {
    let xyz = colorimeter.xyz_from_output(colour);
    let sum = xyz[0] + xyz[1] + xyz[2];
    if !(sum > 1e-12) {
        return None;
    }
    let xy = xyz_to_xy(xyz);
    xy.iter().all(|v| v.is_finite()).then_some(xy)
}

/// Tableau 10, the categorical palette of lines.
const TABLEAU10: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

fn palette(i: usize) -> RGBColor {
    let (r, g, b) = TABLEAU10[i % TABLEAU10.len()];
    RGBColor(r, g, b)
}

/// A sequential ramp (viridis, without its lightest yellow), t ∈ [0, 1].
fn ramp(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 5] = [
        (68, 1, 84),
        (59, 82, 139),
        (33, 145, 140),
        (94, 201, 98),
        (200, 210, 30),
    ];
    let t = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * f).round() as u8;
    RGBColor(
        mix(STOPS[i].0, STOPS[i + 1].0),
        mix(STOPS[i].1, STOPS[i + 1].1),
        mix(STOPS[i].2, STOPS[i + 1].2),
    )
}

// ---------------------------------------------------------------------------------------
// Flag parsing shared by the subcommands
// ---------------------------------------------------------------------------------------

/// Parses a comma-separated list whose items are values or `START:END:STEP` ranges
/// (`0,30,60`, `0:60:30`, `0:20:10,45`), in the order given. Errors name `flag`.
pub fn parse_list(flag: Param, text: &str) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    for part in text.split(',') {
        if part.trim().is_empty() {
            return Err(Error::value(
                flag,
                text,
                "empty item: expected values or START:END:STEP ranges separated by commas, e.g. 0,30,60",
            ));
        }
        out.extend(parse_range(flag, part).map_err(|e| match e {
            Error::Value { message, .. } => Error::value(flag, text, message),
            other => other,
        })?);
    }
    Ok(out)
}

/// Checks that every angle lies strictly between −90° and 90°.
pub fn check_angles(flag: Param, text: &str, angles_deg: &[f64]) -> Result<()> {
    match angles_deg.iter().find(|a| !(a.abs() < 90.0)) {
        Some(a) => Err(Error::Angle {
            origin: flag.into(),
            value: text.into(),
            angle: *a,
        }),
        None => Ok(()),
    }
}

/// The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10ᵏ that is ≥ `v` (`v` > 0).
fn nice_ceiling(v: f64) -> f64 {
    let e = elementary::powf(10.0, elementary::log10(v).floor());
    [1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0]
        .iter()
        .map(|m| m * e)
        .find(|c| *c >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * e)
}

/// An axis label: the value rounded to 10⁻⁹ of its magnitude, without trailing zeros
/// (`400`, `0.25`, `1.5`).
fn fmt_tick(v: &f64) -> String {
    let r = if *v == 0.0 {
        0.0
    } else {
        let e = elementary::powf(10.0, elementary::log10(v.abs()).floor() - 9.0);
        (v / e).round() * e
    };
    let s = format!("{r}");
    if s.len() > 10 {
        format!("{r:.6}").trim_end_matches('0').to_string()
    } else {
        s
    }
}

/// A round step of about `v`: 1, 2, 5 × 10ᵏ.
fn nice_step(v: f64) -> f64 {
    let e = elementary::powf(10.0, elementary::log10(v).floor());
    let m = v / e;
    e * if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    }
}

// ---------------------------------------------------------------------------------------
// Lines: clipping, styles, legends
// ---------------------------------------------------------------------------------------

/// Clips segment a–b to the box [x0, x1] × [y0, y1] (Liang–Barsky).
fn clip_segment(
    a: (f64, f64),
    b: (f64, f64),
    [x0, x1, y0, y1]: [f64; 4],
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                if r > t1 {
                    return None;
                }
                t0 = t0.max(r);
            } else {
                if r < t0 {
                    return None;
                }
                t1 = t1.min(r);
            }
        }
    }
    Some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// Splits a polyline (None: a gap) into the runs that lie inside `bounds`, clipping the
/// segments that cross it: plotters does not clip to the plotting area itself.
fn clip_polyline(points: &[Option<(f64, f64)>], bounds: [f64; 4]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut run: Vec<(f64, f64)> = Vec::new();
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    for w in points.windows(2) {
        let clipped = match (w[0], w[1]) {
            (Some(a), Some(b)) if finite(&a) && finite(&b) => clip_segment(a, b, bounds),
            _ => None,
        };
        match clipped {
            Some((p, q)) => {
                if run.last() != Some(&p) && !run.is_empty() {
                    runs.push(std::mem::take(&mut run));
                }
                if run.is_empty() {
                    run.push(p);
                }
                run.push(q);
            }
            None => {
                if run.len() > 1 {
                    runs.push(std::mem::take(&mut run));
                }
                run.clear();
            }
        }
    }
    if run.len() > 1 {
        runs.push(run);
    }
    runs
}

/// How a line is stroked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dash {
    Solid,
    Dashed,
    Dotted,
}

#[derive(Clone, Copy, Debug)]
struct Line {
    colour: RGBColor,
    width: u32,
    dash: Dash,
}

impl Line {
    fn style(&self) -> ShapeStyle {
        self.colour.stroke_width(self.width)
    }

    fn dash_sizes(&self) -> (u32, u32) {
        match self.dash {
            Dashed => (9, 5),
            _ => (self.width.max(2), 3 + self.width),
        }
    }
}

use Dash::{Dashed, Dotted, Solid};

/// Draws `points` (None: a gap) as a line clipped to `bounds`, with a legend entry when
/// `label` is given.
fn draw_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart2d<'a, DB>,
    points: &[Option<(f64, f64)>],
    bounds: [f64; 4],
    line: Line,
    label: Option<String>,
) -> DrawResult<DB> {
    for run in clip_polyline(points, bounds) {
        match line.dash {
            Solid => {
                chart.draw_series(LineSeries::new(run, line.style()))?;
            }
            Dashed | Dotted => {
                let (size, gap) = line.dash_sizes();
                chart.draw_series(DashedLineSeries::new(run, size, gap, line.style()))?;
            }
        }
    }
    if let Some(label) = label {
        chart
            .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
            .label(label)
            .legend(move |(x, y)| {
                let points = vec![(x, y), (x + 24, y)];
                match line.dash {
                    Solid => PathElement::new(points, line.style()).into_dyn(),
                    Dashed | Dotted => {
                        let (size, gap) = line.dash_sizes();
                        DashedPathElement::new(points, size, gap, line.style()).into_dyn()
                    }
                }
            });
    }
    Ok(())
}

/// Draws the legend of `chart` at `position`.
fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart2d<'a, DB>,
    position: SeriesLabelPosition,
    font_px: u32,
) -> DrawResult<DB> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", font_px))
        .legend_area_size(30)
        .draw()
}

/// Draws a legend box with `entries` at pixel `at` (top left) of `area`, outside any chart.
fn draw_side_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    entries: &[(String, Line)],
) -> DrawResult<DB> {
    const ROW: i32 = 19;
    let (x, y) = at;
    area.draw(&Rectangle::new(
        [(x, y), (x + 150, y + 8 + ROW * entries.len() as i32)],
        BLACK.mix(0.4).stroke_width(1),
    ))?;
    for (k, (label, line)) in entries.iter().enumerate() {
        let cy = y + 4 + ROW * k as i32 + ROW / 2;
        let points = vec![(x + 8, cy), (x + 36, cy)];
        match line.dash {
            Solid => area.draw(&PathElement::new(points, line.style()))?,
            Dashed | Dotted => {
                let (size, gap) = line.dash_sizes();
                area.draw(&DashedPathElement::new(points, size, gap, line.style()))?
            }
        }
        area.draw(&Text::new(
            label.clone(),
            (x + 44, cy),
            ("sans-serif", 14)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    Ok(())
}

mod chart;
mod chromaticity;
mod design;
mod fit;
mod spectrum;
mod table;

pub use chart::*;
pub use chromaticity::*;
pub use design::*;
pub use fit::*;
pub use spectrum::*;
pub use table::*;

#[cfg(test)]
mod tests {
    use super::chromaticity::{locus_fill_colour, scanline, spectral_locus};
    use super::*;

    #[test]
    fn formats_follow_the_extension() {
        assert_eq!(
            ImageFormat::from_path(Path::new("a/b.PNG")).unwrap(),
            ImageFormat::Png
        );
        assert_eq!(
            ImageFormat::from_path(Path::new("b.svg")).unwrap(),
            ImageFormat::Svg
        );
        for bad in ["a.jpg", "a", "-", "png"] {
            let e = ImageFormat::from_path(Path::new(bad)).unwrap_err();
            assert!(e.to_string().starts_with("output `"), "{e}");
        }
    }

    #[test]
    fn srgb_transfer_function() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-12);
        assert!((srgb_encode(0.18) - 0.4613561295).abs() < 1e-9);
        assert_eq!(srgb_encode(-0.5), 0.0);
        assert_eq!(srgb_encode(7.0), srgb_encode(1.0));
        // Continuous at the junction.
        let (a, b) = (
            srgb_encode(0.003_130_8 - 1e-12),
            srgb_encode(0.003_130_8 + 1e-12),
        );
        assert!((a - b).abs() < 1e-7);
    }

    #[test]
    fn lists_and_ranges() {
        assert_eq!(
            parse_list(Param::Angles, "0,30,60").unwrap(),
            vec![0.0, 30.0, 60.0]
        );
        assert_eq!(
            parse_list(Param::Angles, "0:20:10, 45").unwrap(),
            vec![0.0, 10.0, 20.0, 45.0]
        );
        for bad in ["", "0,,3", "a", "0:10"] {
            let e = parse_list(Param::Angles, bad).unwrap_err().to_string();
            assert!(e.starts_with(&format!("angles `{bad}`")), "{e}");
        }
        assert_eq!(nice_ceiling(0.17), 0.2);
        assert_eq!(nice_ceiling(1.0), 1.0);
        assert_eq!(nice_ceiling(0.21), 0.25);
        assert_eq!(nice_step(100.0), 100.0);
        assert_eq!(nice_step(8.9), 10.0);
    }

    #[test]
    fn polylines_are_clipped_into_runs() {
        let b = [0.0, 1.0, 0.0, 1.0];
        let p = |x: f64, y: f64| Some((x, y));
        // Inside, out through the top, back in, a gap.
        let runs = clip_polyline(
            &[
                p(0.1, 0.5),
                p(0.5, 0.5),
                p(0.5, 1.5),
                p(0.7, 0.5),
                None,
                p(0.8, 0.8),
                p(0.9, 0.9),
            ],
            b,
        );
        assert_eq!(runs.len(), 3);
        assert_eq!(runs[0], vec![(0.1, 0.5), (0.5, 0.5), (0.5, 1.0)]);
        assert!((runs[1][0].1 - 1.0).abs() < 1e-12 && runs[1][1] == (0.7, 0.5));
        assert_eq!(runs[2], vec![(0.8, 0.8), (0.9, 0.9)]);
        assert!(clip_polyline(&[p(2.0, 2.0), p(3.0, 3.0)], b).is_empty());
    }

    #[test]
    fn spectrum_csv_errors_name_the_line() {
        let path = Path::new("s.csv");
        let good = format!(
            "{}\n0,400,0.1,0.1,0.1,0.9,0.9,0.9,0\n",
            crate::commands::spectrum::HEADER
        );
        let curves = read_spectrum_csv(path, &good).unwrap();
        assert_eq!(curves.len(), 1);
        assert_eq!(curves[0].values[0][SpectrumQuantity::T.column()], 0.9);
        for (text, line) in [
            ("angle,wavelength\n".to_string(), 1),
            (format!("{good}0,410,0.1,x,0.1,0.9,0.9,0.9,0\n"), 3),
            (format!("\n{good}0,410,0.1\n"), 4),
            (format!("{good}95,410,0.1,0.1,0.1,0.9,0.9,0.9,0\n"), 3),
            (String::new(), 1),
            (format!("{}\n", crate::commands::spectrum::HEADER), 1),
        ] {
            let e = read_spectrum_csv(path, &text).unwrap_err().to_string();
            assert!(e.starts_with(&format!("s.csv:{line}: ")), "{e}");
        }
    }

    #[test]
    fn spectrum_csv_accepts_csv_conventions() {
        let path = Path::new("s.csv");
        let header = crate::commands::spectrum::HEADER.replace(',', " , ");
        let text = format!(
            "\u{feff}# spectrum\r\n{header}\r\n\r\n\"0\", 410 ,0.1,0.1,0.1,0.9,0.9,0.9,0\r\n# c\r\n0,400,0.2,0.2,0.2,0.8,0.8,0.8,0\r\n"
        );
        let curves = read_spectrum_csv(path, &text).unwrap();
        assert_eq!(curves.len(), 1);
        assert_eq!(curves[0].wavelengths_nm, vec![400.0, 410.0]);
        let bad = format!("# c\r\n\r\n{header}\r\n# x\r\n0,410,0.1,y,0.1,0.9,0.9,0.9,0\r\n");
        let e = read_spectrum_csv(path, &bad).unwrap_err().to_string();
        assert!(e.starts_with("s.csv:5: "), "{e}");
    }

    #[test]
    fn the_locus_fill_is_inside_the_locus() {
        let locus: Vec<[f64; 2]> = spectral_locus(Observer::Cie1931_2Deg)
            .iter()
            .map(|(_, xy)| *xy)
            .collect();
        let inside = |x: f64, y: f64| scanline(&locus, y).iter().any(|(a, b)| x >= *a && x <= *b);
        assert!(inside(0.3127, 0.3290));
        assert!(inside(0.05, 0.8) && inside(0.7, 0.29) && inside(0.2, 0.05));
        assert!(!inside(0.1, 0.1) && !inside(0.7, 0.7) && !inside(0.3, 0.8) && !inside(0.5, 0.1));
        // D65 is close to neutral in the fill.
        let RGBColor(r, g, b) = locus_fill_colour([0.3127, 0.3290]);
        assert!(r.abs_diff(g) < 4 && g.abs_diff(b) < 4, "{r} {g} {b}");
    }
}

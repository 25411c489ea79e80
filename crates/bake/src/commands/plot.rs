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
//! | [`ChartPlot`] | a swatch chart: film thickness rows × angle (or film index) columns |
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
use crate::error::{Error, Result};
use nacre_format::Manifest;
use nacre_format::atomic::write_atomic;
use nacre_format::film_lut::{FilmLut, FilmLutAxes, MIN_COS_THETA};
use nacre_format::fourier::FourierTable;
use nacre_format::set::{default_baked_dir, resolve_table};
use nacre_format::table_io::Table3;
use nacre_optics::Stack;
use nacre_optics::colour::{Colorimeter, Observer, OutputSpace, RgbSpace, xy_to_xyz, xyz_to_xy};
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
static FONT: &[u8] = include_bytes!("../../../../tables/fonts/DejaVuSans.ttf");

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
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("svg") => Ok(ImageFormat::Svg),
            _ => Err(Error::Flag {
                flag: "-o/--output".into(),
                value: path.display().to_string(),
                message: "the image format follows the extension: expected a file name ending in .png or .svg".into(),
            }),
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
    let err = |e: String| Error::Invalid {
        context: "nacre plot".into(),
        message: format!("drawing the plot failed: {e}"),
    };
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
        1.055 * v.powf(1.0 / 2.4) - 0.055
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
pub fn parse_list(flag: &str, text: &str) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    for part in text.split(',') {
        if part.trim().is_empty() {
            return Err(Error::Flag {
                flag: flag.into(),
                value: text.into(),
                message: "empty item: expected values or START:END:STEP ranges separated by commas, e.g. 0,30,60".into(),
            });
        }
        out.extend(parse_range(flag, part).map_err(|e| match e {
            Error::Flag { message, .. } => Error::Flag {
                flag: flag.into(),
                value: text.into(),
                message,
            },
            other => other,
        })?);
    }
    Ok(out)
}

/// Checks that every angle lies strictly between −90° and 90°.
pub fn check_angles(flag: &str, text: &str, angles_deg: &[f64]) -> Result<()> {
    match angles_deg.iter().find(|a| !(a.abs() < 90.0)) {
        Some(a) => Err(Error::Flag {
            flag: flag.into(),
            value: text.into(),
            message: format!("angle {a} must lie strictly between -90 and 90 degrees"),
        }),
        None => Ok(()),
    }
}

/// The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10ᵏ that is ≥ `v` (`v` > 0).
fn nice_ceiling(v: f64) -> f64 {
    let e = 10f64.powf(v.log10().floor());
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
        let e = 10f64.powf(v.abs().log10().floor() - 9.0);
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
    let e = 10f64.powf(v.log10().floor());
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

// ---------------------------------------------------------------------------------------
// Spectrum
// ---------------------------------------------------------------------------------------

/// One column of a `nacre spectrum` table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumQuantity {
    /// Reflectance, s polarisation (dashed).
    Rs,
    /// Reflectance, p polarisation (dotted).
    Rp,
    /// Unpolarised reflectance (solid).
    R,
    /// Transmittance into the substrate, s polarisation (dashed).
    Ts,
    /// Transmittance, p polarisation (dotted).
    Tp,
    /// Unpolarised transmittance (solid).
    T,
    /// Absorptance A = 1 − R − T (solid).
    A,
}

impl SpectrumQuantity {
    /// In the column order of [`crate::commands::spectrum::HEADER`] (after the angle and wavelength).
    pub const ALL: [SpectrumQuantity; 7] = [
        SpectrumQuantity::Rs,
        SpectrumQuantity::Rp,
        SpectrumQuantity::R,
        SpectrumQuantity::Ts,
        SpectrumQuantity::Tp,
        SpectrumQuantity::T,
        SpectrumQuantity::A,
    ];

    /// The column name: `R_s`, `R_p`, `R`, `T_s`, `T_p`, `T`, `A`.
    pub fn name(self) -> &'static str {
        ["R_s", "R_p", "R", "T_s", "T_p", "T", "A"][self.column()]
    }

    /// Index into [`SpectrumCurve::values`].
    pub fn column(self) -> usize {
        Self::ALL
            .iter()
            .position(|q| *q == self)
            .expect("listed in ALL")
    }

    /// 0: reflectance, 1: transmittance, 2: absorptance (one panel each).
    fn family(self) -> usize {
        match self {
            SpectrumQuantity::Rs | SpectrumQuantity::Rp | SpectrumQuantity::R => 0,
            SpectrumQuantity::Ts | SpectrumQuantity::Tp | SpectrumQuantity::T => 1,
            SpectrumQuantity::A => 2,
        }
    }

    fn dash(self) -> Dash {
        match self {
            SpectrumQuantity::Rs | SpectrumQuantity::Ts => Dashed,
            SpectrumQuantity::Rp | SpectrumQuantity::Tp => Dotted,
            _ => Solid,
        }
    }

    /// Parses `R,T,R_s,…` (any case, underscore optional: `rs` = `R_s`), without repeats.
    pub fn parse_list(text: &str) -> Result<Vec<Self>> {
        let mut out = Vec::new();
        for item in text.split(',') {
            let key = item.trim().to_ascii_lowercase().replace('_', "");
            let q = Self::ALL
                .iter()
                .find(|q| q.name().to_ascii_lowercase().replace('_', "") == key)
                .ok_or_else(|| Error::Flag {
                    flag: "--quantities".into(),
                    value: text.into(),
                    message: format!(
                        "unknown quantity `{}`: expected any of R, T, A, R_s, R_p, T_s, T_p, separated by commas",
                        item.trim()
                    ),
                })?;
            if !out.contains(q) {
                out.push(*q);
            }
        }
        Ok(out)
    }
}

/// The spectra of one angle.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumCurve {
    /// Incidence angle in the ambient, degrees.
    pub angle_deg: f64,
    /// Vacuum wavelengths, nm, increasing.
    pub wavelengths_nm: Vec<f64>,
    /// Per wavelength: R_s, R_p, R, T_s, T_p, T, A (the order of [`SpectrumQuantity::ALL`]).
    pub values: Vec<[f64; 7]>,
}

/// Computes the curves of `stack` at `angles_deg` over `wavelengths_nm` (exact, as
/// `nacre spectrum`).
pub fn spectrum_curves(
    stack: &Stack,
    angles_deg: &[f64],
    wavelengths_nm: &[f64],
) -> Result<Vec<SpectrumCurve>> {
    let powers = crate::commands::spectrum::compute(stack, angles_deg, wavelengths_nm)?;
    Ok(angles_deg
        .iter()
        .zip(powers.chunks(wavelengths_nm.len().max(1)))
        .map(|(&angle_deg, p)| SpectrumCurve {
            angle_deg,
            wavelengths_nm: wavelengths_nm.to_vec(),
            values: p
                .iter()
                .map(|p| [p.R_s, p.R_p, p.R(), p.T_s, p.T_p, p.T(), p.A()])
                .collect(),
        })
        .collect())
}

/// Reads a `nacre spectrum` CSV (header [`crate::commands::spectrum::HEADER`], then 9 numbers a
/// row; blank lines and `#` comments skipped) into one curve per angle, in the order the
/// angles first appear, each sorted by wavelength. Errors name `path` and the line.
pub fn read_spectrum_csv(path: &Path, text: &str) -> Result<Vec<SpectrumCurve>> {
    let perr = |line: usize, message: String| Error::Recipe {
        path: path.to_path_buf(),
        line,
        message,
    };
    let names: Vec<&str> = crate::commands::spectrum::HEADER.split(',').collect();
    let mut header = false;
    let mut curves: Vec<SpectrumCurve> = Vec::new();
    for row in crate::csv_text::rows(path, text) {
        let row = row?;
        let line = row.line;
        let fields = &row.fields;
        if !header {
            if fields != &names {
                return Err(perr(
                    line,
                    format!(
                        "expected the `nacre spectrum` header `{}`, found `{}`",
                        crate::commands::spectrum::HEADER,
                        crate::csv_text::line_text(text, line)
                    ),
                ));
            }
            header = true;
            continue;
        }
        if fields.len() != names.len() {
            return Err(perr(
                line,
                format!(
                    "expected {} comma-separated numbers, found {} field(s)",
                    names.len(),
                    fields.len()
                ),
            ));
        }
        let mut v = [0.0; 9];
        for (k, (f, name)) in fields.iter().zip(&names).enumerate() {
            v[k] = f
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| perr(line, format!("{name} `{f}` is not a finite number")))?;
        }
        if !(v[0].abs() < 90.0) {
            return Err(perr(
                line,
                format!("angle_deg {} must lie strictly between -90 and 90", v[0]),
            ));
        }
        if !(v[1] > 0.0) {
            return Err(perr(
                line,
                format!("wavelength_nm {} must be positive", v[1]),
            ));
        }
        let k = match curves.iter().rposition(|c| c.angle_deg == v[0]) {
            Some(k) => k,
            None => {
                curves.push(SpectrumCurve {
                    angle_deg: v[0],
                    wavelengths_nm: Vec::new(),
                    values: Vec::new(),
                });
                curves.len() - 1
            }
        };
        curves[k].wavelengths_nm.push(v[1]);
        curves[k].values.push(std::array::from_fn(|j| v[2 + j]));
    }
    if !header {
        return Err(perr(
            1,
            format!(
                "empty: expected the `nacre spectrum` header `{}`",
                crate::commands::spectrum::HEADER
            ),
        ));
    }
    if curves.is_empty() {
        return Err(perr(
            text.lines().count(),
            "no data rows after the header".into(),
        ));
    }
    for c in &mut curves {
        let mut order: Vec<usize> = (0..c.wavelengths_nm.len()).collect();
        order.sort_by(|&a, &b| c.wavelengths_nm[a].total_cmp(&c.wavelengths_nm[b]));
        c.wavelengths_nm = order.iter().map(|&k| c.wavelengths_nm[k]).collect();
        c.values = order.iter().map(|&k| c.values[k]).collect();
    }
    Ok(curves)
}

/// The curves of a CSV to draw: those at `angles_deg` (each must be in the file, within
/// 10⁻⁹°), or by default every curve — or, when there are more than [`MAX_CURVES`], six
/// evenly spread ones, the first and last included. `path` names the file in messages.
pub fn select_curves(
    curves: Vec<SpectrumCurve>,
    angles_deg: Option<(&str, &[f64])>,
    path: &Path,
) -> Result<Vec<SpectrumCurve>> {
    match angles_deg {
        Some((text, wanted)) => wanted
            .iter()
            .map(|&a| {
                curves
                    .iter()
                    .find(|c| (c.angle_deg - a).abs() < 1e-9)
                    .cloned()
                    .ok_or_else(|| Error::Flag {
                        flag: "--angles".into(),
                        value: text.into(),
                        message: format!(
                            "angle {a} is not in {} (it has {} angle(s): {})",
                            path.display(),
                            curves.len(),
                            summarise(&curves.iter().map(|c| c.angle_deg).collect::<Vec<_>>())
                        ),
                    })
            })
            .collect(),
        None if curves.len() <= MAX_CURVES => Ok(curves),
        None => {
            let n = curves.len();
            Ok((0..6)
                .map(|k| curves[(k * (n - 1) + 2) / 5].clone())
                .collect())
        }
    }
}

/// "0, 1, 2, …, 89" for long lists.
fn summarise(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    if s.len() <= 8 {
        s.join(", ")
    } else {
        format!("{}, …, {}", s[..3].join(", "), s[s.len() - 1])
    }
}

/// Reflectance/transmittance spectra against vacuum wavelength: one panel per family
/// present in `quantities` (reflectance, transmittance, absorptance; y from 0 to a round
/// value above the largest), one colour per angle (Tableau 10), solid for unpolarised,
/// dashed for s and dotted for p polarisation.
#[derive(Clone, Debug)]
pub struct SpectrumPlot {
    /// Title (the stack or the CSV file).
    pub title: String,
    /// The curves, one per angle (at most [`MAX_CURVES`]).
    pub curves: Vec<SpectrumCurve>,
    /// What to draw of each curve.
    pub quantities: Vec<SpectrumQuantity>,
}

impl SpectrumPlot {
    /// Checks the number of curves and that there is something to draw.
    pub fn new(
        title: String,
        curves: Vec<SpectrumCurve>,
        quantities: Vec<SpectrumQuantity>,
    ) -> Result<Self> {
        if curves.len() > MAX_CURVES {
            return Err(Error::Flag {
                flag: "--angles".into(),
                value: summarise(&curves.iter().map(|c| c.angle_deg).collect::<Vec<_>>()),
                message: format!(
                    "{} angles: a spectrum plot shows at most {MAX_CURVES}",
                    curves.len()
                ),
            });
        }
        if curves.is_empty() || quantities.is_empty() {
            return Err(Error::Invalid {
                context: "nacre plot spectrum".into(),
                message: "nothing to draw".into(),
            });
        }
        Ok(SpectrumPlot {
            title,
            curves,
            quantities,
        })
    }

    fn families(&self) -> Vec<usize> {
        (0..3)
            .filter(|f| self.quantities.iter().any(|q| q.family() == *f))
            .collect()
    }
}

impl Figure for SpectrumPlot {
    fn size(&self) -> (u32, u32) {
        (1200, 80 + 400 * self.families().len() as u32)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        const NAMES: [&str; 3] = ["reflectance", "transmittance", "absorptance"];
        let area = root.titled(&self.title, ("sans-serif", 20))?;
        let families = self.families();
        let panels = area.split_evenly((families.len(), 1));
        let all_wl = self.curves.iter().flat_map(|c| c.wavelengths_nm.iter());
        let (mut wl0, mut wl1) = all_wl.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
        if !(wl1 > wl0) {
            (wl0, wl1) = (wl0 - 1.0, wl1 + 1.0);
        }
        for (panel, &family) in panels.iter().zip(&families) {
            let quantities: Vec<SpectrumQuantity> = self
                .quantities
                .iter()
                .copied()
                .filter(|q| q.family() == family)
                .collect();
            let max = self
                .curves
                .iter()
                .flat_map(|c| {
                    c.values
                        .iter()
                        .flat_map(|v| quantities.iter().map(move |q| v[q.column()]))
                })
                .filter(|v| v.is_finite())
                .fold(0.0f64, f64::max);
            // Powers stay within [0, 1] without gain: keep that frame when the data does.
            let mut y1 = nice_ceiling((max * 1.02).max(1e-3));
            if max <= 1.0 + 1e-9 {
                y1 = y1.min(1.0);
            }
            let mut chart = ChartBuilder::on(panel)
                .margin(12)
                .margin_right(170)
                .x_label_area_size(46)
                .y_label_area_size(70)
                .build_cartesian_2d(wl0..wl1, 0.0..y1)?;
            chart
                .configure_mesh()
                .x_desc("vacuum wavelength λ (nm)")
                .y_desc(NAMES[family])
                .x_label_formatter(&fmt_tick)
                .y_label_formatter(&fmt_tick)
                .label_style(("sans-serif", 14))
                .axis_desc_style(("sans-serif", 16))
                .bold_line_style(BLACK.mix(0.15))
                .light_line_style(BLACK.mix(0.04))
                .draw()?;
            let mut entries = Vec::new();
            for (i, c) in self.curves.iter().enumerate() {
                for q in &quantities {
                    let points: Vec<Option<(f64, f64)>> = c
                        .wavelengths_nm
                        .iter()
                        .zip(&c.values)
                        .map(|(&w, v)| Some((w, v[q.column()])))
                        .collect();
                    let line = Line {
                        colour: palette(i),
                        width: 2,
                        dash: q.dash(),
                    };
                    entries.push((format!("{} at {}°", q.name(), c.angle_deg), line));
                    draw_line(&mut chart, &points, [wl0, wl1, 0.0, y1], line, None)?;
                }
            }
            // The legend goes in the right margin, never over the curves.
            let (w, _) = panel.dim_in_pixel();
            draw_side_legend(panel, (w as i32 - 160, 14), &entries)?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------
// Chromaticity diagram
// ---------------------------------------------------------------------------------------

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
        let s: RgbSpace = item.trim().parse().map_err(|_| Error::Flag {
            flag: "--gamut".into(),
            value: text.into(),
            message: format!(
                "unknown gamut `{}`: expected any of srgb, p3, rec2020, acescg, separated by commas",
                item.trim()
            ),
        })?;
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
fn spectral_locus(observer: Observer) -> Vec<(f64, [f64; 2])> {
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
fn scanline(polygon: &[[f64; 2]], y: f64) -> Vec<(f64, f64)> {
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
fn locus_fill_colour(xy: [f64; 2]) -> RGBColor {
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
            let norm = dx.hypot(dy).max(1e-9);
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

// ---------------------------------------------------------------------------------------
// Swatch chart
// ---------------------------------------------------------------------------------------

/// What the columns of a swatch chart vary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChartColumns {
    /// Incidence angle in the ambient, degrees.
    Angle,
    /// The film's real index.
    FilmIor,
}

/// A swatch chart of film colours: one row per film thickness (increasing downwards),
/// one column per angle or film index, each swatch filled with the colour as sRGB (see
/// the module's colour conventions: clipped per channel, sRGB-encoded, × exposure).
#[derive(Clone, Debug)]
pub struct ChartPlot {
    /// Title.
    pub title: String,
    /// Row values: film thickness, nm, evenly spaced.
    pub thicknesses_nm: Vec<f64>,
    /// Column values.
    pub columns: Vec<f64>,
    /// What the columns are.
    pub column_kind: ChartColumns,
    /// Linear sRGB (D65, a perfect reflector = 1) per swatch, row-major.
    pub colours: Vec<[f64; 3]>,
    /// Factor applied to the linear colour before clipping.
    pub exposure: f64,
}

impl ChartPlot {
    fn cell_px(&self) -> (u32, u32) {
        let cols = self.columns.len().max(1) as u32;
        let rows = self.thicknesses_nm.len().max(1) as u32;
        ((900 / cols).clamp(48, 150), (900 / rows).clamp(4, 26))
    }
}

impl Figure for ChartPlot {
    fn size(&self) -> (u32, u32) {
        let (cw, rh) = self.cell_px();
        (
            (120 + cw * self.columns.len() as u32).max(640),
            150 + rh * self.thicknesses_nm.len() as u32,
        )
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 17))?;
        let (cw, _) = self.cell_px();
        let cols = self.columns.len();
        let d = &self.thicknesses_nm;
        let step = if d.len() > 1 { d[1] - d[0] } else { 1.0 };
        let (top, bottom) = (-(d[0] - step / 2.0), -(d[d.len() - 1] + step / 2.0));
        let width = (cw * cols as u32) as i32;
        let (w, _) = area.dim_in_pixel();
        let side = ((w as i32 - width - 90) / 2).max(10);
        let mut chart = ChartBuilder::on(&area)
            .margin_top(64)
            .margin_bottom(16)
            .margin_left(side)
            .margin_right(side)
            .y_label_area_size(72)
            .build_cartesian_2d(0.0..cols as f64, bottom..top)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .x_labels(0)
            .y_labels(16)
            .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
            .y_desc("film thickness d (nm)")
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()?;
        let mut cells = Vec::with_capacity(self.colours.len());
        for (r, &t) in d.iter().enumerate() {
            for c in 0..cols {
                let colour = self.colours[r * cols + c].map(|v| v * self.exposure);
                cells.push(Rectangle::new(
                    [
                        (c as f64 + 0.03, -(t - step / 2.0)),
                        (c as f64 + 0.97, -(t + step / 2.0)),
                    ],
                    srgb8(colour).filled(),
                ));
            }
        }
        chart.draw_series(cells)?;
        let header = ("sans-serif", 15)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Bottom));
        for (c, v) in self.columns.iter().enumerate() {
            let (x, y) = chart.backend_coord(&(c as f64 + 0.5, top));
            let text = match self.column_kind {
                ChartColumns::Angle => format!("{v}°"),
                ChartColumns::FilmIor => format!("n = {v}"),
            };
            root.draw(&Text::new(text, (x, y - 6), header.clone()))?;
        }
        let (x0, y0) = chart.backend_coord(&(0.0, top));
        let (x1, _) = chart.backend_coord(&(cols as f64, top));
        let caption = match self.column_kind {
            ChartColumns::Angle => "angle of incidence θ (in the ambient)",
            ChartColumns::FilmIor => "film index n",
        };
        root.draw(&Text::new(
            caption,
            ((x0 + x1) / 2, y0 - 30),
            ("sans-serif", 16)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Bottom)),
        ))?;
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------
// Tables
// ---------------------------------------------------------------------------------------

/// Slices of a `film-lut` table at fixed film indices: for each, an image over cos θ (x,
/// 0 = grazing to 1 = normal incidence) × optical path difference Δ (y, 0 to Δ_max) of
/// the colour the table gives — looked up exactly as a GPU samples it
/// ([`FilmLut::lookup`], at thickness Δ / (2 q(n, θ))) — as sRGB (module colour
/// conventions). A dashed line marks Δ = 2 d_max q(n, θ), the largest path difference of
/// the thickness range at that index; the table holds the whole Δ range for every index.
#[derive(Clone, Debug)]
pub struct FilmLutPlot {
    /// Title.
    pub title: String,
    /// The table's axes.
    pub axes: FilmLutAxes,
    /// The quantity's table (reflectance or transmittance).
    pub table: Table3,
    /// Film indices of the slices.
    pub film_iors: Vec<f64>,
    /// Table colours to linear sRGB.
    pub display: DisplayConverter,
    /// Factor applied to the linear colour before clipping.
    pub exposure: f64,
}

impl Figure for FilmLutPlot {
    fn size(&self) -> (u32, u32) {
        ((110 + 300 * self.film_iors.len() as u32).max(640), 960)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 16))?;
        let panels = area.split_evenly((1, self.film_iors.len()));
        let a = &self.axes;
        let opd_max = a.opd_max_nm();
        let (nx, ny) = if format.fine() {
            (120, (2 * a.opd_count).min(800))
        } else {
            (32, a.opd_count.min(150))
        };
        for (k, (panel, &n)) in panels.iter().zip(&self.film_iors).enumerate() {
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!("film index n = {}", fmt_tick(&n)),
                    ("sans-serif", 16),
                )
                .margin(8)
                .x_label_area_size(44)
                .y_label_area_size(if k == 0 { 70 } else { 50 })
                .build_cartesian_2d(0.0..1.0, 0.0..opd_max)?;
            let mut mesh = chart.configure_mesh();
            mesh.disable_mesh()
                .x_desc("cos θ")
                .x_label_formatter(&fmt_tick)
                .y_label_formatter(&fmt_tick)
                .x_labels(6)
                .y_labels(12)
                .label_style(("sans-serif", 13))
                .axis_desc_style(("sans-serif", 15));
            if k == 0 {
                mesh.y_desc("optical path difference Δ (nm)");
            }
            mesh.draw()?;
            let mut cells = Vec::with_capacity(nx * ny);
            for i in 0..nx {
                let (c0, c1) = (i as f64 / nx as f64, (i + 1) as f64 / nx as f64);
                let cos_theta = (0.5 * (c0 + c1)).max(MIN_COS_THETA);
                let q = a.film_q(cos_theta, n);
                for j in 0..ny {
                    let (o0, o1) = (
                        j as f64 / ny as f64 * opd_max,
                        (j + 1) as f64 / ny as f64 * opd_max,
                    );
                    let opd = 0.5 * (o0 + o1);
                    let d = if q > 0.0 { opd / (2.0 * q) } else { 0.0 };
                    let c = FilmLut::lookup(a, &self.table, cos_theta, d, n);
                    let rgb = self.display.linear_srgb(c).map(|v| v * self.exposure);
                    cells.push(Rectangle::new([(c0, o0), (c1, o1)], srgb8(rgb).filled()));
                }
            }
            chart.draw_series(cells)?;
            let limit: Vec<Option<(f64, f64)>> = (0..=100)
                .map(|i| {
                    let c = (f64::from(i) / 100.0).max(MIN_COS_THETA);
                    Some((c, 2.0 * a.thickness_max_nm * a.film_q(c, n)))
                })
                .collect();
            draw_line(
                &mut chart,
                &limit,
                [0.0, 1.0, 0.0, opd_max],
                Line {
                    colour: WHITE,
                    width: 2,
                    dash: Dashed,
                },
                (k == 0).then(|| format!("Δ at d = {} nm", a.thickness_max_nm)),
            )?;
            if k == 0 {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(BLACK.mix(0.6))
                    .border_style(WHITE.mix(0.6))
                    .label_font(("sans-serif", 13).into_font().color(&WHITE))
                    .draw()?;
            }
        }
        Ok(())
    }
}

/// A `fourier` table: for each channel (rows) the real and imaginary parts (columns) of
/// the stored, demodulated envelope A_j,k(μ) = Ŝ_j,σk(μ) e^{+2πiμν̄_j} against the optical
/// path difference μ, one line per mip level (dark: level 0, unfiltered; light: the
/// coarsest), over 0 to `max_opd_nm`.
#[derive(Clone, Debug)]
pub struct FourierPlot {
    /// Title.
    pub title: String,
    /// The table.
    pub table: FourierTable,
    /// Channel names (R, G, B or X, Y, Z).
    pub channels: [&'static str; 3],
    /// The μ range drawn, nm.
    pub max_opd_nm: f64,
}

impl FourierPlot {
    /// The μ below which the envelopes hold everything above 3 % of their peak, plus a
    /// half, rounded up to a round value (at least 1 µm, at most the table's range).
    pub fn auto_range(table: &FourierTable) -> f64 {
        let peak = table
            .levels
            .iter()
            .flatten()
            .flat_map(|a| a.iter().map(|c| c.norm()))
            .fold(0.0, f64::max);
        let mut last = 0.0f64;
        for (level, &n) in table.levels.iter().zip(&table.axes.level_samples) {
            for (i, a) in level.iter().enumerate() {
                if a.iter().any(|c| c.norm() > 0.03 * peak) {
                    last = last.max((i as f64 + 0.5) * table.axes.max_opd_nm / n as f64);
                }
            }
        }
        nice_ceiling((1.5 * last).max(1000.0)).min(table.axes.max_opd_nm)
    }
}

impl Figure for FourierPlot {
    fn size(&self) -> (u32, u32) {
        (1300, 1080)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 17))?;
        let panels = area.split_evenly((3, 2));
        let t = &self.table;
        let levels = t.levels.len();
        let mu_max_um = self.max_opd_nm / 1000.0;
        for j in 0..3 {
            let bound = t
                .levels
                .iter()
                .zip(&t.axes.level_samples)
                .flat_map(|(level, &n)| {
                    level.iter().enumerate().filter_map(move |(i, a)| {
                        let mu = (i as f64 + 0.5) * t.axes.max_opd_nm / n as f64;
                        (mu <= self.max_opd_nm).then(|| a[j].re.abs().max(a[j].im.abs()))
                    })
                })
                .fold(0.0f64, f64::max);
            let y = nice_ceiling((bound * 1.05).max(1e-6));
            for (part, name) in ["Re", "Im"].iter().enumerate() {
                let panel = &panels[2 * j + part];
                let mut chart = ChartBuilder::on(panel)
                    .caption(
                        format!(
                            "{name} A_{} (channel {})",
                            self.channels[j], self.channels[j]
                        ),
                        ("sans-serif", 15),
                    )
                    .margin(8)
                    .margin_right(20)
                    .x_label_area_size(40)
                    .y_label_area_size(64)
                    .build_cartesian_2d(0.0..mu_max_um, -y..y)?;
                chart
                    .configure_mesh()
                    .x_desc("optical path difference μ (µm)")
                    .x_label_formatter(&fmt_tick)
                    .y_label_formatter(&fmt_tick)
                    .label_style(("sans-serif", 13))
                    .axis_desc_style(("sans-serif", 14))
                    .bold_line_style(BLACK.mix(0.12))
                    .light_line_style(BLACK.mix(0.03))
                    .draw()?;
                for (k, (level, &n)) in t.levels.iter().zip(&t.axes.level_samples).enumerate() {
                    let points: Vec<Option<(f64, f64)>> = level
                        .iter()
                        .enumerate()
                        .map(|(i, a)| {
                            let mu = (i as f64 + 0.5) * t.axes.max_opd_nm / n as f64;
                            (mu <= self.max_opd_nm * 1.01)
                                .then(|| (mu / 1000.0, if part == 0 { a[j].re } else { a[j].im }))
                        })
                        .take_while(Option::is_some)
                        .collect();
                    let sigma = t.axes.level_sigma_nm[k];
                    let label = (j == 0 && part == 0).then(|| {
                        format!(
                            "level {k}: {n} texels, σ = {}",
                            if sigma == 0.0 {
                                "0".to_string()
                            } else {
                                format!("{sigma:.0} nm")
                            }
                        )
                    });
                    draw_line(
                        &mut chart,
                        &points,
                        [0.0, mu_max_um, -y, y],
                        Line {
                            colour: ramp(k as f64 / (levels.max(2) - 1) as f64),
                            width: if k == 0 { 2 } else { 1 },
                            dash: Solid,
                        },
                        label,
                    )?;
                }
                if j == 0 && part == 0 {
                    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 12)?;
                }
            }
        }
        Ok(())
    }
}

/// A baked table as a figure: [`FilmLutPlot`] or [`FourierPlot`] by its kind.
#[derive(Clone, Debug)]
pub enum TablePlot {
    /// A `film-lut` table.
    FilmLut(Box<FilmLutPlot>),
    /// A `fourier` table.
    Fourier(Box<FourierPlot>),
}

impl Figure for TablePlot {
    fn size(&self) -> (u32, u32) {
        match self {
            TablePlot::FilmLut(p) => p.size(),
            TablePlot::Fourier(p) => p.size(),
        }
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> DrawResult<DB> {
        match self {
            TablePlot::FilmLut(p) => p.draw(root, format),
            TablePlot::Fourier(p) => p.draw(root, format),
        }
    }
}

/// What to draw of a table: [`load_table_plot`]'s options.
#[derive(Clone, Debug)]
pub struct TableOptions {
    /// film-lut: reflectance or transmittance.
    pub quantity: Quantity,
    /// film-lut: film indices of the slices [default: n_min + (n_max − n_min) k/4 for
    /// k = 1…4, or the table's single index].
    pub film_iors: Option<Vec<f64>>,
    /// film-lut: factor applied to the linear colour before clipping.
    pub exposure: f64,
    /// fourier: the μ range, nm [default: [`FourierPlot::auto_range`]].
    pub max_opd_nm: Option<f64>,
}

/// The names of the default-set tables (manifests in the default `tables/baked/`).
pub fn default_table_names() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(default_baked_dir())
        .map(|entries| {
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "json"))
                .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// Loads the table `name_or_path` (a default-set name or a manifest path) as a figure.
pub fn load_table_plot(name_or_path: &str, options: &TableOptions) -> Result<TablePlot> {
    let path = resolve_table(name_or_path);
    if !path.is_file() {
        return Err(Error::Flag {
            flag: "TABLE".into(),
            value: name_or_path.into(),
            message: format!(
                "no such table ({} does not exist): expected a default-set table ({}) or the path to a table manifest (.json)",
                path.display(),
                default_table_names().join(", ")
            ),
        });
    }
    let manifest = Manifest::read(&path)?;
    if manifest.fourier().is_some() {
        let table = manifest.load_fourier(&path)?;
        let colorimeter = manifest.colorimeter(&path)?;
        let max_opd_nm = match options.max_opd_nm {
            Some(v) if v > 0.0 && v.is_finite() => v.min(table.axes.max_opd_nm),
            Some(v) => {
                return Err(Error::Flag {
                    flag: "--max-opd".into(),
                    value: format!("{v}"),
                    message: "must be a positive number of nanometres".into(),
                });
            }
            None => FourierPlot::auto_range(&table),
        };
        return Ok(TablePlot::Fourier(Box::new(FourierPlot {
            title: format!(
                "{}: demodulated envelopes of the {} sensitivities' Fourier transforms (observer {}, illuminant {})",
                manifest.name, manifest.space, manifest.observer, manifest.illuminant
            ),
            channels: colorimeter.space().channel_names(),
            table,
            max_opd_nm,
        })));
    }
    let lut = LoadedLut::load(&path)?;
    let axes = lut
        .manifest
        .film_lut()
        .cloned()
        .expect("checked by LoadedLut");
    let (table, what) = match options.quantity {
        Quantity::Reflectance => (lut.reflectance, "reflectance"),
        Quantity::Transmittance => (
            lut.transmittance.ok_or_else(|| Error::Flag {
                flag: "--quantity".into(),
                value: "t".into(),
                message: format!("table `{}` holds no transmittance", manifest.name),
            })?,
            "transmittance",
        ),
    };
    let film_iors = match &options.film_iors {
        Some(v) => {
            if let Some(n) = v
                .iter()
                .find(|n| !(**n >= axes.ior_min - 1e-9 && **n <= axes.ior_max + 1e-9))
            {
                return Err(Error::Flag {
                    flag: "--film-iors".into(),
                    value: format!("{n}"),
                    message: format!(
                        "outside the table's film index range {}–{}",
                        axes.ior_min, axes.ior_max
                    ),
                });
            }
            v.clone()
        }
        None if axes.ior_count <= 1 || axes.ior_max <= axes.ior_min => vec![axes.ior_min],
        // n_min is often the ambient's index (no film at all): start a quarter in.
        None => (1..=4)
            .map(|k| axes.ior_min + (axes.ior_max - axes.ior_min) * f64::from(k) / 4.0)
            .collect(),
    };
    if film_iors.is_empty() || film_iors.len() > MAX_SLICES {
        return Err(Error::Flag {
            flag: "--film-iors".into(),
            value: summarise(&film_iors),
            message: format!("expected 1 to {MAX_SLICES} film indices"),
        });
    }
    let under: String = manifest
        .under
        .iter()
        .map(|(m, d)| format!(" | {m} {d} nm"))
        .collect();
    let exposure = if options.exposure == 1.0 {
        String::new()
    } else {
        format!(", exposure ×{}", options.exposure)
    };
    Ok(TablePlot::FilmLut(Box::new(FilmLutPlot {
        title: format!(
            "{}: {what} colour of {} | film | {}{under} as the GPU samples it; sRGB, clipped{exposure}",
            manifest.name, manifest.ambient, manifest.base
        ),
        display: DisplayConverter::new(&lut.colorimeter),
        axes,
        table,
        film_iors,
        exposure: options.exposure,
    })))
}

#[cfg(test)]
mod tests {
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
            assert!(e.to_string().starts_with("-o/--output `"), "{e}");
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
            parse_list("--angles", "0,30,60").unwrap(),
            vec![0.0, 30.0, 60.0]
        );
        assert_eq!(
            parse_list("--angles", "0:20:10, 45").unwrap(),
            vec![0.0, 10.0, 20.0, 45.0]
        );
        for bad in ["", "0,,3", "a", "0:10"] {
            let e = parse_list("--angles", bad).unwrap_err().to_string();
            assert!(e.starts_with(&format!("--angles `{bad}`")), "{e}");
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

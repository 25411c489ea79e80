//! `nacre compare`: how far each real-time method is from the exact spectral colour, over
//! angle × thickness, for a named case — a CSV and a PNG of ΔE2000 heat maps.
//!
//! Methods compared against `spectral`: `rgb3`, `samples:5`, `gaussian` (glTF's
//! `KHR_materials_iridescence` approximation), `fourier:1`, `fourier:2`, `fourier:3` (exact
//! transforms; the baked table agrees with them to ≤ 0.01 ΔE2000) and `lut:` — a
//! `film-lut` baked in memory for the case (24 × 384 texels over cos θ × optical path,
//! half-float values, as the default tables).

use crate::commands::color::{self, Method, Point, Quantity};
use crate::error::{Error, Param, Result};
use crate::kinds::film_lut::FilmLutJob;
use nacre_format::atomic::write_atomic;
use nacre_format::film_lut::{FilmLut, FilmLutAxes};
use nacre_format::msg;
use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
use nacre_optics::colour::{delta_e_2000, xyz_to_lab};
use nacre_optics::elementary;
use nacre_optics::fourier::Harmonics;
use nacre_optics::{C64, Layer, Material, Stack};
use plotters::prelude::*;
use std::path::Path;

/// A named comparison case: a single film in air on a base.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    /// Name used on the command line.
    pub name: &'static str,
    /// What it is.
    pub description: &'static str,
    /// Film index.
    pub film_ior: f64,
    /// Base material spec.
    pub base: &'static str,
}

/// The named cases.
pub const CASES: &[Case] = &[
    Case {
        name: "fig7",
        description: "Belcour & Barla 2017 Fig. 7: film 1.5 on a base of index 1.09, in air",
        film_ior: 1.5,
        base: "1.09",
    },
    Case {
        name: "dielectric",
        description: "film 1.5 on the glTF default base (index 1.5), in air",
        film_ior: 1.5,
        base: "1.5",
    },
    Case {
        name: "gold",
        description: "film 1.5 on gold (Johnson & Christy 1972), in air",
        film_ior: 1.5,
        base: "au",
    },
    Case {
        name: "soap",
        description: "free soap film (index 1.33) in air",
        film_ior: 1.33,
        base: "1.0",
    },
];

/// One method's ΔE2000 over the grid.
pub struct MethodResult {
    /// Method label.
    pub label: String,
    /// ΔE2000 per grid point (angle-major).
    pub delta_e: Vec<f64>,
}

impl MethodResult {
    /// (mean, 95th percentile, max).
    pub fn summary(&self) -> (f64, f64, f64) {
        let mut v = self.delta_e.clone();
        v.sort_by(f64::total_cmp);
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        (
            mean,
            v[((v.len() - 1) as f64 * 0.95).round() as usize],
            v[v.len() - 1],
        )
    }
}

/// Runs the comparison for `case` over `angles_deg` × `thicknesses_nm`.
pub fn compare(
    case: &Case,
    angles_deg: &[f64],
    thicknesses_nm: &[f64],
) -> Result<Vec<MethodResult>> {
    let c = Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    );
    let air = Material::constant("1.0", C64::new(1.0, 0.0))?;
    let base = nacre_format::materials::resolve(case.base, Param::Case, None)?;
    let film = Material::constant(format!("{}", case.film_ior), C64::new(case.film_ior, 0.0))?;
    let stack = Stack::new(
        air.clone(),
        vec![Layer {
            material: film,
            thickness_nm: 0.0,
        }],
        base.clone(),
    )?;
    let points: Vec<Point> = angles_deg
        .iter()
        .flat_map(|&a| {
            thicknesses_nm.iter().map(move |&d| Point {
                angle_deg: a,
                thickness_nm: Some(d),
                film_ior: Some(case.film_ior),
            })
        })
        .collect();
    let q = Quantity::Reflectance;
    let exact = color::evaluate(&stack, &points, &Method::Spectral, &c, q, None)?;
    let lab = |rgb: [f64; 3]| xyz_to_lab(c.xyz_from_output(rgb), c.white_xyz());
    let delta = |got: &[[f64; 3]]| -> Vec<f64> {
        exact
            .iter()
            .zip(got)
            .map(|(e, g)| delta_e_2000(lab(*e), lab(*g)))
            .collect()
    };
    let mut out = Vec::new();
    for (label, method) in [
        ("rgb3", Method::Rgb3),
        ("samples:5", Method::Samples(5)),
        ("gaussian", Method::GaussianFitBelcour2017),
        ("fourier:1", Method::Fourier(Harmonics::Fixed(1), 0.0, None)),
        ("fourier:2", Method::Fourier(Harmonics::Fixed(2), 0.0, None)),
        ("fourier:3", Method::Fourier(Harmonics::Fixed(3), 0.0, None)),
    ] {
        let got = color::evaluate(&stack, &points, &method, &c, q, None)?;
        out.push(MethodResult {
            label: label.into(),
            delta_e: delta(&got),
        });
    }
    // lut: a film-lut for this case, baked in memory like the default tables.
    let d_max = thicknesses_nm.iter().copied().fold(0.0, f64::max).max(1.0);
    let job = FilmLutJob {
        axes: FilmLutAxes {
            cos_theta_count: 24,
            opd_count: 384,
            ior_count: 1,
            thickness_min_nm: 0.0,
            thickness_max_nm: d_max,
            ior_min: case.film_ior,
            ior_max: case.film_ior,
            ambient_index: 1.0,
        },
        ambient: air,
        under: vec![],
        under_incoherent: vec![],
        base,
        colorimeter: c.clone(),
        transmittance: false,
    };
    let mut lut = job.bake(&|| {})?;
    for v in lut.reflectance.data.iter_mut() {
        *v = half::f16::from_f32(*v).to_f32();
    }
    let got: Vec<[f64; 3]> = points
        .iter()
        .map(|p| {
            FilmLut::lookup(
                &lut.axes,
                &lut.reflectance,
                elementary::cos(p.angle_deg.to_radians()),
                p.thickness_nm.unwrap_or(0.0),
                case.film_ior,
            )
        })
        .collect();
    out.push(MethodResult {
        label: "lut".into(),
        delta_e: delta(&got),
    });
    Ok(out)
}

/// Writes the long-format CSV `method,angle_deg,thickness_nm,delta_e_2000`.
pub fn write_csv(
    path: &Path,
    angles_deg: &[f64],
    thicknesses_nm: &[f64],
    results: &[MethodResult],
) -> Result<()> {
    Ok(write_atomic(path, |w| {
        let mut csv = crate::csv_text::writer(w);
        csv.write_record(["method", "angle_deg", "thickness_nm", "delta_e_2000"])?;
        for r in results {
            let mut it = r.delta_e.iter();
            for &a in angles_deg {
                for &d in thicknesses_nm {
                    let de = it.next().expect("one value per point");
                    csv.write_record([
                        r.label.to_string(),
                        a.to_string(),
                        d.to_string(),
                        format!("{de:.6}"),
                    ])?;
                }
            }
        }
        csv.flush()
    })?)
}

/// The colour of ΔE2000 `v` on a perceptual ramp (dark blue 0 → yellow ≥ `max`).
fn ramp(v: f64, max: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 5] = [
        (68, 1, 84),
        (59, 82, 139),
        (33, 145, 140),
        (94, 201, 98),
        (253, 231, 37),
    ];
    let t = (v / max).clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * f).round() as u8;
    RGBColor(
        mix(STOPS[i].0, STOPS[i + 1].0),
        mix(STOPS[i].1, STOPS[i + 1].1),
        mix(STOPS[i].2, STOPS[i + 1].2),
    )
}

/// Draws one ΔE2000 heat map per method (x: thickness, y: angle, colour clamped at 10) and
/// writes it as PNG.
pub fn write_png(
    path: &Path,
    case: &Case,
    angles_deg: &[f64],
    thicknesses_nm: &[f64],
    results: &[MethodResult],
) -> Result<()> {
    static FONT: &[u8] = include_bytes!("../../../../tables/fonts/DejaVuSans.ttf");
    // Registering twice is harmless; a failure only means no text.
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let (w, h) = (1400u32, 900u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    let draw_err = |e: String| {
        Error::invalid(
            path.display().to_string(),
            format!("drawing the plot failed: {e}"),
        )
    };
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
        let (title, body) = root.split_vertically(50);
        title
            .titled(
                &format!(
                    "ΔE2000 against the spectral reference — {} (colour scale 0 to 10+)",
                    case.description
                ),
                ("sans-serif", 20),
            )
            .map_err(|e| draw_err(e.to_string()))?;
        let panels = body.split_evenly((2, 4));
        let step = |v: &[f64]| if v.len() > 1 { v[1] - v[0] } else { 1.0 };
        let (da, dd) = (step(angles_deg), step(thicknesses_nm));
        let (a0, a1) = (
            angles_deg[0] - da / 2.0,
            angles_deg[angles_deg.len() - 1] + da / 2.0,
        );
        let (d0, d1) = (
            thicknesses_nm[0] - dd / 2.0,
            thicknesses_nm[thicknesses_nm.len() - 1] + dd / 2.0,
        );
        for (panel, r) in panels.iter().zip(results) {
            let (mean, p95, max) = r.summary();
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!("{}: mean {mean:.2}, p95 {p95:.2}, max {max:.2}", r.label),
                    ("sans-serif", 15),
                )
                .margin(8)
                .x_label_area_size(32)
                .y_label_area_size(40)
                .build_cartesian_2d(d0..d1, a0..a1)
                .map_err(|e| draw_err(e.to_string()))?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc("thickness (nm)")
                .y_desc("angle (°)")
                .x_labels(5)
                .y_labels(5)
                .label_style(("sans-serif", 12))
                .draw()
                .map_err(|e| draw_err(e.to_string()))?;
            let mut cells = Vec::with_capacity(r.delta_e.len());
            let mut it = r.delta_e.iter();
            for &a in angles_deg {
                for &d in thicknesses_nm {
                    let de = *it.next().expect("one value per point");
                    cells.push(Rectangle::new(
                        [(d - dd / 2.0, a - da / 2.0), (d + dd / 2.0, a + da / 2.0)],
                        ramp(de, 10.0).filled(),
                    ));
                }
            }
            chart
                .draw_series(cells)
                .map_err(|e| draw_err(e.to_string()))?;
        }
        root.present().map_err(|e| draw_err(e.to_string()))?;
    }
    Ok(write_atomic(path, |out| {
        use image::ImageEncoder;
        image::codecs::png::PngEncoder::new_with_quality(
            out,
            image::codecs::png::CompressionType::Default,
            image::codecs::png::FilterType::Adaptive,
        )
        .write_image(&buf, w, h, image::ExtendedColorType::Rgb8)
        .map_err(std::io::Error::other)
    })?)
}

/// The named case of [`CASES`] (`--case`).
pub fn case_named(name: &str) -> Result<&'static Case> {
    CASES.iter().find(|c| c.name == name).ok_or_else(|| {
        Error::value(
            Param::Case,
            name,
            format!(
                "expected one of {}",
                CASES.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
            ),
        )
    })
}

/// Most angle × thickness points of one comparison.
pub const MAX_POINTS: u64 = 200_000;

/// The angle and thickness grids of a comparison from their ranges (`--angles`,
/// `--thicknesses`): angles strictly between -90 and 90 degrees, thicknesses
/// non-negative, at most [`MAX_POINTS`] points.
pub fn grid(angles_text: &str, thicknesses_text: &str) -> Result<(Vec<f64>, Vec<f64>)> {
    let angles = crate::commands::grid::parse_range(Param::Angles, angles_text)?;
    if let Some(a) = angles.iter().find(|a| !(a.abs() < 90.0)) {
        return Err(Error::Angle {
            origin: Param::Angles.into(),
            value: angles_text.into(),
            angle: *a,
        });
    }
    let thicknesses = crate::commands::grid::parse_range(Param::Thicknesses, thicknesses_text)?;
    if let Some(d) = thicknesses.iter().find(|d| !(**d >= 0.0)) {
        return Err(Error::value(
            Param::Thicknesses,
            thicknesses_text,
            format!("thickness {d} must be non-negative"),
        ));
    }
    let points = angles.len() as u64 * thicknesses.len() as u64;
    if points > MAX_POINTS {
        return Err(nacre_format::Error::TooLarge {
            what: msg![Param::Angles, " × ", Param::Thicknesses, " points"],
            count: points,
            limit: MAX_POINTS,
        }
        .into());
    }
    Ok((angles, thicknesses))
}

/// Writes `dir/compare.csv` and `dir/compare.png` (the folder created if needed).
pub fn write(
    dir: &Path,
    case: &Case,
    angles: &[f64],
    thicknesses: &[f64],
    results: &[MethodResult],
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| nacre_format::Error::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    write_csv(&dir.join("compare.csv"), angles, thicknesses, results)?;
    write_png(&dir.join("compare.png"), case, angles, thicknesses, results)
}

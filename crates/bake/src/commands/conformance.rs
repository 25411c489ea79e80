//! `nacre conformance`: reference data for renderers that implement glTF's
//! `KHR_materials_iridescence`.
//!
//! Over the extension's parameter space — film index 1.0–2.333 (`iridescenceIor`), film
//! thickness 0–1200 nm (`iridescenceThicknessMinimum`/`Maximum`), dielectric bases of index
//! 1.0–2.5 (`KHR_materials_ior`) and four metals, incidence 0–89° — the exact colour of
//! the unpolarised reflectance of ambient 1.0 | film | base, integrated with the `spectral`
//! method ([`crate::commands::color::Method::Spectral`]), as XYZ (CIE 1931 2°, D65, perfect
//! reflector Y = 1) and linear sRGB. Beside it, the glTF reference approximation
//! ([`crate::commands::color::Method::GaussianFitBelcour2017`]) at every point with its ΔE2000, and
//! swatch charts. [`Conformance::files`] renders every file in memory; the CLI writes them
//! with [`nacre_format::atomic::write_files_atomic`].
//!
//! Three grids ([`GridSize`]); each is a subset of the next larger one, so that the
//! `quick` rows of a run are byte-identical to the same rows of the committed default set:
//!
//! | grid | angles (°) | thicknesses (nm) | film indices | rows (10 bases) |
//! |---|---|---|---|---|
//! | quick | 0, 30, 60, 85 | 0–1200 step 100 | 1.0, 1.3, 1.5, 2.333 | 2 080 |
//! | default | 0–80 step 10, 85, 89 | 0–1200 step 25 | 1.0, 1.2, 1.3, 1.4, 1.5, 1.6, 1.8, 2.0, 2.333 | 48 510 |
//! | fine | 0–85 step 5, 89 | 0–1200 step 12.5 | 1.0–1.8 step 0.1, 2.0, 2.333 | 202 730 |

use crate::commands::color::{self, Method, Point, Quantity};
use crate::commands::spectrum::fmt_sig;
use crate::error::{Error, Result};
use nacre_format::atomic::write_files_atomic;
use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
use nacre_optics::colour::{delta_e_2000, xyz_to_lab};
use nacre_optics::elementary;
use nacre_optics::fourier::gltf_iridescence;
use nacre_optics::{C64, Layer, Material, Stack};
use plotters::coord::ranged1d::SegmentValue;
use plotters::prelude::*;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// The header of `conformance.csv`.
pub const HEADER: &str = "base_ior,angle_deg,thickness_nm,film_ior,X,Y,Z,R,G,B";

/// The header of `gltf-reference-error.csv`: the glTF approximation's linear sRGB and its
/// ΔE2000 against the reference.
pub const ERROR_HEADER: &str = "base_ior,angle_deg,thickness_nm,film_ior,R,G,B,delta_e_2000";

/// The incidence angles of the swatch charts, degrees (every grid contains them).
pub const SWATCH_ANGLES_DEG: [f64; 2] = [0.0, 60.0];

/// A base of the grid.
#[derive(Clone, Copy, Debug)]
pub struct Base {
    /// The `base_ior` column: a number for a constant index, a bundled name for a
    /// dispersive material.
    pub label: &'static str,
    /// What it is, for the README.
    pub description: &'static str,
}

/// The bases: glTF's dielectric range (`KHR_materials_ior`; 1.0 means no base interface,
/// a free film in air) and four bundled metals.
pub const BASES: &[Base] = &[
    Base {
        label: "1",
        description: "no base interface: the film is free-standing in air (a soap bubble)",
    },
    Base {
        label: "1.25",
        description: "dielectric",
    },
    Base {
        label: "1.5",
        description: "dielectric, the glTF default (KHR_materials_ior ior 1.5)",
    },
    Base {
        label: "1.75",
        description: "dielectric",
    },
    Base {
        label: "2",
        description: "dielectric",
    },
    Base {
        label: "2.5",
        description: "dielectric (the top of glTF's usual range)",
    },
    Base {
        label: "au",
        description: "gold, measured n + iκ (Johnson & Christy 1972)",
    },
    Base {
        label: "ag",
        description: "silver, measured n + iκ (Johnson & Christy 1972)",
    },
    Base {
        label: "cu",
        description: "copper, measured n + iκ (Johnson & Christy 1972)",
    },
    Base {
        label: "al",
        description: "aluminium, measured n + iκ (Rakić 1995)",
    },
];

/// Which grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridSize {
    /// A few points per axis, for tests (`--quick`).
    Quick,
    /// The committed set (`docs/conformance/`).
    Default,
    /// Denser axes (`--fine`), about 21 MB of CSV.
    Fine,
}

impl GridSize {
    /// The command-line flag that selects it (empty for the default).
    pub fn flag(self) -> &'static str {
        match self {
            GridSize::Quick => " --quick",
            GridSize::Default => "",
            GridSize::Fine => " --fine",
        }
    }
}

/// The sampled axes. Rows run base-major, then angle, thickness and film index.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Which grid.
    pub size: GridSize,
    /// Incidence angles in the ambient, degrees.
    pub angles_deg: Vec<f64>,
    /// Film thicknesses, nm.
    pub thicknesses_nm: Vec<f64>,
    /// Film indices (real).
    pub film_iors: Vec<f64>,
}

impl Grid {
    /// The grid of `size` (see the module docs).
    pub fn new(size: GridSize) -> Self {
        let steps =
            |step: u32| -> Vec<f64> { (0..=1200 / step).map(|i| f64::from(i * step)).collect() };
        match size {
            GridSize::Quick => Grid {
                size,
                angles_deg: vec![0.0, 30.0, 60.0, 85.0],
                thicknesses_nm: steps(100),
                film_iors: vec![1.0, 1.3, 1.5, 2.333],
            },
            GridSize::Default => Grid {
                size,
                angles_deg: (0..=8)
                    .map(|i| f64::from(i * 10))
                    .chain([85.0, 89.0])
                    .collect(),
                thicknesses_nm: steps(25),
                film_iors: vec![1.0, 1.2, 1.3, 1.4, 1.5, 1.6, 1.8, 2.0, 2.333],
            },
            GridSize::Fine => Grid {
                size,
                angles_deg: (0..=17).map(|i| f64::from(i * 5)).chain([89.0]).collect(),
                thicknesses_nm: (0..=96).map(|i| f64::from(i) * 12.5).collect(),
                film_iors: vec![1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 2.0, 2.333],
            },
        }
    }

    /// Points per base.
    pub fn points_per_base(&self) -> usize {
        self.angles_deg.len() * self.thicknesses_nm.len() * self.film_iors.len()
    }

    /// The points of one base, in row order.
    pub fn points(&self) -> Vec<Point> {
        let mut out = Vec::with_capacity(self.points_per_base());
        for &angle_deg in &self.angles_deg {
            for &d in &self.thicknesses_nm {
                for &n in &self.film_iors {
                    out.push(Point {
                        angle_deg,
                        thickness_nm: Some(d),
                        film_ior: Some(n),
                    });
                }
            }
        }
        out
    }

    /// Row index within a base of (angle, thickness, film index) indices.
    fn index(&self, a: usize, d: usize, n: usize) -> usize {
        (a * self.thicknesses_nm.len() + d) * self.film_iors.len() + n
    }
}

/// The results for one base.
pub struct BaseResult {
    /// The base.
    pub base: Base,
    /// Reference colours, linear sRGB, in row order.
    pub reference: Vec<[f64; 3]>,
    /// The glTF approximation's colours, linear sRGB, in row order.
    pub gltf: Vec<[f64; 3]>,
    /// ΔE2000 of `gltf` against `reference`, in row order.
    pub delta_e: Vec<f64>,
    /// The bare base's normal-incidence reflectance F0 (linear sRGB): the `baseColor` a
    /// glTF metal needs.
    pub f0: [f64; 3],
}

/// (mean, 95th percentile, max) of `v`.
pub fn summary(v: &[f64]) -> (f64, f64, f64) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let mean = s.iter().sum::<f64>() / s.len() as f64;
    (
        mean,
        s[((s.len() - 1) as f64 * 0.95).round() as usize],
        s[s.len() - 1],
    )
}

/// A computed conformance set.
pub struct Conformance {
    /// The grid.
    pub grid: Grid,
    /// CIE 1931 2°, D65, linear sRGB.
    pub colorimeter: Colorimeter,
    /// One entry per base of [`BASES`].
    pub bases: Vec<BaseResult>,
}

/// The colorimeter of the conformance data: CIE 1931 2°, D65, linear sRGB.
pub fn colorimeter() -> Colorimeter {
    Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    )
}

/// `nacre conformance`: computes the set of `size` and writes its [`Conformance::files`]
/// into `dir` as one unit ([`write_files_atomic`]). A `dir` that exists but is not a folder
/// is refused before any work.
pub fn write(dir: &Path, size: GridSize) -> Result<Conformance> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::invalid(
            dir.display().to_string(),
            "exists and is not a folder: -o takes the output folder",
        ));
    }
    let set = compute(Grid::new(size))?;
    write_files_atomic(dir, &set.files()?)?;
    Ok(set)
}

/// Computes the reference and the glTF approximation at every point of `grid`.
pub fn compute(grid: Grid) -> Result<Conformance> {
    let c = colorimeter();
    let air = Material::constant("1.0", C64::new(1.0, 0.0))?;
    let points = grid.points();
    let q = Quantity::Reflectance;
    let lab = |rgb: [f64; 3]| xyz_to_lab(c.xyz_from_output(rgb), c.white_xyz());
    let mut bases = Vec::with_capacity(BASES.len());
    for base in BASES {
        let context = format!("conformance base `{}`", base.label);
        let material = nacre_format::materials::resolve(base.label, &context, None)?;
        let stack = Stack::new(
            air.clone(),
            vec![Layer {
                material: Material::constant("1.0", C64::new(1.0, 0.0))?,
                thickness_nm: 0.0,
            }],
            material.clone(),
        )?;
        let reference = color::evaluate(&stack, &points, &Method::Spectral, &c, q, None)?;
        let bare = Stack::new(air.clone(), vec![], material)?;
        let f0 = color::evaluate(
            &bare,
            &[Point {
                angle_deg: 0.0,
                thickness_nm: None,
                film_ior: None,
            }],
            &Method::Spectral,
            &c,
            q,
            None,
        )?[0];
        // The glTF approximation sees the base only through F0, as `--method gaussian`
        // does (the same F0, the same call; a test checks them equal).
        let gltf: Vec<[f64; 3]> = points
            .par_iter()
            .map(|p| {
                gltf_iridescence(
                    1.0,
                    p.film_ior.unwrap_or(1.0),
                    elementary::cos(p.angle_deg.to_radians()),
                    p.thickness_nm.unwrap_or(0.0),
                    f0,
                )
            })
            .collect();
        let delta_e = reference
            .iter()
            .zip(&gltf)
            .map(|(r, g)| delta_e_2000(lab(*r), lab(*g)))
            .collect();
        bases.push(BaseResult {
            base: *base,
            reference,
            gltf,
            delta_e,
            f0,
        });
    }
    Ok(Conformance {
        grid,
        colorimeter: c,
        bases,
    })
}

/// The text a CSV writer wrote to memory (its fields are UTF-8 strings).
fn csv_string(csv: csv::Writer<Vec<u8>>) -> String {
    let bytes = csv.into_inner().expect("writing to memory cannot fail");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields")
}

impl Conformance {
    /// `conformance.csv`.
    pub fn csv(&self) -> String {
        let s = Vec::with_capacity(self.bases.len() * self.grid.points_per_base() * 120);
        let mut csv = crate::csv_text::writer(s);
        // Writing to memory cannot fail.
        let _ = csv.write_record(HEADER.split(','));
        let points = self.grid.points();
        for b in &self.bases {
            for (p, rgb) in points.iter().zip(&b.reference) {
                let xyz = self.colorimeter.xyz_from_output(*rgb);
                let _ = csv.write_record([
                    b.base.label.to_string(),
                    p.angle_deg.to_string(),
                    p.thickness_nm.unwrap_or(0.0).to_string(),
                    p.film_ior.unwrap_or(1.0).to_string(),
                    fmt_sig(xyz[0]),
                    fmt_sig(xyz[1]),
                    fmt_sig(xyz[2]),
                    fmt_sig(rgb[0]),
                    fmt_sig(rgb[1]),
                    fmt_sig(rgb[2]),
                ]);
            }
        }
        csv_string(csv)
    }

    /// `gltf-reference-error.csv`.
    pub fn error_csv(&self) -> String {
        let s = Vec::with_capacity(self.bases.len() * self.grid.points_per_base() * 80);
        let mut csv = crate::csv_text::writer(s);
        // Writing to memory cannot fail.
        let _ = csv.write_record(ERROR_HEADER.split(','));
        let points = self.grid.points();
        for b in &self.bases {
            for ((p, rgb), de) in points.iter().zip(&b.gltf).zip(&b.delta_e) {
                let _ = csv.write_record([
                    b.base.label.to_string(),
                    p.angle_deg.to_string(),
                    p.thickness_nm.unwrap_or(0.0).to_string(),
                    p.film_ior.unwrap_or(1.0).to_string(),
                    fmt_sig(rgb[0]),
                    fmt_sig(rgb[1]),
                    fmt_sig(rgb[2]),
                    format!("{de:.6}"),
                ]);
            }
        }
        csv_string(csv)
    }

    /// Every file of the set, named relative to the output folder: `conformance.csv`,
    /// `gltf-reference-error.csv`, `swatches-<base>.png` and `README.md`.
    pub fn files(&self) -> Result<Vec<(String, Vec<u8>)>> {
        let mut out = vec![
            ("conformance.csv".to_string(), self.csv().into_bytes()),
            (
                "gltf-reference-error.csv".to_string(),
                self.error_csv().into_bytes(),
            ),
        ];
        for b in &self.bases {
            let name = swatch_file(b.base.label);
            let png = self.swatch_png(b, &name)?;
            out.push((name, png));
        }
        let sizes: Vec<(String, usize)> = out.iter().map(|(n, b)| (n.clone(), b.len())).collect();
        out.push(("README.md".to_string(), self.readme(&sizes).into_bytes()));
        Ok(out)
    }

    /// Draws the swatch chart of one base: four panels (exact and glTF approximation at
    /// each of [`SWATCH_ANGLES_DEG`]), thickness rows (0 at the top) × film-index columns,
    /// sRGB-encoded with each channel clipped to [0, 1].
    fn swatch_png(&self, b: &BaseResult, name: &str) -> Result<Vec<u8>> {
        static FONT: &[u8] = include_bytes!("../../../../tables/fonts/DejaVuSans.ttf");
        // Registering twice is harmless; a failure only means no text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
        let g = &self.grid;
        let (w, h) = (1400u32, 860u32);
        let mut buf = vec![0u8; (w * h * 3) as usize];
        let draw_err = |e: String| {
            Error::invalid(
                name.to_string(),
                format!("drawing the swatches failed: {e}"),
            )
        };
        let angle_index = |a: f64| {
            g.angles_deg
                .iter()
                .position(|&x| x == a)
                .expect("every grid has the swatch angles")
        };
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
            let (title, body) = root.split_vertically(56);
            title
                .titled(
                    &format!(
                        "base {} — {}: reflectance colour of air | film | base, sRGB, D65",
                        b.base.label, b.base.description
                    ),
                    ("sans-serif", 19),
                )
                .map_err(|e| draw_err(e.to_string()))?;
            let panels = body.split_evenly((1, 4));
            let n = g.film_iors.len();
            let dd = if g.thicknesses_nm.len() > 1 {
                g.thicknesses_nm[1] - g.thicknesses_nm[0]
            } else {
                1.0
            };
            let d_top = g.thicknesses_nm[0] - dd / 2.0;
            let d_bottom = g.thicknesses_nm[g.thicknesses_nm.len() - 1] + dd / 2.0;
            let mut panel_iter = panels.iter();
            for angle in SWATCH_ANGLES_DEG {
                let a = angle_index(angle);
                for (label, colours) in [
                    ("exact (nacre spectral)", &b.reference),
                    ("glTF approximation", &b.gltf),
                ] {
                    let panel = panel_iter.next().expect("four panels");
                    let mut chart = ChartBuilder::on(panel)
                        .caption(format!("{label}, {angle}°"), ("sans-serif", 15))
                        .margin(8)
                        .x_label_area_size(44)
                        .y_label_area_size(48)
                        // 0..n − 1 segmented: n segments (the integer range is inclusive).
                        .build_cartesian_2d((0..n - 1).into_segmented(), d_bottom..d_top)
                        .map_err(|e| draw_err(e.to_string()))?;
                    let iors = g.film_iors.clone();
                    chart
                        .configure_mesh()
                        .disable_mesh()
                        .x_desc("film index")
                        .y_desc("thickness (nm)")
                        .x_labels(n)
                        .y_labels(13)
                        .x_label_formatter(&move |v| match v {
                            SegmentValue::CenterOf(i) | SegmentValue::Exact(i) => {
                                iors.get(*i).map_or(String::new(), |x| format!("{x}"))
                            }
                            SegmentValue::Last => String::new(),
                        })
                        .y_label_formatter(&|v| format!("{v:.0}"))
                        .label_style(("sans-serif", 12))
                        .draw()
                        .map_err(|e| draw_err(e.to_string()))?;
                    let mut cells = Vec::with_capacity(n * g.thicknesses_nm.len());
                    for (di, &d) in g.thicknesses_nm.iter().enumerate() {
                        for ni in 0..n {
                            let [r, gg, bb] = colours[g.index(a, di, ni)].map(srgb_u8);
                            cells.push(Rectangle::new(
                                [
                                    (SegmentValue::Exact(ni), d - dd / 2.0),
                                    (SegmentValue::Exact(ni + 1), d + dd / 2.0),
                                ],
                                RGBColor(r, gg, bb).filled(),
                            ));
                        }
                    }
                    chart
                        .draw_series(cells)
                        .map_err(|e| draw_err(e.to_string()))?;
                }
            }
            root.present().map_err(|e| draw_err(e.to_string()))?;
        }
        let mut png_bytes = Vec::new();
        {
            use image::ImageEncoder;
            image::codecs::png::PngEncoder::new_with_quality(
                &mut png_bytes,
                image::codecs::png::CompressionType::Default,
                image::codecs::png::FilterType::Adaptive,
            )
            .write_image(&buf, w, h, image::ExtendedColorType::Rgb8)
            .map_err(|e| draw_err(e.to_string()))?;
        }
        Ok(png_bytes)
    }

    /// The generated `README.md`; `sizes` are the other files' names and byte counts.
    fn readme(&self, sizes: &[(String, usize)]) -> String {
        let g = &self.grid;
        let c = &self.colorimeter;
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let rows = self.bases.len() * g.points_per_base();
        let flag = g.size.flag();
        let mut s = String::new();
        let w = &mut s;
        let _ = writeln!(
            w,
            "# Thin-film iridescence conformance data for glTF `KHR_materials_iridescence`\n\n\
             <!-- Generated by `nacre conformance{flag} -o DIR` (nacre {}). Do not edit: re-run the command. -->\n\n\
             Exact reference colours of thin-film interference over the parameter space of glTF's\n\
             [`KHR_materials_iridescence`](https://github.com/KhronosGroup/glTF/tree/main/extensions/2.0/Khronos/KHR_materials_iridescence),\n\
             for renderer authors to test their implementation against. They are computed by\n\
             [nacre](../../README.md)'s `spectral` method: the exact multilayer reflectance, in f64,\n\
             integrated over the spectrum with a rule that resolves the film's fringes however\n\
             sharp they are: within ΔE2000 0.01 of a converged brute-force integration (0.05 nm,\n\
             finer where the fringes need it) for every film up to 10 µm of index 1.0–2.5 at\n\
             0–89.9° on the bundled materials and on constant indices n 1.0–3.0, κ 0–5 (the\n\
             worst case a search of the highest-finesse corners finds: ΔE2000 0.0013).\n",
            env!("CARGO_PKG_VERSION")
        );
        let _ = writeln!(w, "## Files\n\n| file | bytes | what |\n|---|---|---|");
        for (name, bytes) in sizes {
            let what = if name == "conformance.csv" {
                format!("the reference: {rows} rows, `{HEADER}`")
            } else if name == "gltf-reference-error.csv" {
                format!(
                    "the glTF reference approximation at the same points, `{ERROR_HEADER}` (R, G, B: its linear sRGB)"
                )
            } else {
                "swatch chart (below)".to_string()
            };
            let _ = writeln!(w, "| [`{name}`]({name}) | {bytes} | {what} |");
        }
        let _ = writeln!(w, "| `README.md` | | this file |\n");
        let _ = writeln!(
            w,
            "## The grid\n\n\
             Every combination of (rows in this order, base outermost, film index innermost):\n\n\
             | column | values |\n|---|---|\n\
             | `base_ior` | {} |\n\
             | `angle_deg` | {} |\n\
             | `thickness_nm` | {} ({} values) |\n\
             | `film_ior` | {} |\n\n\
             {} bases × {} angles × {} thicknesses × {} film indices = {rows} rows.\n\
             `nacre conformance --fine` writes a denser grid (0–85° step 5 and 89°, 12.5 nm steps,\n\
             film index 1.0–1.8 step 0.1, 2.0, 2.333: {} rows, about 21 MB) and `--quick` a\n\
             coarse one for tests ({} rows); each grid's rows are a subset of the next larger one's,\n\
             with identical values.\n",
            self.bases
                .iter()
                .map(|b| format!("`{}`", b.base.label))
                .collect::<Vec<_>>()
                .join(", "),
            list(&g.angles_deg),
            if g.thicknesses_nm.len() > 2 {
                format!(
                    "{}, {}, …, {}",
                    g.thicknesses_nm[0],
                    g.thicknesses_nm[1],
                    g.thicknesses_nm[g.thicknesses_nm.len() - 1]
                )
            } else {
                list(&g.thicknesses_nm)
            },
            g.thicknesses_nm.len(),
            list(&g.film_iors),
            self.bases.len(),
            g.angles_deg.len(),
            g.thicknesses_nm.len(),
            g.film_iors.len(),
            BASES.len() * Grid::new(GridSize::Fine).points_per_base(),
            BASES.len() * Grid::new(GridSize::Quick).points_per_base(),
        );
        let white = c.white_xyz();
        let m = c.matrix();
        let _ = writeln!(
            w,
            "## Conventions\n\n\
             * **Stack**: a semi-infinite ambient of index exactly 1.0 (vacuum/air, non-absorbing),\n\
             \x20 one film of constant real index `film_ior` and physical thickness `thickness_nm`,\n\
             \x20 on a semi-infinite `base`. Smooth parallel interfaces, coherent multiple reflections\n\
             \x20 (all orders, the Airy sum), nothing else: no roughness, no absorption in the film.\n\
             * **`angle_deg`**: the angle of incidence θ measured in the ambient, from the normal:\n\
             \x20 cos θ = N·V (glTF's `NdotV`).\n\
             * **Reflectance**: unpolarised, R(λ) = (R_s(λ) + R_p(λ)) / 2, the power reflectances\n\
             \x20 |r_s|² and |r_p|² of the whole stack (Fresnel coefficients for absorbing media;\n\
             \x20 conventions of Byrnes' `tmm`).\n\
             * **`base_ior`**: a number is the constant real index n of a dielectric base; `n+ki`\n\
             \x20 (e.g. `0.27+2.9i`, not in this grid) a constant complex index; a name is one of nacre's\n\
             \x20 bundled dispersive materials, with its measured n(λ) + iκ(λ) (`nacre materials`,\n\
             \x20 [`tables/materials/`](../../tables/materials/README.md)). `1` means no base\n\
             \x20 interface at all: the film is free-standing in air, like a soap bubble.\n\
             * **Colour**: X, Y, Z = ∫ R(λ) S(λ) (x̄, ȳ, z̄)(λ) dλ / ∫ S(λ) ȳ(λ) dλ over 360–830 nm, with\n\
             \x20 the **CIE 1931 2° observer** and **CIE illuminant D65** (1 nm tables, CIE 015:2018),\n\
             \x20 so that a perfect reflector has **Y = 1**; its XYZ, the white used for CIELAB, is\n\
             \x20 (Xn, Yn, Zn) = ({:.8}, {:.8}, {:.8}).\n\
             * **R, G, B**: linear (no transfer function), Rec. 709 / sRGB primaries, D65 white:\n\
             \x20 (R, G, B) = M · (X, Y, Z) with\n\n\
             \x20 ```text\n\
             \x20 M = [ {:+.10}  {:+.10}  {:+.10} ]\n\
             \x20     [ {:+.10}  {:+.10}  {:+.10} ]\n\
             \x20     [ {:+.10}  {:+.10}  {:+.10} ]\n\
             \x20 ```\n\n\
             \x20 the IEC 61966-2-1 matrix rescaled per channel (by less than 2.5 × 10⁻⁴) so that the\n\
             \x20 white above maps to exactly (1, 1, 1). Values are not clipped: saturated colours can\n\
             \x20 have a channel below 0.\n\
             * **Numbers**: 12 significant digits (XYZ and RGB are rounded from f64).\n",
            white[0],
            white[1],
            white[2],
            m[0][0],
            m[0][1],
            m[0][2],
            m[1][0],
            m[1][1],
            m[1][2],
            m[2][0],
            m[2][1],
            m[2][2],
        );
        let _ = writeln!(
            w,
            "## Mapping to glTF\n\n\
             | glTF | here |\n|---|---|\n\
             | `iridescenceIor` of `KHR_materials_iridescence` (default 1.3) | `film_ior` |\n\
             | thickness = mix(`iridescenceThicknessMinimum`, `iridescenceThicknessMaximum`, texture G) in nm (defaults 100 and 400; `Maximum` without a texture) | `thickness_nm` |\n\
             | `ior` of `KHR_materials_ior` (default 1.5), with `metallic` = 0 and `KHR_materials_specular` at its defaults | a numeric `base_ior` |\n\
             | `metallic` = 1 with `baseColorFactor` = the metal's F0 below | a metal `base_ior` |\n\
             | `NdotV` | cos(`angle_deg`) |\n\
             | `iridescenceFactor` = 1: the thin-film term replaces the Fresnel term of the specular lobe | R, G, B |\n\n\
             glTF describes a metal only by its normal-incidence colour F0 = `baseColor`; the reference\n\
             uses the metal's measured complex index instead, which is what the colour would be. To\n\
             set up a glTF metal for these rows, use its F0 (the colour of the bare metal at normal\n\
             incidence, computed exactly like the rows):\n\n\
             | base | F0 linear sRGB (R, G, B) | F0 sRGB 8-bit |\n|---|---|---|"
        );
        for b in self.bases.iter().filter(|b| !is_numeric(b.base.label)) {
            let [r, gg, bb] = b.f0.map(srgb_u8);
            let _ = writeln!(
                w,
                "| `{}` | {:.6}, {:.6}, {:.6} | #{r:02x}{gg:02x}{bb:02x} |",
                b.base.label, b.f0[0], b.f0[1], b.f0[2]
            );
        }
        let _ = writeln!(
            w,
            "\nFor a dielectric base of index n, F0 = ((n − 1)/(n + 1))² in every channel.\n"
        );
        let _ = writeln!(
            w,
            "## How to check a renderer\n\n\
             1. For every row, evaluate your thin-film Fresnel term — the factor your shader\n\
             \x20  multiplies the specular lighting by, with `iridescenceFactor` = 1 and specular\n\
             \x20  weight 1 — at NdotV = cos(`angle_deg`), the row's thickness, film index and base.\n\
             \x20  Equivalently: render a flat mirror-smooth surface lit by a uniform white environment\n\
             \x20  of radiance 1 and read back the linear value.\n\
             2. Bring your colour into the same space: compare linear Rec. 709 / sRGB directly with\n\
             \x20  R, G, B; from any other space, convert to XYZ relative to D65 (white Y = 1) and\n\
             \x20  compare with X, Y, Z.\n\
             3. Convert both to CIELAB with the white (Xn, Yn, Zn) above and compute CIEDE2000\n\
             \x20  (k_L = k_C = k_H = 1). The colours are absolute reflectances, not exposure-normalised:\n\
             \x20  a dim reflection (a dielectric reflects a few per cent) has a small L* and the same\n\
             \x20  relative error gives a smaller ΔE2000 than on a bright metal. That is how the error\n\
             \x20  looks next to a white surface under the same light.\n\
             4. Report mean, 95th percentile and maximum per base. Suggested thresholds:\n\n\
             | ΔE2000 | meaning |\n|---|---|\n\
             | ≤ 1 | indistinguishable side by side |\n\
             | ≤ 3 | close: a difference visible side by side, acceptable for an approximation |\n\
             | > 5 | a different colour |\n\n\
             For scale, the glTF reference approximation itself — Belcour & Barla 2017's real-time\n\
             model as coded in the Khronos sample renderer (Schlick Fresnel from F0, Gaussian fits of\n\
             the colour-matching functions' Fourier transforms, two harmonics), transcribed in nacre\n\
             as `nacre color --method gaussian` — against the reference on this grid\n\
             (`gltf-reference-error.csv`):\n\n\
             | base | mean ΔE2000 | p95 | max | at (angle°, nm, film) | points ≤ 1 | points ≤ 3 |\n|---|---|---|---|---|---|---|"
        );
        let mut dielectric = Vec::new();
        let mut metal = Vec::new();
        let points = g.points();
        for b in &self.bases {
            let (mean, p95, max) = summary(&b.delta_e);
            let worst = b
                .delta_e
                .iter()
                .enumerate()
                .max_by(|x, y| x.1.total_cmp(y.1))
                .map_or(0, |(i, _)| i);
            let p = &points[worst];
            let frac = |t: f64| {
                100.0 * b.delta_e.iter().filter(|&&x| x <= t).count() as f64
                    / b.delta_e.len() as f64
            };
            let _ = writeln!(
                w,
                "| `{}` | {mean:.2} | {p95:.2} | {max:.2} | {}, {}, {} | {:.0} % | {:.0} % |",
                b.base.label,
                p.angle_deg,
                p.thickness_nm.unwrap_or(0.0),
                p.film_ior.unwrap_or(1.0),
                frac(1.0),
                frac(3.0)
            );
            if is_numeric(b.base.label) {
                dielectric.extend_from_slice(&b.delta_e);
            } else {
                metal.extend_from_slice(&b.delta_e);
            }
        }
        for (label, v) in [
            ("all dielectric bases", &dielectric),
            ("all metals", &metal),
        ] {
            if !v.is_empty() {
                let (mean, p95, max) = summary(v);
                let frac =
                    |t: f64| 100.0 * v.iter().filter(|&&x| x <= t).count() as f64 / v.len() as f64;
                let _ = writeln!(
                    w,
                    "| {label} | {mean:.2} | {p95:.2} | {max:.2} | | {:.0} % | {:.0} % |",
                    frac(1.0),
                    frac(3.0)
                );
            }
        }
        let _ = writeln!(
            w,
            "\nA renderer that implements the glTF reference code exactly should reproduce the R, G, B\n\
             of `gltf-reference-error.csv` (to about 10⁻⁵ in single precision, with F0 as above) and\n\
             therefore its ΔE2000. (Some renderers switch iridescence off at thickness 0, which\n\
             gives the bare base, as the reference does.)\n\
             A renderer that does better than the approximation should show it here. The\n\
             approximation departs most on metals (gold, copper: their colour at normal incidence\n\
             is not enough to predict the phase shifts), at grazing angles, and for `film_ior` = 1:\n\
             a film of the ambient's index is no film at all and the reference shows the bare base,\n\
             but Schlick's Fresnel from F0 = 0 still reflects (1 − cos θ)⁵ at the film's top and\n\
             the approximation paints interference colours (on base `1`, where there is no\n\
             interface at all, up to ΔE2000 100 at grazing incidence).\n"
        );
        let _ = writeln!(
            w,
            "## Swatches\n\n\
             One chart per base: rows are film thickness ({} to {} nm, top to bottom), columns film\n\
             index; four panels, the exact colour and the glTF approximation at {}° and at {}°.\n\
             Each cell is the reflectance colour as a mirror shows it under D65 white light of the\n\
             same luminance as a perfect white (no exposure adjustment), sRGB-encoded (IEC 61966-2-1\n\
             transfer function) with each channel clipped to [0, 1].\n",
            g.thicknesses_nm[0],
            g.thicknesses_nm[g.thicknesses_nm.len() - 1],
            SWATCH_ANGLES_DEG[0],
            SWATCH_ANGLES_DEG[1],
        );
        for b in &self.bases {
            let name = swatch_file(b.base.label);
            let _ = writeln!(w, "![base {}]({name})\n", b.base.label);
        }
        let _ = writeln!(
            w,
            "## Regenerating\n\n\
             ```sh\nnacre conformance{flag} -o DIR\n```\n\n\
             writes every file above into DIR at once (each to a temporary file first; existing files\n\
             are replaced only when all are written). The committed copy in `docs/conformance/` is\n\
             checked against the command by `crates/cli/tests/conformance.rs`."
        );
        s
    }
}

/// Whether a base label is a constant index (a number or `n+ki`) rather than a name.
fn is_numeric(label: &str) -> bool {
    label
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_digit() || c == '.')
}

/// The swatch chart's file name for a base.
pub fn swatch_file(label: &str) -> String {
    format!("swatches-{label}.png")
}

/// A linear value encoded with the sRGB transfer function (IEC 61966-2-1), clipped to
/// [0, 1], as 8 bits.
pub fn srgb_u8(linear: f64) -> u8 {
    let v = linear.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * elementary::powf(v, 1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_nest_and_hold_the_swatch_angles() {
        let [q, d, f] = [GridSize::Quick, GridSize::Default, GridSize::Fine].map(Grid::new);
        for (small, big) in [(&q, &d), (&d, &f)] {
            for (a, b) in [
                (&small.angles_deg, &big.angles_deg),
                (&small.thicknesses_nm, &big.thicknesses_nm),
                (&small.film_iors, &big.film_iors),
            ] {
                assert!(a.iter().all(|x| b.contains(x)), "{a:?} ⊄ {b:?}");
            }
        }
        for g in [&q, &d, &f] {
            assert!(SWATCH_ANGLES_DEG.iter().all(|a| g.angles_deg.contains(a)));
            assert_eq!(g.thicknesses_nm[0], 0.0);
            assert_eq!(*g.thicknesses_nm.last().unwrap(), 1200.0);
            assert_eq!((g.film_iors[0], *g.film_iors.last().unwrap()), (1.0, 2.333));
            let p = g.points();
            assert_eq!(p.len(), g.points_per_base());
            let (a, dd, n) = (2, 3, 1);
            let i = g.index(a, dd, n);
            assert_eq!(p[i].angle_deg, g.angles_deg[a]);
            assert_eq!(p[i].thickness_nm, Some(g.thicknesses_nm[dd]));
            assert_eq!(p[i].film_ior, Some(g.film_iors[n]));
        }
        assert_eq!(BASES.len() * d.points_per_base(), 48_510);
        assert_eq!(BASES.len() * f.points_per_base(), 202_730);
    }

    #[test]
    fn gltf_column_is_the_gaussian_method() {
        let set = compute(Grid::new(GridSize::Quick)).unwrap();
        let c = colorimeter();
        let points = set.grid.points();
        for b in set
            .bases
            .iter()
            .filter(|b| ["1.5", "au", "1"].contains(&b.base.label))
        {
            let base = nacre_format::materials::resolve(b.base.label, "test", None).unwrap();
            let stack = color::film_stack(
                Material::constant("1.0", C64::new(1.0, 0.0)).unwrap(),
                Material::constant("1.0", C64::new(1.0, 0.0)).unwrap(),
                0.0,
                vec![],
                base,
            )
            .unwrap();
            let got = color::evaluate(
                &stack,
                &points,
                &Method::GaussianFitBelcour2017,
                &c,
                Quantity::Reflectance,
                None,
            )
            .unwrap();
            assert_eq!(got, b.gltf, "{}", b.base.label);
            // The bare base's F0 at the film's zero thickness (film of the ambient index).
            let i = set.grid.index(0, 0, 0);
            for k in 0..3 {
                assert!((b.reference[i][k] - b.f0[k]).abs() < 1e-12);
            }
        }
        // Perfect agreement gives ΔE 0; the approximation is off somewhere on every base.
        assert!(set.bases.iter().all(|b| b.delta_e.iter().any(|&e| e > 1.0)));
    }

    #[test]
    fn srgb_encoding() {
        assert_eq!(srgb_u8(-1.0), 0);
        assert_eq!(srgb_u8(0.0), 0);
        assert_eq!(srgb_u8(1.0), 255);
        assert_eq!(srgb_u8(7.0), 255);
        assert_eq!(srgb_u8(0.18), 118);
        assert_eq!(srgb_u8(0.002), 7);
    }
}

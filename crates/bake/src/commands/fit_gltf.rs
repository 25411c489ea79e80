//! `nacre fit gltf`: the `KHR_materials_iridescence` material whose glTF reference
//! evaluation (`nacre color --method gaussian`, [`nacre_optics::fit::gltf`]) comes closest
//! in CIEDE2000 to the exact colour of a stack over 0–85°.
//!
//! The targets are the stack's exact reflected colours ([`color::Method::Spectral`]) in
//! linear sRGB under D65 (glTF's working space), at every [`ANGLES_DEG`] and, when the top
//! film's thickness varies over a range (a thickness texture), at [`RANGE_SAMPLES`] evenly
//! spaced texture values t ∈ [0, 1] (thickness START + t·(END − START)). The fit starts
//! from the naive mapping ([`naive`]) and is scored by the same code: mean and largest
//! ΔE2000 over the targets.

use crate::commands::color::{self, Method, Point, Quantity};
use crate::commands::fit_template::FitTemplate;
use crate::commands::grid::parse_thickness_nm;
use crate::error::{Error, Param, Result};
use nacre_optics::colour::{Colorimeter, Illuminant, Observer, OutputSpace, RgbSpace};
use nacre_optics::fit::FreeKind;
use nacre_optics::fit::gltf::{self, Errors, Fit, GltfBase, GltfFilm, Setup, Target};
use nacre_optics::{SpectralRule, Stack};

/// The incidence angles the error is taken over: 0–85° every 5°.
pub const ANGLES_DEG: [f64; 18] = [
    0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0, 60.0, 65.0, 70.0, 75.0,
    80.0, 85.0,
];

/// Thickness texture values sampled over a thickness range (t = 0, 1/8, …, 1).
pub const RANGE_SAMPLES: usize = 9;

/// A substrate whose extinction coefficient at 550 nm exceeds this is a conductor (a
/// metallic base); otherwise a dielectric (`KHR_materials_ior`).
pub const METAL_KAPPA: f64 = 0.5;

/// The thickest film the fit considers, nm, unless the stack's own film is thicker (then
/// 1.5 times that).
pub const MAX_THICKNESS_NM: f64 = 1000.0;

/// Parses the `--thicknesses START:END` range of the top film (nm; `START < END`).
pub fn parse_thickness_range(text: &str) -> Result<(f64, f64)> {
    let (a, b) = text.split_once(':').ok_or_else(|| {
        Error::value(
            Param::Thicknesses,
            text,
            "expected START:END in nm, e.g. 200:600 (the top film's thickness over its texture)",
        )
    })?;
    let (a, b) = (
        parse_thickness_nm(Param::Thicknesses, a)?,
        parse_thickness_nm(Param::Thicknesses, b)?,
    );
    if !(a < b) {
        return Err(Error::value(
            Param::Thicknesses,
            text,
            "START must be below END",
        ));
    }
    Ok((a, b))
}

/// The top film's thickness range of `template`, in the fit commands' one syntax: a range
/// on the top film's thickness (`--layer oil@200:800`, `thickness_nm = [200, 800]` in a
/// recipe: the film spans it, as a glTF thickness texture does) or `flag`
/// (`--thicknesses START:END`, the older spelling), not both. No other value of the stack
/// may be a range; a range whose ends are equal is the fixed thickness.
pub fn template_range(
    template: &FitTemplate,
    flag: Option<(f64, f64)>,
) -> Result<Option<(f64, f64)>> {
    let mut range = None;
    for (i, f) in template.free().iter().enumerate() {
        if f.layer == 1 && f.kind == FreeKind::ThicknessNm {
            range = (f.lo < f.hi).then_some((f.lo, f.hi));
        } else {
            return Err(Error::invalid(
                template.origin(i).clone(),
                "fit gltf takes a range only on the top film's thickness (the glTF film's thickness texture): give every other value one number",
            ));
        }
    }
    match (range, flag) {
        (Some((a, b)), Some(_)) => Err(Error::invalid(
            Param::Thicknesses,
            format!(
                "the top film already spans {a}:{b} nm: give the range once, on the layer (`@{a}:{b}`) or with --thicknesses"
            ),
        )),
        (Some(r), None) => Ok(Some(r)),
        (None, flag) => Ok(flag),
    }
}

/// The result of a fit: the fitted material, the naive one, and their errors.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfFitReport {
    /// The fitted material and its error.
    pub fit: Fit,
    /// The naive mapping.
    pub naive: GltfFilm,
    /// The naive mapping's error, by the same code.
    pub naive_errors: Errors,
    /// The targets (exact colours) both were scored against.
    pub targets: Vec<Target>,
}

/// The colorimeter of glTF's working space: CIE 1931, D65, linear sRGB.
pub fn gltf_colorimeter() -> Colorimeter {
    Colorimeter::new(
        Observer::Cie1931_2Deg,
        Illuminant::D65,
        OutputSpace::Rgb(RgbSpace::Srgb),
    )
}

/// The naive mapping of `stack`: `iridescenceIor` the top film's real index at 550 nm, its
/// thickness (or `range`) as minimum and maximum, factor 1, and the substrate as the base —
/// a dielectric of its real index at 550 nm, or (extinction above [`METAL_KAPPA`]) a metal
/// whose base colour is the bare substrate's exact normal-incidence colour (clamped to
/// 0–1), the F0 `nacre color --method gaussian` gives the film.
pub fn naive(
    stack: &Stack,
    range: Option<(f64, f64)>,
    colorimeter: &Colorimeter,
) -> Result<GltfFilm> {
    let top = stack.layers().first().ok_or_else(|| {
        Error::invalid(
            Param::Layer,
            "fitting a glTF film needs a stack with at least one film",
        )
    })?;
    let n = top.material.index_at(550.0)?;
    let (d0, d1) = range.unwrap_or((top.thickness_nm, top.thickness_nm));
    let substrate = stack.substrate().index_at(550.0)?;
    let base = if substrate.im > METAL_KAPPA {
        let bare = Stack::new(stack.ambient().clone(), vec![], stack.substrate().clone())?;
        let rule = SpectralRule::new(colorimeter, 0.0);
        let p = bare.sweep(&[0.0], rule.wavelengths_nm())?;
        let f0 = rule.colour(p.iter().map(|p| p.R()));
        GltfBase::Metal {
            base_colour: f0.map(|v| v.clamp(0.0, 1.0)),
        }
    } else {
        GltfBase::Dielectric {
            ior: substrate.re.max(1.0),
        }
    };
    Ok(GltfFilm {
        iridescence_ior: n.re.max(1.0),
        thickness_min_nm: d0,
        thickness_max_nm: d1,
        factor: 1.0,
        base,
    })
}

/// The exact colours of `stack` (reflectance, [`ANGLES_DEG`] × the range's samples) as
/// fit targets.
pub fn targets(
    stack: &Stack,
    range: Option<(f64, f64)>,
    colorimeter: &Colorimeter,
) -> Result<Vec<Target>> {
    let ts: Vec<f64> = match range {
        Some(_) => (0..RANGE_SAMPLES)
            .map(|k| k as f64 / (RANGE_SAMPLES - 1) as f64)
            .collect(),
        None => vec![1.0],
    };
    let mut points = Vec::with_capacity(ts.len() * ANGLES_DEG.len());
    let mut where_ = Vec::with_capacity(points.capacity());
    for &t in &ts {
        for &angle_deg in &ANGLES_DEG {
            points.push(Point {
                angle_deg,
                thickness_nm: range.map(|(a, b)| a + (b - a) * t),
                film_ior: None,
            });
            where_.push((angle_deg, t));
        }
    }
    let colours = color::evaluate(
        stack,
        &points,
        &Method::Spectral,
        colorimeter,
        Quantity::Reflectance,
        None,
    )?;
    Ok(where_
        .into_iter()
        .zip(colours)
        .map(|((angle_deg, t), c)| Target {
            angle_deg,
            t,
            lab: gltf::lab_of_output(colorimeter, c),
        })
        .collect())
}

/// Fits the glTF material closest to `stack` (its top film's thickness over `range` when
/// given) and scores the naive mapping beside it.
pub fn fit_gltf(stack: &Stack, range: Option<(f64, f64)>) -> Result<GltfFitReport> {
    let colorimeter = gltf_colorimeter();
    let naive = naive(stack, range, &colorimeter)?;
    let targets = targets(stack, range, &colorimeter)?;
    let max_thickness_nm =
        MAX_THICKNESS_NM.max(1.5 * naive.thickness_max_nm.max(naive.thickness_min_nm));
    let setup = Setup::new(naive, range.is_some(), max_thickness_nm);
    let naive_errors = gltf::errors(&naive, &targets, &colorimeter);
    let mut fit = gltf::fit(&targets, &colorimeter, &setup);
    // Scored as written (rounded); the naive mapping is one of the starts, kept should the
    // polish not beat it.
    fit.film = rounded(&fit.film);
    fit.errors = gltf::errors(&fit.film, &targets, &colorimeter);
    if naive_errors.mean < fit.errors.mean {
        fit.film = naive;
        fit.errors = naive_errors;
    }
    Ok(GltfFitReport {
        fit,
        naive,
        naive_errors,
        targets,
    })
}

/// Rounds to 4 significant figures for the JSON (as a glTF author would type them).
fn round4(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let digits = 3 - nacre_optics::elementary::log10(v.abs()).floor() as i32;
    let scale = nacre_optics::elementary::powi(10.0, digits);
    (v * scale).round() / scale
}

/// The glTF material object (with its extensions, ready to paste into `materials`) of
/// `film`; `name` is its name. A dielectric base has a black base colour (the film's
/// specular reflection alone: add a diffuse colour or transmission as the asset needs),
/// a metal's base colour is its F0. Values are rounded to 4 significant figures.
pub fn material_json(film: &GltfFilm, name: &str) -> serde_json::Value {
    use serde_json::json;
    let r = round4;
    let (base_colour, metallic, ior) = match film.base {
        GltfBase::Dielectric { ior } => ([0.0; 3], 0.0, Some(r(ior))),
        GltfBase::Metal { base_colour } => (base_colour.map(r), 1.0, None),
    };
    let mut extensions = serde_json::Map::new();
    extensions.insert(
        "KHR_materials_iridescence".into(),
        json!({
            "iridescenceFactor": r(film.factor),
            "iridescenceIor": r(film.iridescence_ior),
            "iridescenceThicknessMinimum": r(film.thickness_min_nm),
            "iridescenceThicknessMaximum": r(film.thickness_max_nm),
        }),
    );
    if let Some(ior) = ior {
        extensions.insert("KHR_materials_ior".into(), json!({ "ior": ior }));
    }
    json!({
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [base_colour[0], base_colour[1], base_colour[2], 1.0],
            "metallicFactor": metallic,
            "roughnessFactor": 0.0,
        },
        "extensions": extensions,
    })
}

/// The material as it is written: `film` rounded as [`material_json`] rounds it.
pub fn rounded(film: &GltfFilm) -> GltfFilm {
    let r = round4;
    GltfFilm {
        iridescence_ior: r(film.iridescence_ior),
        thickness_min_nm: r(film.thickness_min_nm),
        thickness_max_nm: r(film.thickness_max_nm),
        factor: r(film.factor),
        base: match film.base {
            GltfBase::Dielectric { ior } => GltfBase::Dielectric { ior: r(ior) },
            GltfBase::Metal { base_colour } => GltfBase::Metal {
                base_colour: base_colour.map(r),
            },
        },
    }
}

/// A one-line description of a material's parameters.
pub fn describe(film: &GltfFilm) -> String {
    let base = match film.base {
        GltfBase::Dielectric { ior } => format!("dielectric base ior {ior:.4}"),
        GltfBase::Metal { base_colour: c } => {
            format!("metal base colour ({:.3}, {:.3}, {:.3})", c[0], c[1], c[2])
        }
    };
    let d = if film.thickness_min_nm == film.thickness_max_nm {
        format!("{:.1} nm", film.thickness_max_nm)
    } else {
        format!(
            "{:.1}–{:.1} nm",
            film.thickness_min_nm, film.thickness_max_nm
        )
    };
    format!(
        "iridescenceIor {:.4}, thickness {d}, factor {:.3}, {base}",
        film.iridescence_ior, film.factor
    )
}

//! `fit_spectrum`, `fit_color` and `fit_gltf`: the computations of `nacre fit spectrum`,
//! `nacre fit color` and `nacre fit gltf` ([`fit_spectrum_cmd`], [`fit_color_cmd`],
//! [`fit_gltf_cmd`]) with numpy arrays instead of CSV files.
//! The template is read by the command line's own parser (`--layer sio2@50:400` texts, or
//! a template recipe); many spectra are fitted in parallel by [`fit_spectrum_cmd::fit_all`]
//! with the GIL released, each fit alone, so the results are the same whatever the thread
//! count. A colour design runs [`fit_color_cmd::design`], the command's own function, on
//! target rows made by [`fit_color_cmd::target_row`], the targets file's own conversion. The
//! public API and its docs are `fit_spectrum`/`fit_color`/`fit_gltf` in
//! `pysrc/nacre/_fit.py`.

use crate::errors::{Result, bake_err};
use crate::stack::{PyStack, database_of};
use nacre_bake::commands::color_request::{ColourSettings as ColourNames, colorimeter};
use nacre_bake::commands::fit_color as fit_color_cmd;
use nacre_bake::commands::fit_gltf as fit_gltf_cmd;
use nacre_bake::commands::fit_spectrum as fit_spectrum_cmd;
use nacre_bake::commands::fit_template::FitTemplate;
use nacre_bake::commands::stack_spec::TemplateSpec;
use nacre_bake::error::{Error, Param};
use nacre_optics::fit::gltf::{Errors, GltfBase, GltfFilm};
use nacre_optics::fit::{ColourSettings, FreeKind, Measurement, Quantity, Settings};
use numpy::ndarray::Array2;
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// The measured points of row `row` of `measured` (one spectrum per row), checked as
/// `nacre fit spectrum` checks a CSV's rows (finite numbers, positive wavelengths and σ,
/// angles inside (−90°, 90°), wavelengths increasing within an angle), each problem named
/// by its argument and index.
fn points(
    measured: &Array2<f64>,
    row: usize,
    wavelengths_nm: &[f64],
    angles_deg: &[f64],
    sigma: Option<&[f64]>,
) -> Result<Vec<Measurement>> {
    let name = |what: &str, i: usize| {
        if what == "measured" && measured.nrows() > 1 {
            format!("measured[{row}, {i}]")
        } else {
            format!("{what}[{i}]")
        }
    };
    let bad = |what: &str, i: usize, v: f64, m: &str| {
        Error::value(name(what, i), format!("{v}"), m.to_string())
    };
    let mut out = Vec::with_capacity(wavelengths_nm.len());
    let mut last: Option<(f64, f64)> = None;
    for (i, (&w, &a)) in wavelengths_nm.iter().zip(angles_deg).enumerate() {
        if !(w > 0.0 && w.is_finite()) {
            return Err(bad(
                "wavelengths_nm",
                i,
                w,
                "a wavelength must be positive and finite",
            ));
        }
        if !(a.abs() < 90.0) {
            return Err(bad(
                "angles_deg",
                i,
                a,
                "an angle must lie inside (−90°, 90°)",
            ));
        }
        let s = match sigma {
            Some(s) if !(s[i] > 0.0 && s[i].is_finite()) => {
                return Err(bad("sigma", i, s[i], "a sigma must be positive and finite"));
            }
            Some(s) => Some(s[i]),
            None => None,
        };
        if let Some((pa, pw)) = last
            && pa == a
            && w <= pw
        {
            let what = if w == pw { "repeats" } else { "comes after" };
            return Err(bad(
                "wavelengths_nm",
                i,
                w,
                &format!(
                    "{what} the point before's {pw} nm: within an angle the wavelengths must increase"
                ),
            ));
        }
        last = Some((a, w));
        let value = measured[[row, i]];
        if !value.is_finite() {
            return Err(bad(
                "measured",
                i,
                value,
                "a measured value must be a finite number",
            ));
        }
        out.push(Measurement {
            angle_deg: a,
            wavelength_nm: w,
            value,
            sigma: s,
        });
    }
    Ok(out)
}

/// The template: `recipe` (a template recipe file) or the stack flags' texts.
fn template(
    layers: Option<Vec<String>>,
    ambient: Option<String>,
    substrate: Option<String>,
    recipe: Option<PathBuf>,
    material_db: Option<PathBuf>,
) -> Result<FitTemplate> {
    let spec = match recipe {
        Some(path) => TemplateSpec::read(&path)?,
        None => TemplateSpec::from_flags(
            ambient.as_deref(),
            &layers.unwrap_or_default(),
            substrate.as_deref(),
        )?,
    };
    match database_of(material_db) {
        Some(db) => FitTemplate::build_with(spec, Some(&db)),
        None => FitTemplate::build(spec),
    }
}

/// The name of free parameter `f`, as the columns of `nacre fit spectrum`'s thickness map:
/// `layer1_thickness_nm`, `layer2_index`.
fn param_name(f: &nacre_optics::fit::Free) -> String {
    match f.kind {
        FreeKind::ThicknessNm => format!("layer{}_thickness_nm", f.layer),
        FreeKind::Index => format!("layer{}_index", f.layer),
    }
}

/// Fits the template's free parameters to every row of `measured` (spectra × points) at the
/// points `wavelengths_nm`, `angles_deg`, `sigma` (one per column), as `nacre fit spectrum`
/// does a wide CSV. Returns a dict of arrays, one row per spectrum: `x`, `sigma`, `rms`,
/// `chi2`, `points`, `scale`, `offset`, `iterations`, `starts`, `on_bound`, `fringes`,
/// `fitted`, and lists `params`, `ambiguous`, `warnings`, `recipes` (the TOML the command
/// writes with `-o`).
#[pyfunction]
#[pyo3(signature = (measured, wavelengths_nm, angles_deg, sigma, layers, ambient, substrate, recipe, material_db, quantity, scale, offset, fit_range, loss, starts, names))]
#[allow(clippy::too_many_arguments)]
pub fn fit_spectrum<'py>(
    py: Python<'py>,
    measured: PyReadonlyArray2<'py, f64>,
    wavelengths_nm: PyReadonlyArray1<'py, f64>,
    angles_deg: PyReadonlyArray1<'py, f64>,
    sigma: Option<PyReadonlyArray1<'py, f64>>,
    layers: Option<Vec<String>>,
    ambient: Option<String>,
    substrate: Option<String>,
    recipe: Option<PathBuf>,
    material_db: Option<PathBuf>,
    quantity: &str,
    scale: &str,
    offset: &str,
    fit_range: Option<String>,
    loss: &str,
    starts: usize,
    names: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let measured = measured.as_array().to_owned();
    let wavelengths = wavelengths_nm.as_array().to_vec();
    let angles = angles_deg.as_array().to_vec();
    let sigma = sigma.map(|s| s.as_array().to_vec());
    let columns = measured.ncols();
    for (what, len) in [
        ("wavelengths_nm", Some(wavelengths.len())),
        ("angles_deg", Some(angles.len())),
        ("sigma", sigma.as_ref().map(Vec::len)),
    ] {
        if let Some(len) = len
            && len != columns
        {
            return Err(bake_err(Error::value(
                what,
                format!("{len} values"),
                format!("expected one per measured point: {columns}"),
            )));
        }
    }
    let (quantity, scale, offset, loss, fit_range) = (
        quantity.to_string(),
        scale.to_string(),
        offset.to_string(),
        loss.to_string(),
        fit_range,
    );
    let computed = py.detach(move || -> Result<_> {
        let template = template(layers, ambient, substrate, recipe, material_db)?;
        let quantity = quantity_of(&quantity)?;
        let request = fit_spectrum_cmd::Request {
            settings: Settings {
                scale: fit_spectrum_cmd::parse_baseline(Param::Scale, &scale)?,
                offset: fit_spectrum_cmd::parse_baseline(Param::Offset, &offset)?,
                loss: fit_spectrum_cmd::parse_loss(&loss)?,
                starts: starts.max(1),
                ..Settings::default()
            },
            window: fit_range
                .as_deref()
                .map(fit_spectrum_cmd::parse_window)
                .transpose()?,
        };
        let spectra = (0..measured.nrows())
            .map(|row| {
                Ok(fit_spectrum_cmd::Spectrum {
                    name: names[row].clone(),
                    quantity,
                    points: points(&measured, row, &wavelengths, &angles, sigma.as_deref())?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let outcomes = fit_spectrum_cmd::fit_all(&template, &spectra, &request)?;
        let recipes = outcomes
            .iter()
            .map(|o| fit_spectrum_cmd::recipe_toml(&template, o))
            .collect::<Result<Vec<_>>>()?;
        Ok((template, outcomes, recipes))
    });
    let (template, outcomes, recipes) = computed.map_err(bake_err)?;
    let n = outcomes.len();
    let d = PyDict::new(py);
    let rows = |f: &dyn Fn(&fit_spectrum_cmd::Outcome) -> Vec<f64>| {
        let width = outcomes.first().map_or(0, |o| f(o).len());
        let flat: Vec<f64> = outcomes.iter().flat_map(f).collect();
        Array2::from_shape_vec((n, width), flat)
            .expect("every spectrum has the same parameters and points")
            .into_pyarray(py)
    };
    d.set_item(
        "params",
        template.free().iter().map(param_name).collect::<Vec<_>>(),
    )?;
    d.set_item("x", rows(&|o| o.fit.x.clone()))?;
    d.set_item("sigma", rows(&|o| o.fit.sigma.clone()))?;
    d.set_item("rms", rows(&|o| vec![o.fit.rms]))?;
    d.set_item("chi2", rows(&|o| vec![o.fit.chi2]))?;
    d.set_item("scale", rows(&|o| o.fit.scale.clone()))?;
    d.set_item("offset", rows(&|o| o.fit.offset.clone()))?;
    d.set_item("fringes", rows(&|o| o.fit.fringes.clone()))?;
    d.set_item("fitted", rows(&|o| o.fit.fitted.clone()))?;
    d.set_item(
        "points",
        outcomes.iter().map(|o| o.fit.points).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "iterations",
        outcomes
            .iter()
            .map(|o| o.fit.iterations)
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "starts",
        outcomes.iter().map(|o| o.fit.starts).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "on_bound",
        outcomes
            .iter()
            .map(|o| o.fit.on_bound.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "ambiguous",
        outcomes
            .iter()
            .map(|o| o.fit.ambiguous.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "warnings",
        outcomes
            .iter()
            .map(|o| fit_spectrum_cmd::warnings(&template, &o.fit))
            .collect::<Vec<_>>(),
    )?;
    d.set_item("recipes", recipes)?;
    Ok(d)
}

/// The quantity of `--quantity r|t`.
fn quantity_of(text: &str) -> Result<Quantity> {
    match text.trim() {
        "r" | "R" => Ok(Quantity::Reflectance),
        "t" | "T" => Ok(Quantity::Transmittance),
        other => Err(Error::value(Param::Quantity, other, "expected r or t")),
    }
}

/// The target rows of `targets` (rows × 3, the colour as `given`, named `given_name` in
/// messages), `angles_deg` and `weights` (one per row), checked and converted as
/// `nacre fit color` reads its targets file ([`fit_color_cmd::target_row`]); a problem
/// names the argument and row.
fn target_rows(
    targets: &Array2<f64>,
    given: fit_color_cmd::Given,
    given_name: &str,
    angles_deg: &[f64],
    weights: Option<&[f64]>,
    colorimeter: &nacre_optics::colour::Colorimeter,
) -> Result<Vec<fit_color_cmd::TargetRow>> {
    let n = targets.nrows();
    if n == 0 {
        return Err(Error::value(
            given_name,
            "no rows",
            "expected one target colour per row",
        ));
    }
    for (what, len) in [
        ("angles_deg", Some(angles_deg.len())),
        ("weights", weights.map(<[f64]>::len)),
    ] {
        if let Some(len) = len
            && len != n
        {
            return Err(Error::value(
                what,
                format!("{len} values"),
                format!("expected one per target row: {n}"),
            ));
        }
    }
    let finite = |name: String, v: f64| {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(Error::value(
                name,
                format!("{v}"),
                "expected a finite number",
            ))
        }
    };
    (0..n)
        .map(|i| {
            let angle = finite(format!("angles_deg[{i}]"), angles_deg[i])?;
            let weight = match weights {
                Some(w) => finite(format!("weights[{i}]"), w[i])?,
                None => 1.0,
            };
            let mut v = [0.0; 3];
            for (k, slot) in v.iter_mut().enumerate() {
                *slot = finite(format!("{given_name}[{i}, {k}]"), targets[[i, k]])?;
            }
            fit_color_cmd::target_row(i + 1, angle, given, v, weight, colorimeter).map_err(|bad| {
                let name = match bad.field {
                    "angle_deg" => format!("angles_deg[{i}]"),
                    "weight" => format!("weights[{i}]"),
                    _ => format!("{given_name}[{i}, 0]"),
                };
                Error::value(name, format!("{}", bad.value), bad.requirement)
            })
        })
        .collect()
}

/// Designs the template's free thicknesses and indices for the target colours `targets`
/// (rows × 3: linear R, G, B in `space`, X, Y, Z or L, a, b as `given` says) seen at
/// `angles_deg`, weighted by `weights`: `nacre fit color` through its own
/// [`fit_color_cmd::design`]. Returns a dict: `params`, per solution (best first) `x`
/// (solutions × params), `colour` and `lab` (solutions × rows × 3, by `nacre color`'s
/// spectral method), `delta_e` (solutions × rows), `iterations`, `recipes` (the TOML the
/// command writes with `-o`, naming the targets `targets_name`), `summary` (the lines the
/// command prints, a row named `lab[1]` instead of `line 4`), and `target_lab`, `target_colour` (rows × 3), `samples`, `starts`,
/// `reached_delta_e`.
#[pyfunction]
#[pyo3(signature = (targets, given, angles_deg, weights, layers, ambient, substrate, recipe, material_db, quantity, observer, illuminant, space, solutions, distinct_nm, starts, targets_name))]
#[allow(clippy::too_many_arguments)]
pub fn fit_color<'py>(
    py: Python<'py>,
    targets: PyReadonlyArray2<'py, f64>,
    given: &str,
    angles_deg: PyReadonlyArray1<'py, f64>,
    weights: Option<PyReadonlyArray1<'py, f64>>,
    layers: Option<Vec<String>>,
    ambient: Option<String>,
    substrate: Option<String>,
    recipe: Option<PathBuf>,
    material_db: Option<PathBuf>,
    quantity: &str,
    observer: Option<String>,
    illuminant: Option<String>,
    space: Option<String>,
    solutions: usize,
    distinct_nm: f64,
    starts: usize,
    targets_name: String,
) -> PyResult<Bound<'py, PyDict>> {
    let targets = targets.as_array().to_owned();
    let angles = angles_deg.as_array().to_vec();
    let weights = weights.map(|w| w.as_array().to_vec());
    let (given, given_name) = match given {
        "rgb" => (fit_color_cmd::Given::Rgb, "rgb"),
        "xyz" => (fit_color_cmd::Given::Xyz, "xyz"),
        "lab" => (fit_color_cmd::Given::Lab, "lab"),
        other => {
            return Err(bake_err(Error::value(
                "given",
                other,
                "expected rgb, xyz or lab",
            )));
        }
    };
    if targets.ncols() != 3 {
        return Err(bake_err(Error::value(
            given_name,
            format!("{} columns", targets.ncols()),
            "expected three per row",
        )));
    }
    let quantity = quantity.to_string();
    let computed = py.detach(move || -> Result<_> {
        let colorimeter = colorimeter(&ColourNames {
            observer: observer.as_deref(),
            illuminant: illuminant.as_deref(),
            space: space.as_deref(),
        })?;
        let settings = ColourSettings {
            quantity: quantity_of(&quantity)?,
            starts: starts.max(1),
            solutions: fit_color_cmd::parse_solutions(solutions)?,
            distinct_nm: fit_color_cmd::check_distinct(distinct_nm)?,
            ..ColourSettings::default()
        };
        let template = template(layers, ambient, substrate, recipe, material_db)?;
        let rows = target_rows(
            &targets,
            given,
            given_name,
            &angles,
            weights.as_deref(),
            &colorimeter,
        )?;
        let design = fit_color_cmd::design(&template, &rows, &colorimeter, &settings)?;
        let recipes = (0..design.solutions.len())
            .map(|k| {
                fit_color_cmd::recipe_toml(
                    &template,
                    &design,
                    k,
                    &rows,
                    &colorimeter,
                    &targets_name,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        // A row is named as its argument's: `lab[1]`.
        let place = |r: &fit_color_cmd::TargetRow| format!("{given_name}[{}]", r.line - 1);
        let summary = fit_color_cmd::describe(&template, &design, &rows, &place);
        Ok((template, rows, design, recipes, summary))
    });
    let (template, rows, design, recipes, summary) = computed.map_err(bake_err)?;
    let (k, n, p) = (design.solutions.len(), rows.len(), template.free().len());
    let per_row = |f: &dyn Fn(&fit_color_cmd::Achieved) -> &Vec<[f64; 3]>| {
        let flat: Vec<f64> = design
            .solutions
            .iter()
            .flat_map(|s| f(s).iter().flatten().copied())
            .collect();
        Array3::from_shape_vec((k, n, 3), flat)
            .expect("every solution has a colour per row")
            .into_pyarray(py)
    };
    let rows_of = |f: &dyn Fn(&fit_color_cmd::TargetRow) -> [f64; 3]| {
        let flat: Vec<f64> = rows.iter().flat_map(f).collect();
        Array2::from_shape_vec((n, 3), flat)
            .expect("three values per row")
            .into_pyarray(py)
    };
    let flat_x: Vec<f64> = design.solutions.iter().flat_map(|s| s.x.clone()).collect();
    let flat_e: Vec<f64> = design
        .solutions
        .iter()
        .flat_map(|s| s.delta_e.clone())
        .collect();
    let d = PyDict::new(py);
    d.set_item(
        "params",
        template.free().iter().map(param_name).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "x",
        Array2::from_shape_vec((k, p), flat_x)
            .expect("every solution has the template's parameters")
            .into_pyarray(py),
    )?;
    d.set_item("colour", per_row(&|s| &s.colour))?;
    d.set_item("lab", per_row(&|s| &s.lab))?;
    d.set_item(
        "delta_e",
        Array2::from_shape_vec((k, n), flat_e)
            .expect("every solution has a ΔE2000 per row")
            .into_pyarray(py),
    )?;
    d.set_item(
        "iterations",
        design
            .solutions
            .iter()
            .map(|s| s.iterations)
            .collect::<Vec<_>>(),
    )?;
    d.set_item("target_lab", rows_of(&|r| r.lab))?;
    d.set_item("target_colour", rows_of(&|r| r.colour))?;
    d.set_item("samples", design.samples)?;
    d.set_item("starts", design.starts)?;
    d.set_item("reached_delta_e", nacre_optics::fit::color::REACHED_DELTA_E)?;
    d.set_item("recipes", recipes)?;
    d.set_item("summary", summary)?;
    Ok(d)
}

/// A glTF film as a dict: `iridescence_ior`, `thickness_min_nm`, `thickness_max_nm`,
/// `factor`, and `base_ior` (dielectric) or `base_colour` (metal).
fn film_dict<'py>(py: Python<'py>, film: &GltfFilm) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iridescence_ior", film.iridescence_ior)?;
    d.set_item("thickness_min_nm", film.thickness_min_nm)?;
    d.set_item("thickness_max_nm", film.thickness_max_nm)?;
    d.set_item("factor", film.factor)?;
    match film.base {
        GltfBase::Dielectric { ior } => d.set_item("base_ior", ior)?,
        GltfBase::Metal { base_colour } => d.set_item("base_colour", base_colour.to_vec())?,
    }
    Ok(d)
}

fn errors_dict<'py>(py: Python<'py>, e: &Errors) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("mean", e.mean)?;
    d.set_item("max", e.max)?;
    Ok(d)
}

/// The closest `KHR_materials_iridescence` material to `stack` (its top film's thickness
/// over `thicknesses`, START:END nm, when given): [`fit_gltf_cmd::fit_gltf`]. Returns a dict:
/// `film` and `naive` (film dicts), `errors` and `naive_errors` (ΔE2000 `mean`, `max`),
/// `evaluations`, and `material_json` (the text `nacre fit gltf -o` writes).
#[pyfunction]
#[pyo3(signature = (stack, thicknesses=None))]
pub fn fit_gltf<'py>(
    py: Python<'py>,
    stack: &PyStack,
    thicknesses: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = stack.stack.clone();
    let (report, json) = py
        .detach(move || -> Result<_> {
            let range = thicknesses
                .as_deref()
                .map(fit_gltf_cmd::parse_thickness_range)
                .transpose()?;
            let report = fit_gltf_cmd::fit_gltf(&s, range)?;
            let json = fit_gltf_cmd::material_json(&report.fit.film, "nacre fit gltf");
            let mut text = serde_json::to_string_pretty(&json)
                .map_err(|e| Error::invalid(Param::Output, e.to_string()))?;
            text.push('\n');
            Ok((report, text))
        })
        .map_err(bake_err)?;
    let d = PyDict::new(py);
    d.set_item("film", film_dict(py, &report.fit.film)?)?;
    d.set_item("errors", errors_dict(py, &report.fit.errors)?)?;
    d.set_item("evaluations", report.fit.evaluations)?;
    d.set_item("naive", film_dict(py, &report.naive)?)?;
    d.set_item("naive_errors", errors_dict(py, &report.naive_errors)?)?;
    d.set_item("material_json", json)?;
    Ok(d)
}

//! `spectrum`, `color`, `bake` and `conformance`: the library functions behind the `nacre`
//! binary's commands of the same names, with numpy arrays instead of CSV files. The GIL is
//! released while they run; the libraries parallelise with rayon.

use crate::errors::{Result, bake_err};
use crate::stack::PyStack;
use nacre_bake::commands::color::{self as color_cmd, Method, Point, Quantity};
use nacre_bake::commands::color_request::{self as request, ColorRequest, ColourSettings};
use nacre_bake::commands::conformance::{self as conformance_cmd, BASES, Grid, GridSize};
use nacre_bake::commands::spectrum as spectrum_cmd;
use nacre_bake::error::{Error, Param};
use nacre_optics::Power;
use numpy::ndarray::{Array, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyReadonlyArray1, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::path::PathBuf;

/// An array of `shape` from `values` (row-major), handed to numpy without a copy.
fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    shape: &[usize],
    values: Vec<T>,
) -> Bound<'py, PyArrayDyn<T>> {
    Array::from_shape_vec(IxDyn(shape), values)
        .expect("shape matches the values")
        .into_pyarray(py)
}

fn vec_of(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().to_vec()
}

// A `Power` is four `f64` (`#[repr(C)]`: R_s, R_p, T_s, T_p).
const _: () = assert!(
    std::mem::size_of::<Power>() == 4 * std::mem::size_of::<f64>()
        && std::mem::align_of::<Power>() == std::mem::align_of::<f64>()
);

/// The powers as `4 n` floats (R_s, R_p, T_s, T_p per element), without copying.
fn powers_as_floats(powers: Vec<Power>) -> Vec<f64> {
    let mut powers = std::mem::ManuallyDrop::new(powers);
    let (ptr, len, cap) = (powers.as_mut_ptr(), powers.len(), powers.capacity());
    // SAFETY: `Power` is `#[repr(C)]` with four `f64` fields, no padding (size and
    // alignment asserted above), so `cap` powers are `4 cap` floats in the same allocation
    // with the same layout (size 32 cap, alignment 8); the original vector is not dropped.
    unsafe { Vec::from_raw_parts(ptr.cast::<f64>(), 4 * len, 4 * cap) }
}

/// Unpolarised reflectance, transmittance and absorptance ([`Power::R`], [`Power::T`],
/// [`Power::A`]) of an array of powers whose last axis holds (R_s, R_p, T_s, T_p): three
/// arrays of the other axes' shape.
#[pyfunction]
pub fn unpolarised<'py>(
    py: Python<'py>,
    powers: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<Vec<Bound<'py, PyArrayDyn<f64>>>> {
    let shape = powers.shape().to_vec();
    let (last, rest) = shape.split_last().unzip();
    if last != Some(&4) {
        return Err(bake_err(Error::value(
            "powers",
            format!("{shape:?}"),
            "expected an array whose last axis holds R_s, R_p, T_s, T_p",
        )));
    }
    let values = powers.as_array();
    let floats: Vec<f64> = match values.as_slice() {
        Some(s) => s.to_vec(),
        None => values.iter().copied().collect(),
    };
    let (r, t, a) = py.detach(|| {
        let p: Vec<Power> = floats
            .chunks_exact(4)
            .map(|c| Power {
                R_s: c[0],
                R_p: c[1],
                T_s: c[2],
                T_p: c[3],
            })
            .collect();
        let r = p.par_iter().map(Power::R).collect();
        let t = p.par_iter().map(Power::T).collect();
        let a = p.par_iter().map(Power::A).collect();
        (r, t, a)
    });
    let rest = rest.unwrap_or(&[]);
    Ok(vec![
        array(py, rest, r),
        array(py, rest, t),
        array(py, rest, a),
    ])
}

/// Reflectance and transmittance of `stack` over angle × wavelength (× thickness of film
/// `layer` when `thickness_nm` is given): one array of shape (angles, wavelengths[,
/// thicknesses], 4) holding R_s, R_p, T_s, T_p (the sweep's own memory, not copied). The computation of `nacre spectrum`
/// ([`spectrum_cmd::compute`], [`spectrum_cmd::compute_thickness`]). With it, the warnings
/// `nacre spectrum` prints: the coherent films whose fringes the wavelength grid cannot
/// follow ([`nacre_optics::Stack::undersampled_films`]; not for a thickness sweep).
#[pyfunction]
#[pyo3(signature = (stack, angles_deg, wavelengths_nm, thickness_nm=None, layer=1))]
pub fn spectrum<'py>(
    py: Python<'py>,
    stack: &PyStack,
    angles_deg: PyReadonlyArray1<'py, f64>,
    wavelengths_nm: PyReadonlyArray1<'py, f64>,
    thickness_nm: Option<PyReadonlyArray1<'py, f64>>,
    layer: usize,
) -> PyResult<(Bound<'py, PyArrayDyn<f64>>, Vec<String>)> {
    let angles = vec_of(&angles_deg);
    let wavelengths = vec_of(&wavelengths_nm);
    let thicknesses = thickness_nm.as_ref().map(vec_of);
    let s = stack.stack.clone();
    let mut shape = vec![angles.len(), wavelengths.len()];
    if let Some(d) = &thicknesses {
        shape.push(d.len());
    }
    shape.push(4);
    let (powers, warnings) = py
        .detach(|| -> Result<_> {
            let (powers, warnings) = match &thicknesses {
                None => (
                    spectrum_cmd::compute(&s, &angles, &wavelengths)?,
                    undersampled(&s, &wavelengths),
                ),
                Some(d) => (
                    spectrum_cmd::compute_thickness(&s, layer, &angles, &wavelengths, d)?,
                    Vec::new(),
                ),
            };
            Ok((powers_as_floats(powers), warnings))
        })
        .map_err(bake_err)?;
    Ok((array(py, &shape, powers), warnings))
}

/// The texts of `nacre spectrum`'s undersampling warnings for `stack` on `wavelengths_nm`.
fn undersampled(stack: &nacre_optics::Stack, wavelengths_nm: &[f64]) -> Vec<String> {
    stack
        .undersampled_films(wavelengths_nm)
        .iter()
        .map(ToString::to_string)
        .collect()
}

/// [`spectrum`] with the exact derivatives of the powers by every film's thickness (the
/// computation of `nacre spectrum --jacobian`, [`spectrum_cmd::compute_jacobian`]): the powers,
/// shape (angles, wavelengths, 4), and ∂R_s, ∂R_p, ∂T_s, ∂T_p per nm of each film's thickness
/// (top film first), shape (angles, wavelengths, films, 4); and the undersampling warnings.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn spectrum_jacobian<'py>(
    py: Python<'py>,
    stack: &PyStack,
    angles_deg: PyReadonlyArray1<'py, f64>,
    wavelengths_nm: PyReadonlyArray1<'py, f64>,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Vec<String>,
)> {
    let angles = vec_of(&angles_deg);
    let wavelengths = vec_of(&wavelengths_nm);
    let s = stack.stack.clone();
    let films = s.layers().len();
    let (powers, d_thickness, warnings) = py
        .detach(|| -> Result<_> {
            let (powers, jacobian) = spectrum_cmd::compute_jacobian(&s, &angles, &wavelengths)?;
            Ok((
                powers_as_floats(powers),
                powers_as_floats(jacobian.d_thickness),
                undersampled(&s, &wavelengths),
            ))
        })
        .map_err(bake_err)?;
    let (na, nw) = (angles.len(), wavelengths.len());
    Ok((
        array(py, &[na, nw, 4], powers),
        array(py, &[na, nw, films, 4], d_thickness),
        warnings,
    ))
}

/// The points of `color`: each angle, with the first film's thickness and real index
/// overridden where given. Checked as `nacre color --points` checks its rows.
fn points(
    angles: &[f64],
    thickness: Option<&[f64]>,
    film_ior: Option<&[f64]>,
) -> Result<Vec<Point>> {
    angles
        .iter()
        .enumerate()
        .map(|(i, &angle_deg)| {
            let point = Point {
                angle_deg,
                thickness_nm: thickness.map(|d| d[i]),
                film_ior: film_ior.map(|n| n[i]),
            };
            point.check().map_err(|problem| {
                let param = match problem.column {
                    "angle_deg" => Param::Angles,
                    "thickness_nm" => Param::Thickness,
                    _ => Param::FilmIors,
                };
                Error::value(param, problem.value.to_string(), problem.requirement)
            })?;
            Ok(point)
        })
        .collect()
}

/// The colour of `stack` at each point by `method` (every method of `nacre color`), through
/// [`request::prepare`] and [`request::compute`]. Returns `(xyz, rgb, thickness_nm,
/// film_ior, monte_carlo)`: XYZ and output-space colours (n, 3), the first film's thickness
/// and real index at each point (the CSV's columns), for `rough-mc` the samples per point
/// and the largest standard error, and the undersampling warnings `nacre color` prints.
#[pyfunction]
#[pyo3(signature = (stack, angles_deg, thickness_nm=None, film_ior=None, method="spectral", quantity="r", observer=None, illuminant=None, space=None, roughness=None, fourier_table=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn color<'py>(
    py: Python<'py>,
    stack: &PyStack,
    angles_deg: PyReadonlyArray1<'py, f64>,
    thickness_nm: Option<PyReadonlyArray1<'py, f64>>,
    film_ior: Option<PyReadonlyArray1<'py, f64>>,
    method: &str,
    quantity: &str,
    observer: Option<&str>,
    illuminant: Option<&str>,
    space: Option<&str>,
    roughness: Option<f64>,
    fourier_table: Option<PathBuf>,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Option<(usize, f64)>,
    Vec<String>,
)> {
    let angles = vec_of(&angles_deg);
    let thickness = thickness_nm.as_ref().map(vec_of);
    let film_ior = film_ior.as_ref().map(vec_of);
    let fourier_table = fourier_table.map(|p| p.to_string_lossy().into_owned());
    let s = stack.stack.clone();
    let (xyz, rgb, d, n, mc, warnings) = py
        .detach(|| -> Result<_> {
            let quantity = match quantity.trim().to_ascii_lowercase().as_str() {
                "r" | "reflectance" => Quantity::Reflectance,
                "t" | "transmittance" => Quantity::Transmittance,
                _ => {
                    return Err(Error::value(
                        Param::Quantity,
                        quantity,
                        "expected 'r' (reflectance) or 't' (transmittance)",
                    ));
                }
            };
            let points = points(&angles, thickness.as_deref(), film_ior.as_deref())?;
            let parsed = Method::parse(method)?;
            let prepared = request::prepare(
                &s,
                parsed,
                &ColorRequest {
                    method,
                    roughness,
                    colour: ColourSettings {
                        observer,
                        illuminant,
                        space,
                    },
                    fourier_table: fourier_table.as_deref(),
                },
            )?;
            let out = request::compute(&s, &points, &prepared, quantity)?;
            let mut xyz = Vec::with_capacity(3 * points.len());
            let mut rgb = Vec::with_capacity(3 * points.len());
            let mut d = Vec::with_capacity(points.len());
            let mut n = Vec::with_capacity(points.len());
            for (p, c) in points.iter().zip(&out.colours) {
                xyz.extend(color_cmd::output_to_xyz(&prepared.colorimeter, *c));
                rgb.extend(c);
                let (dp, np) = color_cmd::film_columns(&s, p);
                d.push(dp);
                n.push(np);
            }
            let warnings = out.undersampled.iter().map(ToString::to_string).collect();
            Ok((xyz, rgb, d, n, out.monte_carlo, warnings))
        })
        .map_err(bake_err)?;
    let len = d.len();
    Ok((
        array(py, &[len, 3], xyz),
        array(py, &[len, 3], rgb),
        array(py, &[len], d),
        array(py, &[len], n),
        mc,
        warnings,
    ))
}

/// Bakes each recipe into `out_dir` (the work of `nacre bake RECIPE… --out DIR`); returns
/// the manifests written. Every recipe is read and checked before any is baked.
#[pyfunction]
pub fn bake(py: Python<'_>, recipes: Vec<PathBuf>, out_dir: PathBuf) -> PyResult<Vec<PathBuf>> {
    py.detach(|| -> Result<_> {
        let recipes = recipes
            .iter()
            .map(|p| nacre_bake::kinds::read_recipe(p))
            .collect::<Result<Vec<_>>>()?;
        recipes
            .iter()
            .map(|r| r.bake(&out_dir, &|| {}))
            .collect::<Result<Vec<_>>>()
    })
    .map_err(bake_err)
}

/// The rows of `nacre conformance`'s `conformance.csv` and `gltf-reference-error.csv` as
/// arrays: `base_ior` (labels), `angle_deg`, `thickness_nm`, `film_ior`, `xyz` and `rgb`
/// (rows, 3) of the exact reference, `gltf_rgb` (rows, 3) and `delta_e_2000` of glTF's
/// approximation. `grid` is `quick`, `default` or `fine`.
#[pyfunction]
#[pyo3(signature = (grid="default"))]
pub fn conformance<'py>(py: Python<'py>, grid: &str) -> PyResult<Bound<'py, PyDict>> {
    let size = match grid {
        "quick" => GridSize::Quick,
        "default" => GridSize::Default,
        "fine" => GridSize::Fine,
        other => {
            return Err(bake_err(Error::value(
                "grid",
                other,
                "expected 'quick', 'default' or 'fine'",
            )));
        }
    };
    let set = py
        .detach(|| conformance_cmd::compute(Grid::new(size)))
        .map_err(bake_err)?;
    let points = set.grid.points();
    let rows = set.bases.len() * points.len();
    let mut labels = Vec::with_capacity(rows);
    let (mut a, mut d, mut n) = (
        Vec::with_capacity(rows),
        Vec::with_capacity(rows),
        Vec::with_capacity(rows),
    );
    let (mut xyz, mut rgb, mut gltf, mut de) = (
        Vec::with_capacity(3 * rows),
        Vec::with_capacity(3 * rows),
        Vec::with_capacity(3 * rows),
        Vec::with_capacity(rows),
    );
    for b in &set.bases {
        for (i, p) in points.iter().enumerate() {
            labels.push(b.base.label);
            a.push(p.angle_deg);
            d.push(p.thickness_nm.unwrap_or(0.0));
            n.push(p.film_ior.unwrap_or(1.0));
            xyz.extend(set.colorimeter.xyz_from_output(b.reference[i]));
            rgb.extend(b.reference[i]);
            gltf.extend(b.gltf[i]);
            de.push(b.delta_e[i]);
        }
    }
    debug_assert_eq!(set.bases.len(), BASES.len());
    let out = PyDict::new(py);
    out.set_item("base_ior", labels)?;
    out.set_item("angle_deg", array(py, &[rows], a))?;
    out.set_item("thickness_nm", array(py, &[rows], d))?;
    out.set_item("film_ior", array(py, &[rows], n))?;
    out.set_item("xyz", array(py, &[rows, 3], xyz))?;
    out.set_item("rgb", array(py, &[rows, 3], rgb))?;
    out.set_item("gltf_rgb", array(py, &[rows, 3], gltf))?;
    out.set_item("delta_e_2000", array(py, &[rows], de))?;
    Ok(out)
}

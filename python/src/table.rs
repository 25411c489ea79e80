//! `nacre.Table`: a baked table read through its manifest, its texels, and the CPU lookups
//! that reproduce what a GPU samples (the code behind `nacre color --method lut:` and
//! `rough-lut:`).

use crate::errors::{Result, bake_err};
use nacre_bake::commands::color::LoadedLut;
use nacre_bake::error::{Error, Param};
use nacre_format::film_lut::FilmLut;
use nacre_format::fourier::FourierTable;
use nacre_format::load::LoadedRoughLut;
use nacre_format::rough_film_lut::RoughFilmLut;
use nacre_format::table_io::Table3;
use nacre_format::{Manifest, set};
use num_complex::Complex64;
use numpy::ndarray::{Array, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyReadonlyArray1};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::PathBuf;

/// What a table kind gives on the CPU.
enum Data {
    /// A `film-lut`: trilinear lookups ([`FilmLut::lookup`]).
    Film(Box<LoadedLut>),
    /// A `rough-film-lut`: lookups at a roughness ([`RoughFilmLut::lookup`]).
    Rough(Box<LoadedRoughLut>),
    /// A `fourier` table: samples of the sensitivities' transforms ([`FourierTable::sample`]).
    Fourier(Box<FourierTable>),
    /// Another kind (`diffraction`): the manifest only.
    Manifest,
}

/// A baked table (film-lut, rough-film-lut, fourier or diffraction), loaded through its
/// manifest.
#[pyclass(frozen, module = "nacre._nacre", name = "Table")]
pub struct PyTable {
    path: PathBuf,
    manifest: Manifest,
    data: Data,
}

fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    shape: &[usize],
    values: Vec<T>,
) -> Bound<'py, PyArrayDyn<T>> {
    Array::from_shape_vec(IxDyn(shape), values)
        .expect("shape matches the values")
        .into_pyarray(py)
}

/// Lookup coordinates must be finite (a huge value clamps to the table's edge).
fn finite(param: Param, values: &[f64]) -> Result<()> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(Error::value(
            param,
            v.to_string(),
            "lookup coordinates must be finite",
        )),
        None => Ok(()),
    }
}

impl PyTable {
    fn quantity_table(&self, quantity: &str) -> Result<&Table3> {
        let (reflectance, transmittance) = match &self.data {
            Data::Film(l) => (&l.reflectance, l.transmittance.as_ref()),
            Data::Rough(l) => (&l.lut.reflectance, l.lut.transmittance.as_ref()),
            _ => {
                return Err(Error::invalid(
                    self.path.display().to_string(),
                    format!(
                        "table `{}` is a `{}` table; texels and lookups are for film-lut and rough-film-lut tables",
                        self.manifest.name, self.manifest.kind
                    ),
                ));
            }
        };
        match quantity {
            "reflectance" | "r" => Ok(reflectance),
            "transmittance" | "t" => transmittance.ok_or_else(|| {
                Error::invalid(
                    Param::Quantity.given(quantity),
                    format!("table `{}` has no transmittance", self.manifest.name),
                )
            }),
            other => Err(Error::value(
                Param::Quantity,
                other,
                "expected 'reflectance' or 'transmittance'",
            )),
        }
    }
}

#[pymethods]
impl PyTable {
    /// Loads a table: a default-set name (`soap-film`, `film-dielectric`, …, from the
    /// `tables/baked/` folder of the working directory or of the checkout nacre was built
    /// from) or the path of a manifest (`.json`).
    #[staticmethod]
    fn load(py: Python<'_>, name_or_manifest: PathBuf) -> PyResult<Self> {
        let text = name_or_manifest.to_string_lossy().into_owned();
        py.detach(|| -> Result<Self> {
            let path = set::resolve_table(&text);
            let manifest = Manifest::read(&path)?;
            let data = if manifest.film_lut().is_some() {
                Data::Film(Box::new(LoadedLut::load(&path)?))
            } else if manifest.rough_film_lut().is_some() {
                Data::Rough(Box::new(LoadedRoughLut::load(&path)?))
            } else if manifest.fourier().is_some() {
                Data::Fourier(Box::new(manifest.load_fourier(&path)?))
            } else {
                Data::Manifest
            };
            Ok(PyTable {
                path,
                manifest,
                data,
            })
        })
        .map_err(bake_err)
    }

    /// The manifest's path.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The table's name.
    #[getter]
    fn name(&self) -> String {
        self.manifest.name.clone()
    }

    /// The table's kind: `film-lut`, `fourier`, `rough-film-lut` or `diffraction`.
    #[getter]
    fn kind(&self) -> String {
        self.manifest.kind.to_string()
    }

    /// The manifest as JSON text (what `nacre info` prints).
    #[getter]
    fn manifest_json(&self) -> String {
        serde_json::to_string(&self.manifest).expect("manifest serialises")
    }

    /// The quantities with texels: `reflectance`, and `transmittance` where baked.
    #[getter]
    fn quantities(&self) -> Vec<&'static str> {
        let t = match &self.data {
            Data::Film(l) => l.transmittance.is_some(),
            Data::Rough(l) => l.lut.transmittance.is_some(),
            _ => return vec![],
        };
        if t {
            vec!["reflectance", "transmittance"]
        } else {
            vec!["reflectance"]
        }
    }

    /// The texels of `quantity` as float32, shape (z, y, x, 3) (the table's memory order,
    /// x fastest: for a film-lut z = film index, y = optical path difference, x = cos θ).
    #[pyo3(signature = (quantity="reflectance"))]
    fn texels<'py>(
        &self,
        py: Python<'py>,
        quantity: &str,
    ) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let t = self.quantity_table(quantity).map_err(bake_err)?;
        Ok(array(py, &[t.nz, t.ny, t.nx, 3], t.data.clone()))
    }

    /// The colour at each (cos θ, thickness_nm, film_ior) exactly as a GPU samples the
    /// table (trilinear, clamp to edge; a rough-film-lut also mixes the two α blocks around
    /// `roughness`), shape (n, 3).
    #[pyo3(signature = (cos_theta, thickness_nm, film_ior, quantity="reflectance", roughness=None))]
    fn lookup<'py>(
        &self,
        py: Python<'py>,
        cos_theta: PyReadonlyArray1<'py, f64>,
        thickness_nm: PyReadonlyArray1<'py, f64>,
        film_ior: PyReadonlyArray1<'py, f64>,
        quantity: &str,
        roughness: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let c = cos_theta.as_array().to_vec();
        let d = thickness_nm.as_array().to_vec();
        let n = film_ior.as_array().to_vec();
        let alpha = roughness.map(|a| a.as_array().to_vec());
        let out = py
            .detach(|| -> Result<Vec<[f64; 3]>> {
                let table = self.quantity_table(quantity)?;
                finite(Param::Angles, &c)?;
                finite(Param::Thickness, &d)?;
                finite(Param::FilmIors, &n)?;
                match (&self.data, &alpha) {
                    (Data::Film(l), None) => {
                        let axes = l.manifest.film_lut().expect("a film-lut");
                        Ok((0..c.len())
                            .into_par_iter()
                            .map(|i| FilmLut::lookup(axes, table, c[i], d[i], n[i]))
                            .collect())
                    }
                    (Data::Rough(l), Some(a)) => {
                        finite(Param::Roughness, a)?;
                        Ok((0..c.len())
                            .into_par_iter()
                            .map(|i| {
                                RoughFilmLut::lookup(&l.lut.axes, table, c[i], a[i], d[i], n[i])
                            })
                            .collect())
                    }
                    (Data::Film(_), Some(_)) => Err(Error::invalid(
                        Param::Roughness,
                        format!(
                            "table `{}` is a film-lut, which has no roughness axis",
                            self.manifest.name
                        ),
                    )),
                    _ => Err(Error::invalid(
                        Param::Roughness,
                        format!(
                            "table `{}` is a rough-film-lut: give roughness (GGX α)",
                            self.manifest.name
                        ),
                    )),
                }
            })
            .map_err(bake_err)?;
        let len = out.len();
        Ok(array(py, &[len, 3], out.into_iter().flatten().collect()))
    }

    /// A `fourier` table's transforms Ŝ_j at optical path differences `mu_nm`, prefiltered
    /// for standard deviations `sigma_mu_nm` (nm in μ), exactly as a GPU samples the mip
    /// chain ([`FourierTable::sample`]), complex, shape (n, 3).
    fn sample<'py>(
        &self,
        py: Python<'py>,
        mu_nm: PyReadonlyArray1<'py, f64>,
        sigma_mu_nm: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<Complex64>>> {
        let mu = mu_nm.as_array().to_vec();
        let sigma = sigma_mu_nm.as_array().to_vec();
        let out = py
            .detach(|| -> Result<Vec<Complex64>> {
                let Data::Fourier(t) = &self.data else {
                    return Err(Error::invalid(
                        self.path.display().to_string(),
                        format!(
                            "table `{}` is a `{}` table, not a fourier table",
                            self.manifest.name, self.manifest.kind
                        ),
                    ));
                };
                finite(Param::MaxOpd, &mu)?;
                finite(Param::MaxOpd, &sigma)?;
                Ok((0..mu.len())
                    .into_par_iter()
                    .flat_map_iter(|i| {
                        t.sample(mu[i], sigma[i])
                            .map(|c| Complex64::new(c.re, c.im))
                    })
                    .collect())
            })
            .map_err(bake_err)?;
        let len = out.len() / 3;
        Ok(array(py, &[len, 3], out))
    }

    fn __repr__(&self) -> String {
        format!(
            "Table(name={:?}, kind={:?}, path={:?})",
            self.manifest.name,
            self.manifest.kind.to_string(),
            self.path.display().to_string()
        )
    }
}

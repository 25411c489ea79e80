//! `nacre.Stack`: an ambient medium, films (top first) and a substrate, from the material
//! specifications the command line takes (`nacre spectrum --ambient/--layer/--substrate`):
//! numbers, complex numbers, bundled names, `.yml`/`.csv` paths and refractiveindex.info
//! pages `SHELF/BOOK/PAGE` of a local database.

use crate::errors::{Result, bake_err};
use nacre_bake::commands::stack_spec::{StackRecipe, parse_layer};
use nacre_bake::error::{Error, Origin, Param};
use nacre_format::materials::{MaterialDb, resolve_with};
use nacre_optics::{Layer, Material, Stack};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyComplex, PyString, PyTuple};
use std::path::PathBuf;
use std::sync::Arc;

/// A material argument: its specification text, or an index given as a Python number.
pub enum MaterialArg {
    /// A number or complex number, written as the command line would take it (`1.33`,
    /// `0.27+2.9i`): the material is named by this text.
    Index(String),
    /// A name, path or database page.
    Spec(String),
}

impl MaterialArg {
    /// Reads a Python material: `str`, `os.PathLike`, `int`/`float` or `complex`.
    pub fn extract(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        if obj.is_instance_of::<PyBool>() {
            return Err(PyTypeError::new_err(
                "a material is a number, a complex number, a name or a path, not a bool",
            ));
        }
        if obj.is_instance_of::<PyString>() {
            return Ok(MaterialArg::Spec(obj.extract::<String>()?));
        }
        if let Ok(c) = obj.cast::<PyComplex>() {
            let (re, im) = (c.real(), c.imag());
            // κ < 0 is written with its sign so that the core's message names it.
            let text = if im.is_sign_negative() && im != 0.0 {
                format!("{re}-{}i", -im)
            } else {
                format!("{re}+{}i", im.abs())
            };
            return Ok(MaterialArg::Index(text));
        }
        if let Ok(v) = obj.extract::<f64>() {
            return Ok(MaterialArg::Index(format!("{v}")));
        }
        let os = obj.py().import("os")?;
        if let Ok(path) = os.call_method1("fspath", (obj,)) {
            let path: PathBuf = path.extract()?;
            return Ok(MaterialArg::Spec(path.to_string_lossy().into_owned()));
        }
        Err(PyTypeError::new_err(format!(
            "a material is a number, a complex number, a name (str) or a path, not {}",
            obj.get_type().name()?
        )))
    }

    /// Loads the material; `context` names the argument in messages.
    pub fn load(&self, context: Origin, db: Option<&MaterialDb>) -> Result<Material> {
        match self {
            MaterialArg::Index(text) => {
                Material::parse_index(text).map_err(|source| Error::optics_in(context, source))
            }
            MaterialArg::Spec(spec) => Ok(resolve_with(spec, context, None, db)?),
        }
    }
}

/// The database of `material_db=` (named by that argument), else of the environment variable
/// `NACRE_MATERIAL_DB`, as for the `nacre` binary.
pub fn database_of(given: Option<PathBuf>) -> Option<MaterialDb> {
    match given {
        Some(dir) => Some(MaterialDb::new(dir, Param::MaterialDb)),
        None => std::env::var_os("NACRE_MATERIAL_DB")
            .filter(|v| !v.is_empty())
            .map(|dir| MaterialDb::new(PathBuf::from(dir), "NACRE_MATERIAL_DB")),
    }
}

/// A multilayer stack: ambient | films (top first) | substrate.
#[pyclass(frozen, module = "nacre._nacre", name = "Stack")]
pub struct PyStack {
    pub stack: Arc<Stack>,
}

#[pymethods]
impl PyStack {
    /// Builds a stack. `ambient` (non-absorbing) and `substrate` (absorbing allowed) are
    /// materials; `layers` is a sequence, top first, of `(material, thickness_nm)`,
    /// `(material, thickness_nm, incoherent)` (a bool: a thick slab whose reflections add
    /// in intensity) or strings in the `--layer` syntax of the `nacre` binary,
    /// `MATERIAL@THICKNESS[:incoherent]` (`"mgf2@99.75nm"`, `"bk7@2mm:incoherent"`).
    #[new]
    #[pyo3(signature = (ambient, layers, substrate, material_db=None))]
    fn new(
        py: Python<'_>,
        ambient: &Bound<'_, PyAny>,
        layers: Vec<Bound<'_, PyAny>>,
        substrate: &Bound<'_, PyAny>,
        material_db: Option<PathBuf>,
    ) -> PyResult<Self> {
        let ambient = MaterialArg::extract(ambient)?;
        let substrate = MaterialArg::extract(substrate)?;
        let layers = layers
            .iter()
            .enumerate()
            .map(|(i, layer)| LayerArg::extract(i, layer))
            .collect::<PyResult<Vec<_>>>()?;
        let db = database_of(material_db);
        let stack = py
            .detach(|| build(&ambient, &layers, &substrate, db.as_ref()))
            .map_err(bake_err)?;
        Ok(PyStack {
            stack: Arc::new(stack),
        })
    }

    /// The stack of a stack recipe (TOML: `ambient`, `substrate`, `[[layers]]` with
    /// `material` and `thickness_nm`; relative paths from the recipe's folder).
    #[staticmethod]
    #[pyo3(signature = (path, material_db=None))]
    fn from_recipe(py: Python<'_>, path: PathBuf, material_db: Option<PathBuf>) -> PyResult<Self> {
        let db = database_of(material_db);
        let stack = py
            .detach(|| StackRecipe::read(&path)?.stack.build_with(db.as_ref()))
            .map_err(bake_err)?;
        Ok(PyStack {
            stack: Arc::new(stack),
        })
    }

    /// The ambient's name.
    #[getter]
    fn ambient(&self) -> String {
        self.stack.ambient().name().to_string()
    }

    /// The substrate's name.
    #[getter]
    fn substrate(&self) -> String {
        self.stack.substrate().name().to_string()
    }

    /// Per film, top first: whether it is incoherent (a slab whose reflections add in
    /// intensity, `nacre_optics::incoherent`).
    #[getter]
    fn incoherent(&self) -> Vec<bool> {
        self.stack.incoherent_flags()
    }

    /// The films, top first, as `(material name, thickness_nm)`.
    #[getter]
    fn layers(&self) -> Vec<(String, f64)> {
        self.stack
            .layers()
            .iter()
            .map(|l| (l.material.name().to_string(), l.thickness_nm))
            .collect()
    }

    /// Complex refractive indices ñ = n + iκ of every medium at `wavelength_nm`: ambient,
    /// films (top first), substrate.
    fn indices_at(&self, wavelength_nm: f64) -> PyResult<Vec<(f64, f64)>> {
        self.stack
            .indices_at(wavelength_nm)
            .map(|v| v.iter().map(|c| (c.re, c.im)).collect())
            .map_err(|e| bake_err(Error::optics_in(Param::Wavelengths, e)))
    }

    fn __repr__(&self) -> String {
        let layers: Vec<String> = self
            .stack
            .layers()
            .iter()
            .zip(self.stack.incoherent_flags())
            .map(|(l, inc)| match inc {
                false => format!("({:?}, {})", l.material.name(), l.thickness_nm),
                true => format!("({:?}, {}, True)", l.material.name(), l.thickness_nm),
            })
            .collect();
        format!(
            "Stack(ambient={:?}, layers=[{}], substrate={:?})",
            self.stack.ambient().name(),
            layers.join(", "),
            self.stack.substrate().name()
        )
    }
}

/// A film argument: its material, thickness (nm) and whether it is incoherent.
pub struct LayerArg {
    material: MaterialArg,
    thickness_nm: f64,
    incoherent: bool,
}

impl LayerArg {
    /// Reads film `index` of `layers=`: a `(material, thickness_nm)` or `(material,
    /// thickness_nm, incoherent)` tuple, or a string in the `--layer` syntax read by the
    /// binary's own parser ([`parse_layer`]: `"bk7@2mm:incoherent"`).
    fn extract(index: usize, obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        if obj.is_instance_of::<PyString>() {
            let text: String = obj.extract()?;
            let (material, thickness_nm, incoherent) =
                parse_layer(format!("layers[{index}]"), &text).map_err(bake_err)?;
            return Ok(LayerArg {
                material: MaterialArg::Spec(material.to_string()),
                thickness_nm,
                incoherent,
            });
        }
        let parts: Vec<Bound<'_, PyAny>> = match obj.cast::<PyTuple>() {
            Ok(t) => t.iter().collect(),
            Err(_) => obj.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "layers[{index}]: a layer is (material, thickness_nm), (material, thickness_nm, incoherent) or a string MATERIAL@THICKNESS[:incoherent]"
                ))
            })?,
        };
        let (material, thickness_nm, incoherent) = match parts.as_slice() {
            [m, d] => (m, d, false),
            [m, d, inc] if inc.is_instance_of::<PyBool>() => (m, d, inc.extract::<bool>()?),
            [_, _, inc] => {
                return Err(PyTypeError::new_err(format!(
                    "layers[{index}]: the third item says whether the layer is incoherent (True or False), not {}",
                    inc.get_type().name()?
                )));
            }
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "layers[{index}]: a layer tuple has 2 or 3 items (material, thickness_nm[, incoherent]), not {}",
                    parts.len()
                )));
            }
        };
        Ok(LayerArg {
            material: MaterialArg::extract(material)?,
            thickness_nm: thickness_nm.extract()?,
            incoherent,
        })
    }
}

/// Loads every material and builds the stack; thicknesses must be finite and non-negative
/// (a string layer is also held to the command line's limit of a metre).
fn build(
    ambient: &MaterialArg,
    layers: &[LayerArg],
    substrate: &MaterialArg,
    db: Option<&MaterialDb>,
) -> Result<Stack> {
    let ambient = ambient.load(Param::Ambient.into(), db)?;
    let built = layers
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let (m, d) = (&l.material, &l.thickness_nm);
            let context = Origin::from(format!("layers[{i}]"));
            if !(*d >= 0.0 && d.is_finite()) {
                return Err(Error::value(
                    context,
                    format!("{d}"),
                    "thickness_nm must be finite and non-negative",
                ));
            }
            Ok(Layer {
                material: m.load(context, db)?,
                thickness_nm: *d,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let substrate = substrate.load(Param::Substrate.into(), db)?;
    let stack =
        Stack::new(ambient, built, substrate).map_err(|e| Error::optics_in(Param::Ambient, e))?;
    if layers.iter().any(|l| l.incoherent) {
        let flags = layers.iter().map(|l| l.incoherent).collect();
        return stack
            .with_incoherent(flags)
            .map_err(|e| Error::optics_in(Param::Ambient, e));
    }
    Ok(stack)
}

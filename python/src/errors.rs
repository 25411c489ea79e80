//! The libraries' errors as Python exceptions.
//!
//! The libraries name the inputs that went wrong with [`Param`] values and never spell a
//! flag; [`PythonNames`] spells each as the Python argument that supplies it (`angles_deg`,
//! `wavelengths_nm`, `layers`, …), so a message says what the `nacre` binary's says with the
//! binding's names. Every exception subclasses [`NacreError`], itself a `ValueError`.

use nacre_format::param::{Naming, Param, Render};
use pyo3::PyErr;
use pyo3::exceptions::PyValueError;

pyo3::create_exception!(
    nacre,
    NacreError,
    PyValueError,
    "Bad input or a failed computation in nacre (a ValueError); the message names the argument or file concerned."
);
pyo3::create_exception!(
    nacre,
    MaterialError,
    NacreError,
    "A material that cannot be read or used: an unknown name, a malformed index or data file, a refractiveindex.info page not found, a wavelength outside its data."
);
pyo3::create_exception!(
    nacre,
    TableError,
    NacreError,
    "A baked table that cannot be read or used: its manifest, files, checksum or kind."
);
pyo3::create_exception!(
    nacre,
    ParseError,
    NacreError,
    "A recipe, points or data file malformed at a line (`file:line: …`)."
);

/// The Python argument that supplies `param` (parameters no Python function takes keep
/// their neutral names, [`Param::name`]).
pub fn python_name(param: Param) -> &'static str {
    match param {
        Param::Angles => "angles_deg",
        Param::Angle => "angle_deg",
        Param::Thickness | Param::Thicknesses => "thickness_nm",
        Param::Wavelengths => "wavelengths_nm",
        Param::Layer => "layers",
        Param::Points => "thickness_nm/film_ior",
        Param::FilmIors => "film_ior",
        Param::Table => "name_or_manifest",
        Param::Output => "out_dir",
        Param::Distinct => "distinct_nm",
        other => other.name(),
    }
}

/// The binding's [`Naming`]: parameters as Python arguments, given values as keyword
/// arguments (`method='lut:soap-film'`).
pub struct PythonNames;

impl Naming for PythonNames {
    fn name(&self, param: Param) -> &'static str {
        python_name(param)
    }

    fn given(&self, param: Param, value: &str) -> String {
        format!("{}='{value}'", python_name(param))
    }
}

/// Which exception class an optics error belongs to.
fn optics_class(e: &nacre_optics::Error) -> Class {
    use nacre_optics::Error as E;
    match e {
        E::WavelengthOutOfRange { .. }
        | E::Parse { .. }
        | E::InvalidIndex { .. }
        | E::NonPhysicalIndex { .. }
        | E::UnknownName { .. } => Class::Material,
        _ => Class::Nacre,
    }
}

fn format_class(e: &nacre_format::Error) -> Class {
    use nacre_format::Error as E;
    match e {
        E::UnknownMaterial { .. } | E::MaterialDb { .. } => Class::Material,
        E::Optics(o) | E::OpticsIn { source: o, .. } => optics_class(o),
        E::Parse { .. } => Class::Parse,
        E::Table { .. } | E::Checksum { .. } | E::WrongKind { .. } => Class::Table,
        _ => Class::Nacre,
    }
}

enum Class {
    Nacre,
    Material,
    Table,
    Parse,
}

fn raise(class: Class, message: String) -> PyErr {
    match class {
        Class::Nacre => NacreError::new_err(message),
        Class::Material => MaterialError::new_err(message),
        Class::Table => TableError::new_err(message),
        Class::Parse => ParseError::new_err(message),
    }
}

/// A `nacre_bake::Error` as the Python exception of its kind, its message rendered with
/// [`PythonNames`].
pub fn bake_err(e: nacre_bake::Error) -> PyErr {
    let class = match &e {
        nacre_bake::Error::Format(f) => format_class(f),
        nacre_bake::Error::Optics(o) => optics_class(o),
        _ => Class::Nacre,
    };
    raise(class, e.named(&PythonNames).to_string())
}

/// A `nacre_format::Error` as a Python exception ([`bake_err`]).
pub fn format_err(e: nacre_format::Error) -> PyErr {
    let class = format_class(&e);
    raise(class, e.named(&PythonNames).to_string())
}

/// Shorthand: the binding's results.
pub type Result<T> = std::result::Result<T, nacre_bake::Error>;

//! The native module `nacre._nacre` of the Python package `nacre`: thin wrappers over
//! nacre's Rust libraries (nacre-optics, nacre-format, nacre-bake), with numpy arrays in and
//! out. The public API, its broadcasting and its docs are in `pysrc/nacre/__init__.py`.

// `!(x > 0.0)` is how nacre rejects NaN together with out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod compute;
mod errors;
mod fit;
mod stack;
mod table;

use pyo3::prelude::*;

#[pymodule]
fn _nacre(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("NacreError", py.get_type::<errors::NacreError>())?;
    m.add("MaterialError", py.get_type::<errors::MaterialError>())?;
    m.add("TableError", py.get_type::<errors::TableError>())?;
    m.add("ParseError", py.get_type::<errors::ParseError>())?;
    m.add_class::<stack::PyStack>()?;
    m.add_class::<table::PyTable>()?;
    m.add_function(wrap_pyfunction!(compute::spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(compute::spectrum_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(compute::color, m)?)?;
    m.add_function(wrap_pyfunction!(compute::unpolarised, m)?)?;
    m.add_function(wrap_pyfunction!(compute::bake, m)?)?;
    m.add_function(wrap_pyfunction!(compute::conformance, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_color, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_gltf, m)?)?;
    m.add_function(wrap_pyfunction!(bundled_materials, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

/// A bundled material: name, description and the range of its data, nm.
type BundledRow = (&'static str, &'static str, (f64, f64));

/// The bundled materials: `(name, description, (min_nm, max_nm))`, as `nacre materials`.
#[pyfunction]
fn bundled_materials() -> PyResult<Vec<BundledRow>> {
    nacre_format::materials::BUNDLED
        .iter()
        .map(|b| {
            let m = nacre_format::materials::load_bundled(b).map_err(errors::format_err)?;
            Ok((b.name, b.description, m.range_nm()))
        })
        .collect()
}

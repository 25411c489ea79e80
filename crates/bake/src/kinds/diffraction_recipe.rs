//! A parsed `diffraction` recipe: what both layouts bake from. Parsing is in
//! [`crate::kinds::diffraction`]; the layout "integrated" bakes in
//! [`crate::kinds::diffraction_integrated`].

use nacre_format::diffraction::DiffractionRecord;
use nacre_optics::colour::Colorimeter;
use nacre_optics::diffraction::HeightField;
use std::path::PathBuf;

/// A parsed `diffraction` recipe ([`crate::kinds::diffraction`] documents the format).
pub struct DiffractionRecipe {
    /// Table name.
    pub name: String,
    /// Recipe file.
    pub path: PathBuf,
    /// Recipe text.
    pub text: String,
    /// Description.
    pub description: String,
    /// Colour settings.
    pub colorimeter: Colorimeter,
    /// The height field, as written.
    pub source_text: String,
    /// The height field (generated or read and checked at parse time).
    pub field: HeightField,
    /// The Taylor order, bound and checks, as recorded (layout "integrated": the
    /// measured error is filled in by the bake).
    pub record: DiffractionRecord,
    /// The wavelength grid of the colour sums, nm.
    pub wavelengths_nm: Vec<f64>,
}

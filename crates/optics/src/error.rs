//! The one error type of `nacre-optics`.

/// Everything that can go wrong in `nacre-optics`. Variants carry the values that went
/// wrong so that a front end can print one precise message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A material was asked for its index outside the wavelengths its data covers.
    #[error(
        "material `{material}` has no data at {wavelength_nm} nm: its data covers {min_nm}–{max_nm} nm"
    )]
    WavelengthOutOfRange {
        /// Material name.
        material: String,
        /// Requested vacuum wavelength in nm.
        wavelength_nm: f64,
        /// Shortest covered wavelength in nm.
        min_nm: f64,
        /// Longest covered wavelength in nm.
        max_nm: f64,
    },
    /// The ambient (incidence) medium absorbs; the plane-wave formalism needs a real
    /// ambient index so that the incident power is well defined.
    #[error(
        "ambient medium `{material}` absorbs at {wavelength_nm} nm (κ = {kappa}); the ambient must be non-absorbing (give its real index instead)"
    )]
    AbsorbingAmbient {
        /// Material name.
        material: String,
        /// Vacuum wavelength in nm.
        wavelength_nm: f64,
        /// Extinction coefficient found.
        kappa: f64,
    },
    /// Text handed to a parser (material file, index literal) is malformed.
    #[error("{source_name}:{line}: {message}")]
    Parse {
        /// File name or other label of the text.
        source_name: String,
        /// 1-based line number (0 when the text has no lines, e.g. a flag value).
        line: usize,
        /// What was wrong and what was expected.
        message: String,
    },
    /// A refractive-index literal such as `1.5` or `0.27+2.9i` is malformed or unphysical.
    #[error("invalid refractive index `{text}`: {reason}")]
    InvalidIndex {
        /// The literal.
        text: String,
        /// What was expected.
        reason: String,
    },
    /// A dispersion formula produced a non-physical index (n² ≤ 0, NaN) inside its range.
    #[error("material `{material}` gives a non-physical index {value} at {wavelength_nm} nm")]
    NonPhysicalIndex {
        /// Material name.
        material: String,
        /// Vacuum wavelength in nm.
        wavelength_nm: f64,
        /// The offending value, as text.
        value: String,
    },
    /// A film thickness is negative or not finite.
    #[error(
        "layer {layer} (`{material}`): thickness {thickness_nm} nm must be finite and non-negative"
    )]
    InvalidThickness {
        /// 1-based layer number, top layer first.
        layer: usize,
        /// Material name.
        material: String,
        /// The thickness given, in nm.
        thickness_nm: f64,
    },
    /// An incidence angle outside (−90°, 90°) or not finite.
    #[error("incidence angle {angle_deg}° must be finite and strictly between −90° and 90°")]
    InvalidAngle {
        /// The angle given, in degrees.
        angle_deg: f64,
    },
    /// A wavelength that is not finite and positive.
    #[error("wavelength {wavelength_nm} nm must be finite and positive")]
    InvalidWavelength {
        /// The wavelength given, in nm.
        wavelength_nm: f64,
    },
    /// A layer index that the stack does not have.
    #[error("layer {layer} does not exist: the stack has {count} layer(s), numbered from 1")]
    NoSuchLayer {
        /// 1-based layer number asked for.
        layer: usize,
        /// Number of films in the stack.
        count: usize,
    },
    /// A numeric parameter outside its documented range (e.g. a GGX roughness α ≤ 0).
    #[error("{what} = {value} is out of range: expected {expected}")]
    OutOfRange {
        /// The parameter, e.g. `GGX roughness α`.
        what: &'static str,
        /// The value given.
        value: f64,
        /// The accepted range.
        expected: &'static str,
    },
    /// A name (observer, illuminant, colour space) that is not one of the known ones.
    #[error("unknown {what} `{name}`: expected one of {expected}")]
    UnknownName {
        /// What kind of name was asked for, e.g. `observer`.
        what: &'static str,
        /// The name given.
        name: String,
        /// The accepted names, e.g. `1931, 1964`.
        expected: &'static str,
    },
}

/// Shorthand for `Result<T, nacre_optics::Error>`.
pub type Result<T, E = Error> = std::result::Result<T, E>;

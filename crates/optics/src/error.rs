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
    /// A wavelength inside a material's range where its dispersion formula gives no physical
    /// index (a stretch its reader found and reported with a warning).
    #[error(
        "material `{material}` has no physical index at {wavelength_nm} nm: its formula gives none between {from_nm} and {to_nm} nm (choose wavelengths outside that interval or another page)"
    )]
    NoPhysicalIndex {
        /// Material name.
        material: String,
        /// Vacuum wavelength in nm.
        wavelength_nm: f64,
        /// Start of the interval, nm.
        from_nm: f64,
        /// End of the interval, nm.
        to_nm: f64,
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
    /// An incoherent slab that lets (almost) nothing through in one pass: less than
    /// [`crate::incoherent::OPAQUE_PASS`] (10⁻³⁰).
    #[error(
        "layer {layer} (`{material}`, {thickness_nm} nm, incoherent) absorbs everything at {wavelength_nm} nm and {angle_deg:.3}°: one pass lets through {pass:.3e} of the light; make it thinner, or make it the substrate"
    )]
    OpaqueSlab {
        /// 1-based layer number, top layer first.
        layer: usize,
        /// Material name.
        material: String,
        /// The slab's thickness, nm.
        thickness_nm: f64,
        /// Vacuum wavelength, nm.
        wavelength_nm: f64,
        /// Incidence angle in the ambient, degrees.
        angle_deg: f64,
        /// The single-pass transmission exp(−4π d Im(ñ cos θ)/λ).
        pass: f64,
    },
    /// A computation that needs the amplitudes of a fully coherent stack was asked of a
    /// stack with incoherent layers (whose powers only [`crate::Stack::sweep`] gives).
    #[error(
        "{operation} needs a coherent stack, but layer {layer} (`{material}`) is incoherent: only reflectance and transmittance spectra take incoherent layers"
    )]
    IncoherentLayer {
        /// What was asked, e.g. `complex amplitudes`.
        operation: &'static str,
        /// 1-based layer number of the first incoherent layer.
        layer: usize,
        /// Its material's name.
        material: String,
    },
    /// The coherence flags of a stack do not match its layers.
    #[error("{given} coherence flag(s) for a stack of {count} layer(s)")]
    CoherenceCount {
        /// Flags given.
        given: usize,
        /// Films in the stack.
        count: usize,
    },
    /// A sweep's film thicknesses do not match its stack's films.
    #[error("{given} film thickness(es) for a stack of {count} film(s)")]
    ThicknessCount {
        /// Thicknesses given.
        given: usize,
        /// Films in the stack.
        count: usize,
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
    /// A height field holds a NaN or infinite height.
    #[error("height field sample (x = {x}, y = {y}) is not a finite number")]
    NonFiniteHeight {
        /// Column, from 0.
        x: usize,
        /// Row, from 0.
        y: usize,
    },
    /// The Taylor expansion of e^{ikwh} would need more terms than the limit: the
    /// structure is too tall for the wavelength.
    #[error(
        "the Taylor expansion of the diffraction phase needs more than {max_order} terms for max |k w h| = {x_max:.3} at tolerance {tolerance:e}: the height field is too tall for the shortest wavelength (lower the height scale or raise the shortest wavelength)"
    )]
    TaylorOrder {
        /// max |k w h| asked for.
        x_max: f64,
        /// Tolerance on the remainder bound.
        tolerance: f64,
        /// The highest order accepted.
        max_order: usize,
    },
    /// A height-field patch smaller than the coherence window along an axis it varies along.
    #[error(
        "the height field spans {patch_um} µm along {axis}, less than the coherence diameter 4σ_s = {coherence_diameter_um} µm: use a larger patch (more samples or a coarser pitch) or a smaller coherence diameter"
    )]
    PatchTooSmall {
        /// `x` or `y`.
        axis: &'static str,
        /// Patch size along the axis, µm.
        patch_um: f64,
        /// 4σ_s, µm.
        coherence_diameter_um: f64,
    },
    /// A height-field pitch too coarse for the spatial frequencies asked for.
    #[error(
        "height-field pitch {pitch_um} µm exceeds the Nyquist limit {max_pitch_um:.6} µm = λ/(2·{max_uv:.4}) for {wavelength_nm} nm at the directions asked for: use a finer pitch, longer wavelengths or directions closer to the specular one"
    )]
    NyquistExceeded {
        /// The pitch, µm.
        pitch_um: f64,
        /// The largest acceptable pitch, µm.
        max_pitch_um: f64,
        /// The shortest wavelength, nm.
        wavelength_nm: f64,
        /// The largest |u| or |v| reached.
        max_uv: f64,
    },
    /// A fit template's free parameter is malformed ([`crate::fit::Template`]).
    #[error("free parameter of layer {layer}: {message}")]
    FitTemplate {
        /// 1-based film number (0: the template as a whole).
        layer: usize,
        /// What was wrong.
        message: String,
    },
    /// Data a fit cannot use (too few points for the free parameters, nothing to fit).
    #[error("{message}")]
    FitData {
        /// What was wrong.
        message: String,
    },
    /// A fit stopped because its caller cancelled it ([`crate::fit::Watch`]).
    #[error("the fit was cancelled after {done} of {total} steps")]
    FitCancelled {
        /// Steps done when it stopped.
        done: usize,
        /// Steps in all.
        total: usize,
    },
}

/// Shorthand for `Result<T, nacre_optics::Error>`.
pub type Result<T, E = Error> = std::result::Result<T, E>;

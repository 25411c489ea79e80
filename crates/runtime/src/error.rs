//! The runtime's error type.

use nacre_format::param::{Msg, Naming, Render};
use nacre_format::wgsl_header::TECHNIQUE_SLOT;
use std::fmt;
use std::path::PathBuf;

/// Everything that can go wrong in `nacre-runtime`.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// wgpu found no adapter (no GPU and no software driver such as Mesa's lavapipe or
    /// llvmpipe).
    #[error(
        "no GPU adapter found: install a Vulkan driver (on Debian: `apt install mesa-vulkan-drivers` for the software rasteriser lavapipe), or Mesa's OpenGL for WGPU_BACKEND=gl (`apt install libegl1 libegl-mesa0 libgl1-mesa-dri`) ({0})"
    )]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("could not create a device on {adapter}: {message}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// wgpu's message.
        message: String,
    },
    /// A table or manifest could not be read or does not describe what was asked for, or a
    /// material it names could not be resolved.
    #[error(transparent)]
    Table(#[from] nacre_format::Error),
    /// The physics core rejected a value (a material, a stack).
    #[error(transparent)]
    Optics(#[from] nacre_optics::Error),
    /// A manifest and its files disagree, or a manifest asks for something the runtime
    /// cannot upload.
    #[error("{path}: {message}")]
    Manifest {
        /// The manifest.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A table exceeds what the device supports.
    #[error("{what} needs {needed}, but the device allows at most {limit} ({adapter})")]
    Limit {
        /// What was being created.
        what: String,
        /// The size needed.
        needed: u64,
        /// The device's limit.
        limit: u64,
        /// Adapter name.
        adapter: String,
    },
    /// wgpu reported a validation or internal error (a pipeline, shader module, texture or
    /// buffer it refused, or a submission it could not run); `context` names the operation,
    /// wgpu's message the object's label.
    #[error("GPU error while {context}: {message}")]
    Gpu {
        /// What the runtime was doing.
        context: String,
        /// wgpu's message.
        message: String,
    },
    /// The device ran out of memory.
    #[error("the GPU on {adapter} ran out of memory while {context}")]
    OutOfMemory {
        /// Adapter name.
        adapter: String,
        /// What the runtime was doing.
        context: String,
    },
    /// The device was lost (driver reset, GPU removed, or `wgpu::Device::destroy`): nothing
    /// more can run on it; create a new [`crate::GpuContext`].
    #[error(
        "the GPU device on {adapter} was lost while {context} ({reason}): create a new device and reload the tables"
    )]
    DeviceLost {
        /// Adapter name.
        adapter: String,
        /// What the runtime was doing.
        context: String,
        /// wgpu's reason and message.
        reason: String,
    },
    /// A number outside its documented range (a render option, a material, a light, a
    /// diffraction setting).
    #[error("{what}: {value}{unit} (expected {expected})")]
    OutOfRange {
        /// The quantity (`image width`, `exposure`, `material film index`).
        what: String,
        /// Its value.
        value: f64,
        /// Its unit with a leading space (` pixels`, ` EV`, ` nm`), or empty.
        unit: &'static str,
        /// The accepted range, in words.
        expected: String,
    },
    /// A stack with an incoherent slab given to a technique that sums coherent amplitudes
    /// only (`film_stack`).
    #[error(
        "technique `{technique}`: layer {layer} is incoherent and `{technique}` sums coherent amplitudes only: draw the coated glass with technique `glass`"
    )]
    IncoherentStack {
        /// The technique.
        technique: &'static str,
        /// The incoherent film, 1-based.
        layer: usize,
    },
    /// A name that is not one of the choices (a scene, a film evaluation).
    #[error("{what} `{name}`: expected {expected}")]
    UnknownName {
        /// What was being named (`scene`, `film evaluation`).
        what: &'static str,
        /// The name given.
        name: String,
        /// The choices, in words.
        expected: String,
    },
    /// A technique or pass needs a table of a kind the table set lacks.
    #[error("{needed_by}: needs a `{kind}` table in the table set{}", .example.map(|e| format!(" (e.g. {e})")).unwrap_or_default())]
    MissingTable {
        /// The technique, pass or film evaluation that needs it.
        needed_by: String,
        /// The table kind (`film-lut`, `rough-film-lut`, `diffraction`).
        kind: &'static str,
        /// A default table of that kind.
        example: Option<&'static str>,
    },
    /// A table does not cover what the material asks for.
    #[error("{table}: {mismatch}")]
    TableRange {
        /// The table (`film-lut `soap-film``).
        table: String,
        /// What lies outside it.
        mismatch: TableMismatch,
    },
    /// A picture, environment or map whose size is outside the accepted range.
    #[error("{}: {what} of {width}x{height} texels (expected 1 to {max} texels on each side)", .path.display())]
    ImageSize {
        /// The file (or what the picture is, for one in memory).
        path: PathBuf,
        /// What the picture is for.
        what: String,
        /// Its width.
        width: u64,
        /// Its height.
        height: u64,
        /// The largest side accepted.
        max: u64,
    },
    /// A picture in memory whose texel count does not match its size.
    #[error("{what}: {texels} texels for {width}x{height}")]
    TexelCount {
        /// What the picture is for.
        what: &'static str,
        /// Its texel count.
        texels: usize,
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
    },
    /// A picture or environment file that could not be decoded (or encoded).
    #[error("{}: {message}", .path.display())]
    Image {
        /// The file (`-` for a picture being encoded).
        path: PathBuf,
        /// The decoder's message.
        message: String,
    },
    /// A thickness map the technique cannot read.
    #[error("{}: {problem}", .path.display())]
    ThicknessMap {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: ThicknessMapProblem,
    },
    /// A light the renderer cannot draw.
    #[error("{}: {problem}", .index.map_or("light".to_string(), |k| format!("punctual light {k}")))]
    Light {
        /// The punctual light's index; `None` for the scene's directional light.
        index: Option<usize>,
        /// What is wrong with it.
        problem: String,
    },
    /// More punctual lights than the renderer draws.
    #[error("punctual lights: {count} lights (at most {max} are drawn)")]
    TooManyLights {
        /// The number given.
        count: usize,
        /// The most drawn.
        max: usize,
    },
    /// A camera that cannot be projected.
    #[error("{}: {problem}", .name.as_ref().map_or("camera".to_string(), |n| format!("camera `{n}`")))]
    Camera {
        /// The glTF camera's name; `None` for the scene's own.
        name: Option<String>,
        /// What is wrong with it.
        problem: String,
    },
    /// A renderer asked for the output it does not write.
    #[error("render: this renderer writes {writes}: use {call}")]
    WrongOutput {
        /// What it writes (`linear radiance`, `display pixels`).
        writes: &'static str,
        /// The call that reads it.
        call: &'static str,
    },
    /// A diffraction table whose coherence window is too wide for the pass.
    #[error(
        "diffraction `{table}`: the coherence window spans {bins} bins on each side (at most {max}): the patch is too large for σ_s"
    )]
    CoherenceWindow {
        /// The table.
        table: String,
        /// The bins the window needs on each side.
        bins: f64,
        /// The most the pass reads.
        max: i32,
    },
    /// A diffraction wavelength step that gives too few or too many wavelengths.
    #[error(
        "diffraction wavelength step: {step_nm} nm over {}–{} nm (expected 2 to {max_count} wavelengths)",
        .range_nm[0],
        .range_nm[1]
    )]
    WavelengthStep {
        /// The step, nm.
        step_nm: f64,
        /// The table's wavelength range, nm.
        range_nm: [f64; 2],
        /// The most wavelengths a pass sums.
        max_count: usize,
    },
    /// A complex index for the diffraction Fresnel factor that is not physical.
    #[error("diffraction Fresnel index: {index} (expected n > 0, κ ≥ 0, finite)")]
    FresnelIndex {
        /// The index n + iκ.
        index: String,
    },
    /// An integrated diffraction table loaded for another Fresnel factor than the pass's.
    #[error(
        "integrated diffraction `{table}`: the table was loaded with another Fresnel factor than the pass's {fresnel} (load it with that one)"
    )]
    FresnelMismatch {
        /// The table.
        table: String,
        /// The pass's Fresnel factor.
        fresnel: String,
    },
    /// A render target outside the device's texture size.
    #[error("{what}: a {width}×{height} target (each side 1 to {max} on this device)")]
    TargetSize {
        /// What renders into it.
        what: &'static str,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// The device's largest side.
        max: u32,
    },
    /// Array layers of differing sizes given for one array texture.
    #[error("{label}: layers of differing sizes")]
    LayerSizes {
        /// The texture.
        label: String,
    },
    /// WGSL modules that do not compose (an unknown or malformed import, a cycle).
    #[error("composing WGSL: {0}")]
    Compose(#[from] ComposeError),
    /// A request the runtime refuses that none of the typed variants describes (a SPIR-V
    /// probe, a Monte Carlo reference, …).
    #[error("{context}: {message}")]
    Invalid {
        /// Where.
        context: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A request the runtime refuses, with advice that names parameters (rendered by a
    /// [`Naming`]: `Display` names them neutrally).
    #[error("{context}: {message}")]
    Refused {
        /// Where.
        context: String,
        /// What is wrong and the way out.
        message: Msg,
    },
    /// A glTF file nacre cannot load: the file, and what is wrong in it (naming the
    /// accessor, buffer, mesh, node, camera or light and the value).
    #[error("glTF {}: {error}", path.display())]
    Gltf {
        /// The glTF / GLB file (or the buffer file beside it).
        path: PathBuf,
        /// What is wrong.
        #[source]
        error: crate::gltf_scene::GltfError,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

impl Error {
    /// True when no usable GPU was found: no adapter, or the adapter refused to create a
    /// device (the `nacre` binary's distinct exit status).
    pub fn is_no_gpu(&self) -> bool {
        matches!(self, Error::NoAdapter(_) | Error::Device { .. })
    }
}

impl Render for Error {
    fn render(&self, f: &mut fmt::Formatter<'_>, naming: &dyn Naming) -> fmt::Result {
        match self {
            Error::Table(e) => e.render(f, naming),
            Error::Refused { context, message } => {
                write!(f, "{context}: {}", message.named(naming))
            }
            other => fmt::Display::fmt(other, f),
        }
    }
}

/// What a table does not cover ([`Error::TableRange`]).
#[derive(Debug, Clone, PartialEq)]
pub enum TableMismatch {
    /// The table's ambient index is not the material's.
    Ambient {
        /// The table's.
        table: f64,
        /// The material's.
        material: f64,
    },
    /// The material's film index lies outside the table's range.
    FilmIndex {
        /// The material's.
        index: f64,
        /// The table's [min, max].
        range: [f64; 2],
    },
    /// The material is thicker than the table reaches.
    Thickness {
        /// The material's thickest point, nm.
        thickness_nm: f64,
        /// The table's largest thickness, nm.
        max_nm: f64,
    },
    /// A transmitting material and a table without a transmittance.
    NoTransmittance,
}

impl fmt::Display for TableMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TableMismatch::Ambient { table, material } => write!(
                f,
                "the table was baked for ambient index {table}, the material has {material}"
            ),
            TableMismatch::FilmIndex {
                index,
                range: [lo, hi],
            } => write!(f, "film index {index} lies outside the table's {lo}–{hi}"),
            TableMismatch::Thickness {
                thickness_nm,
                max_nm,
            } => write!(
                f,
                "the material reaches {thickness_nm} nm, beyond the table's {max_nm} nm"
            ),
            TableMismatch::NoTransmittance => f.write_str(
                "a transmitting material (the bubble) needs a table with a transmittance (e.g. soap-film)",
            ),
        }
    }
}

/// What is wrong with a thickness map ([`Error::ThicknessMap`]).
#[derive(Debug, Clone, PartialEq)]
pub enum ThicknessMapProblem {
    /// A picture of a colour type no thickness map has.
    ColourType(String),
    /// A colour map (one film per channel) given to a technique that reads one thickness.
    ColourForTechnique(String),
}

impl fmt::Display for ThicknessMapProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ThicknessMapProblem::ColourType(t) => write!(
                f,
                "a {t} picture; a thickness map must be greyscale or RGB(A), 8 or 16 bits"
            ),
            ThicknessMapProblem::ColourForTechnique(t) => write!(
                f,
                "a colour thickness map (channels R, G, B for a stack's films) is read by technique `stack`; technique `{t}` reads a greyscale map"
            ),
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

/// Why a composition failed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ComposeError {
    /// An import names no module of [`MODULES`](crate::shaders::MODULES).
    #[error("{importer} imports `{name}`, which is no module of shaders/")]
    UnknownModule {
        /// The importing module (or the root asked for).
        importer: String,
        /// The unknown name.
        name: String,
    },
    /// The imports form a cycle.
    #[error("import cycle: {}", cycle.join(" → "))]
    Cycle {
        /// The modules of the cycle, the first repeated at the end.
        cycle: Vec<String>,
    },
    /// A module imports `<technique>` but the composition has no technique.
    #[error("{importer} imports {TECHNIQUE_SLOT}, but no technique was given")]
    NoTechnique {
        /// The importing module.
        importer: String,
    },
    /// An import line that is not `// import: name, name, …` (names of letters, digits and
    /// `_`, or `<technique>`) or `// import: (none)`.
    #[error("{module} line {line}: bad import header `{text}`")]
    BadImport {
        /// The module.
        module: String,
        /// 1-based line in the module.
        line: usize,
        /// The line.
        text: String,
    },
}

//! The WGSL modules under `shaders/`, their import headers and their composition.
//!
//! WGSL has no `import`: a pipeline's source is the concatenation of modules, each followed by
//! a newline. Every module declares what it needs in its comment header, on one line that
//! [`parse_imports`] reads (through `nacre_format::wgsl_header`, which the Bevy plugin reads
//! it with too):
//!
//! ```text
//! // import: common, <technique>, rough_lut_mapping
//! // import: (none)
//! ```
//!
//! A name is a module of [`MODULES`] (its file name without `.wgsl`); `<technique>` stands for
//! whichever technique module the host composes the consumer with (`film_lut`, `film_fourier`,
//! `film_spectral` or `plain` for the film consumers; `diffraction` or
//! `diffraction_integrated_technique` for `diffraction_scene`). [`resolve`] orders the
//! modules depth first — each module after its imports, in the order they are declared, each
//! module once — and reports unknown names and cycles as a [`ComposeError`]. The result,
//! [`Composed`], carries a [`SourceMap`] from the lines of the composed source back to
//! `module.wgsl:line`, which the runtime uses when wgpu (naga) rejects a shader.
//!
//! [`flatten`] gives a host engine one self-contained file per technique (or per consumer with
//! [`flatten_with`]); [`compose`] keeps the runtime's historical order for the film pipelines:
//! [`COMMON`], [`LUT_MAPPING`], one technique module ([`Technique::source`], from
//! [`crate::technique::REGISTRY`]), then the
//! consumers with whatever they import. See `shaders/README.md` for the bind-group contract
//! each module follows.

use crate::technique::REGISTRY;
use std::fmt;
use std::ops::Range;

/// Constants, complex arithmetic, Fresnel at an interface, NaN guards, `FilmInput`/`FilmOutput`.
pub const COMMON: &str = include_str!("../../../shaders/common.wgsl");
/// The film-lut coordinate mappings (mirror of `nacre_format::film_lut::FilmLutAxes`).
pub const LUT_MAPPING: &str = include_str!("../../../shaders/lut_mapping.wgsl");
/// Baseline "technique" without a film (Schlick Fresnel) for `nacre bench-gpu`.
pub const PLAIN: &str = include_str!("../../../shaders/plain.wgsl");
/// Consumer: the full-screen GGX pass of `nacre bench-gpu`.
pub const BENCH: &str = include_str!("../../../shaders/bench.wgsl");
/// Consumer: the GPU = CPU probe pass.
pub const PROBE: &str = include_str!("../../../shaders/probe.wgsl");
/// The rough-film-lut coordinate mappings and two-fetch lookup (mirror of
/// `nacre_bake::kinds::rough_film_lut`; no bindings of its own).
pub const ROUGH_LUT_MAPPING: &str = include_str!("../../../shaders/rough_lut_mapping.wgsl");
/// Display output shared by [`MATERIAL`] and the diffraction scenes: the Khronos PBR Neutral
/// and max-channel tone mappers and the sRGB encoding (no bindings of its own).
pub const OUTPUT: &str = include_str!("../../../shaders/output.wgsl");
/// Group 0 of every scene (the material scenes, glTF meshes and diffraction scenes): the
/// view uniform `ViewParams` ([`crate::render::ViewUniform`]) and the environment's
/// textures. It imports [`ROUGH_LUT_MAPPING`] (the `RoughLutParams` of binding 7).
pub const VIEW: &str = include_str!("../../../shaders/view.wgsl");
/// Consumer: the thin-film microfacet material (GGX + film, environment, light, tone
/// mapping; groups 0 and 2). It imports [`ROUGH_LUT_MAPPING`] (its exact split-sum path
/// samples a `rough-film-lut`), [`VIEW`] (group 0) and [`OUTPUT`], which [`compose`] places
/// before it. Compose it before
/// [`SCENE`] or [`MESH`] (which import it).
pub const MATERIAL: &str = include_str!("../../../shaders/material.wgsl");
/// Consumer: the ray-cast analytic scenes of `nacre render` (sphere, bubble, plane).
pub const SCENE: &str = include_str!("../../../shaders/scene.wgsl");
/// Consumer: rasterised triangle meshes (glTF scenes of `nacre render --gltf`; group 3 holds
/// the view-projection). Compose it after [`MATERIAL`].
pub const MESH: &str = include_str!("../../../shaders/mesh.wgsl");
/// The box-filter mip-level pass of the picture behind transmissive glTF surfaces.
pub const MIP_DOWN: &str = include_str!("../../../shaders/mip_down.wgsl");

pub use crate::error::ComposeError;
pub use nacre_format::wgsl_header::{Import, TECHNIQUE_SLOT};

/// One WGSL module of `shaders/`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Module {
    /// The file name without `.wgsl`: what import headers name.
    pub name: &'static str,
    /// The file's text.
    pub source: &'static str,
}

impl Module {
    /// The module's imports, from its header.
    ///
    /// # Errors
    /// [`ComposeError::BadImport`] for a malformed import line.
    pub fn imports(&self) -> Result<Vec<Import<'static>>, ComposeError> {
        parse_imports(self.name, self.source)
    }
}

macro_rules! modules {
    ($($name:literal),* $(,)?) => {
        &[$(Module {
            name: $name,
            source: include_str!(concat!("../../../shaders/", $name, ".wgsl")),
        }),*]
    };
}

/// The modules of `shaders/` that are no technique of [`crate::technique::REGISTRY`].
const SHARED_MODULES: &[Module] = modules![
    "common",
    "lut_mapping",
    "plain",
    "rough_lut_mapping",
    "output",
    "view",
    "material",
    "scene",
    "mesh",
    "mip_down",
    "probe",
    "bench",
    "diffraction_common",
    "diffraction",
    "diffraction_integrated",
    "diffraction_integrated_technique",
    "diffraction_scene",
    "diffraction_integrated_probe",
];

const MODULE_COUNT: usize = SHARED_MODULES.len() + REGISTRY.len();

/// Every module of `shaders/`: the shared ones, then each technique's (its entry in
/// [`crate::technique::REGISTRY`] names it; a test checks that the list matches the
/// directory).
pub const MODULES: &[Module] = &{
    let mut all = [SHARED_MODULES[0]; MODULE_COUNT];
    let mut i = 0;
    while i < MODULE_COUNT {
        all[i] = if i < SHARED_MODULES.len() {
            SHARED_MODULES[i]
        } else {
            Module {
                name: REGISTRY[i - SHARED_MODULES.len()].module,
                source: REGISTRY[i - SHARED_MODULES.len()].source,
            }
        };
        i += 1;
    }
    all
};

/// The host-side techniques that are no film technique of the registry.
const OTHER_TECHNIQUES: [&str; 3] = ["plain", "diffraction", "diffraction_integrated"];

/// The technique modules a host can flatten on their own ([`flatten`]): one file each —
/// every film technique of [`crate::technique::REGISTRY`], then `plain` and the two
/// diffraction techniques.
pub const TECHNIQUE_MODULES: &[&str] = &{
    let mut all = [""; REGISTRY.len() + OTHER_TECHNIQUES.len()];
    let mut i = 0;
    while i < all.len() {
        all[i] = if i < REGISTRY.len() {
            REGISTRY[i].module
        } else {
            OTHER_TECHNIQUES[i - REGISTRY.len()]
        };
        i += 1;
    }
    all
};

/// The module of [`MODULES`] called `name`.
pub fn module(name: &str) -> Option<&'static Module> {
    MODULES.iter().find(|m| m.name == name)
}

/// The imports declared in the leading comment block of `source`
/// ([`nacre_format::wgsl_header::parse_imports`], the one reader of the header); `module`
/// names the source in errors.
///
/// # Errors
/// [`ComposeError::BadImport`] for a malformed import line.
pub fn parse_imports<'a>(module: &str, source: &'a str) -> Result<Vec<Import<'a>>, ComposeError> {
    nacre_format::wgsl_header::parse_imports(module, source).map_err(|e| ComposeError::BadImport {
        module: e.module,
        line: e.line,
        text: e.text,
    })
}

/// A root of a composition: a module of [`MODULES`] by name, or a source text of the host's
/// (its import header is honoured too).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part<'a> {
    /// A module of [`MODULES`].
    Module(&'a str),
    /// A source that is not in `shaders/`; `label` names it in the [`SourceMap`].
    Source {
        /// What errors and the source map call it.
        label: &'a str,
        /// The WGSL text.
        source: &'a str,
    },
}

impl<'a> Part<'a> {
    /// `source` as the module of [`MODULES`] with that exact text, else as a host source
    /// called `label`.
    pub fn of_source(label: &'a str, source: &'a str) -> Part<'a> {
        match MODULES.iter().find(|m| m.source == source) {
            Some(m) => Part::Module(m.name),
            None => Part::Source { label, source },
        }
    }

    fn label(&self) -> String {
        match self {
            Part::Module(name) => format!("{name}.wgsl"),
            Part::Source { label, .. } => (*label).to_string(),
        }
    }
}

/// Where one module lies in a composed source.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Span {
    /// `name.wgsl` for a module of [`MODULES`], else the label of the host's source.
    pub file: String,
    /// Its bytes in the composed source (without the newline that follows it).
    pub bytes: Range<usize>,
    /// The composed source's 1-based line of its first line.
    pub first_line: u32,
    /// How many lines it occupies, the newline that follows it included.
    pub lines: u32,
}

/// A place in one module.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The module's file (see [`Span::file`]).
    pub file: String,
    /// 1-based line in the module.
    pub line: u32,
    /// 1-based column in bytes, where known.
    pub column: Option<u32>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.column {
            Some(c) => write!(f, "{}:{}:{c}", self.file, self.line),
            None => write!(f, "{}:{}", self.file, self.line),
        }
    }
}

/// Which module each line of a composed source came from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SourceMap {
    /// The modules in composition order.
    pub spans: Vec<Span>,
}

impl SourceMap {
    /// The module and its line for 1-based `line` of the composed source (naga's and wgpu's
    /// `SourceLocation::line_number`).
    pub fn locate_line(&self, line: u32) -> Option<Location> {
        let span = self
            .spans
            .iter()
            .find(|s| line >= s.first_line && line < s.first_line + s.lines)?;
        Some(Location {
            file: span.file.clone(),
            line: line - span.first_line + 1,
            column: None,
        })
    }

    /// [`Self::locate_line`] from a 1-based line and column.
    pub fn locate(&self, line: u32, column: u32) -> Option<Location> {
        self.locate_line(line).map(|l| Location {
            column: Some(column),
            ..l
        })
    }

    /// A one-line summary: "lines 1–250 common.wgsl, lines 251–300 lut_mapping.wgsl, …".
    pub fn describe(&self) -> String {
        self.spans
            .iter()
            .map(|s| {
                format!(
                    "lines {}–{} {}",
                    s.first_line,
                    s.first_line + s.lines - 1,
                    s.file
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// wgpu's compilation messages with their positions as `module.wgsl:line:column`, one a
    /// line (messages without a position keep their text).
    pub fn annotate(&self, info: &wgpu::CompilationInfo) -> String {
        info.messages
            .iter()
            .map(|m| {
                let kind = match m.message_type {
                    wgpu::CompilationMessageType::Error => "error",
                    wgpu::CompilationMessageType::Warning => "warning",
                    wgpu::CompilationMessageType::Info => "info",
                };
                match m
                    .location
                    .and_then(|l| self.locate(l.line_number, l.line_position))
                {
                    Some(at) => format!("{at}: {kind}: {}", m.message),
                    None => format!("{kind}: {}", m.message),
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// A composed WGSL source and where its modules lie.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Composed {
    /// The source: every module followed by a newline.
    pub source: String,
    /// Its modules.
    pub map: SourceMap,
}

impl Composed {
    /// The module, line and column of byte `offset` of [`Self::source`] (naga's
    /// `SourceLocation::offset`, `Span::to_range().start`).
    pub fn locate_offset(&self, offset: usize) -> Option<Location> {
        let span = self
            .map
            .spans
            .iter()
            .find(|s| offset >= s.bytes.start && offset <= s.bytes.end)?;
        let before = self.source.get(span.bytes.start..offset)?;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Some(Location {
            file: span.file.clone(),
            line: before.matches('\n').count() as u32 + 1,
            column: Some((before.len() - line_start) as u32 + 1),
        })
    }
}

impl From<Composed> for String {
    fn from(c: Composed) -> String {
        c.source
    }
}

/// Composes `roots` in order, each after its imports (depth first, in the order of the import
/// headers; every module once). `technique` fills the `<technique>` imports.
///
/// # Errors
/// [`ComposeError`]: an unknown module, a cycle, a `<technique>` import without a technique,
/// or a malformed header.
pub fn resolve(roots: &[Part<'_>], technique: Option<Part<'_>>) -> Result<Composed, ComposeError> {
    resolve_in(MODULES, roots, technique)
}

/// [`resolve`] over another table of modules than [`MODULES`].
///
/// # Errors
/// As [`resolve`].
pub fn resolve_in(
    modules: &[Module],
    roots: &[Part<'_>],
    technique: Option<Part<'_>>,
) -> Result<Composed, ComposeError> {
    let mut resolver = Resolver {
        modules,
        technique,
        done: Vec::new(),
        stack: Vec::new(),
        out: Composed {
            source: String::with_capacity(64 * 1024),
            map: SourceMap::default(),
        },
    };
    for root in roots {
        resolver.visit(*root, "the composition")?;
    }
    Ok(resolver.out)
}

struct Resolver<'a> {
    modules: &'a [Module],
    technique: Option<Part<'a>>,
    done: Vec<Part<'a>>,
    stack: Vec<Part<'a>>,
    out: Composed,
}

impl<'a> Resolver<'a> {
    fn visit(&mut self, part: Part<'a>, importer: &str) -> Result<(), ComposeError> {
        if self.done.contains(&part) {
            return Ok(());
        }
        if let Some(at) = self.stack.iter().position(|p| *p == part) {
            let mut cycle: Vec<String> = self.stack[at..].iter().map(Part::label).collect();
            cycle.push(part.label());
            return Err(ComposeError::Cycle { cycle });
        }
        let (label, source) = match part {
            Part::Module(name) => {
                let m = self
                    .modules
                    .iter()
                    .find(|m| m.name == name)
                    .ok_or_else(|| ComposeError::UnknownModule {
                        importer: importer.to_string(),
                        name: name.to_string(),
                    })?;
                (part.label(), m.source)
            }
            Part::Source { label, source } => (label.to_string(), source),
        };
        self.stack.push(part);
        for import in parse_imports(&label, source)? {
            let next = match import {
                Import::Module(name) => Part::Module(name),
                Import::Technique => self.technique.ok_or_else(|| ComposeError::NoTechnique {
                    importer: label.clone(),
                })?,
            };
            self.visit(next, &label)?;
        }
        self.stack.pop();
        self.done.push(part);
        let out = &mut self.out;
        let start = out.source.len();
        let first_line = out.map.spans.last().map_or(1, |s| s.first_line + s.lines);
        out.source.push_str(source);
        out.source.push('\n');
        out.map.spans.push(Span {
            file: label,
            bytes: start..start + source.len(),
            first_line,
            lines: source.matches('\n').count() as u32 + 1,
        });
        Ok(())
    }
}

/// The module `entry` of [`MODULES`] with everything it imports: for a technique of
/// [`TECHNIQUE_MODULES`], the one file a host engine includes before its own consumer.
///
/// # Errors
/// As [`resolve`]; [`ComposeError::NoTechnique`] when `entry` needs a technique (use
/// [`flatten_with`]).
pub fn flatten(entry: &str) -> Result<Composed, ComposeError> {
    resolve(&[Part::Module(entry)], None)
}

/// [`flatten`] with `technique` (a module name) for the `<technique>` imports: e.g.
/// `flatten_with("scene", "film_fourier")` is a complete pipeline source.
///
/// # Errors
/// As [`resolve`].
pub fn flatten_with(entry: &str, technique: &str) -> Result<Composed, ComposeError> {
    resolve(&[Part::Module(entry)], Some(Part::Module(technique)))
}

/// A film pipeline in the runtime's order: [`COMMON`], [`LUT_MAPPING`], the technique module
/// `technique` (e.g. [`Technique::module`] or `"plain"`), then the modules `consumers` after
/// their imports, `<technique>` being `technique`.
///
/// # Errors
/// As [`resolve`].
pub fn film_pipeline(technique: &str, consumers: &[&str]) -> Result<Composed, ComposeError> {
    let technique = Part::Module(technique);
    let mut roots = vec![
        Part::Module("common"),
        Part::Module("lut_mapping"),
        technique,
    ];
    roots.extend(consumers.iter().map(|&c| Part::Module(c)));
    resolve(&roots, Some(technique))
}

pub use crate::technique::Technique;

/// The full source of a pipeline: common + mapping + `technique` + `consumer`, each consumer
/// after its imports (e.g. [`MATERIAL`] brings [`ROUGH_LUT_MAPPING`]). A consumer whose text is
/// a module of [`MODULES`] is composed as that module; any other text as given, after the
/// imports of its own header.
///
/// # Panics
/// When a consumer's header names an unknown module or makes a cycle ([`try_compose`] returns
/// the error; the modules of `shaders/` always resolve, which the tests check).
pub fn compose(technique: Technique, consumer: &[&str]) -> String {
    compose_source(technique.source(), consumer)
}

/// [`compose`] with any module that defines `film_colour` (e.g. [`PLAIN`]).
///
/// # Panics
/// As [`compose`].
pub fn compose_source(technique_source: &str, consumer: &[&str]) -> String {
    try_compose(technique_source, consumer)
        .unwrap_or_else(|e| panic!("composing WGSL: {e}"))
        .source
}

/// [`compose_source`] with its [`SourceMap`], and the error instead of a panic. Host
/// sources are labelled "technique" and "consumer 1", "consumer 2", … in the map.
///
/// # Errors
/// As [`resolve`].
pub fn try_compose(technique_source: &str, consumer: &[&str]) -> Result<Composed, ComposeError> {
    let labels: Vec<String> = (1..=consumer.len())
        .map(|i| format!("consumer {i}"))
        .collect();
    let technique = Part::of_source("technique", technique_source);
    let mut roots = vec![
        Part::Module("common"),
        Part::Module("lut_mapping"),
        technique,
    ];
    roots.extend(
        consumer
            .iter()
            .zip(&labels)
            .map(|(&source, label)| Part::of_source(label, source)),
    );
    resolve(&roots, Some(technique))
}

/// Creates the shader module of `composed` on `ctx`'s device. When wgpu rejects it, the
/// [`crate::Error::Gpu`] message leads with naga's messages placed as `module.wgsl:line:column`
/// ([`SourceMap::annotate`]), then wgpu's own report (whose lines are those of the composed
/// source, summarised by [`SourceMap::describe`]).
///
/// # Errors
/// [`crate::Error::Gpu`] or [`crate::Error::DeviceLost`].
///
/// # Panics
/// Never: the closure run by [`crate::GpuContext::checked`] always creates the module.
pub fn create_module(
    ctx: &crate::GpuContext,
    label: &str,
    composed: &Composed,
) -> crate::error::Result<wgpu::ShaderModule> {
    let mut module = None;
    let context = format!("compiling the `{label}` shader");
    let checked = ctx.checked(&context, || {
        module = Some(
            ctx.device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(label),
                    source: wgpu::ShaderSource::Wgsl(composed.source.as_str().into()),
                }),
        );
    });
    match (checked, module) {
        (Ok(()), Some(module)) => Ok(module),
        (Err(crate::error::Error::Gpu { context, message }), Some(module)) => {
            let info = pollster::block_on(module.get_compilation_info());
            Err(crate::error::Error::Gpu {
                context,
                message: format!(
                    "{}\n{message}\n(composed source: {})",
                    composed.map.annotate(&info),
                    composed.map.describe()
                ),
            })
        }
        (Err(e), _) => Err(e),
        (Ok(()), None) => unreachable!("the closure ran"),
    }
}

#[cfg(test)]
mod tests;

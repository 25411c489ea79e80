//! Helpers shared by the runtime's integration tests (`mod support;` in each test file).
//! Each test binary uses only some of them.
#![allow(dead_code)]

use nacre_runtime::{GpuContext, TableSet};
use naga::back::{glsl, hlsl, msl, spv};
use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use std::path::PathBuf;
use std::sync::OnceLock;

/// The test binary's GPU context, created once. A missing adapter fails the test that asks
/// for it — GPU tests never skip (CI installs `mesa-vulkan-drivers`, Mesa's lavapipe).
pub fn ctx() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| {
        let ctx = GpuContext::new_headless().unwrap_or_else(|e| {
            panic!("the GPU tests need an adapter (CI installs mesa-vulkan-drivers): {e}")
        });
        eprintln!("adapter: {}", ctx.describe());
        ctx
    })
}

/// The repository root.
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The manifest of the default set's table `name` (`film-dielectric` →
/// `tables/baked/film-dielectric.json`).
pub fn manifest(name: &str) -> PathBuf {
    nacre_format::set::default_baked_dir().join(format!("{name}.json"))
}

/// The default set's film-lut `lut` and `fourier-srgb` on `ctx`: the tables of `nacre
/// render` (with `film-dielectric`, those of `nacre render --gltf`).
pub fn film_tables_on(ctx: &GpuContext, lut: &str) -> TableSet {
    let mut tables = TableSet::load(ctx, &manifest(lut))
        .unwrap_or_else(|e| panic!("the default table {lut}: {e}"));
    tables
        .add(ctx, &manifest("fourier-srgb"))
        .unwrap_or_else(|e| panic!("the default table fourier-srgb: {e}"));
    tables
}

/// [`film_tables_on`] the test binary's context.
pub fn film_tables(lut: &str) -> TableSet {
    film_tables_on(ctx(), lut)
}

/// Khronos' glTF sample assets with films, `../shared/gltf-samples` (or
/// `$NACRE_GLTF_SAMPLES`, for a checkout elsewhere): see [`shared_folder`].
pub fn gltf_samples() -> Option<PathBuf> {
    shared_folder(
        std::env::var_os("NACRE_GLTF_SAMPLES")
            .map_or_else(|| repo_root().join("../shared/gltf-samples"), PathBuf::from),
    )
}

/// Khronos' core glTF sample models, `../shared/gltf-core-samples`: see [`shared_folder`].
pub fn gltf_core_samples() -> Option<PathBuf> {
    shared_folder(repo_root().join("../shared/gltf-core-samples"))
}

/// `dir`, a folder of `../shared` (not part of this repository, `../shared/DATA.md`): `None`
/// (the test skips, saying why) when missing outside CI; a panic when missing in CI (`CI`
/// set).
fn shared_folder(dir: PathBuf) -> Option<PathBuf> {
    if dir.is_dir() {
        return Some(dir);
    }
    if std::env::var_os("CI").is_some() {
        panic!(
            "{} is missing: CI must provide the Khronos glTF samples (../shared/DATA.md)",
            dir.display()
        );
    }
    eprintln!(
        "skipped: {} not found (the Khronos glTF samples of ../shared/DATA.md)",
        dir.display()
    );
    None
}

/// Parses and validates WGSL `source`, panicking with naga's annotated report (line and
/// column in `source`; `map` says which module a line of a composed source belongs to, or is
/// empty).
pub fn validate(name: &str, source: &str, map: &str) -> (naga::Module, ModuleInfo) {
    let map = if map.is_empty() { "as given" } else { map };
    let module = naga::front::wgsl::parse_str(source).unwrap_or_else(|e| {
        panic!(
            "{name}: WGSL parse error\n{}\ncomposed source: {map}",
            e.emit_to_string(source)
        )
    });
    let info = Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| {
            panic!(
                "{name}: validation error\n{}\ncomposed source: {map}",
                e.emit_to_string(source)
            )
        });
    (module, info)
}

/// A validated module with its pipeline-overridable constants resolved as wgpu resolves them
/// for a pipeline (`naga::back::pipeline_constants::process_overrides`): at their defaults
/// and, when it has any, all set to 1 (`true`; `shaders/mesh.wgsl`'s `MESH_PRIMITIVE_UNLIT`,
/// the pipeline of unlit lines and points).
pub fn resolved(
    name: &str,
    module: &naga::Module,
    info: &ModuleInfo,
) -> Vec<(naga::Module, ModuleInfo)> {
    let mut sets = vec![naga::back::PipelineConstants::default()];
    if !module.overrides.is_empty() {
        let mut all = naga::back::PipelineConstants::default();
        for (_, o) in module.overrides.iter() {
            if let Some(id) = &o.name {
                all.insert(id.clone(), 1.0);
            }
        }
        sets.push(all);
    }
    sets.iter()
        .map(|constants| {
            let (m, i) =
                naga::back::pipeline_constants::process_overrides(module, info, None, constants)
                    .unwrap_or_else(|e| panic!("{name}: overrides {constants:?}: {e}"));
            (m.into_owned(), i.into_owned())
        })
        .collect()
}

/// Translates a validated module, its overrides resolved each way ([`resolved`]), to SPIR-V,
/// MSL, HLSL and GLSL (4.50 core and ES 3.10, per entry point): what every backend of wgpu
/// would be given.
pub fn translate(name: &str, module: &naga::Module, info: &ModuleInfo) {
    for (module, info) in resolved(name, module, info) {
        translate_resolved(name, &module, &info);
    }
}

/// [`translate`] of a module without overrides.
fn translate_resolved(name: &str, module: &naga::Module, info: &ModuleInfo) {
    spv::write_vec(module, info, &spv::Options::default(), None)
        .unwrap_or_else(|e| panic!("{name}: SPIR-V: {e}"));

    let msl_options = msl::Options {
        lang_version: (2, 0),
        ..msl::Options::default()
    };
    msl::write_string(module, info, &msl_options, &msl::PipelineOptions::default())
        .unwrap_or_else(|e| panic!("{name}: MSL: {e}"));

    let mut hlsl_out = String::new();
    let hlsl_options = hlsl::Options::default();
    let hlsl_pipeline = hlsl::PipelineOptions::default();
    hlsl::Writer::new(&mut hlsl_out, &hlsl_options, &hlsl_pipeline)
        .write(module, info, None)
        .unwrap_or_else(|e| panic!("{name}: HLSL: {e}"));

    for version in [glsl::Version::Desktop(450), glsl::Version::new_gles(310)] {
        for entry in &module.entry_points {
            let options = glsl::Options {
                version,
                ..glsl::Options::default()
            };
            let pipeline = glsl::PipelineOptions {
                shader_stage: entry.stage,
                entry_point: entry.name.clone(),
                multiview: None,
            };
            let mut out = String::new();
            glsl::Writer::new(
                &mut out,
                module,
                info,
                &options,
                &pipeline,
                naga::proc::BoundsCheckPolicies::default(),
            )
            .and_then(|mut w| w.write())
            .unwrap_or_else(|e| panic!("{name}: GLSL {version} `{}`: {e}", entry.name));
        }
    }
}

/// sRGB byte → display-linear value in [0, 1] (IEC 61966-2-1).
pub fn linear(byte: u8) -> f64 {
    let c = f64::from(byte) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Display-linear (tone-mapped) → radiance × exposure: the inverse of the diffraction
/// scenes' tone map m = c/(1 + max c) (`tone_map_max_channel`, shaders/output.wgsl),
/// c = m/(1 − max m). A channel at the top of the range (max m ≥ 254/255) is clamped there.
pub fn radiance(p: [f64; 3]) -> [f64; 3] {
    let top = p.iter().copied().fold(0.0, f64::max).min(254.0 / 255.0);
    p.map(|m| m / (1.0 - top))
}

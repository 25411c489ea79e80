//! GPU = CPU for the engine shader libraries (`shaders/glsl/nacre.glsl`,
//! `shaders/hlsl/nacre.hlsl`): each is compiled inside a small compute probe by
//! `glslangValidator` (GLSL → SPIR-V with `-V`; HLSL → SPIR-V with `-D -V -e main -S comp`),
//! the SPIR-V goes through naga's SPIR-V front end into wgpu on whatever adapter wgpu finds
//! (Mesa's lavapipe in CI), and the outputs are compared with the CPU methods at the points
//! of the WGSL techniques' probes (`gpu_probe.rs`, `probe_support`):
//!
//! * film-lut: `FilmLut::lookup` (nacre-format), ≤ 2×10⁻³ per channel (half-float table);
//! * fourier: `nacre color --method fourier:M` (Belcour & Barla 2017 Eq. 10 over the table,
//!   nacre-optics), ≤ 10⁻⁴ per channel (full-float table), M = 1, 2, 3 (the runtime's
//!   default), auto, and M = 3 prefiltered with σ_d = 40 nm;
//! * rough-film-lut: `RoughFilmLut::lookup` (nacre-format), ≤ 2×10⁻³ (half-float table);
//! * film_stack: `StackEvaluation::colour` (nacre-optics), ≤ 10⁻⁴ per channel, over the
//!   stacks of `probe_support::stack_cases` (1 to 8 films, metal films and bases, dispersive
//!   materials, total internal reflection; the rule ladder and a fixed rule) and the
//!   alternating stacks of 1 to 8 films, read from the stack table (`StackGpu::texels`, an
//!   RGBA32F texture) and `NacreStackParams` as an engine uploads them from `nacre export`;
//! * every library output finite for NaN, ±∞, negative, zero and huge inputs.
//!
//! Neither a missing adapter nor a missing `glslangValidator` skips: both fail, the latter
//! with a message to install glslang-tools (`scripts/test.sh` installs it).

use nacre_bake::commands::color::{Method, Quantity};
use nacre_format::Manifest;
use nacre_format::export::{read_stack_json, stack_json};
use nacre_format::film_lut::FilmLut;
use nacre_format::gpu_params::{STACK_TEXTURE_WIDTH, StackGpu};
use nacre_format::load::LoadedRoughLut;
use nacre_format::rough_film_lut::RoughFilmLut;
use nacre_optics::fourier::Harmonics;
use nacre_optics::{C64, Material};
use nacre_runtime::bindings::{TechniqueBinding, TechniqueOptions};
use nacre_runtime::probe::{SpirvProbe, run_spirv_probe};
use nacre_runtime::render::RoughLutUniform;
use nacre_runtime::{BufferInitExt, FilmInput, TableSet, Technique};
use std::path::PathBuf;
use std::process::Command;
use std::sync::Arc;

#[path = "../../crates/runtime/tests/support/mod.rs"]
mod support;
use support::ctx;

mod probe_support;
use probe_support::{Lcg, cpu_colours, input, manifest, max_diff, random_points, stack_cases};

/// The two libraries.
#[derive(Clone, Copy, Debug)]
enum Lang {
    Glsl,
    Hlsl,
}

const LANGS: [Lang; 2] = [Lang::Glsl, Lang::Hlsl];

fn library(lang: Lang) -> &'static str {
    match lang {
        Lang::Glsl => include_str!("../../shaders/glsl/nacre.glsl"),
        Lang::Hlsl => include_str!("../../shaders/hlsl/nacre.hlsl"),
    }
}

/// Compiles `source` (a whole compute shader) to SPIR-V with glslangValidator.
fn glslang(lang: Lang, name: &str, source: &str) -> Vec<u8> {
    let dir = std::env::temp_dir().join(format!("nacre-engine-probe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (file, args): (PathBuf, &[&str]) = match lang {
        Lang::Glsl => (dir.join(format!("{name}.comp")), &["-V"]),
        Lang::Hlsl => (
            dir.join(format!("{name}.hlsl")),
            &["-D", "-V", "-e", "main", "-S", "comp"],
        ),
    };
    let spv = file.with_extension("spv");
    std::fs::write(&file, source).unwrap();
    let output = Command::new("glslangValidator")
        .args(args)
        .arg(&file)
        .arg("-o")
        .arg(&spv)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "running glslangValidator ({e}): the engine-library tests need it — install \
                 glslang-tools (`apt-get install glslang-tools`; scripts/test.sh does)"
            )
        });
    assert!(
        output.status.success(),
        "glslangValidator rejected the {lang:?} probe {}:\n{}{}",
        file.display(),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    let bytes = std::fs::read(&spv).unwrap();
    let _ = std::fs::remove_file(&file);
    let _ = std::fs::remove_file(&spv);
    bytes
}

/// Group 2 of every probe (inputs, count, outputs), GLSL: `Input` is the input struct.
fn glsl_io(input: &str) -> String {
    format!(
        "layout(set = 2, binding = 0, std430) readonly buffer ProbeInputs {{ {input} probe_inputs[]; }};\n\
         layout(set = 2, binding = 1, std140) uniform ProbeCount {{ uint probe_count; }};\n\
         layout(set = 2, binding = 2, std430) buffer ProbeOutputs {{ vec4 probe_outputs[]; }};\n"
    )
}

fn hlsl_io(input: &str) -> String {
    format!(
        "[[vk::binding(0, 2)]] StructuredBuffer<{input}> probe_inputs;\n\
         [[vk::binding(1, 2)]] cbuffer ProbeCount {{ uint probe_count; }};\n\
         [[vk::binding(2, 2)]] RWStructuredBuffer<float4> probe_outputs;\n"
    )
}

/// A compute probe of `lang` around `library`: its first lines build an `ivec2` (`lane`; in
/// HLSL a private global, which glslang cannot fold away),
/// which puts a 2-component signed-integer vector type into the module: naga 30's SPIR-V
/// front end looks that type up for the coordinates of `OpImageFetch` on a 2-D array image
/// (the fourier table's texelFetch/Load) and panics when no instruction declared it.
///
/// The rest: : declarations of group 1, and the body that
/// computes `NacreFilmOutput o` (or two `vec4`s `a`, `b` when `film` is false) for input `x`.
fn probe_source(lang: Lang, group1: &str, input: &str, body: &str, film: bool) -> String {
    let lib = library(lang);
    let store = if film {
        ("vec4(o.reflectance, 1.0)", "vec4(o.transmittance, 1.0)")
    } else {
        ("a", "b")
    };
    match lang {
        Lang::Glsl => format!(
            "#version 450\n#extension GL_EXT_samplerless_texture_functions : require\n\
             #define NACRE_VULKAN_SEPARATE_SAMPLERS\n{lib}\n{group1}\n{io}\n\
             layout(local_size_x = 64) in;\n\
             void main() {{\n    uint i = gl_GlobalInvocationID.x;\n    {lane}\n    if (i >= probe_count) {{ return; }}\n\
             {input} x = probe_inputs[i];\n{body}\n\
             probe_outputs[2u * i] = {r};\n    probe_outputs[2u * i + 1u] = {t};\n}}\n",
            io = glsl_io(input),
            lane = "ivec2 lane = ivec2(int(i), int(probe_count));\n    if (lane.x > lane.y) { return; }",
            r = store.0,
            t = store.1,
        ),
        Lang::Hlsl => format!(
            "{lib}\n{group1}\n{io}\nstatic int2 lane;\n[numthreads(64, 1, 1)]\n\
             void main(uint3 id : SV_DispatchThreadID) {{\n    uint i = id.x;\n    {lane}\n    if (i >= probe_count) {{ return; }}\n\
             {input} x = probe_inputs[i];\n{body}\n\
             probe_outputs[2u * i] = {r};\n    probe_outputs[2u * i + 1u] = {t};\n}}\n",
            io = hlsl_io(input),
            lane = "lane = int2(int(i), int(probe_count));\n    if (lane.x > lane.y) { return; }",
            r = store.0.replace("vec4", "float4"),
            t = store.1.replace("vec4", "float4"),
        ),
    }
}

/// The film-lut probe (group 1 as `TechniqueBinding` lays it out for `Technique::Lut`).
fn film_lut_probe(lang: Lang) -> Vec<u8> {
    let (group1, body) = match lang {
        Lang::Glsl => (
            "layout(set = 1, binding = 0) uniform texture3D film_lut_reflectance;\n\
             layout(set = 1, binding = 1) uniform texture3D film_lut_transmittance;\n\
             layout(set = 1, binding = 2) uniform sampler film_lut_sampler;\n\
             layout(set = 1, binding = 3, std140) uniform FilmLut { NacreFilmLutParams film_lut_params; };",
            "    NacreFilmOutput o = nacre_film_lut_colour(film_lut_reflectance, film_lut_sampler, \
             film_lut_transmittance, film_lut_sampler, film_lut_params, x);",
        ),
        Lang::Hlsl => (
            "[[vk::binding(0, 1)]] Texture3D<float4> film_lut_reflectance;\n\
             [[vk::binding(1, 1)]] Texture3D<float4> film_lut_transmittance;\n\
             [[vk::binding(2, 1)]] SamplerState film_lut_sampler;\n\
             [[vk::binding(3, 1)]] cbuffer FilmLut { NacreFilmLutParams film_lut_params; };",
            "    NacreFilmOutput o = nacre_film_lut_colour(film_lut_reflectance, film_lut_sampler, \
             film_lut_transmittance, film_lut_sampler, film_lut_params, x);",
        ),
    };
    glslang(
        lang,
        "film_lut",
        &probe_source(lang, group1, "NacreFilmInput", body, true),
    )
}

/// The fourier probe (group 1 as `TechniqueBinding` lays it out for `Technique::Fourier`).
fn fourier_probe(lang: Lang) -> Vec<u8> {
    let (group1, body) = match lang {
        Lang::Glsl => (
            "layout(set = 1, binding = 0) uniform texture2DArray fourier_table;\n\
             layout(set = 1, binding = 1, std140) uniform Fourier { NacreFourierParams fourier_params; };",
            "    NacreFilmOutput o = nacre_film_fourier_colour(fourier_table, fourier_params, x);",
        ),
        Lang::Hlsl => (
            "[[vk::binding(0, 1)]] Texture2DArray<float4> fourier_table;\n\
             [[vk::binding(1, 1)]] cbuffer Fourier { NacreFourierParams fourier_params; };",
            "    NacreFilmOutput o = nacre_film_fourier_colour(fourier_table, fourier_params, x);",
        ),
    };
    glslang(
        lang,
        "fourier",
        &probe_source(lang, group1, "NacreFilmInput", body, true),
    )
}

/// The rough-film-lut probe: group 1 = E_r, E_t, a linear sampler, `RoughLutParams`; input
/// (cos θ_o, α, d nm, n_f); outputs E_r and E_t.
fn rough_probe(lang: Lang) -> Vec<u8> {
    let (group1, body, input) = match lang {
        Lang::Glsl => (
            "layout(set = 1, binding = 0) uniform texture3D rough_reflectance;\n\
             layout(set = 1, binding = 1) uniform texture3D rough_transmittance;\n\
             layout(set = 1, binding = 2) uniform sampler rough_sampler;\n\
             layout(set = 1, binding = 3, std140) uniform Rough { NacreRoughLutParams rough_params; };",
            "    vec4 a = vec4(nacre_rough_lut_sample(rough_reflectance, rough_sampler, rough_params, x.x, x.y, x.z, x.w), 1.0);\n\
                 vec4 b = vec4(nacre_rough_lut_sample(rough_transmittance, rough_sampler, rough_params, x.x, x.y, x.z, x.w), 1.0);",
            "vec4",
        ),
        Lang::Hlsl => (
            "[[vk::binding(0, 1)]] Texture3D<float4> rough_reflectance;\n\
             [[vk::binding(1, 1)]] Texture3D<float4> rough_transmittance;\n\
             [[vk::binding(2, 1)]] SamplerState rough_sampler;\n\
             [[vk::binding(3, 1)]] cbuffer Rough { NacreRoughLutParams rough_params; };",
            "    float4 a = float4(nacre_rough_lut_sample(rough_reflectance, rough_sampler, rough_params, x.x, x.y, x.z, x.w), 1.0);\n\
                 float4 b = float4(nacre_rough_lut_sample(rough_transmittance, rough_sampler, rough_params, x.x, x.y, x.z, x.w), 1.0);",
            "float4",
        ),
    };
    glslang(
        lang,
        "rough",
        &probe_source(lang, group1, input, body, false),
    )
}

/// Runs a film probe (`FilmInput` in, reflectance and transmittance out).
fn run_film(spirv: &[u8], binding: &TechniqueBinding, inputs: &[FilmInput]) -> Vec<[[f32; 3]; 2]> {
    let probe = SpirvProbe {
        spirv,
        entry_point: "main",
        tables: (&binding.layout, &binding.bind_group),
    };
    let count = u32::try_from(inputs.len()).unwrap();
    run_spirv_probe(ctx(), &probe, bytemuck::cast_slice(inputs), count)
        .unwrap()
        .into_iter()
        .map(|[r, t]| [[r[0], r[1], r[2]], [t[0], t[1], t[2]]])
        .collect()
}

/// NaN, ±∞, negative, zero and huge values in every field (`gpu_probe.rs`'s hostile set).
fn hostile_inputs() -> Vec<FilmInput> {
    let values = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -1.0,
        0.0,
        1e-30,
        0.5,
        1.0,
        1.33,
        2.5,
        1e30,
        f32::MAX,
    ];
    let mut rng = Lcg(99);
    let mut pick = || values[(rng.next() * values.len() as f64) as usize];
    let mut inputs: Vec<FilmInput> = (0..2000)
        .map(|_| FilmInput {
            cos_theta_i: pick(),
            thickness_nm: pick() * 500.0,
            film_ior: pick(),
            sigma_thickness_nm: pick() * 50.0,
            ambient_ior: pick(),
            base_ior: [pick(), pick(), pick()],
            base_kappa: [pick(), pick(), pick()],
            ..Default::default()
        })
        .collect();
    // Total internal reflection and evanescent films, exactly grazing.
    inputs.push(input(0.0, 300.0, 1.0, 0.0, 1.5, C64::new(1.0, 0.0)));
    inputs.push(input(0.1, 300.0, 1.2, 0.0, 1.5, C64::new(1.33, 0.0)));
    inputs
}

fn assert_finite(what: &str, out: &[[[f32; 3]; 2]], inputs: &[FilmInput]) {
    for (i, o) in out.iter().enumerate() {
        assert!(
            o.iter().flatten().all(|v| v.is_finite()),
            "{what}: {o:?} for {:?}",
            inputs[i]
        );
    }
}

#[test]
fn film_lut_libraries_match_the_cpu_lookup() {
    let ctx = ctx();
    let spirv: Vec<(Lang, Vec<u8>)> = LANGS.iter().map(|&l| (l, film_lut_probe(l))).collect();
    for name in ["film-dielectric", "soap-film", "film-gold"] {
        let path = manifest(name);
        let tables = TableSet::load(ctx, &path).unwrap();
        let m = Manifest::read(&path).unwrap();
        let axes = m.film_lut().cloned().unwrap();
        let refl = m.load_table(&path, "reflectance").unwrap().unwrap();
        let trans = m.load_table(&path, "transmittance").unwrap();
        let binding = TechniqueBinding::new(
            ctx,
            &tables,
            Technique::Lut,
            &TechniqueOptions::default(),
            &tables.colorimeter().unwrap(),
        )
        .unwrap();
        let mut rng = Lcg(7);
        let mut points: Vec<(f64, f64, f64)> = (0..3000)
            .map(|_| {
                let c = rng.next();
                let d = axes.thickness_min_nm
                    + rng.next() * (axes.thickness_max_nm - axes.thickness_min_nm);
                let n = axes.ior_min + rng.next() * (axes.ior_max - axes.ior_min);
                (c, d, n)
            })
            .collect();
        points.push((1.0, 0.0, axes.ior_min));
        points.push((0.0, axes.thickness_max_nm, axes.ior_max));
        let inputs: Vec<FilmInput> = points
            .iter()
            .map(|&(c, d, n)| input(c, d, n, 0.0, axes.ambient_index, C64::new(1.5, 0.0)))
            .collect();
        let cpu_r: Vec<[f64; 3]> = points
            .iter()
            .map(|&(c, d, n)| FilmLut::lookup(&axes, &refl, c, d, n))
            .collect();
        let cpu_t: Option<Vec<[f64; 3]>> = trans.as_ref().map(|trans| {
            points
                .iter()
                .map(|&(c, d, n)| FilmLut::lookup(&axes, trans, c, d, n))
                .collect()
        });
        let hostile = hostile_inputs();
        for (lang, spirv) in &spirv {
            let gpu = run_film(spirv, &binding, &inputs);
            let gpu_r: Vec<[f32; 3]> = gpu.iter().map(|o| o[0]).collect();
            let (worst, at) = max_diff(&cpu_r, &gpu_r);
            eprintln!("{lang:?} film-lut {name} reflectance: max |GPU − CPU| = {worst:.2e}");
            assert!(
                worst <= 2e-3,
                "{lang:?} {name}: {worst:e} at {:?}: CPU {:?} GPU {:?}",
                points[at],
                cpu_r[at],
                gpu_r[at]
            );
            if let Some(cpu_t) = &cpu_t {
                let gpu_t: Vec<[f32; 3]> = gpu.iter().map(|o| o[1]).collect();
                let (worst, at) = max_diff(cpu_t, &gpu_t);
                eprintln!("{lang:?} film-lut {name} transmittance: max |GPU − CPU| = {worst:.2e}");
                assert!(
                    worst <= 2e-3,
                    "{lang:?} {name} T: {worst:e} at {:?}",
                    points[at]
                );
            }
            let out = run_film(spirv, &binding, &hostile);
            assert_finite(&format!("{lang:?} film-lut {name}"), &out, &hostile);
        }
    }
}

#[test]
fn fourier_libraries_match_the_cpu_series() {
    let ctx = ctx();
    let spirv: Vec<(Lang, Vec<u8>)> = LANGS.iter().map(|&l| (l, fourier_probe(l))).collect();
    let path = manifest("fourier-srgb");
    let tables = TableSet::load(ctx, &path).unwrap();
    let colorimeter = tables.colorimeter().unwrap();
    let table = Arc::new(Manifest::read(&path).unwrap().load_fourier(&path).unwrap());
    // A free film (base 1.0) has the largest |ρ| of the dielectric bases: the most harmonics.
    let bases = [
        C64::new(1.5, 0.0),
        C64::new(2.2, 0.0),
        C64::new(1.0, 0.0),
        C64::new(0.27, 2.9),
        C64::new(1.2, 1.5),
    ];
    // Automatic harmonics (0) are the runtime's default (`TechniqueOptions::default()`).
    assert_eq!(TechniqueOptions::default().harmonics, 0);
    let hostile = hostile_inputs();
    // 0: automatic harmonics, the runtime's default (`TechniqueOptions::default().harmonics`).
    for (harmonics, sigma) in [
        (1u32, 0.0),
        (2, 0.0),
        (3, 0.0),
        (3, 40.0),
        (0, 0.0),
        (0, 40.0),
    ] {
        let options = TechniqueOptions {
            harmonics,
            ..Default::default()
        };
        let binding =
            TechniqueBinding::new(ctx, &tables, Technique::Fourier, &options, &colorimeter)
                .unwrap();
        let h = if harmonics == 0 {
            Harmonics::Auto
        } else {
            Harmonics::Fixed(harmonics as usize)
        };
        let method = Method::Fourier(h, sigma, Some(table.clone()));
        for base in bases {
            let points = random_points(11 + u64::from(harmonics), 400, 10_000.0);
            let inputs: Vec<FilmInput> = points
                .iter()
                .map(|&(c, d, n)| input(c, d, n, sigma, 1.0, base))
                .collect();
            let material = Material::constant("base", base).unwrap();
            let quantities: &[Quantity] = if base.im == 0.0 {
                &[Quantity::Reflectance, Quantity::Transmittance]
            } else {
                &[Quantity::Reflectance]
            };
            let cpu: Vec<Vec<[f64; 3]>> = quantities
                .iter()
                .map(|&q| cpu_colours(&method, &material, &points, q, &colorimeter))
                .collect();
            for (lang, spirv) in &spirv {
                let gpu = run_film(spirv, &binding, &inputs);
                for (k, quantity) in quantities.iter().enumerate() {
                    let g: Vec<[f32; 3]> = gpu.iter().map(|o| o[k]).collect();
                    let (worst, at) = max_diff(&cpu[k], &g);
                    eprintln!(
                        "{lang:?} fourier M={harmonics} σ={sigma} base {base}: {quantity:?} max |GPU − CPU| = {worst:.2e}"
                    );
                    assert!(
                        worst <= 1e-4,
                        "{lang:?} M={harmonics} base {base} {quantity:?}: {worst:e} at {:?}: CPU {:?} GPU {:?}",
                        points[at],
                        cpu[k][at],
                        g[at]
                    );
                }
            }
        }
        if harmonics == 0 || harmonics == 3 {
            for (lang, spirv) in &spirv {
                let out = run_film(spirv, &binding, &hostile);
                assert_finite(&format!("{lang:?} fourier M={harmonics}"), &out, &hostile);
            }
        }
    }
}

/// Group 1 of the rough probe: the table's two textures, a trilinear sampler, its axes.
fn rough_binding(tables: &TableSet) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let device = &ctx().device;
    let lut = tables.rough_film_lut.as_ref().expect("a rough-film-lut");
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        },
        count: None,
    };
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("rough probe tables"),
        entries: &[
            texture(0),
            texture(1),
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 3,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
        ],
    });
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("rough probe trilinear"),
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("RoughLutParams"),
        contents: bytemuck::bytes_of(&RoughLutUniform::new(&lut.axes, lut.has_transmittance)),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let r = lut.reflectance.create_view(&Default::default());
    let t = lut.transmittance.create_view(&Default::default());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("rough probe tables"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&r),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&t),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: uniform.as_entire_binding(),
            },
        ],
    });
    (layout, group)
}

#[test]
fn rough_lut_libraries_match_the_cpu_lookup() {
    let ctx = ctx();
    let path = manifest("rough-film-dielectric");
    let tables = TableSet::load(ctx, &path).unwrap();
    let loaded = LoadedRoughLut::load(&path).unwrap();
    let lut = &loaded.lut;
    let axes = &lut.axes;
    let (layout, group) = rough_binding(&tables);
    let mut rng = Lcg(31);
    let mut points: Vec<[f32; 4]> = (0..3000)
        .map(|_| {
            let c = rng.next();
            let alpha = axes.alpha_min * (axes.alpha_max / axes.alpha_min).powf(rng.next());
            let d = rng.next() * axes.thickness_max_nm;
            let n = axes.ior_min + rng.next() * (axes.ior_max - axes.ior_min);
            [c as f32, alpha as f32, d as f32, n as f32]
        })
        .collect();
    points.push([1.0, axes.alpha_min as f32, 0.0, axes.ior_min as f32]);
    points.push([
        0.0,
        axes.alpha_max as f32,
        axes.thickness_max_nm as f32,
        axes.ior_max as f32,
    ]);
    let cpu = |table: &nacre_format::table_io::Table3| -> Vec<[f64; 3]> {
        points
            .iter()
            .map(|p| {
                let [c, a, d, n] = p.map(f64::from);
                RoughFilmLut::lookup(axes, table, c, a, d, n)
            })
            .collect()
    };
    let cpu_r = cpu(&lut.reflectance);
    let cpu_t = lut.transmittance.as_ref().map(cpu);
    let values = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -1.0,
        0.0,
        0.5,
        2.0,
        1e30,
    ];
    let mut hostile_rng = Lcg(5);
    let mut pick = || values[(hostile_rng.next() * values.len() as f64) as usize];
    let hostile: Vec<[f32; 4]> = (0..1000)
        .map(|_| [pick(), pick(), pick() * 500.0, pick()])
        .collect();
    for lang in LANGS {
        let spirv = rough_probe(lang);
        let probe = SpirvProbe {
            spirv: &spirv,
            entry_point: "main",
            tables: (&layout, &group),
        };
        let gpu = run_spirv_probe(
            ctx,
            &probe,
            bytemuck::cast_slice(&points),
            points.len() as u32,
        )
        .unwrap();
        let rgb = |k: usize| -> Vec<[f32; 3]> {
            gpu.iter().map(|o| [o[k][0], o[k][1], o[k][2]]).collect()
        };
        let (worst, at) = max_diff(&cpu_r, &rgb(0));
        eprintln!("{lang:?} rough-film-lut E_r: max |GPU − CPU| = {worst:.2e}");
        assert!(worst <= 2e-3, "{lang:?} E_r: {worst:e} at {:?}", points[at]);
        if let Some(cpu_t) = &cpu_t {
            let (worst, at) = max_diff(cpu_t, &rgb(1));
            eprintln!("{lang:?} rough-film-lut E_t: max |GPU − CPU| = {worst:.2e}");
            assert!(worst <= 2e-3, "{lang:?} E_t: {worst:e} at {:?}", points[at]);
        }
        let out = run_spirv_probe(
            ctx,
            &probe,
            bytemuck::cast_slice(&hostile),
            hostile.len() as u32,
        )
        .unwrap();
        for (i, o) in out.iter().enumerate() {
            assert!(
                o.iter().flatten().all(|v| v.is_finite()),
                "{lang:?} rough-film-lut: {o:?} for {:?}",
                hostile[i]
            );
        }
    }
}

/// The film_stack probe: group 1 = the stack table (RGBA32F, read with texelFetch / Load)
/// and `NacreStackParams`.
fn stack_probe(lang: Lang) -> Vec<u8> {
    let group1 = match lang {
        Lang::Glsl => {
            "layout(set = 1, binding = 0) uniform texture2D stack_table;\n\
             layout(set = 1, binding = 1, std140) uniform Stack { NacreStackParams stack_params; };"
        }
        Lang::Hlsl => {
            "[[vk::binding(0, 1)]] Texture2D<float4> stack_table;\n\
             [[vk::binding(1, 1)]] cbuffer Stack { NacreStackParams stack_params; };"
        }
    };
    let body = "    NacreFilmOutput o = nacre_film_stack_colour(stack_table, stack_params, x);";
    glslang(
        lang,
        "stack",
        &probe_source(lang, group1, "NacreFilmInput", body, true),
    )
}

/// Group 1 of the stack probe for `gpu`: its texels as an RGBA32F texture and its uniform.
fn stack_binding(gpu: &StackGpu) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let ctx = ctx();
    let device = &ctx.device;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("stack probe"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
        ],
    });
    let texels = gpu.texels();
    let size = wgpu::Extent3d {
        width: STACK_TEXTURE_WIDTH as u32,
        height: gpu.nodes.len() as u32,
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("stack table"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    ctx.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(STACK_TEXTURE_WIDTH as u32 * 16),
            rows_per_image: Some(size.height),
        },
        size,
    );
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("NacreStackParams"),
        contents: bytemuck::bytes_of(&gpu.params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let view = texture.create_view(&Default::default());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("stack probe"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: uniform.as_entire_binding(),
            },
        ],
    });
    (layout, group)
}

#[test]
fn stack_libraries_match_the_cpu_twin() {
    use nacre_optics::few_wavelengths::StackEvaluation;
    use nacre_runtime::bindings::StackSetup;
    let colorimeter = TableSet::load(ctx(), &manifest("fourier-srgb"))
        .unwrap()
        .colorimeter()
        .unwrap();
    let spirv: Vec<(Lang, Vec<u8>)> = LANGS.iter().map(|&l| (l, stack_probe(l))).collect();
    let mut cases: Vec<(String, StackSetup)> = stack_cases()
        .into_iter()
        .map(|(name, stack, samples)| {
            let films = stack.layers().len();
            let setup = StackSetup {
                stack,
                relative_nm: (0..films).map(|j| 15.0 * j as f64).collect(),
                // One thickness-map channel per film (R, G, B in turn).
                channels: (0..films).map(|j| j % 3).collect(),
                samples,
            };
            (name.to_string(), setup)
        })
        .collect();
    for films in 1..=8 {
        cases.push((
            format!("{films} alternating films"),
            StackSetup::alternating(films).unwrap(),
        ));
    }
    // The hostile set, with hostile variations too.
    let hostile: Vec<FilmInput> = hostile_inputs()
        .into_iter()
        .enumerate()
        .map(|(i, x)| {
            let v = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -3.0, 0.5][i % 6];
            FilmInput {
                variation: v,
                variation_g: -v,
                variation_b: v,
                ..x
            }
        })
        .collect();
    for (name, setup) in &cases {
        let mut eval = StackEvaluation::new(
            &colorimeter,
            &setup.stack,
            &setup.relative_nm,
            setup.samples,
        )
        .unwrap();
        if !setup.channels.is_empty() {
            eval = eval.with_channels(&setup.channels).unwrap();
        }
        let gpu = StackGpu::new(&eval);
        // The numbers as an engine reads them: through the exported JSON's text.
        let text = serde_json::to_string(&stack_json(&gpu, serde_json::json!({}))).unwrap();
        let read = read_stack_json(&serde_json::from_str(&text).unwrap(), "probe").unwrap();
        assert_eq!(read, gpu, "{name}: the JSON round trip");
        let (layout, group) = stack_binding(&read);
        let mut rng = Lcg(43);
        let inputs: Vec<FilmInput> = (0..400)
            .map(|_| {
                let (c, d) = (rng.next(), 500.0 * rng.next());
                let s = [(); 3].map(|_| (2.0 * rng.next() - 1.0) as f32);
                FilmInput {
                    variation: s[0],
                    variation_g: s[1],
                    variation_b: s[2],
                    ..input(c, d, 1.5, 0.0, 1.0, C64::new(1.5, 0.0))
                }
            })
            .collect();
        // The CPU twin at the f32 inputs the GPU saw.
        let cpu: Vec<([f64; 3], [f64; 3])> = inputs
            .iter()
            .map(|i| {
                eval.colour(
                    f64::from(i.cos_theta_i),
                    f64::from(i.thickness_nm),
                    [i.variation, i.variation_g, i.variation_b].map(f64::from),
                )
            })
            .collect();
        for (lang, spirv) in &spirv {
            let probe = SpirvProbe {
                spirv,
                entry_point: "main",
                tables: (&layout, &group),
            };
            let run = |inputs: &[FilmInput]| -> Vec<[[f32; 3]; 2]> {
                run_spirv_probe(
                    ctx(),
                    &probe,
                    bytemuck::cast_slice(inputs),
                    inputs.len() as u32,
                )
                .unwrap()
                .into_iter()
                .map(|[r, t]| [[r[0], r[1], r[2]], [t[0], t[1], t[2]]])
                .collect()
            };
            let out = run(&inputs);
            for (k, quantity) in ["R", "T"].iter().enumerate() {
                let c: Vec<[f64; 3]> = cpu.iter().map(|x| if k == 0 { x.0 } else { x.1 }).collect();
                let g: Vec<[f32; 3]> = out.iter().map(|o| o[k]).collect();
                let (worst, at) = max_diff(&c, &g);
                eprintln!("{lang:?} stack {name}: {quantity} max |GPU − CPU| = {worst:.2e}");
                assert!(
                    worst <= 1e-4,
                    "{lang:?} stack {name} {quantity}: {worst:e} at {:?}: CPU {:?} GPU {:?}",
                    inputs[at],
                    c[at],
                    g[at]
                );
            }
            let out = run(&hostile);
            assert_finite(&format!("{lang:?} stack {name}"), &out, &hostile);
        }
    }
}

/// Bytes that are not SPIR-V are a typed error, not a panic.
#[test]
fn a_spirv_probe_rejects_bytes_that_are_not_spirv() {
    let ctx = ctx();
    let tables = TableSet::load(ctx, &manifest("soap-film")).unwrap();
    let binding = TechniqueBinding::new(
        ctx,
        &tables,
        Technique::Lut,
        &TechniqueOptions::default(),
        &tables.colorimeter().unwrap(),
    )
    .unwrap();
    for bytes in [&b"not spir-v at all!!!"[..], &[3, 2, 35, 7, 0][..], &[][..]] {
        let probe = SpirvProbe {
            spirv: bytes,
            entry_point: "main",
            tables: (&binding.layout, &binding.bind_group),
        };
        let error = run_spirv_probe(ctx, &probe, &[0; 64], 1).expect_err("not SPIR-V");
        assert!(error.to_string().contains("SPIR-V"), "{error}");
    }
}

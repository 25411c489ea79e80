//! The engine shader libraries (`shaders/glsl/nacre.glsl`, `shaders/hlsl/nacre.hlsl`, and the
//! Unity Shader Graph entry points `shaders/hlsl/unity/NacreShaderGraph.hlsl`) stay in step
//! with the WGSL modules they translate, and compile — no GPU needed
//! (`tests/tests/engine_shaders_gpu.rs` proves they compute what nacre computes):
//!
//! * every function of common, lut_mapping, film_lut, film_fourier, rough_lut_mapping and
//!   film_stack has
//!   its counterpart `nacre_<name>` (a technique's `film_colour`: `nacre_<module>_colour`);
//! * every constant `NAME` is `NACRE_NAME` with the same value, every struct `S` is
//!   `NacreS` with the same fields in the same order;
//! * each WGSL module's symbol table (its header lines from `Symbols` to the next empty
//!   comment line) appears in both libraries, line for line;
//! * glslangValidator accepts the GLSL library as GLSL ES 3.00 (three.js / WebGL 2), as
//!   OpenGL GLSL 4.50 (→ SPIR-V with `-G`) and with `NACRE_VULKAN_SEPARATE_SAMPLERS` as Vulkan
//!   GLSL, the HLSL library and the Shader Graph wrapper (with stand-ins for Shader Graph's
//!   `UnityTexture3D`, `UnityTexture2DArray` and `UnitySamplerState`, which declare the
//!   fields Unity's `Texture.hlsl` declares) as HLSL → SPIR-V.
//!
//! A missing glslangValidator fails (install glslang-tools; scripts/test.sh does).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

mod support;
use support::repo_root;

const MODULES: [&str; 6] = [
    "common",
    "lut_mapping",
    "film_lut",
    "film_fourier",
    "rough_lut_mapping",
    "film_stack",
];

fn read(path: &str) -> String {
    std::fs::read_to_string(repo_root().join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn libraries() -> [(&'static str, String); 2] {
    [
        ("shaders/glsl/nacre.glsl", read("shaders/glsl/nacre.glsl")),
        ("shaders/hlsl/nacre.hlsl", read("shaders/hlsl/nacre.hlsl")),
    ]
}

/// Identifier after `prefix` at the start of a line, up to the first non-identifier char.
fn names_after<'a>(source: &'a str, prefix: &str) -> Vec<&'a str> {
    source
        .lines()
        .filter_map(|l| l.strip_prefix(prefix))
        .map(|rest| {
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            &rest[..end]
        })
        .collect()
}

/// Functions defined in a GLSL/HLSL source: `type name(` at the start of a line.
fn library_functions(source: &str) -> Vec<String> {
    source
        .lines()
        .filter(|l| !l.starts_with(' ') && !l.starts_with("//") && !l.starts_with('#'))
        .filter_map(|l| {
            let open = l.find('(')?;
            let head = &l[..open];
            let mut words = head.split_whitespace();
            let (_ty, name) = (words.next()?, words.next()?);
            words.next().is_none().then(|| name.to_string())
        })
        .collect()
}

/// `const NAME: type = value;` of a WGSL module → value without a `u` suffix.
fn wgsl_constants(source: &str) -> BTreeMap<String, f64> {
    source
        .lines()
        .filter_map(|l| l.strip_prefix("const "))
        .map(|rest| {
            let (name, rest) = rest.split_once(':').unwrap();
            let value = rest.split_once('=').unwrap().1.trim().trim_end_matches(';');
            let value = value.trim_end_matches('u');
            (name.trim().to_string(), value.parse::<f64>().unwrap())
        })
        .collect()
}

/// `[static] const type NACRE_NAME = value;` of a library.
fn library_constants(source: &str) -> BTreeMap<String, f64> {
    source
        .lines()
        .filter_map(|l| {
            let l = l.strip_prefix("static ").unwrap_or(l);
            let rest = l.strip_prefix("const ")?;
            let (_ty, rest) = rest.split_once(' ')?;
            let (name, value) = rest.split_once('=')?;
            let value = value.trim().trim_end_matches(';').trim_end_matches('u');
            Some((name.trim().to_string(), value.parse::<f64>().ok()?))
        })
        .collect()
}

/// Fields of `struct name` (WGSL `field: type,` or GLSL/HLSL `type field;`), in order.
fn struct_fields(source: &str, name: &str, wgsl: bool) -> Option<Vec<String>> {
    let start = source.find(&format!("\nstruct {name} {{\n"))?;
    let body = &source[start..];
    let body = &body[body.find('{')? + 1..body.find("\n}")?];
    Some(
        body.lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with("//"))
            .map(|l| {
                if wgsl {
                    l.split(':').next().unwrap().trim().to_string()
                } else {
                    // `uvec4 rule_offset[4];` declares `rule_offset`.
                    let name = l.trim_end_matches(';').split_whitespace().last().unwrap();
                    name.split('[').next().unwrap().to_string()
                }
            })
            .collect(),
    )
}

#[test]
fn every_wgsl_function_constant_and_struct_has_its_counterpart() {
    let libs = libraries();
    let mut checked = 0;
    for module in MODULES {
        let wgsl = read(&format!("shaders/{module}.wgsl"));
        for (path, lib) in &libs {
            let functions = library_functions(lib);
            for f in names_after(&wgsl, "fn ") {
                let expected = if f == "film_colour" {
                    format!("nacre_{module}_colour")
                } else {
                    format!("nacre_{f}")
                };
                assert!(
                    functions.contains(&expected),
                    "{path}: no `{expected}` for `{f}` of {module}.wgsl"
                );
                checked += 1;
            }
            let constants = library_constants(lib);
            for (name, value) in wgsl_constants(&wgsl) {
                let key = format!("NACRE_{name}");
                let got = constants
                    .get(&key)
                    .unwrap_or_else(|| panic!("{path}: no `{key}` for {module}.wgsl's `{name}`"));
                assert_eq!(
                    *got, value,
                    "{path}: {key} = {got}, {module}.wgsl says {value}"
                );
            }
            for s in names_after(&wgsl, "struct ") {
                let ours = format!("Nacre{s}");
                let expected = struct_fields(&wgsl, s, true).unwrap();
                let got = struct_fields(lib, &ours, false).unwrap_or_else(|| {
                    panic!("{path}: no `struct {ours}` for {module}.wgsl's `{s}`")
                });
                assert_eq!(got, expected, "{path}: fields of {ours}");
            }
        }
    }
    // The 5 modules hold 61 functions; a parser that found none would pass silently.
    assert!(checked > 2 * 50, "only {checked} functions checked");
}

#[test]
fn each_wgsl_symbol_table_is_in_both_libraries() {
    let libs = libraries();
    for module in MODULES {
        let wgsl = read(&format!("shaders/{module}.wgsl"));
        let lines: Vec<&str> = wgsl.lines().take_while(|l| l.starts_with("//")).collect();
        let start = lines
            .iter()
            .position(|l| l.starts_with("// Symbols"))
            .unwrap_or_else(|| panic!("{module}.wgsl: no symbol table"));
        // The `Symbols` line, then the table up to the next empty comment line.
        let mut end = start + 1;
        while end < lines.len() && lines[end] == "//" {
            end += 1;
        }
        while end < lines.len() && lines[end] != "//" {
            end += 1;
        }
        let table = &lines[start..end];
        assert!(
            table.len() > 3,
            "{module}.wgsl: symbol table of {} lines",
            table.len()
        );
        for (path, lib) in &libs {
            let block = table.join("\n");
            assert!(
                lib.contains(&block),
                "{path}: {module}.wgsl's symbol table is missing or differs:\n{block}"
            );
        }
    }
}

/// Runs glslangValidator with `args` on `source` saved as `name` in a fresh directory that
/// also holds `extra` files; panics with its output when it rejects the source.
fn glslang(name: &str, source: &str, args: &[&str], extra: &[(&str, &str)]) {
    let dir = std::env::temp_dir().join(format!(
        "nacre-engine-shaders-{}-{}",
        std::process::id(),
        name.replace('.', "-")
    ));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, text) in extra {
        std::fs::write(dir.join(file), text).unwrap();
    }
    let file = dir.join(name);
    std::fs::write(&file, source).unwrap();
    let mut command = Command::new("glslangValidator");
    command.args(args).arg(&file);
    if !args.is_empty() {
        command.arg("-o").arg(dir.join("out.spv"));
    }
    let output = command.output().unwrap_or_else(|e| {
        panic!(
            "running glslangValidator ({e}): the engine-library tests need it — install \
                 glslang-tools (`apt-get install glslang-tools`; scripts/test.sh does)"
        )
    });
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        output.status.success(),
        "glslangValidator {args:?} rejected {name}:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

const GLSL_CONSUMER: &str = r#"
void nacre_test(inout vec4 o) {
    NacreFilmInput i = nacre_make_film_input(0.5, 300.0, 1.4, 10.0, 1.0, vec3(1.5), vec3(0.0));
    NacreFilmOutput a = nacre_film_lut_colour(LUT_ARGS, lut_params, i);
    NacreFilmOutput b = nacre_film_fourier_colour(fourier_table, fourier_params, i);
    vec3 e = nacre_rough_lut_sample(ROUGH_ARGS, rough_params, 0.5, 0.2, 300.0, 1.4);
    NacreFilmOutput s = nacre_film_stack_colour(stack_table, stack_params, i);
    o = vec4(a.reflectance + a.transmittance + b.reflectance + b.transmittance + e + s.reflectance + s.transmittance, 1.0);
}
"#;

#[test]
fn the_glsl_library_compiles_for_webgl_opengl_and_vulkan() {
    let lib = read("shaders/glsl/nacre.glsl");
    // GLSL ES 3.00 (three.js: precision statements first, combined samplers, plain uniforms).
    let es = format!(
        "#version 300 es\nprecision highp float;\nprecision highp int;\n\
         precision highp sampler3D;\nprecision highp sampler2DArray;\nprecision highp sampler2D;\n{lib}\n\
         uniform sampler3D lut_r;\nuniform sampler3D lut_t;\nuniform sampler2DArray fourier_table;\n\
         uniform sampler2D stack_table;\nuniform NacreStackParams stack_params;\n\
         uniform NacreFilmLutParams lut_params;\nuniform NacreFourierParams fourier_params;\n\
         uniform NacreRoughLutParams rough_params;\nout vec4 colour;\n\
         #define LUT_ARGS lut_r, lut_t\n#define ROUGH_ARGS lut_r\n{GLSL_CONSUMER}\n\
         void main() {{ nacre_test(colour); }}\n"
    );
    glslang("es300.frag", &es, &[], &[]);
    // OpenGL 4.50 (SPIR-V for OpenGL: explicit bindings, std140 block).
    let gl = format!(
        "#version 450\n{lib}\n\
         layout(binding = 0) uniform sampler3D lut_r;\nlayout(binding = 1) uniform sampler3D lut_t;\n\
         layout(binding = 2) uniform sampler2DArray fourier_table;\n\
         layout(binding = 4) uniform sampler2D stack_table;\n\
         layout(std140, binding = 3) uniform Params {{ NacreFilmLutParams lut_params; \
         NacreFourierParams fourier_params; NacreRoughLutParams rough_params; \
         NacreStackParams stack_params; }};\n\
         layout(location = 0) out vec4 colour;\n\
         #define LUT_ARGS lut_r, lut_t\n#define ROUGH_ARGS lut_r\n{GLSL_CONSUMER}\n\
         void main() {{ nacre_test(colour); }}\n"
    );
    glslang("gl450.frag", &gl, &["-G"], &[]);
    // Vulkan GLSL with separate textures and samplers.
    let vk = format!(
        "#version 450\n#extension GL_EXT_samplerless_texture_functions : require\n\
         #define NACRE_VULKAN_SEPARATE_SAMPLERS\n{lib}\n\
         layout(set = 0, binding = 0) uniform texture3D lut_r;\n\
         layout(set = 0, binding = 1) uniform texture3D lut_t;\n\
         layout(set = 0, binding = 2) uniform sampler lut_s;\n\
         layout(set = 0, binding = 3) uniform texture2DArray fourier_table;\n\
         layout(set = 0, binding = 5) uniform texture2D stack_table;\n\
         layout(std140, set = 0, binding = 4) uniform Params {{ NacreFilmLutParams lut_params; \
         NacreFourierParams fourier_params; NacreRoughLutParams rough_params; \
         NacreStackParams stack_params; }};\n\
         layout(location = 0) out vec4 colour;\n\
         #define LUT_ARGS lut_r, lut_s, lut_t, lut_s\n#define ROUGH_ARGS lut_r, lut_s\n{GLSL_CONSUMER}\n\
         void main() {{ nacre_test(colour); }}\n"
    );
    glslang("vulkan.frag", &vk, &["-V"], &[]);
}

#[test]
fn the_hlsl_library_and_the_shader_graph_entry_points_compile() {
    let hlsl_dir: PathBuf = repo_root().join("shaders/hlsl");
    let include = format!("-I{}", hlsl_dir.display());
    let lib = read("shaders/hlsl/nacre.hlsl");
    let plain = format!(
        "{lib}\nTexture3D<float4> lut_r;\nTexture3D<float4> lut_t;\nSamplerState lut_s;\n\
         Texture2DArray<float4> fourier_table;\nTexture2D<float4> stack_table;\n\
         cbuffer Params {{ NacreFilmLutParams lut_params; NacreFourierParams fourier_params; \
         NacreRoughLutParams rough_params; NacreStackParams stack_params; }};\n\
         float4 main() : SV_Target {{\n\
         NacreFilmInput i = nacre_make_film_input(0.5, 300.0, 1.4, 10.0, 1.0, (float3)1.5, (float3)0.0);\n\
         NacreFilmOutput a = nacre_film_lut_colour(lut_r, lut_s, lut_t, lut_s, lut_params, i);\n\
         NacreFilmOutput b = nacre_film_fourier_colour(fourier_table, fourier_params, i);\n\
         float3 e = nacre_rough_lut_sample(lut_r, lut_s, rough_params, 0.5, 0.2, 300.0, 1.4);\n\
         NacreFilmOutput s = nacre_film_stack_colour(stack_table, stack_params, i);\n\
         return float4(a.reflectance + a.transmittance + b.reflectance + b.transmittance + e \
         + s.reflectance + s.transmittance, 1.0);\n}}\n"
    );
    glslang(
        "plain.hlsl",
        &plain,
        &["-D", "-V", "-e", "main", "-S", "frag"],
        &[],
    );
    // Shader Graph declares these in Packages/com.unity.shadergraph/ShaderGraphLibrary/Texture.hlsl
    // (fields `tex` and `samplerstate`); stand-ins with the same fields.
    let shim = "struct UnityTexture3D { Texture3D<float4> tex; SamplerState samplerstate; };\n\
                struct UnityTexture2DArray { Texture2DArray<float4> tex; SamplerState samplerstate; };\n\
                struct UnitySamplerState { SamplerState samplerstate; };\n";
    let graph = r#"#include "shim.hlsl"
#include "unity/NacreShaderGraph.hlsl"
Texture3D<float4> r;
Texture2DArray<float4> f;
SamplerState s;
float4 main() : SV_Target {
    UnityTexture3D t;
    t.tex = r;
    t.samplerstate = s;
    UnityTexture2DArray a;
    a.tex = f;
    a.samplerstate = s;
    UnitySamplerState ss;
    ss.samplerstate = s;
    float3 R;
    float3 T;
    float3 R2;
    float3 T2;
    float3 E;
    NacreFilmLut_float(t, t, ss, float3(64, 256, 32), float2(0, 1000), float2(1.2, 2.4), 1.0, 1.0, 0.5, 300.0, 1.4, R, T);
    NacreFilmFourier_float(a, 20000.0, 8.0, 10.0, float3(0.0017, 0.0019, 0.0022), (float3)1.0, 3.0, 0.5, 300.0, 1.4, 0.0, 1.0, (float3)1.5, (float3)0.0, R2, T2);
    NacreRoughFilmLut_float(t, ss, float4(16, 64, 8, 8), 1000.0, float2(1.2, 2.4), float2(0.01, 1.0), 1.0, 0.5, 0.3, 300.0, 1.4, E);
    return float4(R + T + R2 + T2 + E, 1.0);
}
"#;
    glslang(
        "graph.hlsl",
        graph,
        &["-D", "-V", "-e", "main", "-S", "frag", &include],
        &[("shim.hlsl", shim)],
    );
    assert!(Path::new(&hlsl_dir.join("unity/NacreShaderGraph.hlsl")).is_file());
}

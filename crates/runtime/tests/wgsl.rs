//! Every WGSL composition under `shaders/` parses, validates and translates to every backend
//! (SPIR-V, MSL, HLSL, GLSL 4.50 core and GLSL ES 3.10) with naga — no GPU needed. Also
//! checks the bind-group contract of the technique modules, the byte layouts that the Rust
//! `bytemuck` mirrors rely on, and that every `.wgsl` file opens with a comment header.

use nacre_runtime::shaders::{
    self, ComposeError, MODULES, Part, TECHNIQUE_MODULES, Technique, compose, resolve,
};
use std::path::PathBuf;

mod support;
use support::{translate, validate};

/// A tiny consumer: a fragment entry point fed from a group-2 uniform and the fragment
/// position, writing reflectance and transmittance so that nothing is dead code, and a compute
/// entry point that round-trips the film-lut mappings and evaluates the technique too.
const CONSUMER: &str = r#"
// Test consumer (crates/runtime/tests/wgsl.rs).
@group(2) @binding(0) var<uniform> test_film: FilmInput;
@group(2) @binding(1) var<storage, read_write> test_out: array<vec4<f32>>;

struct TestFragment {
    @location(0) reflectance: vec4<f32>,
    @location(1) transmittance: vec4<f32>,
}

@fragment
fn fs_test(@builtin(position) frag: vec4<f32>) -> TestFragment {
    var input = test_film;
    input.cos_theta_i = input.cos_theta_i * fract(frag.x / 64.0);
    input.thickness_nm = input.thickness_nm + frag.y;
    let film = film_colour(input);
    var out: TestFragment;
    out.reflectance = vec4<f32>(film.reflectance, 1.0);
    out.transmittance = vec4<f32>(film.transmittance, 1.0);
    return out;
}

@compute @workgroup_size(1)
fn cs_test(@builtin(global_invocation_id) id: vec3<u32>) {
    let axes = FilmLutParams(17u, 33u, 9u, 0.0, 1200.0, 1.0, 2.5, 1.0, 0u, 0u, 0u, 0u);
    let t = vec3<f32>(f32(id.x) / 16.0, f32(id.y) / 32.0, f32(id.z) / 8.0);
    let physical = lut_inverse(axes, t);
    let q = lut_film_q(axes, physical.x, physical.z);
    let d = select(0.0, physical.y / (2.0 * q), q > 0.0);
    let back = lut_forward(axes, physical.x, d, physical.z);
    let uvw = lut_texture_coordinate(back, lut_counts(axes));
    var input = test_film;
    input.cos_theta_i = physical.x;
    input.thickness_nm = d;
    input.film_ior = physical.z;
    let film = film_colour(input);
    let i = id.x + 17u * (id.y + 33u * id.z);
    test_out[2u * i] = vec4<f32>(uvw, lut_opd_nm(axes, physical.x, d, physical.z));
    test_out[2u * i + 1u] = vec4<f32>(film.reflectance + film.transmittance, 0.0);
}
"#;

/// Extra consumer for `film_fourier`: the prefilter width from screen-space derivatives.
const FOURIER_CONSUMER: &str = r#"
// Test consumer for film_fourier (crates/runtime/tests/wgsl.rs).
@fragment
fn fs_test_prefiltered(@location(0) thickness_nm: f32) -> @location(0) vec4<f32> {
    var input = test_film;
    input.thickness_nm = thickness_nm;
    input.sigma_thickness_nm = fourier_sigma_from_derivatives(dpdx(thickness_nm), dpdy(thickness_nm), test_film.sigma_thickness_nm);
    let film = film_colour(input);
    return vec4<f32>(film.reflectance, 1.0);
}
"#;

/// A consumer that declares no bindings: what remains belongs to the technique.
const BINDINGLESS_CONSUMER: &str = r#"
@fragment
fn fs_bindingless() -> @location(0) vec4<f32> {
    var input: FilmInput;
    input.cos_theta_i = 0.5;
    input.thickness_nm = 300.0;
    input.film_ior = 1.33;
    input.ambient_ior = 1.0;
    input.base_ior = vec3<f32>(1.5);
    let film = film_colour(input);
    return vec4<f32>(film.reflectance + film.transmittance, 1.0);
}
"#;

fn shaders_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shaders")
}

/// The composition of `technique` and `consumer`, with a map from its lines to the modules
/// they came from ("lines 1–250 common.wgsl, …") for error reports.
fn composition(technique: Technique, consumer: &[(&str, &str)]) -> (String, String) {
    let technique_part = Part::Module(technique.module());
    let mut roots = vec![
        Part::Module("common"),
        Part::Module("lut_mapping"),
        technique_part,
    ];
    roots.extend(
        consumer
            .iter()
            .map(|&(name, text)| Part::of_source(name, text)),
    );
    let composed = resolve(&roots, Some(technique_part)).expect("the composition resolves");
    let sources: Vec<&str> = consumer.iter().map(|&(_, text)| text).collect();
    assert_eq!(composed.source, compose(technique, &sources));
    (composed.source, composed.map.describe())
}

#[test]
fn every_composition_validates_and_translates() {
    for technique in Technique::ALL {
        let mut consumer = vec![("test consumer", CONSUMER)];
        if technique == Technique::Fourier {
            consumer.push(("fourier test consumer", FOURIER_CONSUMER));
        }
        let (source, map) = composition(technique, &consumer);
        let name = format!("film_{} + test consumer", technique.name());
        let (module, info) = validate(&name, &source, &map);
        assert!(
            module
                .functions
                .iter()
                .any(|(_, f)| f.name.as_deref() == Some("film_colour")),
            "{name}: no `fn film_colour`"
        );
        translate(&name, &module, &info);
    }
}

#[test]
fn techniques_bind_only_group_1() {
    for technique in Technique::ALL {
        let (source, map) =
            composition(technique, &[("bindingless consumer", BINDINGLESS_CONSUMER)]);
        let name = format!("film_{}", technique.name());
        let (module, info) = validate(&name, &source, &map);
        let groups: Vec<(String, u32, u32)> = module
            .global_variables
            .iter()
            .filter_map(|(_, g)| {
                let b = g.binding.as_ref()?;
                Some((g.name.clone().unwrap_or_default(), b.group, b.binding))
            })
            .collect();
        assert!(!groups.is_empty(), "{name}: binds nothing");
        for (var, group, binding) in &groups {
            assert_eq!(
                *group, 1,
                "{name}: `{var}` is in group {group} (binding {binding}); techniques own group 1 only"
            );
        }
        translate(&name, &module, &info);
    }
}

/// A struct's name, size in bytes, and (member, offset) list.
type StructLayout = (&'static str, u32, &'static [(&'static str, u32)]);

/// The member offsets and sizes that the Rust `#[repr(C)]` mirrors in `nacre_runtime` must
/// reproduce (see the layout comments in the `.wgsl` files).
#[test]
fn uniform_layouts_match_the_documented_ones() {
    let expected: [StructLayout; 7] = [
        (
            "FilmInput",
            64,
            &[
                ("cos_theta_i", 0),
                ("thickness_nm", 4),
                ("film_ior", 8),
                ("sigma_thickness_nm", 12),
                ("ambient_ior", 16),
                ("variation", 20),
                ("variation_g", 24),
                ("variation_b", 28),
                ("base_ior", 32),
                ("_pad3", 44),
                ("base_kappa", 48),
                ("_pad4", 60),
            ],
        ),
        (
            "FilmLutParams",
            48,
            &[
                ("cos_theta_count", 0),
                ("opd_count", 4),
                ("ior_count", 8),
                ("thickness_min_nm", 12),
                ("thickness_max_nm", 16),
                ("ior_min", 20),
                ("ior_max", 24),
                ("ambient_index", 28),
                ("has_transmittance", 32),
                ("_pad0", 36),
                ("_pad1", 40),
                ("_pad2", 44),
            ],
        ),
        (
            "FourierParams",
            48,
            &[
                ("max_opd_nm", 0),
                ("level_count", 4),
                ("sigma1_nm", 8),
                ("harmonics", 12),
                ("carrier_nu_per_nm", 16),
                ("_pad0", 28),
                ("white", 32),
                ("_pad1", 44),
            ],
        ),
        (
            "SpectralSample",
            32,
            &[
                ("wavelength_nm", 0),
                ("base_ior", 4),
                ("base_kappa", 8),
                ("_pad", 12),
                ("weight", 16),
            ],
        ),
        (
            "SpectralParams",
            16,
            &[("count", 0), ("_pad0", 4), ("_pad1", 8), ("_pad2", 12)],
        ),
        (
            "StackNode",
            32,
            &[
                ("wavelength_nm", 0),
                ("_pad0", 4),
                ("_pad1", 8),
                ("_pad2", 12),
                ("weight", 16),
            ],
        ),
        (
            "StackParams",
            288,
            &[
                ("films", 0),
                ("dispersive", 4),
                ("rule_count", 8),
                ("fixed_rule", 12),
                ("base_count", 16),
                ("count_per_opd_nm", 20),
                ("finesse", 24),
                ("_pad0", 28),
                ("rule_offset", 32),
                ("rule_size", 96),
                ("layers", 160),
            ],
        ),
    ];
    let modules: Vec<naga::Module> = Technique::ALL
        .iter()
        .map(|&t| {
            let (source, map) = composition(t, &[("bindingless consumer", BINDINGLESS_CONSUMER)]);
            validate(t.name(), &source, &map).0
        })
        .collect();
    for (struct_name, span, members) in expected {
        let found = modules
            .iter()
            .flat_map(|m| m.types.iter())
            .find(|(_, ty)| ty.name.as_deref() == Some(struct_name))
            .unwrap_or_else(|| panic!("struct {struct_name} not declared"));
        let naga::TypeInner::Struct {
            members: ref actual,
            span: actual_span,
        } = found.1.inner
        else {
            panic!("{struct_name} is not a struct");
        };
        let actual: Vec<(&str, u32)> = actual
            .iter()
            .map(|m| (m.name.as_deref().unwrap_or(""), m.offset))
            .collect();
        assert_eq!(actual, members, "{struct_name}: member offsets");
        assert_eq!(actual_span, span, "{struct_name}: size");
    }
    // The host mirrors (`nacre_runtime::params`, the table kinds' uniforms of
    // `nacre_format::gpu_params`) have the same sizes.
    use nacre_runtime::params;
    use std::mem::size_of;
    let host: [(&str, usize); 7] = [
        ("FilmInput", size_of::<params::FilmInput>()),
        ("FilmLutParams", size_of::<params::FilmLutParams>()),
        ("FourierParams", size_of::<params::FourierParams>()),
        ("SpectralSample", size_of::<params::SpectralSample>()),
        ("SpectralParams", size_of::<params::SpectralParams>()),
        ("StackNode", size_of::<params::StackNode>()),
        ("StackParams", size_of::<params::StackParams>()),
    ];
    for ((name, size), (struct_name, span, _)) in host.iter().zip(&expected) {
        assert_eq!((*name, *size), (*struct_name, *span as usize));
    }
}

/// `nacre_runtime::mesh::MeshUniform` (480 bytes) mirrors `MeshParams` (`shaders/mesh.wgsl`)
/// member by member: naga's offsets are Rust's.
#[test]
fn mesh_uniform_matches_mesh_params() {
    use nacre_runtime::mesh::MeshUniform;
    use nacre_runtime::shaders::{MATERIAL, MESH};
    let (source, map) = composition(
        Technique::Lut,
        &[("material.wgsl", MATERIAL), ("mesh.wgsl", MESH)],
    );
    let (module, _) = validate("mesh.wgsl", &source, &map);
    let found = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some("MeshParams"))
        .expect("MeshParams declared");
    let naga::TypeInner::Struct { ref members, span } = found.1.inner else {
        panic!("MeshParams is not a struct");
    };
    let actual: Vec<(&str, u32)> = members
        .iter()
        .map(|m| (m.name.as_deref().unwrap_or(""), m.offset))
        .collect();
    macro_rules! offsets {
        ($($field:ident),* $(,)?) => {
            vec![$((stringify!($field), std::mem::offset_of!(MeshUniform, $field) as u32)),*]
        };
    }
    let host = offsets![
        view_proj,
        base_colour,
        emissive,
        metallic,
        specular_colour,
        roughness,
        specular,
        normal_scale,
        occlusion_strength,
        alpha_cutoff,
        dielectric_ior,
        iridescence,
        alpha_mode,
        flags,
        transmission,
        lobes,
        volume_thickness,
        attenuation_distance,
        attenuation_colour,
        clearcoat,
        clearcoat_roughness,
        clearcoat_normal_scale,
        coat_slots,
        transforms,
    ];
    assert_eq!(actual, host, "MeshParams member offsets");
    assert_eq!(span, 480);
    assert_eq!(std::mem::size_of::<MeshUniform>(), span as usize);
}

#[test]
fn every_shader_file_opens_with_a_comment_header() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(shaders_dir())
        .expect("shaders/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 5,
        "expected the shader modules, found {files:?}"
    );
    for path in files {
        let text = std::fs::read_to_string(&path).expect("readable shader");
        assert!(
            text.starts_with("//"),
            "{} does not begin with a `//` comment header",
            path.display()
        );
    }
}

/// The consumers the runtime itself composes (the glTF mesh pass, probe, bench; the plain
/// baseline).
#[test]
fn the_runtimes_own_pipelines_validate_and_translate() {
    use nacre_runtime::shaders::{BENCH, MATERIAL, MESH, PLAIN, PROBE, SCENE, compose_source};
    for technique in Technique::ALL {
        let (source, map) = composition(
            technique,
            &[("material.wgsl", MATERIAL), ("mesh.wgsl", MESH)],
        );
        let name = format!("film_{} + material.wgsl + mesh.wgsl", technique.name());
        let (module, info) = validate(&name, &source, &map);
        translate(&name, &module, &info);
        // The ray-cast scenes: display and linear (split-sum comparison) outputs.
        let (source, map) = composition(
            technique,
            &[("material.wgsl", MATERIAL), ("scene.wgsl", SCENE)],
        );
        let name = format!("film_{} + material.wgsl + scene.wgsl", technique.name());
        let (module, info) = validate(&name, &source, &map);
        translate(&name, &module, &info);
        for entry in ["scene_fs", "scene_fs_linear"] {
            assert!(
                module.entry_points.iter().any(|e| e.name == entry),
                "{name}: {entry} missing"
            );
        }
        for (consumer_name, consumer) in [("probe.wgsl", PROBE), ("bench.wgsl", BENCH)] {
            let (source, map) = composition(technique, &[(consumer_name, consumer)]);
            let name = format!("film_{} + {consumer_name}", technique.name());
            let (module, info) = validate(&name, &source, &map);
            translate(&name, &module, &info);
        }
    }
    let source = compose_source(PLAIN, &[BENCH]);
    let (module, info) = validate(
        "plain + bench",
        &source,
        "common, lut_mapping, plain, bench",
    );
    assert_eq!(
        source,
        shaders::film_pipeline("plain", &["bench"]).unwrap().source
    );
    translate("plain + bench", &module, &info);
}

/// The `diffraction` technique and its consumers (`shaders/diffraction.wgsl`,
/// `shaders/diffraction_scene.wgsl`): they validate and translate to every backend, the
/// technique alone binds group 1 only, and the uniforms have the documented layouts that
/// `nacre_runtime::diffraction`'s `#[repr(C)]` mirrors reproduce.
#[test]
fn diffraction_technique_validates_and_translates() {
    use nacre_runtime::diffraction::{
        DIFFRACTION, DiffractionLightsUniform, DiffractionUniform, compose,
    };
    let source = compose();
    let (module, info) = validate(
        "diffraction + diffraction_scene",
        &source,
        "diffraction.wgsl, diffraction_scene.wgsl",
    );
    translate("diffraction + diffraction_scene", &module, &info);
    for entry in [
        "diffraction_vs",
        "diffraction_scene_fs",
        "diffraction_probe",
    ] {
        assert!(
            module.entry_points.iter().any(|e| e.name == entry),
            "{entry} missing"
        );
    }
    let layout = |name: &str| -> (u32, Vec<(String, u32)>) {
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("struct {name} not declared"));
        let naga::TypeInner::Struct { ref members, span } = ty.inner else {
            panic!("{name} is not a struct");
        };
        (
            span,
            members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                .collect(),
        )
    };
    let (span, members) = layout("DiffractionParams");
    assert_eq!(span as usize, std::mem::size_of::<DiffractionUniform>());
    let offsets: Vec<u32> = members.iter().map(|m| m.1).collect();
    assert_eq!(offsets, [0, 8, 16, 24, 32, 36, 40, 44, 48, 56]);
    let (span, members) = layout("DiffractionLights");
    assert_eq!(
        span as usize,
        std::mem::size_of::<DiffractionLightsUniform>()
    );
    let offsets: Vec<u32> = members.iter().map(|m| m.1).collect();
    assert_eq!(offsets, [0, 4, 8, 12, 16, 144, 272, 288, 304]);
    // Group 0 is every scene's view (shaders/view.wgsl, `ViewUniform`).
    let (span, _) = layout("ViewParams");
    assert_eq!(
        span as usize,
        std::mem::size_of::<nacre_runtime::render::ViewUniform>()
    );

    // The technique alone, with a consumer that binds nothing: group 1 only.
    let consumer = "
@fragment
fn fs_bindingless(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let frame = diffraction_frame(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(1.0, 0.0, 0.0));
    let c = diffraction_colour(frame * vec3<f32>(-0.3, 0.0, 0.9), vec3<f32>(p.x, 0.0, 1.0));
    return vec4<f32>(c + diffraction_specular_order_colour(p.y), 1.0);
}
";
    let source = format!("{DIFFRACTION}\n{consumer}\n");
    let (module, info) = validate("diffraction", &source, "diffraction.wgsl, consumer");
    translate("diffraction", &module, &info);
    for (_, g) in module.global_variables.iter() {
        if let Some(b) = &g.binding {
            assert_eq!(
                b.group, 1,
                "diffraction: `{:?}` is in group {}",
                g.name, b.group
            );
        }
    }
}

/// What a host gets: every module of `shaders/` flattened with its imports (those that import
/// `<technique>` once with each technique of their family) parses, validates and translates,
/// so that every header declares all that its module needs.
#[test]
fn every_flattened_file_validates_and_translates() {
    let film = ["film_lut", "film_fourier", "film_spectral", "plain"];
    let diffraction = ["diffraction", "diffraction_integrated_technique"];
    let mut count = 0;
    for m in MODULES {
        let techniques: Vec<Option<&str>> = match shaders::flatten(m.name) {
            Ok(_) => vec![None],
            Err(ComposeError::NoTechnique { .. }) if m.name.starts_with("diffraction") => {
                diffraction.iter().copied().map(Some).collect()
            }
            Err(ComposeError::NoTechnique { .. }) => film.iter().copied().map(Some).collect(),
            Err(e) => panic!("{}: {e}", m.name),
        };
        for technique in techniques {
            let composed = match technique {
                None => shaders::flatten(m.name),
                Some(t) => shaders::flatten_with(m.name, t),
            }
            .unwrap_or_else(|e| panic!("{}: {e}", m.name));
            let name = format!("{} ({})", m.name, technique.unwrap_or("no technique"));
            assert_eq!(
                composed.map.spans.last().map(|s| s.file.as_str()),
                Some(format!("{}.wgsl", m.name).as_str()),
                "{name}: the entry comes last"
            );
            let (module, info) = validate(&name, &composed.source, &composed.map.describe());
            translate(&name, &module, &info);
            count += 1;
        }
    }
    assert!(count >= MODULES.len());
    for t in TECHNIQUE_MODULES.iter().filter(|&&t| t != "plain") {
        let composed = shaders::flatten(t).unwrap_or_else(|e| panic!("{t}: {e}"));
        assert!(composed.source.contains("@group(1)"), "{t}: binds group 1");
    }
    for t in Technique::ALL {
        assert!(TECHNIQUE_MODULES.contains(&t.module()));
        assert_eq!(shaders::module(t.module()).unwrap().source, t.source());
    }
}

/// The technique constants of the diffraction modules are their flattened files.
#[test]
fn diffraction_constants_are_the_flattened_modules() {
    use nacre_runtime::diffraction::{self, DIFFRACTION, DIFFRACTION_COMMON, DIFFRACTION_SCENE};
    use nacre_runtime::diffraction_integrated::{
        self as integrated, PROBE, TECHNIQUE_ADAPTER, WGSL,
    };
    use nacre_runtime::shaders::{OUTPUT, ROUGH_LUT_MAPPING, VIEW};
    let flat = |name: &str| shaders::flatten(name).unwrap().source;
    assert_eq!(format!("{DIFFRACTION}\n"), flat("diffraction"));
    assert_eq!(format!("{WGSL}\n"), flat("diffraction_integrated"));
    assert_eq!(
        format!("{DIFFRACTION_COMMON}\n"),
        flat("diffraction_common")
    );
    // The concatenations of the three pipelines (the scenes share view.wgsl's group 0).
    assert_eq!(
        diffraction::compose(),
        format!("{DIFFRACTION}\n{ROUGH_LUT_MAPPING}\n{VIEW}\n{OUTPUT}\n{DIFFRACTION_SCENE}\n")
    );
    assert_eq!(integrated::compose_probe(), format!("{WGSL}\n{PROBE}\n"));
    assert_eq!(
        integrated::compose_scene(),
        format!(
            "{WGSL}\n{TECHNIQUE_ADAPTER}\n{ROUGH_LUT_MAPPING}\n{VIEW}\n{OUTPUT}\n{DIFFRACTION_SCENE}\n"
        )
    );
}

/// naga's error positions in a composed source map back to the module and its line: a parse
/// error and a validation error in a module composed after common.wgsl and a technique.
#[test]
fn naga_error_positions_map_to_module_lines() {
    // Line 4 of "broken.wgsl" lacks an operand.
    let broken = "// broken.wgsl: a test module\n// import: common, <technique>\nfn broken() -> f32 {\n    return 1.0 +;\n}\n";
    let technique = Some(Part::Module("film_fourier"));
    let composed = resolve(
        &[Part::Source {
            label: "broken.wgsl",
            source: broken,
        }],
        technique,
    )
    .unwrap();
    let files: Vec<&str> = composed.map.spans.iter().map(|s| s.file.as_str()).collect();
    assert_eq!(files, ["common.wgsl", "film_fourier.wgsl", "broken.wgsl"]);
    let error = naga::front::wgsl::parse_str(&composed.source).expect_err("a syntax error");
    let at = error.location(&composed.source).expect("a position");
    let place = composed
        .map
        .locate(at.line_number, at.line_position)
        .unwrap();
    assert_eq!(
        (place.file.as_str(), place.line),
        ("broken.wgsl", 4),
        "{place}"
    );
    assert!(
        at.line_number > 100,
        "the composed line is not the module's"
    );
    let by_offset = composed.locate_offset(at.offset as usize).unwrap();
    assert_eq!(by_offset, place);

    // A validation error (a vec2 returned as f32) in the function that begins on line 4 of
    // "wrong.wgsl" (where naga places it), composed before probe.wgsl.
    let wrong =
        "// wrong.wgsl\n// import: common\n\nfn wrong() -> f32 {\n    return vec2<f32>(1.0);\n}\n";
    let composed = resolve(
        &[
            Part::Source {
                label: "wrong.wgsl",
                source: wrong,
            },
            Part::Module("probe"),
        ],
        technique,
    )
    .unwrap();
    let module = naga::front::wgsl::parse_str(&composed.source).expect("parses");
    let error = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .expect_err("a type error");
    let at = error.location(&composed.source).expect("a position");
    let place = composed
        .map
        .locate(at.line_number, at.line_position)
        .unwrap();
    assert_eq!(
        (place.file.as_str(), place.line),
        ("wrong.wgsl", 4),
        "{place}"
    );
}

//! `shaders/rough_lut_mapping.wgsl` (the rough-film-lut mappings and two-fetch lookup, issue
//! 6) parses and validates with naga, on its own, with a consumer that uses every function,
//! and translates to SPIR-V — no GPU needed — and its uniform mirror is 48 bytes.

use naga::back::spv;
use naga::valid::{Capabilities, ValidationFlags, Validator};

const MAPPING: &str = include_str!("../../../shaders/rough_lut_mapping.wgsl");

const CONSUMER: &str = r#"
// Test consumer (crates/runtime/tests/rough_lut_wgsl.rs).
@group(0) @binding(0) var<uniform> rough_params: RoughLutParams;
@group(0) @binding(1) var rough_reflectance: texture_3d<f32>;
@group(0) @binding(2) var rough_sampler: sampler;
@group(0) @binding(3) var<storage, read_write> rough_out: array<vec4<f32>>;

@fragment
fn fs_test(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let cos_o = fract(frag.x / 64.0);
    let alpha = fract(frag.y / 64.0);
    let e = rough_lut_sample(rough_reflectance, rough_sampler, rough_params, cos_o, alpha, 400.0, 1.5);
    return vec4<f32>(e, 1.0);
}

@compute @workgroup_size(1)
fn cs_test(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = vec4<f32>(f32(id.x) / 15.0, f32(id.y) / 255.0, f32(id.z) / 15.0, 0.5);
    let phys = rough_lut_inverse(rough_params, t);
    let q = rough_lut_film_q(rough_params, rough_lut_reference_cos(phys.x, phys.w), phys.z);
    let d = select(0.0, phys.y / (2.0 * q), q > 0.0);
    let back = rough_lut_forward(rough_params, phys.x, phys.w, d, phys.z);
    let k = rough_lut_coords(rough_params, phys.x, phys.w, d, phys.z);
    let i = id.x + 16u * (id.y + 256u * id.z);
    rough_out[2u * i] = back;
    rough_out[2u * i + 1u] = vec4<f32>(k.uvw0.z, k.uvw1.z, k.blend, rough_lut_opd_nm(rough_params, phys.x, phys.w, d, phys.z));
}
"#;

fn validate(source: &str) -> (naga::Module, naga::valid::ModuleInfo) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("WGSL parse error\n{}", e.emit_to_string(source)));
    let info = Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("validation error\n{}", e.emit_to_string(source)));
    (module, info)
}

#[test]
fn rough_lut_mapping_validates_alone_and_with_a_consumer() {
    assert!(MAPPING.starts_with("// nacre · shaders/rough_lut_mapping.wgsl"));
    validate(MAPPING);
    let source = format!("{MAPPING}\n{CONSUMER}");
    let (module, info) = validate(&source);
    spv::write_vec(&module, &info, &spv::Options::default(), None).expect("translates to SPIR-V");
    // The uniform mirror of `RoughLutAxes` is 48 bytes (12 four-byte fields).
    let ty = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("RoughLutParams"))
        .expect("RoughLutParams declared")
        .0;
    assert_eq!(module.types[ty].inner.size(module.to_ctx()), 48);
}

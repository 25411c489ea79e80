// probe.wgsl — consumer module of the GPU = CPU tests (crates/runtime/src/probe.rs).
// import: common, <technique>
//
// Renders one FilmInput per pixel of a full-screen triangle: pixel (x, y) evaluates
// probe_inputs[y * width + x] with the technique's `film_colour` and writes reflectance to
// target 0 and transmittance to target 1 (both Rgba32Float, alpha 1). Pixels beyond `count`
// write zero. No view state: group 0 is empty; group 1 is the technique's tables.
//
// Symbols: width — pixels per row of the probe target; count — number of probe points.

struct ProbeParams {
    width: u32,
    count: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(2) @binding(0) var<storage, read> probe_inputs: array<FilmInput>;
@group(2) @binding(1) var<uniform> probe: ProbeParams;

@vertex
fn probe_vs(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
    let x = f32(i32(index & 1u) * 4 - 1);
    let y = f32(i32(index >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

struct ProbeOutput {
    @location(0) reflectance: vec4<f32>,
    @location(1) transmittance: vec4<f32>,
}

@fragment
fn probe_fs(@builtin(position) position: vec4<f32>) -> ProbeOutput {
    let index = u32(position.y) * probe.width + u32(position.x);
    var out: ProbeOutput;
    out.reflectance = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    out.transmittance = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if index < probe.count {
        let film = film_colour(probe_inputs[index]);
        out.reflectance = vec4<f32>(film.reflectance, 1.0);
        out.transmittance = vec4<f32>(film.transmittance, 1.0);
    }
    return out;
}

// bevy_nacre · tests/probe.wgsl — GPU = CPU probe through the plugin's shader modules.
//
// One invocation per input: nacre's `film_colour` of the three techniques, as Bevy's
// composer builds them from the repository's shaders (src/shaders.rs), with
// MATERIAL_BIND_GROUP = 0 so that the tables sit at bindings 100–105 and the stack's buffers
// at 111–113 of group 0, next to the probe's buffers.

#import nacre::common::{FilmInput, FilmOutput}
#import nacre::film_lut
#import nacre::film_fourier
#import nacre::film_stack

struct ProbeOutput {
    lut_reflectance: vec4<f32>,
    lut_transmittance: vec4<f32>,
    fourier_reflectance: vec4<f32>,
    fourier_transmittance: vec4<f32>,
    stack_reflectance: vec4<f32>,
    stack_transmittance: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> probe_inputs: array<FilmInput>;
@group(0) @binding(1) var<storage, read_write> probe_outputs: array<ProbeOutput>;

@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&probe_inputs) {
        return;
    }
    let lut = film_lut::film_colour(probe_inputs[i]);
    let fourier = film_fourier::film_colour(probe_inputs[i]);
    let stack = film_stack::film_colour(probe_inputs[i]);
    probe_outputs[i] = ProbeOutput(
        vec4<f32>(lut.reflectance, 0.0),
        vec4<f32>(lut.transmittance, 0.0),
        vec4<f32>(fourier.reflectance, 0.0),
        vec4<f32>(fourier.transmittance, 0.0),
        vec4<f32>(stack.reflectance, 0.0),
        vec4<f32>(stack.transmittance, 0.0),
    );
}

// nacre · shaders/mip_down.wgsl — one mip level of a float picture from the level above
// import: (none)
//
// A full-screen triangle whose fragment at texel (x, y) of level k + 1 is the mean of the
// 2 × 2 texels (2x, 2y) … (2x + 1, 2y + 1) of level k (clamped to level k's edge: an odd
// size repeats its last row or column): the box-filtered mip chain of the picture of the
// opaque scene that transmissive glTF surfaces refract (crates/runtime/src/mesh.rs), read
// through `mesh_behind_sample` at the level the surface's roughness asks for. Alpha is
// averaged like colour: the picture is premultiplied (cleared to 0 where nothing was drawn),
// so a level's alpha is the share of its footprint that shows the scene.
//
// Group 0: binding 0, level k (one mip level's view; textureLoad, so the format need not be
// filterable).

@group(0) @binding(0) var mip_source: texture_2d<f32>;

@vertex
fn mip_down_vs(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
    let x = f32(i32(index & 1u) * 4 - 1);
    let y = f32(i32(index >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn mip_down_fs(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let last = vec2<i32>(textureDimensions(mip_source)) - 1;
    let corner = 2 * vec2<i32>(position.xy);
    var sum = vec4<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let texel = min(corner + vec2<i32>(k & 1, k >> 1u), last);
        sum += textureLoad(mip_source, texel, 0);
    }
    return 0.25 * sum;
}

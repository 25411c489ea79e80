// nacre · shaders/scene.wgsl — consumer: analytic scenes ray-cast in a fragment shader
// import: material
//
// A full-screen triangle (`scene_vs`) whose fragment shader (`scene_fs`) casts one camera ray
// per pixel into an analytic scene chosen by ViewParams.scene, shades the hit with
// material.wgsl's `material_shade` and writes the tone-mapped, sRGB-encoded colour to an
// Rgba8Unorm target. No meshes, no depth buffer. Composed after material.wgsl
// (crates/runtime/src/render/mod.rs: `shaders::compose(technique, &[MATERIAL, SCENE])`).
//
// Scenes (world units; y up; the camera comes from ViewParams.inv_view_proj):
//
//   0 sphere  a film-coated sphere (centre SCENE_SPHERE_CENTRE, radius SCENE_SPHERE_RADIUS)
//             on the material's base (dielectric or metal)
//   1 bubble  the same sphere as a thin transparent shell (a soap bubble): the front wall
//             reflects and transmits, the ray continues to the back wall, which reflects (seen
//             from inside) and transmits the environment behind; the material's drainage term
//             thickens the film towards the bottom, the map adds swirls
//   2 plane   the plane y = SCENE_PLANE_HEIGHT to the horizon (an oil film on a dark base),
//             the map tiled across it: minified towards the horizon, where the film_fourier
//             prefilter matters
//
// Anything a ray misses shows the environment (mip level 0).
//
// The thickness map is projected triplanarly (no seams, no poles): a map coordinate p — the
// unit normal on the sphere, the world position (x, 0, z) on the plane — is projected along
// each axis, uv = p.(zy | xz | xy) s/2 + 1/2 with s = MaterialParams.thickness_map_scale (so
// one map tile spans 2/s units of p), and the three samples are blended with weights
// w_i = |n_i|⁴ / Σ|n_j|⁴. The blend keeps the mean E[g] = Σ w_i E_i[g] and the weighted
// within-footprint variance Σ w_i Var_i[g] (not the spread between the projections, which
// is no sub-pixel variation of the film).
//
// Symbols
//
//   symbol     code                meaning
//   o, ω       Ray                 camera ray origin (eye) and unit direction
//   t          SceneHit.t          ray parameter of the hit, world units
//   n          normal              outward unit normal (the shading normal faces the viewer)
//   p          map_position        map coordinate (see above)
//   h          height              normalised object height for drainage (sphere n.y; plane 1)
//
// Derivatives: the thickness d, its screen-space derivatives (∂d/∂x, ∂d/∂y → σ_d) and the map
// coordinate's derivatives (→ the map's mip level) are computed for every pixel in uniform
// control flow, before any branch on the hit. So that they stay meaningful at silhouettes,
// a ray that misses the sphere is given the sphere point nearest to it (continuous across
// the silhouette), and a ray above the plane's horizon the point at distance SCENE_FAR.

const SCENE_SPHERE: u32 = 0u;
const SCENE_BUBBLE: u32 = 1u;
const SCENE_PLANE: u32 = 2u;
const SCENE_SPHERE_CENTRE: vec3<f32> = vec3<f32>(0.0, 1.0, 0.0);
const SCENE_SPHERE_RADIUS: f32 = 1.0;
const SCENE_PLANE_HEIGHT: f32 = 0.0;
// Largest ray distance (the plane's horizon), world units.
const SCENE_FAR: f32 = 1000.0;

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

struct SceneHit {
    // The ray hits the object.
    hit: bool,
    // Distance to the (front) hit, or to the stand-in point of a miss.
    t: f32,
    // Distance to the sphere's back wall (bubble).
    t_exit: f32,
    // Outward unit normal at the (stand-in) point.
    normal: vec3<f32>,
    // Map coordinate p.
    map_position: vec3<f32>,
    // Normalised height for drainage.
    height: f32,
}

@vertex
fn scene_vs(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
    let x = f32(i32(index & 1u) * 4 - 1);
    let y = f32(i32(index >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

// The camera ray through a pixel position (pixel centres at +0.5, y down).
fn scene_camera_ray(pixel: vec2<f32>) -> Ray {
    let res = max(view.resolution, vec2<f32>(1.0));
    let ndc = vec2<f32>(2.0 * pixel.x / res.x - 1.0, 1.0 - 2.0 * pixel.y / res.y);
    let near = view.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = view.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let a = near.xyz / select(1.0, near.w, near.w != 0.0);
    let b = far.xyz / select(1.0, far.w, far.w != 0.0);
    var ray: Ray;
    ray.origin = view.eye_position;
    ray.dir = safe_normalize(b - a, vec3<f32>(0.0, 0.0, -1.0));
    return ray;
}

fn scene_intersect_sphere(ray: Ray) -> SceneHit {
    var out: SceneHit;
    let oc = ray.origin - SCENE_SPHERE_CENTRE;
    let b = dot(oc, ray.dir);
    let c = dot(oc, oc) - SCENE_SPHERE_RADIUS * SCENE_SPHERE_RADIUS;
    let disc = b * b - c;
    let root = sqrt(max(disc, 0.0));
    let t_near = -b - root;
    let t_far = -b + root;
    out.hit = disc >= 0.0 && t_far > 0.0 && f32_is_finite(disc);
    // Front wall (or, from inside, the far wall); a miss takes the nearest point on the ray.
    out.t = select(max(-b, 0.0), select(t_far, t_near, t_near > 0.0), out.hit);
    out.t_exit = select(out.t, t_far, out.hit);
    let p = ray.origin + out.t * ray.dir;
    out.normal = safe_normalize(p - SCENE_SPHERE_CENTRE, -ray.dir);
    out.map_position = out.normal;
    out.height = out.normal.y;
    return out;
}

fn scene_intersect_plane(ray: Ray) -> SceneHit {
    var out: SceneHit;
    let dy = ray.dir.y;
    let t = (SCENE_PLANE_HEIGHT - ray.origin.y) / select(-1.0, dy, dy < 0.0);
    out.hit = dy < 0.0 && t > 0.0 && t < SCENE_FAR;
    out.t = select(SCENE_FAR, t, out.hit);
    out.t_exit = out.t;
    let p = ray.origin + out.t * ray.dir;
    out.normal = vec3<f32>(0.0, 1.0, 0.0);
    out.map_position = vec3<f32>(p.x, 0.0, p.z);
    out.height = 1.0;
    return out;
}

fn scene_intersect(ray: Ray) -> SceneHit {
    if view.scene == SCENE_PLANE {
        return scene_intersect_plane(ray);
    }
    return scene_intersect_sphere(ray);
}

// The thickness map's (E[g], E[g²], E[g_G], E[g_B]) at map coordinate p with normal n,
// projected triplanarly, for a footprint given by the screen-space derivatives of p.
fn scene_sample_thickness(p: vec3<f32>, n: vec3<f32>, dp_dx: vec3<f32>, dp_dy: vec3<f32>) -> vec4<f32> {
    let s = 0.5 * finite_or(material_params.thickness_map_scale, 1.0);
    let a = abs(safe_normalize(n, vec3<f32>(0.0, 1.0, 0.0)));
    let a2 = a * a;
    let w = (a2 * a2) / max(dot(a2, a2), 1e-30);
    let gx = select(vec3<f32>(0.0), dp_dx, vec3_is_finite(dp_dx)) * s;
    let gy = select(vec3<f32>(0.0), dp_dy, vec3_is_finite(dp_dy)) * s;
    let q = p * s + 0.5;
    var mean = 0.0;
    var variance = 0.0;
    var others = vec2<f32>(0.0);
    if w.x > 1e-3 {
        let m = material_sample_thickness_texel(q.zy, gx.zy, gy.zy);
        mean += w.x * m.x;
        variance += w.x * max(m.y - m.x * m.x, 0.0);
        others += w.x * m.zw;
    }
    if w.y > 1e-3 {
        let m = material_sample_thickness_texel(q.xz, gx.xz, gy.xz);
        mean += w.y * m.x;
        variance += w.y * max(m.y - m.x * m.x, 0.0);
        others += w.y * m.zw;
    }
    if w.z > 1e-3 {
        let m = material_sample_thickness_texel(q.xy, gx.xy, gy.xy);
        mean += w.z * m.x;
        variance += w.z * max(m.y - m.x * m.x, 0.0);
        others += w.z * m.zw;
    }
    // The skipped weights (< 1e-3 each) renormalised away.
    let total = select(0.0, w.x, w.x > 1e-3) + select(0.0, w.y, w.y > 1e-3) + select(0.0, w.z, w.z > 1e-3);
    let k = select(1.0, 1.0 / total, total > 0.0);
    let g = mean * k;
    return vec4<f32>(g, g * g + variance * k, others * k);
}

// Display output: the pixel's radiance exposed, tone-mapped and sRGB-encoded (Rgba8Unorm).
@fragment
fn scene_fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return material_display(scene_radiance(frag.xy));
}

// Linear output: the pixel's scene radiance before exposure and tone mapping, for an
// Rgba32Float target (crates/runtime/src/render/mod.rs, RenderOutput::Linear; the Monte Carlo
// comparisons of issue 6). Non-finite or negative channels are 0.
@fragment
fn scene_fs_linear(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(sanitize_radiance(scene_radiance(frag.xy)), 1.0);
}

// The linear radiance seen through pixel position `pixel` (see the header).
fn scene_radiance(pixel: vec2<f32>) -> vec3<f32> {
    let ray = scene_camera_ray(pixel);
    let hit = scene_intersect(ray);

    // Uniform control flow up to the derivatives (no branch on the pixel before them).
    let dp_dx = dpdx(hit.map_position);
    let dp_dy = dpdy(hit.map_position);
    let moments = scene_sample_thickness(hit.map_position, hit.normal, dp_dx, dp_dy);
    let thickness_nm = material_thickness_nm(moments.x, hit.height);
    let sigma_nm = material_thickness_sigma(dpdx(thickness_nm), dpdy(thickness_nm), material_thickness_roughness_nm(moments.xy));

    // The surfaces along the ray, front to back: none for a miss, the front wall of an opaque
    // object, or both walls of a bubble. Each adds its reflection times the colour that the
    // walls in front let through; what passes every wall sees the environment. (One call site
    // of material_shade, in a loop with a run-time trip count: see material_shade.)
    let walls = select(0u, select(1u, 2u, view.scene == SCENE_BUBBLE && material_params.transmission != 0u), hit.hit);
    var radiance = vec3<f32>(0.0);
    var throughput = vec3<f32>(1.0);
    for (var k = 0u; k < walls; k++) {
        var surface: SurfacePoint;
        surface.view_dir = -ray.dir;
        surface.sigma_thickness_nm = sigma_nm;
        if k == 0u {
            surface.position = ray.origin + hit.t * ray.dir;
            surface.normal = hit.normal;
            surface.thickness_nm = thickness_nm;
            surface.variation = 2.0 * vec3<f32>(moments.x, moments.z, moments.w) - 1.0;
        } else {
            // The back wall, seen from inside: its normal faces the centre, its thickness comes
            // from the map at its own point (with the front's footprint).
            let p_back = ray.origin + hit.t_exit * ray.dir;
            let n_back = safe_normalize(p_back - SCENE_SPHERE_CENTRE, ray.dir);
            let m = scene_sample_thickness(n_back, n_back, dp_dx, dp_dy);
            surface.position = p_back;
            surface.normal = -n_back;
            surface.thickness_nm = material_thickness_nm(m.x, n_back.y);
            surface.variation = 2.0 * vec3<f32>(m.x, m.z, m.w) - 1.0;
        }
        let shade = material_shade(surface);
        radiance += throughput * shade.radiance;
        throughput *= shade.transmittance;
    }
    if any(throughput > vec3<f32>(0.0)) {
        radiance += throughput * env_radiance(ray.dir, 0.0);
    }
    return radiance;
}

// nacre · shaders/diffraction_scene.wgsl
// import: diffraction_common, <technique>, view, output
//
// Consumers of the `diffraction` technique (composed after diffraction.wgsl by
// `nacre_runtime::diffraction`): the ray-cast scenes of `nacre render --scene cd-disc |
// snake-skin | grating-plane`, the bench pass of `nacre bench-gpu`, and the GPU = CPU probe (compute).
//
// Symbols
//   p, n          hit point and unit normal (world units; y up)
//   t             direction across the grating lines at p (the grating tangent map below)
//   ω_i, ω_r      towards the light, towards the eye;  F = diffraction_frame(n, t)
//   L_k, ω_k      radiance and direction of the light (k = 0) and of the environment samples
//
// Radiance leaving a grating point towards the eye:
//
//   L = Σ_k I_k cos θ_k · Σ_λ (λ₀/λ)² ρ(F ω_k, F ω_r, λ) u(λ)  light (+ environment samples)
//     + L_env(reflect(−ω_r, n)) ⊙ Σ_λ F² |P_DC(k w)|² u(λ)  the specular order of the environment
//     + Σ_λ u(λ) ⊙ Σ_c F² G/w² η_c(k w_c) L_env(ω_c(λ))     the environment through the lobes
//     + base (snake skin only: a dark Lambertian layer of albedo π · base,
//             base × (n·ω_0 E_0 + E_env(n)), E_env the environment's irradiance)
//
// where each Σ_λ (λ₀/λ)² ρ u is filtered over the pixel's footprint (diffraction_colour_footprint,
// issue 37: the footprint's σ_uv from the neighbouring pixels' rays, scene_footprint below;
// the integrated layout's adapter reads prefiltered levels); a rough grating's light is its
// lobes blurred by the footprint and the microfacets' slopes instead (scene_rough_light, the
// two-scale model), or, with an integrated table (no lobes: lobe_wavelength_count 0), its
// footprint filter widened by the slopes (the adapter's σ² = σ_uv² + w² σ_m²).
//
// I_k = E_k · (σ_s k₀)²/π is the radiance of source k's mirror image spread over the
// coherence lobe (E_k its irradiance at normal incidence, k₀ = 2π/λ₀, λ₀ = 555 nm; computed
// on the CPU, `nacre_runtime::diffraction::lobe_gain`): a flat mirror's lobe |P̃|² integrates
// to π/(σ_s k)² over (u, v), so Stam's BRDF is f = ρ (σ_s k)²/π and the reflected radiance
// f E_k cos θ_k = ρ I_k (k/k₀)² cos θ_k, θ_k the angle of ω_k from the normal (the
// irradiance the surface receives is E_k cos θ_k). The technique weights each wavelength
// by (k/k₀)² = (λ₀/λ)² (diffraction_colour_footprint's reference_nm), the scene multiplies
// by cos θ_k: the Mitsuba plugin's f cos θ (nacre.mitsuba, `nacre_grating`). An integrated
// table's adapter leaves the (λ₀/λ)² out (its bake summed ρ u without it).
//
// The environment's lobes need neither factor: their integral runs over (u, v), and
// du dv = cos θ_i dω_i at a fixed ω_r, so ∫ L_env f cos θ_i dω_i = ∫ L_env ρ (σ_s k)²/π du dv,
// and a lobe's η_c (π/σ_s²) N(k(u, v); κ_c, v_c) integrates over (u, v) to η_c π/(σ_s k)²:
// the k² cancels and each lobe brings F² G/w² η_c L_env.
//
// The environment enters through its mirror image in the zeroth order (exact for an extended
// source: the order keeps |P_DC|² of the radiance) and, with a "terms" table, through the
// table's lobes c (`nacre_runtime::diffraction::lobes`, which derives it): the integral
// ∫ L_env ρ (σ_s k)²/π du dv of Stam's BRDF against the whole environment, per wavelength a
// sum over the lobes of F² G/w² η_c(kw) times the environment averaged over the lobe, read
// where the grating equation puts it (ω_c,t = −ω_r,t − κ_c/k) from the environment's mip
// chain at the level of the lobe's angular size (`scene_env_diffracted`). Otherwise
// (an "integrated" table, which keeps no bins, or `--env-samples K`) the K brightest texels
// of a 32 × 16 downsampled copy are directional samples (`DiffractionLights.samples`,
// chosen on the CPU at least 25° apart above the horizon, each with E_k = L_texel · Ω_texel)
// diffracted like the light: extended sources as if they were points (thin rainbow lines
// instead of wide bands).
//
// Scenes (ViewParams.scene):
//   0 cd-disc     an annulus in the plane y = 0 centred at the origin: a clear hub
//                 (r < 0.38, a plain mirror with F² of the hub), the data area (0.38 ≤ r ≤ 0.98)
//                 whose tracks are circles (t = the radial direction) and a clear rim; the
//                 centre hole (r < 0.12) shows the background.
//   1 snake-skin  a patch of the cylinder y² + z² = 1 (axis x, |x| ≤ 1.6, within 75° of the top),
//                 tiled with domed diamond scales (a rhombic lattice in (x, arc length));
//                 in each scale the ridges run along the body with a per-scale random
//                 rotation of ±15° and a fan of ±12° across the scale; t is perpendicular
//                 to the ridges in the tangent plane. The scales' dark skin shows between
//                 the coloured orders.
//   3 grating-plane  the square |x|, |z| ≤ 1 in the plane y = 0, a flat 1200 lines/mm
//                 grating whose grooves run along x (t = +z everywhere); seen from below,
//                 the same grooves (normal −y).
//   2 bench       `nacre bench-gpu`: the sphere-like normal field of bench.wgsl over the
//                 whole target, t swirling over the screen, the light only, no environment.
//
// Output: linear radiance × 2^exposure, tone mapped c/(1 + max channel) (hue-preserving
// Reinhard on the largest channel), sRGB-encoded into an Rgba8Unorm target (the tone mapper
// and the sRGB transfer function are output.wgsl's).

// Group 0 is every scene's (view.wgsl: `view`, `env_map`, `env_sampler`; the split-sum
// textures there are unused placeholders), with view.light_intensity = E_0, the light's
// irradiance at normal incidence, and view.scene = 0 cd-disc, 1 snake-skin, 2 bench,
// 3 grating-plane.
//
// Group 2, the lights as the gratings see them (binding 0: 448 bytes, uniform;
// `nacre_runtime::diffraction::DiffractionLightsUniform` mirrors it; bindings 1–3:
// `nacre_runtime::diffraction::LobeData`):
//
//   offset size field
//        0    4 light_radiance: f32         I_0 = E_0 (σ_s k₀)²/π
//        4    4 sample_count: u32           environment samples used (≤ 8)
//        8    4 lobe_count: u32             environment lobes (0: none)
//       12    4 lobe_wavelength_count: u32  wavelengths of lobe_spectrum
//       16  128 samples: array<vec4<f32>, 8>          direction xyz (unit), w unused
//      144  128 sample_radiance: array<vec4<f32>, 8>  I_k rgb (× env_intensity on the CPU)
//      272   16 lobe_kw: vec4<f32>          (kw_min, samples per unit kw, Δλ µm, 0)
//      288   16 roughness: vec4<f32>        (σ_m² = α²/2 the microfacet slope variance per
//                                           axis, α the GGX roughness, π/σ_s², 0): the grating's
//                                           micro-geometry, π/σ_s² (scene_rough_light)
//      304  144 irradiance: array<vec4<f32>, 9>  the environment's irradiance in nine spherical
//                                           harmonics, × env_intensity (rgb; scene_irradiance)
struct DiffractionLights {
    light_radiance: f32,
    sample_count: u32,
    lobe_count: u32,
    lobe_wavelength_count: u32,
    samples: array<vec4<f32>, 8>,
    sample_radiance: array<vec4<f32>, 8>,
    lobe_kw: vec4<f32>,
    roughness: vec4<f32>,
    irradiance: array<vec4<f32>, 9>,
}

@group(2) @binding(0) var<uniform> lights: DiffractionLights;
// Per lobe (κ_x, κ_y rad/µm in the grating frame, variance per axis of q (rad/µm)², 0).
@group(2) @binding(1) var<storage, read> lobes: array<vec4<f32>>;
// η_c(kw) at SCENE_LOBE_SAMPLES points per lobe, kw = kw_min … 0.
@group(2) @binding(2) var<storage, read> lobe_efficiency: array<f32>;
// (λ nm, u_R, u_G, u_B) per wavelength of the lobe sum.
@group(2) @binding(3) var<storage, read> lobe_spectrum: array<vec4<f32>>;

// Efficiency samples per lobe (`nacre_runtime::diffraction::lobes::LOBE_KW_SAMPLES`).
const SCENE_LOBE_SAMPLES: u32 = 64u;

const SCENE_PI: f32 = 3.14159265358979;

// The light's gain wavelength k₀ = 2π/555 nm (`nacre_runtime::diffraction::LOBE_REFERENCE_NM`).
const SCENE_LOBE_REFERENCE_NM: f32 = 555.0;

@vertex
fn diffraction_vs(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i32(index & 1u) * 4 - 1);
    let y = f32(i32(index >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

// Equirectangular (u, v) of a unit direction (nacre_runtime::ibl::env_direction_to_uv).
fn scene_env_uv(d: vec3<f32>) -> vec2<f32> {
    let u = 0.5 + atan2(d.x, -d.z) / (2.0 * SCENE_PI);
    let v = acos(clamp(d.y, -1.0, 1.0)) / SCENE_PI;
    return vec2<f32>(u, v);
}

fn scene_env(d: vec3<f32>, lod: f32) -> vec3<f32> {
    return textureSampleLevel(env_map, env_sampler, scene_env_uv(d), lod).rgb * view.env_intensity;
}

// Deterministic hash of a lattice cell, in [0, 1)².
fn scene_hash(c: vec2<i32>) -> vec2<f32> {
    var h = (bitcast<u32>(c.x) * 0x9e3779b9u) ^ (bitcast<u32>(c.y) * 0x85ebca6bu + 0x632be5abu);
    h ^= h >> 16u;
    h *= 0x7feb352du;
    h ^= h >> 15u;
    let h2 = h * 0x846ca68bu;
    return vec2<f32>(f32(h >> 8u), f32((h2 ^ (h2 >> 16u)) >> 8u)) / 16777216.0;
}

struct Surface {
    hit: bool,
    position: vec3<f32>,
    normal: vec3<f32>,
    across: vec3<f32>,      // t: across the grating lines
    grating: f32,           // 1 on the grating, 0 on clear parts
    base: vec3<f32>,        // Lambertian BRDF albedo/π under the grating (0: none)
}

fn miss() -> Surface {
    var s: Surface;
    s.hit = false;
    return s;
}

fn cd_disc(origin: vec3<f32>, dir: vec3<f32>) -> Surface {
    if abs(dir.y) < 1e-6 {
        return miss();
    }
    let t = -origin.y / dir.y;
    if t <= 0.0 {
        return miss();
    }
    let p = origin + t * dir;
    let r = length(p.xz);
    if r > 1.0 || r < 0.12 {
        return miss();
    }
    var s: Surface;
    s.hit = true;
    s.position = p;
    // Seen from below, the disc's other face (the same tracks mirrored).
    s.normal = vec3<f32>(0.0, sign(origin.y), 0.0);
    s.across = vec3<f32>(p.x, 0.0, p.z) / max(r, 1e-6);
    s.grating = select(0.0, 1.0, r >= 0.38 && r <= 0.98);
    s.base = vec3<f32>(0.0);
    return s;
}

fn grating_plane(origin: vec3<f32>, dir: vec3<f32>) -> Surface {
    if abs(dir.y) < 1e-6 {
        return miss();
    }
    let t = -origin.y / dir.y;
    if t <= 0.0 {
        return miss();
    }
    let p = origin + t * dir;
    if abs(p.x) > 1.0 || abs(p.z) > 1.0 {
        return miss();
    }
    var s: Surface;
    s.hit = true;
    s.position = p;
    s.normal = vec3<f32>(0.0, sign(origin.y), 0.0);
    s.across = vec3<f32>(0.0, 0.0, 1.0);
    s.grating = 1.0;
    s.base = vec3<f32>(0.0);
    return s;
}

fn snake_skin(origin: vec3<f32>, dir: vec3<f32>) -> Surface {
    // Cylinder y² + z² = 1 around the x axis: the outer hit.
    let a = dir.y * dir.y + dir.z * dir.z;
    let b = origin.y * dir.y + origin.z * dir.z;
    let c = origin.y * origin.y + origin.z * origin.z - 1.0;
    let disc = b * b - a * c;
    if a < 1e-8 || disc < 0.0 {
        return miss();
    }
    let t = (-b - sqrt(disc)) / a;
    if t <= 0.0 {
        return miss();
    }
    let p = origin + t * dir;
    let phi = atan2(p.z, p.y); // 0 at the top, towards +z
    if abs(p.x) > 1.6 || abs(phi) > 1.31 {
        return miss();
    }
    let n0 = vec3<f32>(0.0, p.y, p.z);
    let along = vec3<f32>(1.0, 0.0, 0.0);
    let around = vec3<f32>(0.0, -p.z, p.y); // d p / d phi
    // Rhombic scale lattice in (x, arc length): cells 0.4 long, 0.3 wide, a 45° grid.
    let q = vec2<f32>(p.x / 0.4, phi / 0.3);
    let g = vec2<f32>(q.x + q.y, q.x - q.y);
    let cell = vec2<i32>(floor(g));
    let f = fract(g) - 0.5; // in the cell, [−0.5, 0.5)²
    let rnd = scene_hash(cell);
    // Local position within the scale along the body (a) and across it (b), in [−0.5, 0.5].
    let la = 0.5 * (f.x + f.y);
    let lb = 0.5 * (f.x - f.y);
    // Dome: the normal tilts towards the scale's edges; keel ridge along the middle.
    let tilt = 0.55 * la * along + 0.9 * lb * normalize(around);
    var s: Surface;
    s.hit = true;
    s.position = p;
    s.normal = normalize(n0 - tilt);
    // Ridge direction: along the body, rotated per scale (±15°) and fanned across it (±12°).
    let angle = (rnd.x - 0.5) * 0.52 + lb * 0.84;
    let ridge = cos(angle) * along + sin(angle) * normalize(around);
    s.across = cross(s.normal, ridge);
    // Scale edges (the skin between the scales) are matt, without a grating.
    let edge = max(abs(f.x), abs(f.y));
    s.grating = 1.0 - smoothstep(0.42, 0.5, edge);
    let tint = 0.6 + 0.4 * rnd.y;
    s.base = vec3<f32>(0.022, 0.018, 0.014) * tint;
    return s;
}

// η_c(kw) of lobe `l`, linear between its samples (clamped to its range; 0 past the buffer).
fn scene_lobe_efficiency(l: u32, kw: f32) -> f32 {
    let x = clamp((kw - lights.lobe_kw.x) * lights.lobe_kw.y, 0.0, f32(SCENE_LOBE_SAMPLES - 1u));
    let i = min(u32(floor(x)), SCENE_LOBE_SAMPLES - 2u);
    let base = l * SCENE_LOBE_SAMPLES + i;
    if base + 1u >= arrayLength(&lobe_efficiency) || !diffraction_finite(x) {
        return 0.0;
    }
    return mix(lobe_efficiency[base], lobe_efficiency[base + 1u], x - f32(i));
}

// The environment diffracted towards ω_r (grating frame, unit) through the lobes (header):
// Σ_λ u(λ) ⊙ Σ_c F²(θ_h) G/w² η_c(k w) L_env(ω_c), ω_c,t = −ω_r,t − κ_c/k. A lobe of
// variance σ_q² per axis spans σ_q/k in (u, v), and the band of one wavelength step Δλ
// sweeps it by |κ_c| Δλ/2π (a uniform spread, variance /12); the pixel's footprint adds the
// spread σ_fp of ω_r,t across the pixel (ray differentials, `scene_footprint` with no light:
// ω_c,t follows −ω_r,t) and a rough grating its microfacets' w² σ_m² (scene_rough_light:
// a facet of slope s moves the lobe by w s in (u, v)), the variances adding as for
// independent spreads; divided by cos θ_c that is its angular size σ, read at the mip level
// log₂(2.5 σ/texel₀) of the environment's box chain.
fn scene_env_diffracted(frame: mat3x3<f32>, wr: vec3<f32>, sigma_fp: f32) -> vec3<f32> {
    let count = min(lights.lobe_count, arrayLength(&lobes));
    let wavelengths = min(lights.lobe_wavelength_count, arrayLength(&lobe_spectrum));
    if count == 0u || wavelengths == 0u || !(wr.z > 0.0) {
        return vec3<f32>(0.0);
    }
    let texel = SCENE_PI / f32(max(textureDimensions(env_map, 0).y, 1u));
    let to_world = transpose(frame);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < wavelengths; i++) {
        let s = lobe_spectrum[i];
        let k = 2.0 * SCENE_PI / (s.x * 1e-3);
        var band = vec3<f32>(0.0);
        for (var l = 0u; l < count; l++) {
            let lobe = lobes[l];
            let t = -wr.xy - lobe.xy / k;
            let t2 = dot(t, t);
            if !(t2 < 1.0) {
                continue;
            }
            let wi = vec3<f32>(t, sqrt(1.0 - t2));
            let g = diffraction_geometry_over_w2(wi, wr);
            if !(g > 0.0) {
                continue;
            }
            let uvw = -wi - wr;
            let cos_h = -dot(wi, uvw) * inverseSqrt(dot(uvw, uvw));
            let eta = scene_lobe_efficiency(l, k * uvw.z);
            let sweep = length(lobe.xy) * lights.lobe_kw.z / (2.0 * SCENE_PI);
            let spread2 = lobe.z / (k * k) + sweep * sweep / 12.0 + sigma_fp * sigma_fp + uvw.z * uvw.z * lights.roughness.x;
            let sigma = sqrt(spread2) / max(wi.z, 0.05);
            let lod = clamp(log2(max(2.5 * sigma / texel, 1.0)), 0.0, view.env_lod_max);
            band += (diffraction_fresnel(cos_h) * g * eta) * scene_env(to_world * wi, lod);
        }
        sum += band * s.yzw;
    }
    return select(vec3<f32>(0.0), sum, diffraction_finite3(sum));
}

// A neighbouring pixel's view of the surface (a ray differential, issue 37; Igehy, "Tracing
// ray differentials", SIGGRAPH 1999, here as the finite difference to the next pixel's ray,
// which also carries the change of the grating frame): its grating frame and its direction
// to the eye in that frame; `ok` false when its ray misses.
struct Neighbour {
    ok: bool,
    frame: mat3x3<f32>,
    wr: vec3<f32>,
}

// The camera ray through framebuffer position `pixel` (y down), as (origin, unit direction).
fn scene_ray(pixel: vec2<f32>) -> array<vec3<f32>, 2> {
    let ndc = vec2<f32>(
        pixel.x / view.resolution.x * 2.0 - 1.0,
        1.0 - pixel.y / view.resolution.y * 2.0,
    );
    let near = view.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = view.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let origin = near.xyz / near.w;
    return array<vec3<f32>, 2>(origin, normalize(far.xyz / far.w - origin));
}

fn scene_hit(origin: vec3<f32>, dir: vec3<f32>) -> Surface {
    if view.scene == 0u {
        return cd_disc(origin, dir);
    } else if view.scene == 3u {
        return grating_plane(origin, dir);
    }
    return snake_skin(origin, dir);
}

// The surface seen one pixel away, at framebuffer position `pixel` + `step`.
fn scene_neighbour(pixel: vec2<f32>, step: vec2<f32>) -> Neighbour {
    var n: Neighbour;
    let ray = scene_ray(pixel + step);
    let s = scene_hit(ray[0], ray[1]);
    n.ok = s.hit;
    if s.hit {
        n.frame = diffraction_frame(s.normal, s.across);
        n.wr = n.frame * -ray[1];
    }
    return n;
}

// The change of (u, v) = −(F ω_i + F ω_r)_xy towards one neighbour along an axis of the
// screen: the smaller of the two sides' (a pixel on an edge — the snake's scales, the
// disc's rim — takes the side that sees its own surface); 0 when both miss.
fn scene_uv_step(l: vec3<f32>, uv: vec2<f32>, plus: Neighbour, minus: Neighbour) -> vec2<f32> {
    var best = vec2<f32>(0.0);
    var best_len = -1.0;
    if plus.ok {
        best = -(plus.frame * l + plus.wr).xy - uv;
        best_len = dot(best, best);
    }
    if minus.ok {
        let d = uv + (minus.frame * l + minus.wr).xy;
        if best_len < 0.0 || dot(d, d) < best_len {
            best = d;
        }
    }
    return best;
}

// The pixel's footprint in (u, v) for light from `l` (world): σ_uv per axis of the grating
// frame, from the differences of (u, v) to the neighbouring pixels' (in their own frames:
// the CD's tracks turn across a distant pixel), a box pixel's variance (Δ_x² + Δ_y²)/12,
// at most 0.25 (a pixel spanning a large part of the hemisphere). n: the neighbours at
// +x, −x, +y, −y.
fn scene_footprint(l: vec3<f32>, frame: mat3x3<f32>, wr: vec3<f32>, n: array<Neighbour, 4>) -> vec2<f32> {
    let uv = -(frame * l + wr).xy;
    let dx = scene_uv_step(l, uv, n[0], n[1]);
    let dy = scene_uv_step(l, uv, n[2], n[3]);
    let sigma = sqrt((dx * dx + dy * dy) / 12.0);
    return select(vec2<f32>(0.0), min(sigma, vec2<f32>(0.25)), diffraction_finite(sigma.x) && diffraction_finite(sigma.y));
}

// ─── Rough gratings (issue 37, item 4) ────────────────────────────────────────────────────
//
// The two-scale model (Holzschuch & Pacanowski, "A two-scale microfacet reflectance model
// combining reflection and diffraction", SIGGRAPH 2017): the grating's height field lies on
// microfacets whose normals follow GGX of roughness α, and Stam's BRDF is evaluated in each
// facet's tilted frame. A facet of slope s = (s_x, s_y) (normal ∝ (−s_x, −s_y, 1) in the
// grating frame) has tangent axes x′ ∝ (1, 0, s_x), y′ ∝ (0, 1, s_y), so to first order in s
//
//   (u, v)′ = −(ω_i + ω_r)·(x′, y′) = (u, v) + w s,     q′ = k (u, v)′ = q + k w s,
//
// and the facets' mean of |P̃(q′)|² is |P̃|² convolved with the slope distribution scaled by
// k |w|: every order is blurred in q by the variance k² w² σ_m² per axis (the blur grows with
// k and with |w| = cos θ_i + cos θ_r: per order and per wavelength). The pixel's footprint
// σ_uv (scene_footprint) is one more independent spread: the variances add,
// k² (σ_uv² + w² σ_m²).
//
// GGX's slope distribution P₂₂(s) = 1/(π α² (1 + |s|²/α²)²) has no finite variance (its
// tails fall as |s|⁻⁴); it is matched to the Beckmann distribution of the same α (Walter et
// al., "Microfacet models for refraction through rough surfaces", EGSR 2007: the same
// parameter, the same peak), σ_m² = α²/2 per axis (`nacre_runtime::diffraction::
// rough_slope_variance`). Left out, to first order in α: the change of w, G/w² and F² with
// the tilt and Smith's masking-shadowing; the Mitsuba reference (nacre.mitsuba,
// `roughness`) keeps them all, drawing a facet per path.
//
// Evaluation. The blur is wide against the table's bins: the CD's σ_m k |w| at α = 0.05 is
// 0.6 rad/µm, three bins (Δκ = 0.196 rad/µm), and the footprint filter would need a window
// of ±17 bins, past its cap of 8, where it keeps the energy but not the spread. So a rough
// grating's light is summed over the table's lobes instead (the environment's, `lobes.rs`:
// |P̃(q)|² ≈ Σ_c η_c(kw) (π/σ_s²) N(q; κ_c, v_c) with N the normalised Gaussian of variance
// v_c per axis, the cross terms between bins dropped), each lobe's variance widened by the
// blur, plus the specular order as one more lobe (η = |P_DC(kw)|², v = 1/(2σ_s²), appended
// past the environment's lobes by the host):
//
//   ρ_rough = F² G/w² (π/σ_s²) Σ_c η_c(kw) N(q; κ_c, v_c + k² (σ_uv² + w² σ_m²))
//
// with Stam's k² per wavelength: the light's radiance I₀ = E₀ (σ_s k₀)²/π takes k₀ at 555 nm
// (lobe_gain), so ρ_rough is scaled by (k/k₀)² (as the smooth path's technique does; a
// blurred lobe spreads over (u, v) the same at every wavelength, so left out it would tint
// the rough picture red by (λ/555 nm)²), and scene_shade multiplies by cos θ_i.
//
// — exact for the model's Gaussian blur of each lobe, and cheaper than the filter (lobes ×
// wavelengths reads, no Taylor sums). The environment's lobes are widened the same way
// (scene_env_diffracted), and its zeroth order is read wider at angular spread 2 σ_m (a facet
// tilts the mirror direction by twice its own tilt; scene_rough_mirror_lod). α = 0 (σ_m² = 0)
// takes none of these branches: the smooth picture, bit for bit.

// ρ_rough of the light (above) for ω_i, ω_r in the grating frame and the pixel's footprint
// σ_uv per axis, as a colour Σ_λ ρ_rough u(λ) over the lobes' spectrum. Always finite.
fn scene_rough_light(wi_in: vec3<f32>, wr_in: vec3<f32>, fp: vec2<f32>) -> vec3<f32> {
    let total = min(lights.lobe_count + 1u, arrayLength(&lobes));
    let wavelengths = min(lights.lobe_wavelength_count, arrayLength(&lobe_spectrum));
    let wi = diffraction_unit(wi_in);
    let wr = diffraction_unit(wr_in);
    let g = diffraction_geometry_over_w2(wi, wr);
    if !(g > 0.0) || !diffraction_finite(g) || wavelengths == 0u {
        return vec3<f32>(0.0);
    }
    let uvw = -wi - wr;
    let cos_h = -dot(wi, uvw) * inverseSqrt(dot(uvw, uvw));
    let fresnel = diffraction_fresnel(cos_h);
    let spread = fp * fp + vec2<f32>(uvw.z * uvw.z * lights.roughness.x);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < wavelengths; i++) {
        let sp = lobe_spectrum[i];
        let k = 2.0 * SCENE_PI / (sp.x * 1e-3);
        let q = k * uvw.xy;
        let kw = k * uvw.z;
        var density = 0.0;
        for (var l = 0u; l < total; l++) {
            let lobe = lobes[l];
            let v = vec2<f32>(lobe.z) + k * k * spread;
            let d = q - lobe.xy;
            let n = exp(-0.5 * dot(d * d, vec2<f32>(1.0) / v)) / (2.0 * SCENE_PI * sqrt(v.x * v.y));
            density += scene_lobe_efficiency(l, kw) * n;
        }
        // Stam's k² at this wavelength over the light's gain at k₀ (555 nm; lobe_gain).
        let k_ratio = k * SCENE_LOBE_REFERENCE_NM * 1e-3 / (2.0 * SCENE_PI);
        sum += (density * k_ratio * k_ratio) * sp.yzw;
    }
    let colour = (fresnel * g * lights.roughness.z) * sum;
    return select(vec3<f32>(0.0), colour, diffraction_finite3(colour));
}

// The mip level of the environment's zeroth order on a rough grating: the mirror direction
// spreads by 2 σ_m (radians, per axis), read as the lobes are (level log₂(2.5 σ/texel₀)),
// never sharper than the smooth grating's level 1.
fn scene_rough_mirror_lod() -> f32 {
    let texel = SCENE_PI / f32(max(textureDimensions(env_map, 0).y, 1u));
    let sigma = 2.0 * sqrt(max(lights.roughness.x, 0.0));
    return clamp(log2(max(2.5 * sigma / texel, 2.0)), 1.0, max(view.env_lod_max, 1.0));
}

// World direction into the grating frame of the surface; around: the neighbouring pixels' views
// at +x, −x, +y, −y (the footprint filter of diffraction_colour_footprint).
fn scene_shade(s: Surface, to_eye: vec3<f32>, around: array<Neighbour, 4>) -> vec3<f32> {
    let frame = diffraction_frame(s.normal, s.across);
    let wr = frame * to_eye;
    var radiance = vec3<f32>(0.0);
    let light = normalize(view.light_direction);
    let light_radiance = view.light_colour * lights.light_radiance;
    if s.grating > 0.0 {
        // L = f E₀ cos θ_i with f = ρ (σ_s k)²/π (header): the light's I₀ carries (σ_s k₀)²/π,
        // the technique (k/k₀)² per wavelength, and here the cosine at the light.
        let wi = frame * light;
        let fp_light = scene_footprint(light, frame, wr, around);
        var diffracted: vec3<f32>;
        if lights.roughness.x > 0.0 && lights.lobe_wavelength_count > 0u {
            diffracted = scene_rough_light(wi, wr, fp_light) * (light_radiance * max(wi.z, 0.0));
        } else {
            diffracted = diffraction_colour_footprint(wi, wr, fp_light, SCENE_LOBE_REFERENCE_NM) * (light_radiance * max(wi.z, 0.0));
        }
        let count = min(lights.sample_count, 8u);
        for (var k = 0u; k < count; k++) {
            let l = lights.samples[k].xyz;
            let wk = frame * l;
            diffracted += diffraction_colour_footprint(wk, wr, scene_footprint(l, frame, wr, around), SCENE_LOBE_REFERENCE_NM) * (lights.sample_radiance[k].rgb * max(wk.z, 0.0));
        }
        // The view direction's own spread over the pixel (u, v) = −ω_r,t: its larger axis.
        let fp = scene_footprint(vec3<f32>(0.0), frame, wr, around);
        diffracted += scene_env_diffracted(frame, wr, max(fp.x, fp.y));
        radiance += s.grating * diffracted;
    }
    // The environment through the specular order (the clear parts: a plain mirror, F² only).
    let n = s.normal;
    let cos_v = dot(n, to_eye);
    let mirror = reflect(-to_eye, n);
    let env = scene_env(mirror, 1.0);
    let specular = diffraction_specular_order_colour(cos_v);
    let clear = vec3<f32>(diffraction_fresnel(cos_v));
    if lights.roughness.x > 0.0 {
        // A rough grating's zeroth order sees the environment wider; the clear parts stay
        // smooth mirrors.
        let env_rough = scene_env(mirror, scene_rough_mirror_lod());
        radiance += env * clear * (1.0 - s.grating) + env_rough * specular * s.grating;
    } else {
        radiance += env * mix(clear, specular, s.grating);
    }
    // The snake's dark skin: Lambertian (base = albedo/π; the reference's albedo is π · base)
    // under the light, base E₀ cos θ_i, and under the environment, base E_env(n).
    let n_dot_l = max(dot(n, light), 0.0);
    radiance += s.base * (n_dot_l * view.light_colour * view.light_intensity + scene_irradiance(n));
    return radiance;
}

// The environment's irradiance E(n) = ∫ L_env max(n·ω, 0) dω at the world unit normal n,
// from its nine spherical harmonics (Ramamoorthi & Hanrahan 2001): Σ c_lm Y_lm(n) with the
// coefficients Â_l L_lm of `nacre_runtime::ibl::irradiance_sh9` (the CPU twin: sh9_irradiance;
// the same basis, Y₁₋₁ ∝ y, Y₁₀ ∝ z, Y₁₁ ∝ x), clamped at 0.
fn scene_irradiance(n: vec3<f32>) -> vec3<f32> {
    let c = lights.irradiance;
    let e = c[0].rgb * 0.282095
        + c[1].rgb * (0.488603 * n.y)
        + c[2].rgb * (0.488603 * n.z)
        + c[3].rgb * (0.488603 * n.x)
        + c[4].rgb * (1.092548 * n.x * n.y)
        + c[5].rgb * (1.092548 * n.y * n.z)
        + c[6].rgb * (0.315392 * (3.0 * n.z * n.z - 1.0))
        + c[7].rgb * (1.092548 * n.x * n.z)
        + c[8].rgb * (0.546274 * (n.x * n.x - n.y * n.y));
    return max(e, vec3<f32>(0.0));
}

fn scene_display(radiance: vec3<f32>) -> vec4<f32> {
    var c = max(radiance * view.exposure, vec3<f32>(0.0));
    if !diffraction_finite3(c) {
        c = vec3<f32>(0.0);
    }
    let mapped = tone_map_max_channel(c);
    return vec4<f32>(srgb_transfer(mapped), 1.0);
}

fn scene_bench(position: vec2<f32>) -> vec3<f32> {
    let p = (position / view.resolution) * 2.0 - 1.0;
    let aspect = view.resolution.x / view.resolution.y;
    let xy = vec2<f32>(p.x * aspect, -p.y) * 1.1;
    let r2 = dot(xy, xy);
    var n = normalize(vec3<f32>(0.0, 0.6, 0.8));
    if r2 < 1.0 {
        n = vec3<f32>(xy, sqrt(1.0 - r2));
    }
    let swirl = sin(7.0 * xy.x + 3.0 * sin(5.0 * xy.y)) * cos(6.0 * xy.y - 2.0 * xy.x);
    let across = vec3<f32>(cos(3.0 * swirl), sin(3.0 * swirl), 0.0);
    let frame = diffraction_frame(n, across);
    let v = vec3<f32>(0.0, 0.0, 1.0);
    let l = normalize(view.light_direction);
    return diffraction_colour(frame * l, frame * v) * view.light_colour * lights.light_radiance;
}

@fragment
fn diffraction_scene_fs(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    if view.scene == 2u {
        return scene_display(scene_bench(position.xy));
    }
    let ray = scene_ray(position.xy);
    let dir = ray[1];
    let s = scene_hit(ray[0], dir);
    if !s.hit {
        return scene_display(scene_env(dir, 0.0));
    }
    let n = array<Neighbour, 4>(
        scene_neighbour(position.xy, vec2<f32>(1.0, 0.0)),
        scene_neighbour(position.xy, vec2<f32>(-1.0, 0.0)),
        scene_neighbour(position.xy, vec2<f32>(0.0, 1.0)),
        scene_neighbour(position.xy, vec2<f32>(0.0, -1.0)),
    );
    return scene_display(scene_shade(s, -dir, n));
}

// ─── GPU = CPU probe (compute) ──────────────────────────────────────────────────────────
//
// Input i: probe_in[2i] = ω_i, probe_in[2i + 1] = ω_r (xyz, grating frame; any values).
// Output i: probe_out[2i] = diffraction_colour(ω_i, ω_r),
//           probe_out[2i + 1] = diffraction_specular_order_colour(ω_r.z).

@group(3) @binding(0) var<storage, read> probe_in: array<vec4<f32>>;
@group(3) @binding(1) var<storage, read_write> probe_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn diffraction_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if 2u * i + 1u >= arrayLength(&probe_in) {
        return;
    }
    let wi = probe_in[2u * i].xyz;
    let wr = probe_in[2u * i + 1u].xyz;
    probe_out[2u * i] = vec4<f32>(diffraction_colour(wi, wr), 0.0);
    probe_out[2u * i + 1u] = vec4<f32>(diffraction_specular_order_colour(wr.z), 0.0);
}

// bench.wgsl — consumer module of `nacre bench-gpu`: a full-screen pass that shades every
// import: common, <technique>
// pixel with one GGX microfacet material whose Fresnel term is the technique's
// `film_colour` (plain.wgsl: Schlick), so that the passes differ only in the film term.
//
// Each pixel sees a sphere-like normal field (pixels outside the unit disc see a tilted
// plane), a directional light and a constant ambient term; the film thickness varies
// over the screen (d = 150 + 650 · (0.5 + 0.5 sin(…)) nm) so that texture fetches are not
// uniform. Output: linear colour × exposure, Reinhard-tone-mapped, to an Rgba8Unorm target.
//
// Symbols
//   n, v, l, h   normal, view, light and half vectors;  α  GGX roughness
//   D            GGX distribution α² / (π ((n·h)² (α² − 1) + 1)²)         (Walter et al. 2007, Eq. 33)
//   V            height-correlated Smith visibility G₂ / (4 (n·l)(n·v))   (Heitz 2014, Eq. 99)
//   F            the film term (reflectance colour at cos θ = v·h)

struct BenchParams {
    resolution: vec2<f32>,
    roughness: f32,
    film_ior: f32,
    base_ior: vec3<f32>,
    ambient_ior: f32,
    base_kappa: vec3<f32>,
    _pad: f32,
}

@group(0) @binding(0) var<uniform> bench: BenchParams;

@vertex
fn bench_vs(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i32(index & 1u) * 4 - 1);
    let y = f32(i32(index >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

fn ggx_d(n_dot_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let k = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / max(PI * k * k, 1e-12);
}

fn smith_visibility(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    let gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-12);
}

@fragment
fn bench_fs(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let p = (position.xy / bench.resolution) * 2.0 - 1.0;
    let aspect = bench.resolution.x / bench.resolution.y;
    let xy = vec2<f32>(p.x * aspect, -p.y) * 1.1;
    let r2 = dot(xy, xy);
    var n = normalize(vec3<f32>(0.0, 0.6, 0.8));
    if r2 < 1.0 {
        n = vec3<f32>(xy, sqrt(1.0 - r2));
    }
    let v = vec3<f32>(0.0, 0.0, 1.0);
    let l = normalize(vec3<f32>(0.4, 0.6, 0.7));
    let h = normalize(v + l);
    let n_dot_v = max(dot(n, v), 1e-4);
    let n_dot_l = max(dot(n, l), 0.0);
    let n_dot_h = max(dot(n, h), 0.0);
    let v_dot_h = max(dot(v, h), 0.0);

    let swirl = sin(7.0 * xy.x + 3.0 * sin(5.0 * xy.y)) * cos(6.0 * xy.y - 2.0 * xy.x);
    var input: FilmInput;
    input.cos_theta_i = v_dot_h;
    input.thickness_nm = 150.0 + 650.0 * (0.5 + 0.5 * swirl);
    input.film_ior = bench.film_ior;
    input.sigma_thickness_nm = 0.0;
    input.ambient_ior = bench.ambient_ior;
    input.base_ior = bench.base_ior;
    input.base_kappa = bench.base_kappa;
    let film = film_colour(input);

    let alpha = bench.roughness;
    let specular = film.reflectance * (ggx_d(n_dot_h, alpha) * smith_visibility(n_dot_v, n_dot_l, alpha));
    let diffuse = film.transmittance * vec3<f32>(0.18) / PI;
    let colour = (specular + diffuse) * n_dot_l * 3.0 + vec3<f32>(0.03);
    let mapped = colour / (vec3<f32>(1.0) + colour);
    return vec4<f32>(mapped, 1.0);
}

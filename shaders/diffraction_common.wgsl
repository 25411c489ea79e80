// nacre · shaders/diffraction_common.wgsl
// import: (none)
//
// What both layouts of the technique `diffraction` share (diffraction.wgsl, layout
// "terms"; diffraction_integrated.wgsl, layout "integrated"; each composed after this
// module): finiteness tests, unit vectors, the grating frame, the Fresnel factor F² of
// Stam's BRDF and his G/w² (Stam 1999; symbols of crates/optics/src/diffraction.rs). No
// bindings. Every function is finite for any input.

// True when x is neither NaN nor ±∞ (tested on the bits: fast-math may fold x != x).
fn diffraction_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn diffraction_finite3(v: vec3<f32>) -> bool {
    return diffraction_finite(v.x) && diffraction_finite(v.y) && diffraction_finite(v.z);
}

// A unit vector along v, or 0 when v is non-finite or zero (huge components are scaled down
// first so that |v|² does not overflow).
fn diffraction_unit(v: vec3<f32>) -> vec3<f32> {
    if !diffraction_finite3(v) {
        return vec3<f32>(0.0);
    }
    let m = max(abs(v.x), max(abs(v.y), abs(v.z)));
    if !(m > 0.0) {
        return vec3<f32>(0.0);
    }
    let s = v / m;
    return s * inverseSqrt(dot(s, s));
}

// The grating frame of a surface point: n the normal, t a direction across the grating
// lines (from mesh tangents or a tangent map; need not be unit or orthogonal to n). Rows:
// x across the lines, y along them, z = n. Degenerate input gives an arbitrary frame.
fn diffraction_frame(n_in: vec3<f32>, t_in: vec3<f32>) -> mat3x3<f32> {
    var n = diffraction_unit(n_in);
    if dot(n, n) == 0.0 {
        n = vec3<f32>(0.0, 0.0, 1.0);
    }
    var x = diffraction_unit(t_in - n * dot(t_in, n));
    if dot(x, x) == 0.0 || !diffraction_finite3(x) {
        let a = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
        x = normalize(a - n * dot(a, n));
    }
    let y = cross(n, x);
    // Columns x, y, n; the transpose takes world vectors into the frame.
    return transpose(mat3x3<f32>(x, y, n));
}

// F² at cos θ: 1 for `kind` 0; for `kind` 1 the unpolarised Fresnel reflectance
// (|r_s|² + |r_p|²)/2 from air into ñ = `ior` = (n, κ) (`FresnelTerm::Index`). Always in [0, 1].
fn diffraction_fresnel_of(cos_theta: f32, kind: u32, ior: vec2<f32>) -> f32 {
    if kind == 0u {
        return 1.0;
    }
    let c = select(0.0, clamp(cos_theta, 0.0, 1.0), diffraction_finite(cos_theta));
    // ñ² and q₂ = √(ñ² − sin²θ) (principal branch: Im q₂ ≥ 0 for κ ≥ 0).
    let n2 = vec2<f32>(ior.x * ior.x - ior.y * ior.y, 2.0 * ior.x * ior.y);
    let a = vec2<f32>(n2.x - (1.0 - c * c), n2.y);
    let r = sqrt(length(a));
    let half_angle = 0.5 * atan2(a.y, a.x);
    let q2 = r * vec2<f32>(cos(half_angle), sin(half_angle));
    let q1 = vec2<f32>(c, 0.0);
    let rs = diffraction_cdiv(q1 - q2, q1 + q2);
    let n2q1 = n2 * c;
    let rp = diffraction_cdiv(n2q1 - q2, n2q1 + q2);
    let f = 0.5 * (dot(rs, rs) + dot(rp, rp));
    return select(0.0, clamp(f, 0.0, 1.0), diffraction_finite(f));
}

fn diffraction_cdiv(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let d = dot(b, b);
    if !(d > 0.0) {
        return vec2<f32>(1.0, 0.0);
    }
    return vec2<f32>(a.x * b.x + a.y * b.y, a.y * b.x - a.x * b.y) / d;
}

// Stam's G / w²: 1 in the specular direction, 0 at or below the horizon.
fn diffraction_geometry_over_w2(wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    let ci = wi.z;
    let cr = wr.z;
    if !(ci > 0.0 && cr > 0.0) {
        return 0.0;
    }
    let d = 1.0 + dot(wi, wr);
    let w = ci + cr;
    return d * d / (ci * cr * w * w);
}

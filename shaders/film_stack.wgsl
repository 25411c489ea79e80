// nacre · shaders/film_stack.wgsl — technique `film_stack`
// import: common
//
// Real-time multilayer films: ambient | up to 8 films | base, every medium with a complex
// index that may vary with wavelength, evaluated per pixel by the exact per-polarisation
// recurrence of crates/optics/src/stack.rs at a few wavelengths chosen by the rule of
// crates/optics/src/few_wavelengths/mod.rs. The GPU twin of `nacre color --method stack`
// (`nacre_optics::few_wavelengths::StackEvaluation`); the capability of Sussenbach 2013 §4.2–4.3
// (Algorithms 3 and 4) without its limits (dielectric films only, 5 uniform wavelengths).
//
// Symbols
//
//   symbol          code                          meaning
//   m = 0 … M−1     medium index                  0 ambient, 1 … F films (top first), F+1 base
//   ñ_m(λ_k)        stack_indices[k M + m]        complex index (n, κ) of medium m at node k
//   d_j             thickness[j]                  film j's thickness at the pixel, nm
//   d_j⁰, r_j       StackParams.layers[j].xy      film j's thickness and relative thickness, nm
//   c_j             StackParams.layers[j].w       film j's thickness-map channel: 0 R, 1 G, 2 B
//   s_c             FilmInput.variation(_g, _b)   spatial variation 2g_c − 1 ∈ [−1, 1] of channel c
//   k_j             StackParams.layers[j].z       2 max_λ |ñ_j|: film j's OPD per nm
//   h               StackParams.finesse           the stack's finesse factor (few_wavelengths/mod.rs)
//   λ_k, W_k        StackNode                     node wavelength, per-channel weight
//   q_m             q[m]                          ñ_m cos θ_m = √(ñ_m² − (n₀ sin θ₀)²), forward branch
//   r, t            FresnelInterface              interface m → m+1 amplitudes (common.wgsl)
//   Γ_m, τ_m        gamma, tau                    composite amplitudes below interface m
//
// Films: d_1 = FilmInput.thickness_nm (the pixel's film thickness, as for every technique),
// d_j = max(0, d_j⁰ + r_j s_{c_j}) for j ≥ 2 (Sussenbach 2013 Eq. 4.3, d = d_avg + d_rel Δ(x),
// with one map for all layers — every c_j = 0 — or one channel per layer).
//
// Rule: OPD = h Σ_j k_j d_j; N = ⌈base_count + count_per_opd_nm · OPD⌉ rounded up to the
// ladder (StackParams.rule_size, increasing); the rule's nodes are stack_nodes[offset …
// offset + N). With `fixed_rule` = 1 rule 0 is always used (`stack:N`).
//
// Recurrence at each node (stack.rs, Heavens 1955 §4): Γ_F = r_{F,F+1}, τ_F = t_{F,F+1}; for
// m = F−1 … 0, with e = e^{iδ_{m+1}}, δ = 2π d q / λ,
//
//   Γ_m = (r + Γ_{m+1} e²) / (1 + r Γ_{m+1} e²),   τ_m = t τ_{m+1} e / (1 + r Γ_{m+1} e²)
//
// R = (|Γ_0,s|² + |Γ_0,p|²)/2, T = (|τ_0,s|² f_s + |τ_0,p|² f_p)/2 (the power factors of
// common.wgsl, Byrnes' tmm conventions); C = Σ_k W_k R(λ_k) and likewise for T. Only e^{+iδ}
// with Im δ ≥ 0 appears: thick, absorbing and evanescent (beyond the critical angle) films
// never overflow. When no medium is dispersive (StackParams.dispersive = 0) the q_m and the
// interfaces do not depend on λ and are computed once per pixel, before the wavelength loop
// (the thesis's precalculation of wavelength-invariant terms).
//
// FilmInput fields used: cos_theta_i, thickness_nm, variation, variation_g, variation_b. The ambient index comes from
// the stack (its real part), so do the base and the films; film_ior, ambient_ior, base_*
// and sigma_thickness_nm are ignored. Indices are sanitised like a base index.

// One node (32 bytes, array stride 32, storage):
//
//   offset size field
//        0    4 wavelength_nm: f32
//        4   12 _pad0, _pad1, _pad2: f32
//       16   16 weight: vec4<f32>     rgb: per-channel weight W_k; a: unused (0)
struct StackNode {
    wavelength_nm: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
    weight: vec4<f32>,
}

// (288 bytes, uniform; `nacre_runtime::params::StackParams` mirrors it)
//
//   offset size field
//        0    4 films: u32              F (1 … 8)
//        4    4 dispersive: u32         1 when some index varies with λ
//        8    4 rule_count: u32         rules in the ladder (≤ 16)
//       12    4 fixed_rule: u32         1: always rule 0
//       16    4 base_count: f32         N at OPD 0
//       20    4 count_per_opd_nm: f32   samples per nm of OPD
//       24    4 finesse: f32            h
//       28    4 _pad0: f32
//       32   64 rule_offset: array<vec4<u32>, 4>   first node of rule i (component i % 4 of i / 4)
//       96   64 rule_size: array<vec4<u32>, 4>     nodes of rule i
//      160  128 layers: array<vec4<f32>, 8>        film j: (d_j⁰, r_j, k_j, c_j)
struct StackParams {
    films: u32,
    dispersive: u32,
    rule_count: u32,
    fixed_rule: u32,
    base_count: f32,
    count_per_opd_nm: f32,
    finesse: f32,
    _pad0: f32,
    rule_offset: array<vec4<u32>, 4>,
    rule_size: array<vec4<u32>, 4>,
    layers: array<vec4<f32>, 8>,
}

@group(1) @binding(0) var<storage, read> stack_nodes: array<StackNode>;
@group(1) @binding(1) var<storage, read> stack_indices: array<vec2<f32>>;
@group(1) @binding(2) var<uniform> stack_params: StackParams;

const STACK_MAX_FILMS: u32 = 8u;

// Rule i's (first node, node count).
fn stack_rule(i: u32) -> vec2<u32> {
    return vec2<u32>(stack_params.rule_offset[i / 4u][i % 4u], stack_params.rule_size[i / 4u][i % 4u]);
}

// The rule for the pixel's OPD: the first whose count reaches ⌈base + slope · OPD⌉, else the last.
fn stack_rule_for(opd_nm: f32) -> u32 {
    let rules = clamp(stack_params.rule_count, 1u, 16u);
    if stack_params.fixed_rule == 1u {
        return 0u;
    }
    let needed = ceil(stack_params.base_count + stack_params.count_per_opd_nm * max(opd_nm, 0.0));
    for (var i = 0u; i < rules; i++) {
        if f32(stack_rule(i).y) >= needed {
            return i;
        }
    }
    return rules - 1u;
}

// Medium m's index at node k, sanitised.
fn stack_index(k: u32, m: u32, media: u32) -> vec2<f32> {
    let n = stack_indices[k * media + m];
    return sanitize_base_index(n.x, n.y);
}

fn film_colour(raw: FilmInput) -> FilmOutput {
    let input = sanitize_input(raw);
    let c = max(input.cos_theta_i, COS_THETA_MIN);
    let films = clamp(stack_params.films, 1u, STACK_MAX_FILMS);
    let media = films + 2u;
    // Films' thicknesses at the pixel and the rule's OPD.
    var thickness: array<f32, 8>;
    var opd = 0.0;
    let variation = vec3<f32>(input.variation, input.variation_g, input.variation_b);
    for (var j = 0u; j < films; j++) {
        let layer = stack_params.layers[j];
        var d = input.thickness_nm;
        if j > 0u {
            let s = variation[min(u32(clamp(layer.w, 0.0, 2.0)), 2u)];
            d = clamp(layer.x + layer.y * s, 0.0, THICKNESS_MAX_NM);
            d = select(0.0, d, f32_is_finite(d));
        }
        thickness[j] = d;
        opd += layer.z * d;
    }
    let rule = stack_rule(stack_rule_for(opd * stack_params.finesse));
    let first = rule.x;
    let count = min(rule.y, arrayLength(&stack_nodes) - min(first, arrayLength(&stack_nodes)));
    var q: array<vec2<f32>, 10>;
    var r_s: array<vec2<f32>, 9>;
    var r_p: array<vec2<f32>, 9>;
    var t_s: array<vec2<f32>, 9>;
    var t_p: array<vec2<f32>, 9>;
    var factor_s = 0.0;
    var factor_p = 0.0;
    var r = vec3<f32>(0.0);
    var t = vec3<f32>(0.0);
    for (var i = 0u; i < count; i++) {
        let k = first + i;
        let node = stack_nodes[k];
        if !f32_is_finite(node.wavelength_nm) || !(node.wavelength_nm > 0.0) {
            continue;
        }
        if i == 0u || stack_params.dispersive != 0u {
            // Normal components and interfaces (wavelength-invariant without dispersion).
            let n0 = stack_index(k, 0u, media).x;
            var prev = c_real(n0);
            q[0] = c_real(n0 * c);
            for (var m = 1u; m < media; m++) {
                let n = stack_index(k, m, media);
                q[m] = normal_component_cos(n, n0, c);
                let f = fresnel_interface(prev, q[m - 1u], n, q[m]);
                r_s[m - 1u] = f.r_s;
                r_p[m - 1u] = f.r_p;
                t_s[m - 1u] = f.t_s;
                t_p[m - 1u] = f.t_p;
                prev = n;
            }
            factor_s = power_factor_s(q[0], q[media - 1u]);
            factor_p = power_factor_p(c_real(n0), q[0], prev, q[media - 1u]);
        }
        var gamma_s = r_s[films];
        var gamma_p = r_p[films];
        var tau_s = t_s[films];
        var tau_p = t_p[films];
        for (var jj = 0u; jj < films; jj++) {
            let m = films - 1u - jj;
            // Film m + 1 (medium m + 1): e^{iδ} (phase in cycles reduced first) and
            // e^{2iδ} = (e^{iδ})², as stack.rs forms it.
            let qf = q[m + 1u];
            let x = safe_div(thickness[m], node.wavelength_nm);
            let e1 = c_exp_i_cycles(x * qf.x) * exp(-TWO_PI * x * qf.y);
            let e2 = c_mul(e1, e1);
            let gs = c_mul(gamma_s, e2);
            let gp = c_mul(gamma_p, e2);
            let den_s = c_inv(vec2<f32>(1.0, 0.0) + c_mul(r_s[m], gs));
            let den_p = c_inv(vec2<f32>(1.0, 0.0) + c_mul(r_p[m], gp));
            gamma_s = c_mul(r_s[m] + gs, den_s);
            gamma_p = c_mul(r_p[m] + gp, den_p);
            tau_s = c_mul(c_mul(c_mul(t_s[m], tau_s), e1), den_s);
            tau_p = c_mul(c_mul(c_mul(t_p[m], tau_p), e1), den_p);
        }
        let reflectance = 0.5 * (unit_power(c_abs2(gamma_s)) + unit_power(c_abs2(gamma_p)));
        let transmittance = 0.5 * (unit_power(c_abs2(tau_s) * factor_s) + unit_power(c_abs2(tau_p) * factor_p));
        r += reflectance * node.weight.rgb;
        t += transmittance * node.weight.rgb;
    }
    return sanitize_output(FilmOutput(r, t));
}

// nacre · shaders/film_glass.wgsl — technique `film_glass`
// import: common
//
// Real-time thin-walled coated glass: ambient | films | one incoherent slab | films | base,
// the slab millimetres thick (a spectacle lens, a window pane, a camera lens element), every
// medium with a complex index that may vary with wavelength, at the few wavelengths of
// film_stack.wgsl's rule (crates/optics/src/few_wavelengths/mod.rs). The GPU twin of
// `nacre color --method stack` on a stack with an incoherent layer
// (`nacre_optics::few_wavelengths::StackEvaluation`, crates/optics/src/few_wavelengths/slab.rs).
// Without a slab (GlassParams.slab = 0) it computes what film_stack.wgsl computes.
//
// Symbols (those of film_stack.wgsl, and)
//
//   symbol          code                          meaning
//   s               GlassParams.slab              the slab's medium index (1 … F), 0: none
//   d_s             StackParams.layers[s−1].x     the slab's thickness, nm (its own: neither
//                                                 the pixel's nor the map's)
//   R_A, T_A        upper                         the films above the slab (media 0 … s), from
//                                                 the ambient
//   R′_A, T′_A      upper_back                    the same group from inside the slab (reversed)
//   R_B, T_B        lower                         the films below the slab (media s … F+1),
//                                                 from inside the slab
//   P               slab_pass                     the slab's single pass
//
// Each coherent group is evaluated by film_stack.wgsl's recurrence (stack.rs, Heavens 1955
// §4) on its own media, the slab its first or last medium; the slab adds the groups' powers
// in intensity, per polarisation (Byrnes, arXiv:1603.02720 §4; Katsidis & Siapkas 2002,
// Eq. 13–16; crates/optics/src/incoherent.rs with one slab):
//
//   P = exp(−4π d_s Im(ñ_s cos θ_s) / λ),   D = 1 − R′_A P² R_B,
//   R = R_A + T_A T′_A P² R_B / D,          T = T_A P T_B / D,
//
// R and T averaged over s and p, summed with the rule's weights as film_stack.wgsl does. The
// reversed group's interfaces are computed from its own media (fresnel_interface with the
// media swapped). The rule's OPD leaves the slab out (its fringes are averaged, not sampled).
//
// FilmInput fields used: as film_stack.wgsl.

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

// (288 bytes, uniform; `nacre_format::gpu_params::StackParams` mirrors it, as for film_stack.wgsl)
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

// (16 bytes, uniform; `nacre_runtime::technique::GlassParams` mirrors it)
//
//   offset size field
//        0    4 slab: u32               s (1 … F), 0: no slab
//        4   12 _pad0, _pad1, _pad2: u32
struct GlassParams {
    slab: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(3) var<uniform> glass_params: GlassParams;

// Per polarisation (s in xy, p in zw): the composite (Γ, τ) of a group after one more film
// of phase e^{iδ} (e1) under interface (r, t): stack.rs's step.
struct GlassAmplitudes {
    gamma_s: vec2<f32>,
    gamma_p: vec2<f32>,
    tau_s: vec2<f32>,
    tau_p: vec2<f32>,
}

fn glass_step(a: GlassAmplitudes, r_s: vec2<f32>, r_p: vec2<f32>, t_s: vec2<f32>, t_p: vec2<f32>, e1: vec2<f32>) -> GlassAmplitudes {
    let e2 = c_mul(e1, e1);
    let gs = c_mul(a.gamma_s, e2);
    let gp = c_mul(a.gamma_p, e2);
    let den_s = c_inv(vec2<f32>(1.0, 0.0) + c_mul(r_s, gs));
    let den_p = c_inv(vec2<f32>(1.0, 0.0) + c_mul(r_p, gp));
    var out: GlassAmplitudes;
    out.gamma_s = c_mul(r_s + gs, den_s);
    out.gamma_p = c_mul(r_p + gp, den_p);
    out.tau_s = c_mul(c_mul(c_mul(t_s, a.tau_s), e1), den_s);
    out.tau_p = c_mul(c_mul(c_mul(t_p, a.tau_p), e1), den_p);
    return out;
}

// e^{iδ} of a film of thickness d (nm) and normal component q at wavelength λ (phase in
// cycles reduced first, as film_stack.wgsl).
fn glass_phase(d: f32, q: vec2<f32>, wavelength_nm: f32) -> vec2<f32> {
    let x = safe_div(d, wavelength_nm);
    return c_exp_i_cycles(x * q.x) * exp(-TWO_PI * x * q.y);
}

// (R_s, T_s, R_p, T_p) of amplitudes a with power factors (f_s, f_p).
fn glass_powers(a: GlassAmplitudes, factor_s: f32, factor_p: f32) -> vec4<f32> {
    return vec4<f32>(
        unit_power(c_abs2(a.gamma_s)),
        unit_power(c_abs2(a.tau_s) * factor_s),
        unit_power(c_abs2(a.gamma_p)),
        unit_power(c_abs2(a.tau_p) * factor_p),
    );
}

// One polarisation's (R, T) through the slab: upper (R_A, T_A), back (R′_A, T′_A), lower
// (R_B, T_B), the slab's single pass P.
fn glass_combine(upper: vec2<f32>, back: vec2<f32>, lower: vec2<f32>, slab_pass: f32) -> vec2<f32> {
    let a = slab_pass * slab_pass * lower.x;
    let den = max(1.0 - back.x * a, 1e-6);
    return vec2<f32>(upper.x + upper.y * back.y * a / den, upper.y * slab_pass * lower.y / den);
}

fn film_colour(raw: FilmInput) -> FilmOutput {
    let input = sanitize_input(raw);
    let c = max(input.cos_theta_i, COS_THETA_MIN);
    let films = clamp(stack_params.films, 1u, STACK_MAX_FILMS);
    let media = films + 2u;
    let slab = select(0u, glass_params.slab, glass_params.slab <= films);
    // Films' thicknesses at the pixel and the rule's OPD (the slab's own thickness, no OPD).
    var thickness: array<f32, 8>;
    var opd = 0.0;
    let variation = vec3<f32>(input.variation, input.variation_g, input.variation_b);
    for (var j = 0u; j < films; j++) {
        let layer = stack_params.layers[j];
        var d = input.thickness_nm;
        if j + 1u == slab {
            d = select(0.0, max(layer.x, 0.0), f32_is_finite(layer.x));
        } else if j > 0u {
            let s = variation[min(u32(clamp(layer.w, 0.0, 2.0)), 2u)];
            d = clamp(layer.x + layer.y * s, 0.0, THICKNESS_MAX_NM);
            d = select(0.0, d, f32_is_finite(d));
        }
        thickness[j] = d;
        opd += select(layer.z * d, 0.0, j + 1u == slab);
    }
    let rule = stack_rule(stack_rule_for(opd * stack_params.finesse));
    let first = rule.x;
    let count = min(rule.y, arrayLength(&stack_nodes) - min(first, arrayLength(&stack_nodes)));
    var n_m: array<vec2<f32>, 10>;
    var q: array<vec2<f32>, 10>;
    var r_s: array<vec2<f32>, 9>;
    var r_p: array<vec2<f32>, 9>;
    var t_s: array<vec2<f32>, 9>;
    var t_p: array<vec2<f32>, 9>;
    // Interface m + 1 → m (the upper group reversed).
    var rb_s: array<vec2<f32>, 9>;
    var rb_p: array<vec2<f32>, 9>;
    var tb_s: array<vec2<f32>, 9>;
    var tb_p: array<vec2<f32>, 9>;
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
            n_m[0] = c_real(n0);
            q[0] = c_real(n0 * c);
            for (var m = 1u; m < media; m++) {
                let n = stack_index(k, m, media);
                n_m[m] = n;
                q[m] = normal_component_cos(n, n0, c);
                let f = fresnel_interface(n_m[m - 1u], q[m - 1u], n, q[m]);
                r_s[m - 1u] = f.r_s;
                r_p[m - 1u] = f.r_p;
                t_s[m - 1u] = f.t_s;
                t_p[m - 1u] = f.t_p;
                if m <= slab {
                    let b = fresnel_interface(n, q[m], n_m[m - 1u], q[m - 1u]);
                    rb_s[m - 1u] = b.r_s;
                    rb_p[m - 1u] = b.r_p;
                    tb_s[m - 1u] = b.t_s;
                    tb_p[m - 1u] = b.t_p;
                }
            }
        }
        let last = media - 1u;
        // The group below the slab (media s … F+1), or the whole stack without one.
        var below: GlassAmplitudes;
        below.gamma_s = r_s[films];
        below.gamma_p = r_p[films];
        below.tau_s = t_s[films];
        below.tau_p = t_p[films];
        for (var jj = 0u; jj + slab < films; jj++) {
            let m = films - 1u - jj;
            below = glass_step(below, r_s[m], r_p[m], t_s[m], t_p[m], glass_phase(thickness[m], q[m + 1u], node.wavelength_nm));
        }
        let lower = glass_powers(below, power_factor_s(q[slab], q[last]), power_factor_p(n_m[slab], q[slab], n_m[last], q[last]));
        var power = lower;
        if slab > 0u {
            // The group above the slab (media 0 … s), forward and reversed.
            var above: GlassAmplitudes;
            above.gamma_s = r_s[slab - 1u];
            above.gamma_p = r_p[slab - 1u];
            above.tau_s = t_s[slab - 1u];
            above.tau_p = t_p[slab - 1u];
            var back: GlassAmplitudes;
            back.gamma_s = rb_s[0];
            back.gamma_p = rb_p[0];
            back.tau_s = tb_s[0];
            back.tau_p = tb_p[0];
            for (var jj = 1u; jj < slab; jj++) {
                // Forward: film slab − jj (medium slab − jj) under interface slab − jj − 1.
                let m = slab - 1u - jj;
                above = glass_step(above, r_s[m], r_p[m], t_s[m], t_p[m], glass_phase(thickness[m], q[m + 1u], node.wavelength_nm));
                // Reversed: film jj (medium jj) under interface jj + 1 → jj.
                back = glass_step(back, rb_s[jj], rb_p[jj], tb_s[jj], tb_p[jj], glass_phase(thickness[jj - 1u], q[jj], node.wavelength_nm));
            }
            let upper = glass_powers(above, power_factor_s(q[0], q[slab]), power_factor_p(n_m[0], q[0], n_m[slab], q[slab]));
            let upper_back = glass_powers(back, power_factor_s(q[slab], q[0]), power_factor_p(n_m[slab], q[slab], n_m[0], q[0]));
            let slab_pass = exp(-2.0 * TWO_PI * safe_div(thickness[slab - 1u], node.wavelength_nm) * q[slab].y);
            let s_pol = glass_combine(upper.xy, upper_back.xy, lower.xy, slab_pass);
            let p_pol = glass_combine(upper.zw, upper_back.zw, lower.zw, slab_pass);
            power = vec4<f32>(s_pol, p_pol);
        }
        let reflectance = 0.5 * (unit_power(power.x) + unit_power(power.z));
        let transmittance = 0.5 * (unit_power(power.y) + unit_power(power.w));
        r += reflectance * node.weight.rgb;
        t += transmittance * node.weight.rgb;
    }
    return sanitize_output(FilmOutput(r, t));
}

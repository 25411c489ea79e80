// @nacre/three/webgpu: nacre's thin-film colour for three.js's WebGPURenderer (three/webgpu),
// as a TSL node material.
//
// How it hooks into three.js. A MeshPhysicalNodeMaterial with iridescence > 0 is lit by a
// PhysicalLightingModel (three/webgpu) that computes the film's Fresnel term in `start()`
// (three's evalIridescence, Belcour & Barla 2017's analytic Airy approximation) and reads it
// in two places:
//   * every direct light: BRDF_GGX(…, f: this.iridescenceFresnel, USE_IRIDESCENCE) in
//     `direct()`, F = mix(F_Schlick, iridescenceFresnel, iridescence);
//   * image-based light: `computeMultiscattering(single, multi, specularF90[, f0,
//     iridescenceF0])`, three's split sum with the film re-expressed as a Schlick F0.
// NacreFilmNodeMaterial's lighting model is three's own (the one three's material builds, its
// fields copied onto a subclass, so every flag of every release carries over) with two
// overrides and nothing else replaced:
//   * `start()` runs three's, then sets `iridescenceFresnel` to nacre's film
//     R_f(n·v) — for three's F0 (r171–r180: the metalness-blended specularColor), or
//     mix(R_f(F0 dielectric), R_f(F0 metal), metalness) on releases that evaluate the film
//     per base (r181+: specularColorBlended exists);
//   * `computeMultiscattering()` becomes nacre's "film at n·v" split sum (shaders/material.wgsl,
//     film_eval = 1; the same as the WebGLRenderer material):
//       single scattering  R_f(n·v) E₁,  E₁ = fab.x + fab.y (three's GGX albedo),
//       multiple scattering R_f(n·v) (1 − E₁),
//     mixed with three's terms for the bare base by the iridescence weight (a unit film gives
//     E₁ + (1 − E₁) = 1: the white furnace holds).
// Everything else (maps, the iridescence and thickness maps, shadows, clearcoat, sheen,
// transmission, tone mapping, colour management) stays three's.
//
// The film, in TSL (the same numbers as nacre's WGSL/GLSL libraries, shaders/film_lut.wgsl,
// shaders/lut_mapping.wgsl, shaders/film_fourier.wgsl):
//   * lut: the forward mapping of lut_mapping.wgsl (tₓ = √cos θ, t_y = Δ/Δ_max,
//     t_z = √((q(n) − q_min)/(q_max − q_min)), q(n) = √(n² − n₀² sin²θ)), texel-centre
//     coordinate (t (N − 1) + 0.5)/N, one trilinear sample of the baked table;
//   * fourier: Belcour & Barla 2017 Eq. 10 with exact Fresnel amplitudes (film_fourier.wgsl),
//       C_j = ‖s_j‖ [c₀ + 2 Σ_{m=1}^{M} Re(c_m conj Ŝ_j(m D))],  c_m = ρ^{m−1} K,
//     R: c₀ = r₁₂² + β²/(1 − ρ²), K = β r₁₂ + β² ρ/(1 − ρ²), β = (1 − r₁₂²) Γ, ρ = −r₁₂ Γ,
//     averaged over s and p, with automatic M (harmonics = 0) stopping as the CPU does.
//     three's film sits in air (n₁ = 1, three's outsideIOR) on a dielectric base of index
//     n₃ = (1 + √F0)/(1 − √F0) per channel (three's Fresnel0ToIor), and its film index is
//     ≥ 1 (iridescenceIOR's range): every Fresnel amplitude is real and the film is never
//     evanescent, so the amplitudes are computed in real arithmetic (the complex formulas of
//     common.wgsl with zero imaginary parts) and a film index below 1 is raised to 1. The
//     table is read at level 0 (σ_d = 0, as `nacre color --method fourier`).
//   * stack: nacre's film_stack (shaders/film_stack.wgsl, nacre.glsl's nacre_film_stack_colour)
//     for a NacreStack, the exact per-polarisation recurrence in complex arithmetic on vec2
//     nodes; the stack's sizes are constants of the generated code (the films and media
//     unrolled), the nodes of the pixel's rule a Loop over the stack table. Its ambient,
//     films and base are the stack's own; three's thickness is the top film's, and the lower
//     films follow s = 2g − 1 as in src/material.js. e^{2πix} is computed with polynomial
//     trigonometry (SwiftShader's cos/sin are ~1e-3 off, material.js).
// Tested with three.js r187 and r171 (the first release with the `three/tsl` entry), on the
// WebGPU backend (Chromium's WebGPU on SwiftShader).
import { MeshPhysicalNodeMaterial, PhysicalLightingModel, REVISION } from 'three/webgpu';
import * as TSL from 'three/tsl';
import { setThicknessRange, thicknessRange } from './thickness.js';
import { DataTexture, FloatType, NearestFilter, ClampToEdgeWrapping, NoColorSpace, RGBAFormat, Vector2 } from 'three/webgpu';

const {
  Fn, If, Loop, Break, float, int, vec2, vec3, vec4, ivec2, uniform, texture3D, textureLoad, select,
  mix, clamp, max, min, sqrt, floor, fract, cos, sin, abs, pow, smoothstep, exp, ceil, dot,
  specularColor, specularF90, diffuseColor, metalness, roughness, iridescence, iridescenceIOR,
  iridescenceThickness, normalView, positionViewDirection,
} = TSL;

/** Debug views, as the WebGLRenderer material's: shaded colour, film colour + n·v, unit film. */
export const NacreDebugView = Object.freeze({ NONE: 0, FILM: 1, UNIT_FILM: 2 });

// shaders/common.wgsl and film_fourier.wgsl constants.
const COS_THETA_MIN = 1e-6;
const THICKNESS_MAX_NM = 1e6;
const IOR_MAX = 1e3;
const FOURIER_MAX_HARMONICS = 128;
const FOURIER_AUTO_TOLERANCE = 1e-3;
const FOURIER_AUTO_LEVEL_FLOOR = 0.01;
const FOURIER_THIN_FILM_BLEND_NM = 30.0;
const FOURIER_MIN_ONE_MINUS_RHO2 = 1e-6;
const TWO_PI = 6.28318530717959;
const IOR_MIN = 1e-3;
const BRANCH_TOLERANCE = 1.1920929e-5;

/**
 * Throws, naming the release, when three's node lighting model lost what the material hooks
 * into; returns three's revision otherwise.
 */
export function checkThreeNodeHooks() {
  const problems = [];
  const proto = PhysicalLightingModel?.prototype;
  if (!proto) problems.push('three/webgpu exports no PhysicalLightingModel');
  else {
    for (const m of ['start', 'direct', 'computeMultiscattering']) {
      if (typeof proto[m] !== 'function') problems.push(`PhysicalLightingModel has no ${m}()`);
    }
    const direct = String(proto.direct);
    if (!/f:\s*this\.iridescenceFresnel/.test(direct)) problems.push('PhysicalLightingModel.direct() does not read this.iridescenceFresnel');
    const start = String(proto.start);
    if (!/this\.iridescenceFresnel\s*=/.test(start)) problems.push('PhysicalLightingModel.start() does not set this.iridescenceFresnel');
  }
  if (typeof MeshPhysicalNodeMaterial?.prototype?.setupLightingModel !== 'function') problems.push('MeshPhysicalNodeMaterial has no setupLightingModel()');
  for (const name of ['Fn', 'Loop', 'If', 'Break', 'textureLoad', 'texture3D', 'specularColor', 'iridescenceThickness']) {
    if (!(name in TSL)) problems.push(`three/tsl exports no ${name}`);
  }
  if (problems.length) {
    throw new Error(`@nacre/three/webgpu: three.js r${REVISION} is not supported (${problems.join('; ')}); tested with r171 and r187`);
  }
  return REVISION;
}

// True on releases that evaluate the film once per base, the dielectric's F0
// (specularColor) and the metal's (diffuseColor), mixed by metalness (r181+).
const filmPerBase = 'specularColorBlended' in TSL;

// The fourier table as a 2-D texture N × 2 (row 0 Re A, row 1 Im A): the bytes of the
// loader's 2-layer array texture, read with textureLoad (RGBA32F is not filterable).
const fourierTextures = new WeakMap();
function fourierTexture(table) {
  let tex = fourierTextures.get(table);
  if (!tex) {
    const image = table.texture.image;
    tex = new DataTexture(image.data, image.width, 2, RGBAFormat, FloatType);
    tex.minFilter = tex.magFilter = NearestFilter;
    tex.wrapS = tex.wrapT = ClampToEdgeWrapping;
    tex.generateMipmaps = false;
    tex.colorSpace = NoColorSpace;
    tex.needsUpdate = true;
    fourierTextures.set(table, tex);
  }
  return tex;
}

/**
 * The film-lut lookup (film_lut.wgsl with lut_mapping.wgsl): reflectance at (cos θ, d, n).
 */
function lutFilm(table) {
  const p = table.params;
  const lut = table.reflectance;
  const counts = vec3(Math.max(p.cosThetaCount, 1), Math.max(p.opdCount, 1), Math.max(p.iorCount, 1));
  const a = float(p.ambientIndex);
  const opdMaxNm = float(2 * p.thicknessMaxNm * p.iorMax);
  // q(n) = √max((n − n₀)(n + n₀) + (n₀ cos θ)², 0)
  const q = (c, n) => {
    const ac = a.mul(c);
    return sqrt(max(n.sub(a).mul(n.add(a)).add(ac.mul(ac)), 0.0));
  };
  return Fn(([cosTheta, thicknessNm, filmIor]) => {
    const c = clamp(cosTheta, 0.0, 1.0).toVar();
    const d = clamp(thicknessNm, 0.0, THICKNESS_MAX_NM);
    const n = clamp(filmIor, 1e-3, IOR_MAX);
    const tx = sqrt(c);
    const ty = d.mul(2.0).mul(q(c, n)).div(opdMaxNm);
    const qMin = q(c, float(p.iorMin)).toVar();
    const qMax = q(c, float(p.iorMax)).toVar();
    const tz = select(qMax.greaterThan(qMin), sqrt(max(q(c, n).sub(qMin).div(qMax.sub(qMin)), 0.0)), float(0.0));
    const t = clamp(vec3(tx, ty, tz), 0.0, 1.0);
    const uvw = t.mul(counts.sub(1.0)).add(0.5).div(counts);
    return texture3D(lut, uvw).level(0).rgb;
  });
}

/**
 * The fourier technique (film_fourier.wgsl `film_colour`, reflectance) for a film of index n₂
 * in air on a base of F0 per channel, with `harmonics` (a uniform; 0 = automatic).
 */
function fourierFilm(table, harmonics) {
  const p = table.params;
  const tex = fourierTexture(table);
  const width = table.texture.image.width;
  // u = μ / D_max (0 when D_max is not positive, as the WGSL's select).
  const invMaxOpd = float(p.maxOpdNm > 0 ? 1 / p.maxOpdNm : 0);
  const carrier = vec3(...p.carrierNuPerNm);
  const white = vec3(...p.white);
  // Ŝ_j(μ) at level 0: linear between texel centres, clamp to edge, times e^{−2πiμν̄_j}
  // (fourier_sample_level, fourier_sample).
  const sample = (mu) => {
    const nf = float(width);
    const u = mu.mul(invMaxOpd);
    const x = clamp(u.mul(nf).sub(0.5), 0.0, nf.sub(1.0)).toVar();
    const i0 = min(int(floor(x)), int(width - 1)).toVar();
    const i1 = min(i0.add(1), int(width - 1));
    const f = x.sub(float(i0));
    const re = mix(textureLoad(tex, ivec2(i0, 0)).rgb, textureLoad(tex, ivec2(i1, 0)).rgb, f);
    const im = mix(textureLoad(tex, ivec2(i0, 1)).rgb, textureLoad(tex, ivec2(i1, 1)).rgb, f);
    const phi = fract(carrier.mul(mu)).mul(-TWO_PI).toVar();
    const c = cos(phi);
    const s = sin(phi);
    return { re: re.mul(c).sub(im.mul(s)), im: re.mul(s).add(im.mul(c)) };
  };
  // Reflectance Airy series of one polarisation from r₁₂ and Γ (airy_series_reflectance).
  const series = (r12, gamma) => {
    const beta = float(1.0).sub(r12.mul(r12)).mul(gamma);
    const rho = r12.mul(gamma).negate();
    const inv = float(1.0).div(max(float(1.0).sub(rho.mul(rho)), FOURIER_MIN_ONE_MINUS_RHO2));
    const b2 = beta.mul(beta);
    return { c0: r12.mul(r12).add(b2.mul(inv)), k: beta.mul(r12).add(b2.mul(inv).mul(rho)), rho };
  };
  // 2|c_{m+1}|/(1 − |ρ|) s_max ≤ tolerance per channel (airy_tail_converged).
  const converged = (cm, rho, sMax, tolerance) => {
    const r = abs(rho);
    const tail = abs(cm).mul(2.0).mul(r).div(max(float(1.0).sub(r), vec3(1e-12))).mul(sMax);
    return tail.x.lessThanEqual(tolerance.x).and(tail.y.lessThanEqual(tolerance.y)).and(tail.z.lessThanEqual(tolerance.z));
  };
  return Fn(([cosTheta, thicknessNm, filmIor, baseF0]) => {
    const c = max(clamp(cosTheta, 0.0, 1.0), COS_THETA_MIN).toVar();
    const d = clamp(thicknessNm, 0.0, THICKNESS_MAX_NM).toVar();
    const n1 = float(1.0);
    const m = int(harmonics).toVar();
    // η₂ blend for a fixed number of harmonics (Belcour & Barla §4).
    const n2In = clamp(filmIor, 1.0, IOR_MAX);
    const n2 = select(m.notEqual(0), n1.add(n2In.sub(n1).mul(smoothstep(0.0, FOURIER_THIN_FILM_BLEND_NM, d))), n2In).toVar();
    const q1 = n1.mul(c);
    const q2 = sqrt(n2.sub(n1).mul(n2.add(n1)).add(q1.mul(q1))).toVar();
    const opd = d.mul(2.0).mul(q2).toVar();
    // Base index per channel from three's F0 (Fresnel0ToIor), and its normal component.
    const r = sqrt(clamp(baseF0, 0.0, 0.9999));
    const n3 = float(1.0).add(r).div(float(1.0).sub(r)).toVar();
    const q3 = sqrt(n3.sub(n1).mul(n3.add(n1)).add(q1.mul(q1))).toVar();
    // Film top (air → film) and base (film → base) amplitudes (fresnel_interface).
    const r12s = q1.sub(q2).div(q1.add(q2));
    const a12 = n2.mul(n2).mul(q1);
    const b12 = n1.mul(n1).mul(q2);
    const r12p = a12.sub(b12).div(a12.add(b12));
    const r23s = q2.sub(q3).div(q3.add(q2));
    const a23 = n3.mul(n3).mul(q2);
    const b23 = n2.mul(n2).mul(q3);
    const r23p = a23.sub(b23).div(a23.add(b23));
    const s = series(vec3(r12s), r23s);
    const pp = series(vec3(r12p), r23p);
    const c0 = s.c0.add(pp.c0).mul(0.5).toVar();
    const rhoS = s.rho.toVar();
    const rhoP = pp.rho.toVar();
    const cmS = s.k.toVar();
    const cmP = pp.k.toVar();
    const sum = vec3(0.0).toVar();
    const automatic = m.equal(0);
    // M_max = 128 when automatic, else min(M, 128); arithmetic rather than a select, which
    // r171's Loop does not set up as its bound.
    const mMax = min(m.add(int(automatic).mul(FOURIER_MAX_HARMONICS)), int(FOURIER_MAX_HARMONICS)).toVar();
    const tolerance = pow(max(c0, vec3(FOURIER_AUTO_LEVEL_FLOOR)), vec3(2.0 / 3.0)).mul(FOURIER_AUTO_TOLERANCE).toVar();
    Loop({ start: int(1), end: mMax, condition: '<=' }, ({ i }) => {
      If(i.greaterThan(1), () => {
        cmS.mulAssign(rhoS);
        cmP.mulAssign(rhoP);
      });
      const sHat = sample(float(i).mul(opd));
      const re = sHat.re.toVar();
      const im = sHat.im.toVar();
      // Re(c_m conj Ŝ) = c_m Re Ŝ (c_m real), both polarisations (their mean, times 2).
      sum.addAssign(cmS.add(cmP).mul(re));
      If(automatic, () => {
        const sAbs = sqrt(re.mul(re).add(im.mul(im)));
        const sMax = max(sAbs.x, max(sAbs.y, sAbs.z));
        If(converged(cmS, rhoS, sMax, tolerance).and(converged(cmP, rhoP, sMax, tolerance)), () => {
          Break();
        });
      });
    });
    return c0.add(sum).mul(white);
  });
}

// Complex numbers as vec2 nodes (shaders/common.wgsl's c_* functions).
const cmul = (a, b) => vec2(a.x.mul(b.x).sub(a.y.mul(b.y)), a.x.mul(b.y).add(a.y.mul(b.x)));
// a / b with Smith-style scaling by max(|Re b|, |Im b|) (c_div).
const cdiv = (a, b) => {
  const s = max(max(abs(b.x), abs(b.y)), 1e-30);
  const bs = b.div(s).toVar();
  const as = a.div(s).toVar();
  return vec2(as.x.mul(bs.x).add(as.y.mul(bs.y)), as.y.mul(bs.x).sub(as.x.mul(bs.y))).div(dot(bs, bs));
};
// Principal square root without cancellation (c_sqrt), r = |z|.
const csqrt = (z) => {
  const m = max(max(abs(z.x), abs(z.y)), 1e-30);
  const r = m.mul(sqrt(dot(z.div(m), z.div(m)))).toVar();
  const tPos = sqrt(max(r.add(z.x).mul(0.5), 1e-38)).toVar();
  const tNeg = sqrt(max(r.sub(z.x).mul(0.5), 1e-38)).toVar();
  const pos = vec2(tPos, z.y.mul(0.5).div(tPos));
  const neg = vec2(abs(z.y).mul(0.5).div(tNeg), select(z.y.greaterThanEqual(0.0), tNeg, tNeg.negate()));
  // select, not mix: the branch not taken may divide by a zero t (NaN · 0 is NaN).
  return select(z.x.greaterThanEqual(0.0), pos, neg);
};
// The forward branch of q (forward_branch): Im q > 0, or Re q ≥ 0 when Im q is rounding noise.
const forwardBranch = (q) => {
  const scale = max(abs(q.x), abs(q.y));
  const forward = select(abs(q.y).greaterThan(scale.mul(BRANCH_TOLERANCE)), float(q.y.greaterThan(0.0)), float(q.x.greaterThanEqual(0.0)));
  return q.mul(forward.mul(2.0).sub(1.0));
};
// q = √((n − n₀)(n + n₀) − κ² + (n₀ cos θ)² + 2inκ) on the forward branch (normal_component_cos).
const normalComponentCos = (n, n0, c) => {
  const a = n0.mul(c);
  return forwardBranch(csqrt(vec2(n.x.sub(n0).mul(n.x.add(n0)).sub(n.y.mul(n.y)).add(a.mul(a)), n.x.mul(n.y).mul(2.0))));
};
// e^{2πix} with the trigonometry in arithmetic (as src/material.js's PRECISE_EXP_I_CYCLES):
// x reduced to a quarter turn k/4 plus φ/2π, |φ| ≤ π/4, Taylor polynomials to φ⁹, times i^k.
const expICycles = (x) => {
  const r = fract(x).toVar();
  const k = floor(r.mul(4.0).add(0.5)).toVar();
  const phi = r.sub(k.mul(0.25)).mul(TWO_PI).toVar();
  const p2 = phi.mul(phi).toVar();
  const c = p2.mul(p2.mul(p2.mul(p2.mul(1 / 40320).add(-1 / 720)).add(1 / 24)).add(-0.5)).add(1.0).toVar();
  const s = phi.mul(p2.mul(p2.mul(p2.mul(p2.mul(1 / 362880).add(-1 / 5040)).add(1 / 120)).add(-1 / 6)).add(1.0)).toVar();
  // i^k (c + is): k = 0 (c, s), 1 (−s, c), 2 (−c, −s), 3 or 4 (s, −c) / (c, s).
  const q = k.sub(floor(k.mul(0.25)).mul(4.0)).toVar();
  const cosK = select(q.equal(0.0), float(1.0), select(q.equal(2.0), float(-1.0), float(0.0)));
  const sinK = select(q.equal(1.0), float(1.0), select(q.equal(3.0), float(-1.0), float(0.0)));
  return vec2(c.mul(cosK).sub(s.mul(sinK)), c.mul(sinK).add(s.mul(cosK)));
};

/**
 * The multilayer stack (film_stack.wgsl `film_colour`, reflectance; nacre.glsl's
 * nacre_film_stack_colour) for a NacreStack: ambient | F films | base, the exact recurrence
 *   Γ_m = (r + Γ_{m+1} e²) / (1 + r Γ_{m+1} e²),  e = e^{iδ_{m+1}},  δ = 2π d q / λ
 * per polarisation at the nodes of the pixel's rule, R = Σ_k W_k (|Γ_s|² + |Γ_p|²)/2.
 * The stack's sizes (films, media, rules) are constants of the generated code; the nodes'
 * wavelengths, weights and indices are read from the stack table with textureLoad. The top
 * film's thickness is three's; film j ≥ 2 is max(0, d_j⁰ + r_j s), s = 2g − 1, g = (d − min)
 * / (max − min) from the thickness range `range` (a vec2 uniform; g = 1 for an empty range).
 */
function stackFilm(stack, range) {
  const p = stack.params;
  const tex = stack.texture;
  const films = p.films;
  const media = films + 2;
  const index = (k, m) => {
    const texel = textureLoad(tex, ivec2(int(1 + (m >> 1)), k));
    const n = m % 2 === 0 ? texel.xy : texel.zw;
    return vec2(clamp(n.x, IOR_MIN, IOR_MAX), clamp(n.y, 0.0, IOR_MAX));
  };
  // Amplitudes r_s, r_p of interfaces m → m + 1 (m = 0 … F) and q of every medium at node k.
  const interfaces = (k, c, declare) => {
    const n0 = index(k, 0).x.toVar();
    const q = [vec2(n0.mul(c), 0.0)];
    const rs = [];
    const rp = [];
    let prev = vec2(n0, 0.0);
    for (let m = 1; m < media; m++) {
      const n = index(k, m).toVar();
      q.push(normalComponentCos(n, n0, c).toVar());
      rs.push(declare(cdiv(q[m - 1].sub(q[m]), q[m - 1].add(q[m]))));
      const a = cmul(cmul(n, n), q[m - 1]).toVar();
      const b = cmul(cmul(prev, prev), q[m]).toVar();
      rp.push(declare(cdiv(a.sub(b), a.add(b))));
      prev = n;
    }
    return { q, rs, rp };
  };
  return Fn(([cosTheta, thicknessNm]) => {
    const c = max(clamp(cosTheta, 0.0, 1.0), COS_THETA_MIN).toVar();
    const d1 = clamp(thicknessNm, 0.0, THICKNESS_MAX_NM).toVar();
    const span = range.y.sub(range.x);
    const g = select(span.greaterThan(0.0), clamp(d1.sub(range.x).div(max(span, 1e-30)), 0.0, 1.0), float(1.0));
    const s = g.mul(2.0).sub(1.0).toVar();
    const thickness = p.layers.slice(0, films).map((layer, j) =>
      j === 0 ? d1 : clamp(s.mul(layer[1]).add(layer[0]), 0.0, THICKNESS_MAX_NM).toVar());
    const opd = thickness.reduce((sum, d, j) => sum.add(d.mul(p.layers[j][2])), float(0.0)).mul(p.finesse);
    // The rule: the first whose node count reaches ⌈base + slope · OPD⌉, else the last.
    let first = int(p.ruleOffset[p.ruleCount - 1]);
    let count = int(p.ruleSize[p.ruleCount - 1]);
    if (p.fixedRule === 1) {
      first = int(p.ruleOffset[0]);
      count = int(p.ruleSize[0]);
    } else {
      const needed = ceil(opd.mul(p.countPerOpdNm).add(p.baseCount)).toVar();
      for (let i = p.ruleCount - 2; i >= 0; i--) {
        const fits = float(p.ruleSize[i]).greaterThanEqual(needed);
        first = select(fits, int(p.ruleOffset[i]), first);
        count = select(fits, int(p.ruleSize[i]), count);
      }
    }
    const start = first.toVar();
    const end = start.add(count).toVar();
    const colour = vec3(0.0).toVar();
    // Without dispersion the indices, q and interfaces are the same at every node.
    const fixed = p.dispersive === 0 ? interfaces(start, c, (v) => v.toVar()) : null;
    Loop({ start, end, type: 'int', condition: '<' }, ({ i }) => {
      const node = textureLoad(tex, ivec2(int(0), i)).toVar();
      const lambda = max(node.x, 1e-3);
      const { q, rs, rp } = fixed ?? interfaces(i, c, (v) => v.toVar());
      const gammaS = rs[films].toVar();
      const gammaP = rp[films].toVar();
      for (let m = films - 1; m >= 0; m--) {
        const qf = q[m + 1];
        const x = thickness[m].div(lambda).toVar();
        const e1 = expICycles(x.mul(qf.x)).mul(exp(x.mul(qf.y).mul(-TWO_PI))).toVar();
        const e2 = cmul(e1, e1).toVar();
        const gs = cmul(gammaS, e2).toVar();
        const gp = cmul(gammaP, e2).toVar();
        gammaS.assign(cdiv(rs[m].add(gs), vec2(1.0, 0.0).add(cmul(rs[m], gs))));
        gammaP.assign(cdiv(rp[m].add(gp), vec2(1.0, 0.0).add(cmul(rp[m], gp))));
      }
      const reflectance = clamp(dot(gammaS, gammaS), 0.0, 1.0).add(clamp(dot(gammaP, gammaP), 0.0, 1.0)).mul(0.5);
      colour.addAssign(node.yzw.mul(reflectance));
    });
    return colour;
  });
}

// A serial number per table object: the film's code holds the table's axes as constants, so
// materials over different tables must not share a compiled program (three keys node
// programs by the material's type and its node-valued properties only).
const tableSerials = new WeakMap();
let nextTableSerial = 1;
function tableSerial(table) {
  if (!tableSerials.has(table)) tableSerials.set(table, nextTableSerial++);
  return tableSerials.get(table);
}

/** nacre's state on a MeshPhysicalNodeMaterial: the table, its uniforms, the film function. */
class NacreNodeState {
  constructor(table, { harmonics = 0, debugView = NacreDebugView.NONE } = {}) {
    this.harmonicsUniform = uniform(harmonics);
    this.debugViewUniform = uniform(debugView).setGroup(TSL.renderGroup);
    // The material's film thickness range [min, max] nm (the stack's lower films follow it).
    this.thicknessRangeUniform = uniform(new Vector2()).onObjectUpdate(({ material }, self) => {
      const [lo, hi] = material.filmThicknessRangeNm;
      self.value.set(lo, hi);
    });
    this.setTable(table);
  }

  setTable(table) {
    if (!table || !['film-lut', 'fourier', 'film-stack'].includes(table.kind)) {
      throw new Error('@nacre/three/webgpu: a NacreFilmNodeMaterial needs a film-lut or fourier table (loadNacreTable) or a stack (loadNacreStack)');
    }
    this.table = table;
    const evaluate = table.kind === 'film-lut'
      ? lutFilm(table)
      : table.kind === 'fourier' ? fourierFilm(table, this.harmonicsUniform) : stackFilm(table, this.thicknessRangeUniform);
    const unit = this.debugViewUniform.equal(NacreDebugView.UNIT_FILM);
    // R_f(n·v) for a base of normal-incidence reflectance baseF0 (a film-lut's base is the
    // one it baked: baseF0 is not used).
    // mix, not select: TSL lowers a select to if/else, and a property node first built inside
    // one branch (three's positionViewDirection, normalView) is left unset in the other.
    this.film = (cosTheta, baseF0) => mix(evaluate(cosTheta, iridescenceThickness, iridescenceIOR, baseF0), vec3(1.0), float(unit));
  }
}

/**
 * three's lighting model with nacre's film: `start()` replaces the film Fresnel every direct
 * light reads, `computeMultiscattering()` the image-based light's split sum.
 */
class NacreLightingModel extends PhysicalLightingModel {
  // three's start() sets iridescenceFresnel and then (r175+) runs the lights itself, so the
  // film every direct light reads is served by this accessor rather than assigned after it.
  get iridescenceFresnel() {
    return this.nacreFresnel ?? this.threeIridescenceFresnel ?? null;
  }

  set iridescenceFresnel(value) {
    this.threeIridescenceFresnel = value;
  }

  start(...args) {
    if (this.iridescence && this.nacreFresnel) {
      // nacre's films, before three's start(), which lights and reads them.
      const state = this.nacre;
      // n·v first, at the top of the shader: three's view-direction and normal properties
      // are then set before any branch of the film's code reads them.
      this.nacreDotNV.assign(normalView.dot(positionViewDirection).clamp());
      this.nacreFilmDielectric.assign(state.film(this.nacreDotNV, specularColor));
      if (this.nacreFilmMetal && state.table.kind === 'film-stack') {
        // The stack has its own base: the metal's film is the same.
        this.nacreFilmMetal.assign(this.nacreFilmDielectric);
      } else if (this.nacreFilmMetal) {
        If(metalness.greaterThan(0.0), () => {
          this.nacreFilmMetal.assign(state.film(this.nacreDotNV, diffuseColor.rgb));
        });
      }
    }
    super.start(...args);
  }

  computeMultiscattering(singleScatter, multiScatter, specularF90Node, f0 = specularColor, ...rest) {
    if (!this.iridescence || !this.nacreFresnel) {
      return super.computeMultiscattering(singleScatter, multiScatter, specularF90Node, f0, ...rest);
    }
    const dotNV = this.nacreDotNV;
    const fab = this.dfg ?? TSL.DFGApprox({ roughness, dotNV });
    const film = f0 === specularColor || !this.nacreFilmMetal ? this.nacreFilmDielectric : this.nacreFilmMetal;
    const ess = fab.x.add(fab.y);
    const ems = ess.oneMinus();
    const fssEss = f0.mul(fab.x).add(specularF90Node.mul(fab.y));
    const fAvg = f0.add(f0.oneMinus().mul(0.047619)); // 1/21
    const fms = fssEss.mul(fAvg).div(ems.mul(fAvg).oneMinus());
    singleScatter.addAssign(mix(fssEss, film.mul(ess), iridescence));
    multiScatter.addAssign(mix(fms, film, iridescence).mul(ems));
  }
}

/**
 * three's lighting model `model` (every field as three's material set it) as a
 * NacreLightingModel, with the film variables it assigns in start(): the film over the
 * dielectric F0 and (r181+) over the metal's, and the film every direct light reads.
 */
function nacreLightingModel(model, state) {
  const nacre = Object.assign(Object.create(NacreLightingModel.prototype), model);
  delete nacre.iridescenceFresnel; // the prototype's accessor serves it
  nacre.nacre = state;
  if (nacre.iridescence) {
    nacre.nacreDotNV = float().toVar('nacreDotNV');
    nacre.nacreFilmDielectric = vec3().toVar('nacreFilmDielectric');
    if (filmPerBase) {
      nacre.nacreFilmMetal = vec3().toVar('nacreFilmMetal');
      nacre.nacreFresnel = mix(nacre.nacreFilmDielectric, nacre.nacreFilmMetal, metalness);
    } else {
      nacre.nacreFresnel = nacre.nacreFilmDielectric;
    }
  }
  return nacre;
}

/**
 * MeshPhysicalNodeMaterial (three/webgpu) with nacre's thin film in place of three's
 * iridescence, for every light. Parameters: every MeshPhysicalNodeMaterial parameter plus
 * `table` (loadNacreTable / loadNacreRawTable) or `stack` (loadNacreStack), `harmonics`
 * (fourier: 0 = automatic), `filmThicknessRangeNm` ([min, max] of the thickness map),
 * `debugView` (NacreDebugView), `filmThicknessNm` (three's film thickness range = [d, d]) and
 * `filmIor` (= iridescenceIOR). `iridescence` defaults to 1.
 */
export class NacreFilmNodeMaterial extends MeshPhysicalNodeMaterial {
  static get type() {
    return 'NacreFilmNodeMaterial';
  }

  constructor(parameters = {}) {
    const { table: tableParameter, stack, harmonics, debugView, filmThicknessNm, filmThicknessRangeNm, filmIor, ...physical } = parameters;
    if (tableParameter !== undefined && stack !== undefined) {
      throw new Error('@nacre/three/webgpu: give a NacreFilmNodeMaterial `table` or `stack`, not both');
    }
    if (stack !== undefined && stack?.kind !== 'film-stack') {
      throw new Error('@nacre/three/webgpu: `stack` must be a NacreStack (loadNacreStack)');
    }
    const table = stack ?? tableParameter;
    super();
    checkThreeNodeHooks();
    this.isNacreFilmNodeMaterial = true;
    this.nacre = table === undefined ? null : new NacreNodeState(table, { harmonics, debugView });
    this.setValues({ iridescence: 1, ...physical });
    if (filmThicknessRangeNm !== undefined) this.filmThicknessRangeNm = filmThicknessRangeNm;
    if (filmThicknessNm !== undefined) this.filmThicknessNm = filmThicknessNm;
    if (filmIor !== undefined) this.filmIor = filmIor;
  }

  /**
   * The film thickness in nm (without a thickness map: three's maximum thickness;
   * iridescenceThicknessMinimum/Maximum from r187, iridescenceThicknessRange before).
   */
  get filmThicknessNm() {
    return thicknessRange(this)[1];
  }

  set filmThicknessNm(d) {
    setThicknessRange(this, [d, d]);
  }

  /** [min, max] nm spanned by the thickness map (three's range, or r187's minimum/maximum). */
  get filmThicknessRangeNm() {
    return thicknessRange(this);
  }

  set filmThicknessRangeNm(range) {
    setThicknessRange(this, range);
  }

  /** The multilayer stack (a NacreStack), or null when the material samples a table. */
  get stack() {
    return this.nacre?.table.kind === 'film-stack' ? this.nacre.table : null;
  }

  set stack(stack) {
    if (stack?.kind !== 'film-stack') throw new Error('@nacre/three/webgpu: `stack` must be a NacreStack (loadNacreStack)');
    this.table = stack;
  }

  /** The film's refractive index (three's iridescenceIOR). */
  get filmIor() {
    return this.iridescenceIOR;
  }

  set filmIor(n) {
    this.iridescenceIOR = n;
  }

  /** The table sampled; a new table rebuilds the material's shader. */
  get table() {
    return this.nacre.table;
  }

  set table(table) {
    this.nacre.setTable(table);
    this.needsUpdate = true;
  }

  // harmonics and debugView are uniforms; their setters also mark the material for update,
  // since three's WebGPU renderer uploads a material's uniforms again only when one of the
  // material properties it watches (or the material's version) changed. The shader code
  // stays the same, so three's pipeline cache answers the rebuild.

  /** Fourier harmonics M (0 = automatic). */
  get harmonics() {
    return this.nacre.harmonicsUniform.value;
  }

  set harmonics(m) {
    this.nacre.harmonicsUniform.value = m;
    this.needsUpdate = true;
  }

  /** NacreDebugView. */
  get debugView() {
    return this.nacre.debugViewUniform.value;
  }

  set debugView(v) {
    this.nacre.debugViewUniform.value = v;
    this.needsUpdate = true;
  }

  customProgramCacheKey() {
    const nacre = this.nacre ? `${this.nacre.table.kind}:${tableSerial(this.nacre.table)}` : 'none';
    return `${super.customProgramCacheKey()}|nacre:${nacre}`;
  }

  setupLightingModel(builder) {
    if (!this.nacre) throw new Error('@nacre/three/webgpu: NacreFilmNodeMaterial has no table');
    const model = super.setupLightingModel(builder);
    this.nacreModel = nacreLightingModel(model, this.nacre);
    return this.nacreModel;
  }

  setupOutput(builder, outputNode) {
    const out = super.setupOutput(builder, outputNode);
    const model = this.nacreModel;
    if (!model?.nacreFresnel) return out;
    // NacreDebugView.FILM: the film colour every light reads (rgb) and n·v (a).
    const film = vec4(model.nacreFresnel, model.nacreDotNV);
    // mix, not select: TSL lowers a select to if/else, which would move the lighting (where
    // the film is assigned) into the other branch.
    return mix(out, film, float(this.nacre.debugViewUniform.equal(NacreDebugView.FILM)));
  }

  copy(source) {
    super.copy(source);
    if (source.nacre) {
      this.nacre = new NacreNodeState(source.nacre.table, { harmonics: source.harmonics, debugView: source.debugView });
      }
    return this;
  }
}

// NacreFilmMaterial: three.js's MeshPhysicalMaterial with nacre's thin-film colour in place
// of three's own iridescence (Belcour & Barla 2017's analytic Airy approximation), for every
// light.
//
// How it hooks into three.js. Since r141 every iridescent MeshPhysicalMaterial computes the
// film's Fresnel term once per fragment, in `lights_fragment_begin`, as
//   material.iridescenceFresnel = evalIridescence(1.0, iridescenceIOR, dotNV, thickness, F0)
// (r187: once for the dielectric F0 and once for the metal's, mixed by metalness), and every
// light reads it from there: direct lights in BRDF_GGX (F = mix(F_Schlick, iridescenceFresnel,
// iridescence)), image-based light through computeMultiscatteringIridescence (three's split
// sum of the same term). So the material does not replace any chunk: it defines
// `evalIridescence(...)` as a function-like macro right before `#include
// <lights_fragment_begin>` — after three's own function is defined, before its one caller —
// that evaluates nacre's lookup instead. Everything else (textures, the thickness and
// iridescence maps, shadows, clearcoat, sheen, transmission, tone mapping, colour
// management) stays three's. The material checks that three's chunks still have that shape
// (`checkThreeHooks`) and throws, naming the release, when they do not.
//
// Film parameters are three's own: `iridescence` (weight), `iridescenceIOR` (film index n₂),
// `iridescenceThicknessRange` / `iridescenceThicknessMap` (thickness d in nm; without a map
// d = range[1]), and the base below the film is three's F0 (from `ior`, `specularColor`,
// `specularIntensity`, `metalness`). Technique `lut` samples a baked film-lut whose stack
// (ambient | film | base) is fixed by its recipe (soap-film: air | film | air;
// film-dielectric: air | film | 1.5); technique `fourier` (Belcour & Barla 2017 Eq. 10 with
// exact Fresnel amplitudes) takes the base index from three's F0 per channel,
// n₃ = (1 + √F0)/(1 − √F0) (as three's Fresnel0ToIor), and the ambient index 1.
//
// Technique `stack` (nacre.glsl's nacre_film_stack_colour, the runtime's film_stack: the
// exact recurrence of crates/optics/src/stack.rs at the few wavelengths of the pixel's rule)
// samples a NacreStack (loadNacreStack: ambient | up to 8 films | base, from `nacre export
// --layer … --out stack.json`). The ambient, every film's material and the base are the
// stack's own: iridescenceIOR, ior, specularColor/specularIntensity and metalness do not change
// the film (they still shape three's diffuse and, for iridescence < 1, three's bare base).
// Thickness, as NacreFilmInput in the runtime (shaders/mesh.wgsl, film_stack.wgsl):
//   top film  d₁ = three's film thickness d (iridescenceThicknessRange / iridescenceThicknessMap:
//             d = mix(range[0], range[1], g) with the map's green channel g, range[1] without);
//   film j ≥ 2  d_j = max(0, d_j⁰ + r_j s), s = 2g − 1 ∈ [−1, 1], with
//             g = (d − range[0]) / (range[1] − range[0]) (g = 1 when range[0] = range[1]):
//             one map drives every film (the JSON's per-film channel is not used: three's
//             thickness map has one channel), and without a map s = 1 (d_j = d_j⁰ + r_j).
// three turns the film off where d = 0 (lights_fragment_begin), so the top film needs d > 0.
import { MeshPhysicalMaterial, REVISION, ShaderChunk, Vector2, Vector3, Vector4 } from 'three';
import { nacreGlsl } from './nacre-glsl.js';
import { setThicknessRange, thicknessRange } from './thickness.js';

/** Debug views: the shaded colour, the film colour (rgb) and n·v (alpha), or a unit film. */
export const NacreDebugView = Object.freeze({ NONE: 0, FILM: 1, UNIT_FILM: 2 });

/**
 * Throws when three.js's shader chunks no longer have the shape the material hooks into
 * (see the module comment); returns the three.js revision otherwise.
 */
export function checkThreeHooks() {
  const problems = [];
  if (!/evalIridescence\s*\(/.test(ShaderChunk.lights_fragment_begin ?? '')) {
    problems.push('lights_fragment_begin does not call evalIridescence');
  }
  if (!/material\.iridescenceFresnel\s*=/.test(ShaderChunk.lights_fragment_begin ?? '')) {
    problems.push('lights_fragment_begin does not set material.iridescenceFresnel');
  }
  if (!/material\.iridescenceFresnel/.test(ShaderChunk.lights_physical_pars_fragment ?? '')) {
    problems.push('lights_physical_pars_fragment does not read material.iridescenceFresnel');
  }
  if (!/vec3\s+evalIridescence\s*\(/.test(ShaderChunk.iridescence_fragment ?? '')) {
    problems.push('iridescence_fragment does not define evalIridescence');
  }
  try {
    multiscatteringHook();
  } catch (e) {
    problems.push(e.message);
  }
  if (problems.length) {
    throw new Error(`@nacre/three: three.js r${REVISION} is not supported (${problems.join('; ')}); tested with r160 and r187`);
  }
  return REVISION;
}

/**
 * The macro that sends three's image-based-light term, computeMultiscatteringIridescence,
 * to nacreMultiscatterFilm. Its parameters differ between releases (r160: normal,
 * viewDir, …, roughness, computing the DFG fit inside; r187: the DFG pair `fab`), so the
 * macro is built from the parameter names of the definition in three's chunk.
 */
function multiscatteringHook() {
  const chunk = ShaderChunk.lights_physical_pars_fragment ?? '';
  const m = /void\s+computeMultiscatteringIridescence\s*\(([^)]*)\)/.exec(chunk);
  if (!m) throw new Error('lights_physical_pars_fragment does not define computeMultiscatteringIridescence');
  const names = m[1].split(',').map((p) => p.trim().split(/\s+/).pop());
  const need = ['specularColor', 'specularF90', 'iridescence', 'singleScatter', 'multiScatter'];
  let fab;
  if (names.includes('fab')) fab = 'fab';
  else if (['normal', 'viewDir', 'roughness'].every((n) => names.includes(n))) fab = 'DFGApprox(normal, viewDir, roughness)';
  const missing = need.filter((n) => !names.includes(n));
  if (!fab || missing.length) {
    throw new Error(`computeMultiscatteringIridescence(${names.join(', ')}) lacks ${fab ? missing.join(', ') : 'fab or normal/viewDir/roughness'}`);
  }
  const macro = `#define nacreMultiscatteringIridescence(${names.join(', ')}) nacreMultiscatterFilm(${fab}, specularColor, specularF90, iridescence, singleScatter, multiScatter)`;
  const calls = chunk.replace(/(?<!void\s)\bcomputeMultiscatteringIridescence\s*\(/g, 'nacreMultiscatteringIridescence(');
  return `${macro}\n${calls}`;
}

/**
 * True when three's lights_fragment_begin evaluates the film twice, for the dielectric F0
 * (material.specularColor) and then for the metal's (material.diffuseColor) and mixes them
 * by metalness (r187): the second evaluation is skipped at metalness 0.
 */
function secondFilmIsMetal() {
  const calls = [...(ShaderChunk.lights_fragment_begin ?? '').matchAll(/evalIridescence\s*\(([^;]*)\)\s*;/g)].map((m) => m[1]);
  return calls.length === 2 && /material\.specularColor\s*$/.test(calls[0]) && /material\.diffuseColor\s*$/.test(calls[1]) &&
    /material\.iridescenceFresnel\s*=\s*mix\s*\([^;]*material\.metalness\s*\)/.test(ShaderChunk.lights_fragment_begin);
}

// nacre.glsl's e^{2πi x} (nacre_c_exp_i_cycles) takes GLSL's cos and sin of 2π fract(x).
// Vulkan lets them be off by 2⁻¹¹ (absolute, on [−π, π]) and SwiftShader — the WebGL of
// headless Chromium, and what ANGLE gives many users without a GPU — is about that far off:
// the film_stack colour of a film on silver came out 1e-3 away from the CPU's (the Airy film
// phase e^{iδ}, δ = 2π d q/λ, is in every node of the recurrence). The material swaps in the
// same function with the trigonometry done in arithmetic: x reduced to a quarter turn k/4 plus
// t ∈ [−1/8, 1/8] cycles, φ = 2πt ∈ [−π/4, π/4], the Taylor polynomials
//   cos φ = Σ_{n≤4} (−1)ⁿ φ²ⁿ/(2n)!,  sin φ = Σ_{n≤4} (−1)ⁿ φ²ⁿ⁺¹/(2n+1)!
// (truncation error ≤ φ¹⁰/10! < 3e-8 on that interval), rotated by i^k. Measured on SwiftShader:
// a film on silver per wavelength 1.0e-3 → 5.8e-7 from the f64 recurrence.
const PRECISE_EXP_I_CYCLES = /* glsl */ `vec2 nacre_c_exp_i_cycles(float x) {
    float r = fract(x);
    float k = floor(4.0 * r + 0.5);
    float phi = NACRE_TWO_PI * (r - 0.25 * k);
    float p2 = phi * phi;
    float c = 1.0 + p2 * (-0.5 + p2 * (1.0 / 24.0 + p2 * (-1.0 / 720.0 + p2 * (1.0 / 40320.0))));
    float s = phi * (1.0 + p2 * (-1.0 / 6.0 + p2 * (1.0 / 120.0 + p2 * (-1.0 / 5040.0 + p2 * (1.0 / 362880.0)))));
    int quarter = int(k) & 3;
    return quarter == 0 ? vec2(c, s) : quarter == 1 ? vec2(-s, c) : quarter == 2 ? vec2(-c, -s) : vec2(s, -c);
}`;
const EXP_I_CYCLES = /vec2 nacre_c_exp_i_cycles\(float x\) \{[^}]*\}/;

/** nacre.glsl with PRECISE_EXP_I_CYCLES in place of its nacre_c_exp_i_cycles. */
function libraryGlsl() {
  if (!EXP_I_CYCLES.test(nacreGlsl)) {
    throw new Error('@nacre/three: nacre.glsl no longer defines `vec2 nacre_c_exp_i_cycles(float x) { … }` (src/material.js replaces it)');
  }
  return nacreGlsl.replace(EXP_I_CYCLES, PRECISE_EXP_I_CYCLES);
}

const DECLARATIONS = /* glsl */ `
#ifdef NACRE_FILM_LUT
uniform highp sampler3D nacreReflectance;
uniform vec3 nacreLutCounts;
uniform vec2 nacreLutThicknessRange;
uniform vec2 nacreLutIorRange;
uniform float nacreLutAmbient;
#endif
#ifdef NACRE_FOURIER
uniform highp sampler2DArray nacreFourier;
uniform vec4 nacreFourierAxes; // D_max nm, level count, σ₁ nm, harmonics M (0 = automatic)
uniform vec3 nacreFourierCarrier;
uniform vec3 nacreFourierWhite;
#endif
#ifdef NACRE_FILM_STACK
// The stack table (6 × nodes RGBA32F) and NacreStackParams as float vectors (three's uniform
// support for uvec4 arrays varies by release; every integer here is < 2²⁴, exact in f32):
uniform highp sampler2D nacreStackTable;
uniform vec4 nacreStackCounts; // films, dispersive, rule_count, fixed_rule
uniform vec4 nacreStackRule; // base_count, count_per_opd_nm, finesse, 0
uniform vec4 nacreStackRules[8]; // [0…3]: rule_offset (rule i at [i / 4][i % 4]); [4…7]: rule_size
uniform vec4 nacreStackLayers[8]; // film j: (d_j⁰ nm, r_j nm, k_j, channel c_j)

NacreStackParams nacreStackParams() {
  NacreStackParams p;
  p.films = uint(nacreStackCounts.x + 0.5);
  p.dispersive = uint(nacreStackCounts.y + 0.5);
  p.rule_count = uint(nacreStackCounts.z + 0.5);
  p.fixed_rule = uint(nacreStackCounts.w + 0.5);
  p.base_count = nacreStackRule.x;
  p.count_per_opd_nm = nacreStackRule.y;
  p.finesse = nacreStackRule.z;
  p._pad0 = 0.0;
  for (int i = 0; i < 4; i++) {
    p.rule_offset[i] = uvec4(nacreStackRules[i] + 0.5);
    p.rule_size[i] = uvec4(nacreStackRules[i + 4] + 0.5);
  }
  for (int j = 0; j < 8; j++) {
    p.layers[j] = nacreStackLayers[j];
  }
  return p;
}
#endif

// The films evaluated for this fragment, by base F0 (three evaluates one per base: r160 the
// blended F0, r187 the dielectric and the metal's), for the image-based light below.
vec3 nacreFilmBaseF0[2];
vec3 nacreFilmValue[2];
int nacreFilmCount = 0;

vec3 nacreFilmReflectanceUncached(float ambientIor, float filmIor, float cosTheta, float thicknessNm, vec3 baseF0);

// nacre's film reflectance at cos θ₁ for a film of index n₂ and thickness d (nm) over a base
// of normal-incidence reflectance F0 in an ambient of index n₁; replaces three's
// evalIridescence(n₁, n₂, cos θ₁, d, F0).
vec3 nacreFilmReflectance(float ambientIor, float filmIor, float cosTheta, float thicknessNm, vec3 baseF0, float metalness) {
#ifdef NACRE_SECOND_FILM_IS_METAL
  // three evaluates the metal's film second and weights it by metalness: not needed at 0.
  if (nacreFilmCount == 1 && metalness == 0.0) {
    return vec3(0.0);
  }
#endif
#ifdef NACRE_FILM_STACK
  // The stack has its own base: three's second evaluation (the metal's F0) is the same film.
  if (nacreFilmCount > 0) {
    return nacreFilmValue[0];
  }
#endif
  vec3 film = nacreFilmReflectanceUncached(ambientIor, filmIor, cosTheta, thicknessNm, baseF0);
  if (nacreFilmCount == 0) {
    nacreFilmBaseF0[0] = baseF0;
    nacreFilmValue[0] = film;
    nacreFilmCount = 1;
  } else if (nacreFilmCount == 1) {
    nacreFilmBaseF0[1] = baseF0;
    nacreFilmValue[1] = film;
    nacreFilmCount = 2;
  }
  return film;
}

// The film evaluated for base F0 (the first one when none matches).
vec3 nacreFilmFor(vec3 baseF0) {
  return (nacreFilmCount > 1 && all(equal(baseF0, nacreFilmBaseF0[1]))) ? nacreFilmValue[1] : nacreFilmValue[0];
}

// Image-based light with the film (three's computeMultiscatteringIridescence, replaced):
// nacre's "film at n·v" split sum (shaders/material.wgsl, film_eval = 1),
//   single scattering  E = R_f(n·v) E₁,  E₁ = fab.x + fab.y (three's GGX albedo fit),
//   multiple scattering  R_f(n·v) (1 − E₁)  (three's energy compensation, tinted by the film),
// mixed with three's own terms for the base by the iridescence weight. A unit film gives
// E₁ + (1 − E₁) = 1: the white furnace holds.
void nacreMultiscatterFilm(vec2 fab, vec3 specularColor, float specularF90, float iridescence, inout vec3 singleScatter, inout vec3 multiScatter) {
  float ess = fab.x + fab.y;
  float ems = 1.0 - ess;
  vec3 fssEss = specularColor * fab.x + specularF90 * fab.y;
  vec3 fAvg = specularColor + (1.0 - specularColor) * 0.047619; // 1/21
  vec3 fms = fssEss * fAvg / (1.0 - ems * fAvg);
  vec3 film = nacreFilmFor(specularColor);
  singleScatter += mix(fssEss, film * ess, iridescence);
  multiScatter += mix(fms, film, iridescence) * ems;
}

vec3 nacreFilmReflectanceUncached(float ambientIor, float filmIor, float cosTheta, float thicknessNm, vec3 baseF0) {
#if NACRE_DEBUG_VIEW == 2
  return vec3(1.0);
#elif defined(NACRE_FILM_LUT)
  NacreFilmLutParams p = nacre_make_film_lut_params(uvec3(nacreLutCounts + 0.5), nacreLutThicknessRange,
      nacreLutIorRange, nacreLutAmbient, false);
  NacreFilmInput inp = nacre_make_film_input(cosTheta, thicknessNm, filmIor, 0.0, nacreLutAmbient,
      vec3(1.5), vec3(0.0));
  return nacre_film_lut_colour(nacreReflectance, nacreReflectance, p, inp).reflectance;
#elif defined(NACRE_FILM_STACK)
  // Top film d₁ = d; lower films follow s = 2g − 1, g recovered from d and three's range.
  float span = iridescenceThicknessMaximum - iridescenceThicknessMinimum;
  float g = span > 0.0 ? clamp((thicknessNm - iridescenceThicknessMinimum) / span, 0.0, 1.0) : 1.0;
  NacreFilmInput inp = nacre_make_film_input(cosTheta, thicknessNm, filmIor, 0.0, ambientIor,
      vec3(1.5), vec3(0.0));
  inp.variation = 2.0 * g - 1.0;
  inp.variation_g = inp.variation;
  inp.variation_b = inp.variation;
  return nacre_film_stack_colour(nacreStackTable, nacreStackParams(), inp).reflectance;
#else
  vec3 r = sqrt(clamp(baseF0, 0.0, 0.9999));
  vec3 baseIor = (1.0 + r) / (1.0 - r);
  NacreFourierParams p = nacre_make_fourier_params(nacreFourierAxes.x, uint(nacreFourierAxes.y + 0.5),
      nacreFourierAxes.z, nacreFourierCarrier, nacreFourierWhite, uint(nacreFourierAxes.w + 0.5));
  NacreFilmInput inp = nacre_make_film_input(cosTheta, thicknessNm, filmIor, 0.0, ambientIor,
      baseIor, vec3(0.0));
  return nacre_film_fourier_colour(nacreFourier, p, inp).reflectance;
#endif
}
`;

const HOOK = /* glsl */ `
#define evalIridescence(outsideIOR, eta2, cosTheta1, thinFilmThickness, baseF0) nacreFilmReflectance(outsideIOR, eta2, cosTheta1, thinFilmThickness, baseF0, metalnessFactor)
#include <lights_fragment_begin>
#undef evalIridescence
`;

const DEBUG_OUTPUT = /* glsl */ `
#include <dithering_fragment>
#if NACRE_DEBUG_VIEW == 1
  gl_FragColor = vec4(material.iridescence > 0.0 ? material.iridescenceFresnel : vec3(0.0), dotNVi);
#endif
`;

// The define that selects each table kind's technique.
const TECHNIQUES = Object.freeze({ 'film-lut': 'NACRE_FILM_LUT', fourier: 'NACRE_FOURIER', 'film-stack': 'NACRE_FILM_STACK' });

function replaceOnce(source, needle, replacement) {
  if (!source.includes(needle)) {
    throw new Error(`@nacre/three: the MeshPhysicalMaterial fragment shader of three.js r${REVISION} has no \`${needle}\``);
  }
  return source.replace(needle, replacement);
}

/**
 * The state nacre adds to a MeshPhysicalMaterial: uniforms (shared with every compiled
 * program of the material, so changing them needs no recompilation) and defines.
 */
class NacreFilmState {
  constructor(table, { harmonics = 0, debugView = NacreDebugView.NONE } = {}) {
    this.uniforms = {
      nacreReflectance: { value: null },
      nacreLutCounts: { value: new Vector3() },
      nacreLutThicknessRange: { value: new Vector2() },
      nacreLutIorRange: { value: new Vector2() },
      nacreLutAmbient: { value: 1 },
      nacreFourier: { value: null },
      nacreFourierAxes: { value: new Vector4() },
      nacreFourierCarrier: { value: new Vector3() },
      nacreFourierWhite: { value: new Vector3(1, 1, 1) },
      nacreStackTable: { value: null },
      nacreStackCounts: { value: new Vector4() },
      nacreStackRule: { value: new Vector4() },
      nacreStackRules: { value: Array.from({ length: 8 }, () => new Vector4()) },
      nacreStackLayers: { value: Array.from({ length: 8 }, () => new Vector4()) },
    };
    this.harmonics = harmonics;
    this.debugView = debugView;
    this.setTable(table);
  }

  setTable(table) {
    if (!table || !TECHNIQUES[table.kind]) {
      throw new Error('@nacre/three: a NacreFilmMaterial needs a film-lut or fourier table (loadNacreTable) or a stack (loadNacreStack)');
    }
    this.table = table;
    const u = this.uniforms;
    const p = table.params;
    if (table.kind === 'film-lut') {
      u.nacreReflectance.value = table.reflectance;
      u.nacreLutCounts.value.set(p.cosThetaCount, p.opdCount, p.iorCount);
      u.nacreLutThicknessRange.value.set(p.thicknessMinNm, p.thicknessMaxNm);
      u.nacreLutIorRange.value.set(p.iorMin, p.iorMax);
      u.nacreLutAmbient.value = p.ambientIndex;
    } else if (table.kind === 'fourier') {
      u.nacreFourier.value = table.texture;
      u.nacreFourierCarrier.value.fromArray(p.carrierNuPerNm);
      u.nacreFourierWhite.value.fromArray(p.white);
    } else {
      u.nacreStackTable.value = table.texture;
      u.nacreStackCounts.value.set(p.films, p.dispersive, p.ruleCount, p.fixedRule);
      u.nacreStackRule.value.set(p.baseCount, p.countPerOpdNm, p.finesse, 0);
      for (let i = 0; i < 4; i++) {
        u.nacreStackRules.value[i].fromArray(p.ruleOffset, 4 * i);
        u.nacreStackRules.value[i + 4].fromArray(p.ruleSize, 4 * i);
      }
      p.layers.forEach((layer, j) => u.nacreStackLayers.value[j].fromArray(layer));
    }
    this.updateAxes();
  }

  updateAxes() {
    if (this.table.kind === 'fourier') {
      const p = this.table.params;
      this.uniforms.nacreFourierAxes.value.set(p.maxOpdNm, p.levelCount, p.sigma1Nm, this.harmonics);
    }
  }

  defines() {
    const d = { NACRE_DEBUG_VIEW: String(this.debugView) };
    if (secondFilmIsMetal()) d.NACRE_SECOND_FILM_IS_METAL = '';
    d[TECHNIQUES[this.table.kind]] = '';
    return d;
  }

  cacheKey() {
    return `nacre:${this.table.kind}:${this.debugView}`;
  }

  patch(shader) {
    checkThreeHooks();
    Object.assign(shader.uniforms, this.uniforms);
    const defines = Object.entries(this.defines()).map(([k, v]) => `#define ${k} ${v}`).join('\n');
    let fs = shader.fragmentShader;
    // three r160 declares no precision for sampler3D / sampler2DArray; the library needs both.
    const precision = 'precision highp sampler2D;\nprecision highp sampler3D;\nprecision highp sampler2DArray;';
    fs = replaceOnce(fs, '#include <common>', `#include <common>\n${precision}\n${defines}\n${libraryGlsl()}\n${DECLARATIONS}`);
    fs = replaceOnce(fs, '#include <lights_physical_pars_fragment>', multiscatteringHook());
    fs = replaceOnce(fs, '#include <lights_fragment_begin>', HOOK);
    fs = replaceOnce(fs, '#include <dithering_fragment>', DEBUG_OUTPUT);
    shader.fragmentShader = fs;
  }
}

/**
 * Gives an existing MeshPhysicalMaterial nacre's film (what the glTF plugin does to every
 * KHR_materials_iridescence material): its iridescence parameters stay as they are, their
 * evaluation becomes nacre's. Chains any onBeforeCompile the material already has.
 * `table` is a NacreTable (loadNacreTable, loadNacreRawTable) or a NacreStack (loadNacreStack:
 * the film_stack technique; the stack brings its own ambient, films and base, and three's
 * thickness drives its top film and the relative thickness of the others).
 * @param {MeshPhysicalMaterial} material
 * @param {import('./index.js').NacreTable | import('./index.js').NacreStack} table
 * @param {{harmonics?: number, debugView?: number}} [options]
 */
export function applyNacreFilm(material, table, options = {}) {
  if (!material?.isMeshPhysicalMaterial) {
    throw new Error('@nacre/three: applyNacreFilm needs a MeshPhysicalMaterial');
  }
  checkThreeHooks();
  const state = new NacreFilmState(table, options);
  const previous = material.onBeforeCompile;
  const previousKey = material.customProgramCacheKey;
  material.onBeforeCompile = function (shader, renderer) {
    previous.call(this, shader, renderer);
    state.patch(shader);
  };
  material.customProgramCacheKey = function () {
    return `${previousKey.call(this)}|${state.cacheKey()}`;
  };
  material.userData.nacre = state;
  material.needsUpdate = true;
  return material;
}

/**
 * MeshPhysicalMaterial with nacre's thin film in place of three's iridescence, for every
 * light. Takes every MeshPhysicalMaterial parameter plus `table` (from loadNacreTable or
 * loadNacreRawTable) or `stack` (from loadNacreStack: a multilayer stack, the film_stack
 * technique; see the module comment for what three's thickness means for it), `harmonics`
 * (fourier only: 0 = automatic, as `nacre color --method fourier`), `debugView`
 * (NacreDebugView), and the shorthands `filmThicknessNm` (sets the thickness range to [d, d];
 * the top film's thickness for a stack), `filmThicknessRangeNm` ([min, max], what the
 * thickness map spans, on every three release) and `filmIor` (= iridescenceIOR; not used by
 * a stack). `iridescence` defaults to 1.
 */
export class NacreFilmMaterial extends MeshPhysicalMaterial {
  constructor(parameters = {}) {
    const { table: tableParameter, stack, harmonics, debugView, filmThicknessNm, filmThicknessRangeNm, filmIor, ...physical } = parameters;
    if (tableParameter !== undefined && stack !== undefined) {
      throw new Error('@nacre/three: give a NacreFilmMaterial `table` or `stack`, not both');
    }
    if (stack !== undefined && stack?.kind !== 'film-stack') {
      throw new Error('@nacre/three: `stack` must be a NacreStack (loadNacreStack)');
    }
    const table = stack ?? tableParameter;
    super({ iridescence: 1, ...physical });
    this.isNacreFilmMaterial = true;
    checkThreeHooks();
    // `clone()` constructs without parameters and then copies: the state comes with copy().
    this.nacre = table === undefined ? null : new NacreFilmState(table, { harmonics, debugView });
    if (filmThicknessRangeNm !== undefined) this.filmThicknessRangeNm = filmThicknessRangeNm;
    if (filmThicknessNm !== undefined) this.filmThicknessNm = filmThicknessNm;
    if (filmIor !== undefined) this.filmIor = filmIor;
  }

  /** The film thickness in nm (without a thickness map: the range's maximum). */
  get filmThicknessNm() {
    return this.filmThicknessRangeNm[1];
  }

  set filmThicknessNm(d) {
    this.filmThicknessRangeNm = [d, d];
  }

  /**
   * The film thickness range [min, max] in nm that the thickness map's green channel spans:
   * three's iridescenceThicknessRange before r187, iridescenceThicknessMinimum and
   * iridescenceThicknessMaximum since (r187 deprecates the range, with a warning).
   */
  get filmThicknessRangeNm() {
    return thicknessRange(this);
  }

  set filmThicknessRangeNm(range) {
    setThicknessRange(this, range);
  }

  /** The film's refractive index (three's iridescenceIOR). */
  get filmIor() {
    return this.iridescenceIOR;
  }

  set filmIor(n) {
    this.iridescenceIOR = n;
  }

  /** The table sampled (a film-lut or fourier NacreTable, or a NacreStack); switching kinds recompiles. */
  get table() {
    return this.nacre.table;
  }

  set table(table) {
    const kind = this.nacre.table.kind;
    this.nacre.setTable(table);
    if (table.kind !== kind) this.needsUpdate = true;
  }

  /** The multilayer stack (a NacreStack), or null when the material samples a table. */
  get stack() {
    return this.nacre?.table.kind === 'film-stack' ? this.nacre.table : null;
  }

  set stack(stack) {
    if (stack?.kind !== 'film-stack') throw new Error('@nacre/three: `stack` must be a NacreStack (loadNacreStack)');
    this.table = stack;
  }

  /** Harmonics M of the fourier technique (0 = automatic). */
  get harmonics() {
    return this.nacre.harmonics;
  }

  set harmonics(m) {
    this.nacre.harmonics = m;
    this.nacre.updateAxes();
  }

  get debugView() {
    return this.nacre.debugView;
  }

  set debugView(v) {
    if (v !== this.nacre.debugView) {
      this.nacre.debugView = v;
      this.needsUpdate = true;
    }
  }

  onBeforeCompile(shader) {
    if (!this.nacre) throw new Error('@nacre/three: NacreFilmMaterial has no table');
    this.nacre.patch(shader);
  }

  customProgramCacheKey() {
    return this.nacre ? this.nacre.cacheKey() : 'nacre:none';
  }

  copy(source) {
    super.copy(source);
    if (source.nacre) {
      this.nacre = new NacreFilmState(source.nacre.table, { harmonics: source.nacre.harmonics, debugView: source.nacre.debugView });
    }
    return this;
  }
}

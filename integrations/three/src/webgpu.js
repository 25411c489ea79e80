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
// Tested with three.js r187 and r171 (the first release with the `three/tsl` entry), on the
// WebGPU backend (Chromium's WebGPU on SwiftShader).
import { MeshPhysicalNodeMaterial, PhysicalLightingModel, REVISION } from 'three/webgpu';
import * as TSL from 'three/tsl';
import { DataTexture, FloatType, NearestFilter, ClampToEdgeWrapping, NoColorSpace, RGBAFormat } from 'three/webgpu';

const {
  Fn, If, Loop, Break, float, int, vec3, vec4, ivec2, uniform, texture3D, textureLoad, select,
  mix, clamp, max, min, sqrt, floor, fract, cos, sin, abs, pow, smoothstep,
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
    this.setTable(table);
  }

  setTable(table) {
    if (!table || (table.kind !== 'film-lut' && table.kind !== 'fourier')) {
      throw new Error('@nacre/three/webgpu: a NacreFilmNodeMaterial needs a film-lut or fourier table (loadNacreTable)');
    }
    this.table = table;
    const evaluate = table.kind === 'film-lut' ? lutFilm(table) : fourierFilm(table, this.harmonicsUniform);
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
      if (this.nacreFilmMetal) {
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
 * `table` (loadNacreTable / loadNacreRawTable), `harmonics` (fourier: 0 = automatic),
 * `debugView` (NacreDebugView), `filmThicknessNm` (three's film thickness range = [d, d]) and
 * `filmIor` (= iridescenceIOR). `iridescence` defaults to 1.
 */
export class NacreFilmNodeMaterial extends MeshPhysicalNodeMaterial {
  static get type() {
    return 'NacreFilmNodeMaterial';
  }

  constructor(parameters = {}) {
    const { table, harmonics, debugView, filmThicknessNm, filmIor, ...physical } = parameters;
    super();
    checkThreeNodeHooks();
    this.isNacreFilmNodeMaterial = true;
    this.nacre = table === undefined ? null : new NacreNodeState(table, { harmonics, debugView });
    this.setValues({ iridescence: 1, ...physical });
    if (filmThicknessNm !== undefined) this.filmThicknessNm = filmThicknessNm;
    if (filmIor !== undefined) this.filmIor = filmIor;
  }

  /**
   * The film thickness in nm (without a thickness map: three's maximum thickness;
   * iridescenceThicknessMinimum/Maximum from r187, iridescenceThicknessRange before).
   */
  get filmThicknessNm() {
    return 'iridescenceThicknessMaximum' in this ? this.iridescenceThicknessMaximum : this.iridescenceThicknessRange[1];
  }

  set filmThicknessNm(d) {
    if ('iridescenceThicknessMaximum' in this) {
      this.iridescenceThicknessMinimum = d;
      this.iridescenceThicknessMaximum = d;
    } else {
      this.iridescenceThicknessRange = [d, d];
    }
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

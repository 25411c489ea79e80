// Loaders for nacre's tables: the KTX2 files of a baked table (through its manifest, the
// `NAME.json` beside them in tables/baked/) and the raw RGBA16F exports of `nacre export`
// (through their JSON sidecar). Both give a NacreTable: a three.js texture and the axes the
// GLSL library's parameter structs need (`NacreFilmLutParams`, `NacreFourierParams`). And
// the multilayer stacks `nacre export --layer … --out stack.json` writes (`nacre-film-stack`
// v1, docs/engines/README.md): a NacreStack, the stack table as an RGBA32F DataTexture and
// the fields of nacre.glsl's NacreStackParams.
//
// KTX2 layout written by nacre (crates/format/src/ktx2.rs; README.md "Table layouts"):
// uncompressed, no supercompression, levels smallest first in the file; a film-lut quantity
// is a 3-D texture VK_FORMAT_R16G16B16A16_SFLOAT (97; R32G32B32A32_SFLOAT, 109, for a
// `precision = "float"` recipe), a fourier table a 2-D array of two layers (0: Re, 1: Im),
// height 1, VK_FORMAT_R32G32B32A32_SFLOAT, one mip level per prefilter width.
import {
  ClampToEdgeWrapping,
  Data3DTexture,
  DataArrayTexture,
  DataTexture,
  FloatType,
  HalfFloatType,
  LinearFilter,
  NearestFilter,
  NoColorSpace,
  RGBAFormat,
} from 'three';

const KTX2_IDENTIFIER = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
const VK_FORMAT_R16G16B16A16_SFLOAT = 97;
const VK_FORMAT_R32G32B32A32_SFLOAT = 109;

/** Error thrown by the loaders: names the file and what is wrong with it. */
export class NacreTableError extends Error {
  constructor(url, message) {
    super(`${url}: ${message}`);
    this.name = 'NacreTableError';
    this.url = url;
  }
}

/**
 * Parses an uncompressed KTX 2.0 file (the subset nacre writes): RGBA half or float texels,
 * any width/height/depth/layers, every mip level.
 * @returns {{vkFormat:number, width:number, height:number, depth:number, layers:number,
 *   levels:{width:number,height:number,depth:number,data:Uint16Array|Float32Array}[],
 *   keyValue:Record<string,string>}}
 */
export function parseKtx2(buffer, url = 'KTX2 file') {
  const bytes = new Uint8Array(buffer);
  if (bytes.length < 80 || KTX2_IDENTIFIER.some((b, i) => bytes[i] !== b)) {
    throw new NacreTableError(url, 'not a KTX 2.0 file (identifier missing)');
  }
  const view = new DataView(buffer);
  const u32 = (o) => view.getUint32(o, true);
  const u64 = (o) => {
    const v = view.getBigUint64(o, true);
    if (v > BigInt(Number.MAX_SAFE_INTEGER)) throw new NacreTableError(url, `offset ${v} too large`);
    return Number(v);
  };
  const vkFormat = u32(12);
  const width = u32(20);
  const height = Math.max(u32(24), 1);
  const depth = Math.max(u32(28), 1);
  const layers = Math.max(u32(32), 1);
  const faces = u32(36);
  const levelCount = Math.max(u32(40), 1);
  const supercompression = u32(44);
  if (supercompression !== 0) {
    throw new NacreTableError(url, `supercompression scheme ${supercompression}: nacre writes uncompressed KTX2 only`);
  }
  if (faces !== 1) throw new NacreTableError(url, `${faces} faces: expected 1`);
  let Array_;
  if (vkFormat === VK_FORMAT_R16G16B16A16_SFLOAT) Array_ = Uint16Array;
  else if (vkFormat === VK_FORMAT_R32G32B32A32_SFLOAT) Array_ = Float32Array;
  else throw new NacreTableError(url, `vkFormat ${vkFormat}: expected 97 (RGBA16F) or 109 (RGBA32F)`);
  const levels = [];
  for (let k = 0; k < levelCount; k++) {
    const o = 80 + 24 * k;
    const offset = u64(o);
    const length = u64(o + 8);
    const w = Math.max(width >> k, 1);
    const h = Math.max(height >> k, 1);
    const d = Math.max(depth >> k, 1);
    const expected = w * h * d * layers * 4 * Array_.BYTES_PER_ELEMENT;
    if (length !== expected || offset + length > bytes.length) {
      throw new NacreTableError(url, `level ${k}: ${length} bytes at ${offset}, expected ${expected} inside ${bytes.length}`);
    }
    // Copy: the level's offset need not be aligned to the element size.
    const data = new Array_(bytes.slice(offset, offset + length).buffer);
    levels.push({ width: w, height: h, depth: d, data });
  }
  const keyValue = {};
  const kvdOffset = u32(56);
  const kvdLength = u32(60);
  let p = kvdOffset;
  const decoder = new TextDecoder();
  while (p + 4 <= kvdOffset + kvdLength) {
    const len = u32(p);
    const entry = bytes.subarray(p + 4, p + 4 + len);
    const nul = entry.indexOf(0);
    if (nul > 0) {
      let value = entry.subarray(nul + 1);
      if (value.length && value[value.length - 1] === 0) value = value.subarray(0, value.length - 1);
      keyValue[decoder.decode(entry.subarray(0, nul))] = decoder.decode(value);
    }
    p += 4 + len + ((4 - (len % 4)) % 4);
  }
  return { vkFormat, width, height, depth, layers, levels, keyValue };
}

async function fetchOk(url, what) {
  let response;
  try {
    response = await fetch(url);
  } catch (e) {
    throw new NacreTableError(url, `cannot fetch ${what}: ${e.message}`);
  }
  if (!response.ok) throw new NacreTableError(url, `cannot fetch ${what}: HTTP ${response.status}`);
  return response;
}

function filmLutTexture(data, width, height, depth, half) {
  const tex = new Data3DTexture(data, width, height, depth);
  tex.format = RGBAFormat;
  tex.type = half ? HalfFloatType : FloatType; // the bits are already binary16 / binary32
  tex.minFilter = LinearFilter; // trilinear, no mipmaps: the lookup's texel-centre mapping
  tex.magFilter = LinearFilter;
  tex.wrapS = tex.wrapT = tex.wrapR = ClampToEdgeWrapping;
  tex.generateMipmaps = false;
  tex.unpackAlignment = 1;
  tex.colorSpace = NoColorSpace; // data, not colour-managed
  tex.needsUpdate = true;
  return tex;
}

function filmLutParams(axes, hasTransmittance) {
  const need = ['cos_theta_count', 'opd_count', 'ior_count', 'thickness_min_nm', 'thickness_max_nm', 'ior_min', 'ior_max', 'ambient_index'];
  for (const k of need) {
    if (typeof axes[k] !== 'number') throw new Error(`film-lut axes lack \`${k}\``);
  }
  return {
    cosThetaCount: axes.cos_theta_count,
    opdCount: axes.opd_count,
    iorCount: axes.ior_count,
    thicknessMinNm: axes.thickness_min_nm,
    thicknessMaxNm: axes.thickness_max_nm,
    iorMin: axes.ior_min,
    iorMax: axes.ior_max,
    ambientIndex: axes.ambient_index,
    hasTransmittance,
  };
}

/**
 * Loads a baked nacre table through its manifest (`tables/baked/NAME.json`): a `film-lut`
 * (reflectance, and transmittance when the table has it) or a `fourier` table, from the KTX2
 * files the manifest lists (paths relative to the manifest).
 * @param {string} manifestUrl
 * @returns {Promise<import('./index.js').NacreTable>}
 */
export async function loadNacreTable(manifestUrl) {
  const manifest = await (await fetchOk(manifestUrl, 'the table manifest')).json();
  const base = new URL(manifestUrl, globalThis.location?.href ?? 'file:///');
  const ktx2 = (quantity) => (manifest.files ?? []).find((f) => f.format === 'ktx2' && (quantity === undefined || f.quantity === quantity));
  const load = async (file) => {
    const url = new URL(file.path, base).href;
    const buffer = await (await fetchOk(url, `the ${file.quantity} KTX2 file`)).arrayBuffer();
    return parseKtx2(buffer, url);
  };
  if (manifest.kind === 'film-lut') {
    const rFile = ktx2('reflectance');
    if (!rFile) throw new NacreTableError(manifestUrl, 'the manifest lists no reflectance KTX2 file');
    const tFile = ktx2('transmittance');
    const r = await load(rFile);
    const t = tFile ? await load(tFile) : null;
    const make = (k) => filmLutTexture(k.levels[0].data, k.width, k.height, k.depth, k.vkFormat === VK_FORMAT_R16G16B16A16_SFLOAT);
    return {
      kind: 'film-lut',
      name: manifest.name,
      reflectance: make(r),
      transmittance: t ? make(t) : null,
      params: filmLutParams(manifest.film_lut ?? {}, Boolean(t)),
    };
  }
  if (manifest.kind === 'fourier') {
    const file = ktx2();
    if (!file) throw new NacreTableError(manifestUrl, 'the manifest lists no KTX2 file');
    const k = await load(file);
    if (k.layers !== 2 || k.height !== 1 || k.vkFormat !== VK_FORMAT_R32G32B32A32_SFLOAT) {
      throw new NacreTableError(file.path, `expected a 2-layer RGBA32F array of height 1, got ${k.layers} layers, height ${k.height}, vkFormat ${k.vkFormat}`);
    }
    const f = manifest.fourier ?? {};
    // Level 0 only: three.js uploads one level of a DataArrayTexture, so the σ_d prefilter
    // levels are not available and `levelCount` is 1 (σ_d = 0, as `nacre color --method fourier`).
    const tex = new DataArrayTexture(k.levels[0].data, k.width, 1, 2);
    tex.format = RGBAFormat;
    tex.type = FloatType;
    tex.minFilter = NearestFilter; // read with texelFetch
    tex.magFilter = NearestFilter;
    tex.wrapS = tex.wrapT = ClampToEdgeWrapping;
    tex.generateMipmaps = false;
    tex.unpackAlignment = 1;
    tex.colorSpace = NoColorSpace;
    tex.needsUpdate = true;
    return {
      kind: 'fourier',
      name: manifest.name,
      texture: tex,
      params: {
        maxOpdNm: f.max_opd_nm,
        levelCount: 1,
        sigma1Nm: 0,
        carrierNuPerNm: f.carrier_nu_per_nm,
        white: f.white,
      },
    };
  }
  throw new NacreTableError(manifestUrl, `kind \`${manifest.kind}\`: expected film-lut or fourier`);
}

/**
 * Loads one quantity of a film-lut written by `nacre export --table NAME --quantity Q
 * --out FILE.raw` (RGBA half floats, x fastest; the sidecar FILE.json beside it).
 * The table's reflectance goes in `reflectance` whatever the quantity.
 * @param {string} rawUrl
 * @returns {Promise<import('./index.js').NacreTable>}
 */
export async function loadNacreRawTable(rawUrl) {
  const sidecarUrl = rawUrl.replace(/\.raw$/, '.json');
  const sidecar = await (await fetchOk(sidecarUrl, 'the export sidecar')).json();
  if (sidecar.format !== 'rgba16f-le') throw new NacreTableError(sidecarUrl, `format \`${sidecar.format}\`: expected rgba16f-le`);
  if (sidecar.kind !== 'film-lut') throw new NacreTableError(sidecarUrl, `kind \`${sidecar.kind}\`: the three.js package samples film-lut exports`);
  const bytes = await (await fetchOk(rawUrl, 'the raw table')).arrayBuffer();
  const { width, height, depth } = sidecar;
  if (bytes.byteLength !== width * height * depth * 8) {
    throw new NacreTableError(rawUrl, `${bytes.byteLength} bytes, expected ${width}×${height}×${depth}×8`);
  }
  const p = sidecar.shader_params;
  return {
    kind: 'film-lut',
    name: sidecar.table,
    reflectance: filmLutTexture(new Uint16Array(bytes), width, height, depth, true),
    transmittance: null,
    params: filmLutParams(p, false),
  };
}

const STACK_MAX_FILMS = 8; // nacre.glsl NACRE_STACK_MAX_FILMS
const STACK_MAX_RULES = 16; // StackParams.rule_offset / rule_size: array<vec4<u32>, 4>
const STACK_TABLE_WIDTH = 6; // texel 0: (λ, W_rgb); texels 1…5: (n, κ) of two media each

/**
 * A NacreStack from the parsed `nacre-film-stack` JSON (what loadNacreStack fetches):
 * checks the schema and every field the shader reads, and uploads `texture.data` as a
 * 6 × node_count RGBA32F DataTexture (NearestFilter: read with texelFetch).
 * @param {any} json
 * @param {string} [url] named in errors
 * @returns {import('./index.js').NacreStack}
 */
export function nacreStackFromJson(json, url = 'stack JSON') {
  const bad = (message) => new NacreTableError(url, message);
  if (json?.format !== 'nacre-film-stack') throw bad(`format \`${json?.format}\`: expected nacre-film-stack (written by \`nacre export --layer …\`)`);
  if (json.version !== 1) throw bad(`version ${json.version}: this package reads nacre-film-stack version 1`);
  if (json.technique !== 'film_stack') throw bad(`technique \`${json.technique}\`: expected film_stack`);
  const p = json.shader_params ?? {};
  const int = (k, lo, hi) => {
    if (!Number.isInteger(p[k]) || p[k] < lo || p[k] > hi) throw bad(`shader_params.${k} = ${JSON.stringify(p[k])}: expected an integer in ${lo}…${hi}`);
    return p[k];
  };
  const num = (k) => {
    if (typeof p[k] !== 'number' || !Number.isFinite(p[k])) throw bad(`shader_params.${k} = ${JSON.stringify(p[k])}: expected a finite number`);
    return p[k];
  };
  const list = (k, n) => {
    if (!Array.isArray(p[k]) || p[k].length !== n) throw bad(`shader_params.${k}: expected ${n} entries`);
    return p[k];
  };
  const films = int('films', 1, STACK_MAX_FILMS);
  const ruleCount = int('rule_count', 1, STACK_MAX_RULES);
  const ruleOffset = list('rule_offset', STACK_MAX_RULES).map(Number);
  const ruleSize = list('rule_size', STACK_MAX_RULES).map(Number);
  const layers = list('layers', STACK_MAX_FILMS).map((l, j) => {
    if (!Array.isArray(l) || l.length !== 4 || !l.every((v) => typeof v === 'number' && Number.isFinite(v))) {
      throw bad(`shader_params.layers[${j}]: expected 4 finite numbers [d nm, r nm, k, channel]`);
    }
    return [...l];
  });
  const t = json.texture ?? {};
  if (t.width !== STACK_TABLE_WIDTH || t.format !== 'rgba32f' || !Number.isInteger(t.height) || t.height < 1) {
    throw bad(`texture: ${t.width} × ${t.height} ${t.format}, expected ${STACK_TABLE_WIDTH} × node_count rgba32f`);
  }
  if (!Array.isArray(t.data) || t.data.length !== t.width * t.height * 4) {
    throw bad(`texture.data: ${t.data?.length} floats, expected ${t.width} × ${t.height} × 4`);
  }
  if (json.node_count !== undefined && json.node_count !== t.height) throw bad(`node_count ${json.node_count} but texture.height ${t.height}`);
  for (let i = 0; i < ruleCount; i++) {
    if (!(Number.isInteger(ruleOffset[i]) && Number.isInteger(ruleSize[i]) && ruleSize[i] >= 1 && ruleOffset[i] + ruleSize[i] <= t.height)) {
      throw bad(`rule ${i}: nodes ${ruleOffset[i]} + ${ruleSize[i]} outside the ${t.height} of the stack table`);
    }
  }
  const texture = new DataTexture(new Float32Array(t.data), t.width, t.height, RGBAFormat, FloatType);
  texture.minFilter = NearestFilter; // read with texelFetch: no filtering, no mipmaps
  texture.magFilter = NearestFilter;
  texture.wrapS = texture.wrapT = ClampToEdgeWrapping;
  texture.generateMipmaps = false;
  texture.unpackAlignment = 1;
  texture.colorSpace = NoColorSpace;
  texture.needsUpdate = true;
  return {
    kind: 'film-stack',
    name: url.split('/').pop().replace(/\.json$/, ''),
    texture,
    nodeCount: t.height,
    about: json.about ?? null,
    params: {
      films,
      dispersive: int('dispersive', 0, 1),
      ruleCount,
      fixedRule: int('fixed_rule', 0, 1),
      baseCount: num('base_count'),
      countPerOpdNm: num('count_per_opd_nm'),
      finesse: num('finesse'),
      ruleOffset,
      ruleSize,
      layers,
    },
  };
}

/**
 * Loads a multilayer stack written by `nacre export --layer M@D … --out stack.json` (ambient |
 * up to 8 films | base; dispersive and absorbing media): the `film_stack` technique of
 * NacreFilmMaterial (`stack` option).
 * @param {string} url
 * @returns {Promise<import('./index.js').NacreStack>}
 */
export async function loadNacreStack(url) {
  const response = await fetchOk(url, 'the stack JSON');
  let json;
  try {
    json = await response.json();
  } catch (e) {
    throw new NacreTableError(url, `not JSON: ${e.message}`);
  }
  return nacreStackFromJson(json, url);
}

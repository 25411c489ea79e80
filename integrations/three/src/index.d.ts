// Types of @nacre/three (src/index.js).
import type {
  Data3DTexture,
  DataArrayTexture,
  DataTexture,
  MeshPhysicalMaterial,
  MeshPhysicalMaterialParameters,
} from 'three';

/** Axes of a film-lut table (the fields of nacre.glsl's NacreFilmLutParams). */
export interface NacreFilmLutParams {
  cosThetaCount: number;
  opdCount: number;
  iorCount: number;
  thicknessMinNm: number;
  thicknessMaxNm: number;
  iorMin: number;
  iorMax: number;
  ambientIndex: number;
  hasTransmittance: boolean;
}

/** Axes of a fourier table (the fields of nacre.glsl's NacreFourierParams but M). */
export interface NacreFourierParams {
  maxOpdNm: number;
  /** 1: three.js uploads one level of a DataArrayTexture (no σ_d prefilter). */
  levelCount: number;
  sigma1Nm: number;
  carrierNuPerNm: [number, number, number];
  white: [number, number, number];
}

export type NacreTable =
  | {
      kind: 'film-lut';
      name: string;
      reflectance: Data3DTexture;
      transmittance: Data3DTexture | null;
      params: NacreFilmLutParams;
    }
  | { kind: 'fourier'; name: string; texture: DataArrayTexture; params: NacreFourierParams };

/** The fields of nacre.glsl's NacreStackParams (the JSON's `shader_params`). */
export interface NacreStackParams {
  /** F, 1 … 8 */
  films: number;
  /** 1 when some index varies with wavelength */
  dispersive: 0 | 1;
  ruleCount: number;
  /** 1: always rule 0 (`nacre export --wavelengths N`) */
  fixedRule: 0 | 1;
  baseCount: number;
  countPerOpdNm: number;
  finesse: number;
  /** 16 values: first node of rule i */
  ruleOffset: number[];
  /** 16 values: nodes of rule i */
  ruleSize: number[];
  /** 8 × [d_j⁰ nm, r_j nm, k_j, channel c_j] */
  layers: [number, number, number, number][];
}

/** A multilayer stack from `nacre export --layer … --out stack.json` (nacre-film-stack v1). */
export interface NacreStack {
  kind: 'film-stack';
  name: string;
  /** The stack table: 6 × nodeCount RGBA32F, NearestFilter (read with texelFetch). */
  texture: DataTexture;
  nodeCount: number;
  /** The stack as given to `nacre export` (the JSON's `about`). */
  about: Record<string, unknown> | null;
  params: NacreStackParams;
}

export class NacreTableError extends Error {
  url: string;
}

export interface Ktx2Image {
  vkFormat: number;
  width: number;
  height: number;
  depth: number;
  layers: number;
  levels: { width: number; height: number; depth: number; data: Uint16Array | Float32Array }[];
  keyValue: Record<string, string>;
}

/** Parses the uncompressed KTX 2.0 files nacre writes (RGBA16F / RGBA32F). */
export function parseKtx2(buffer: ArrayBuffer, url?: string): Ktx2Image;
/** Loads a baked table (film-lut or fourier) through its manifest `NAME.json`. */
export function loadNacreTable(manifestUrl: string): Promise<NacreTable>;
/** Loads a film-lut quantity exported by `nacre export` (`FILE.raw` + `FILE.json`). */
export function loadNacreRawTable(rawUrl: string): Promise<NacreTable>;
/** Loads a multilayer stack written by `nacre export --layer … --out stack.json`. */
export function loadNacreStack(url: string): Promise<NacreStack>;
/** A NacreStack from the parsed stack JSON (checked; errors name `url`). */
export function nacreStackFromJson(json: unknown, url?: string): NacreStack;

export const NacreDebugView: Readonly<{ NONE: 0; FILM: 1; UNIT_FILM: 2 }>;
export type NacreDebugViewValue = 0 | 1 | 2;

export interface NacreFilmOptions {
  /** Fourier harmonics M; 0 (default) = automatic, as `nacre color --method fourier`. */
  harmonics?: number;
  debugView?: NacreDebugViewValue;
}

interface NacreFilmMaterialCommon extends MeshPhysicalMaterialParameters, NacreFilmOptions {
  /** Sets the thickness range to [d, d] (nm); a stack's top film. */
  filmThicknessNm?: number;
  /** [min, max] nm spanned by the thickness map (iridescenceThicknessRange, or r187's Minimum/Maximum). */
  filmThicknessRangeNm?: [number, number];
  /** The film index (three's iridescenceIOR; not used by a stack). */
  filmIor?: number;
}

export type NacreFilmMaterialParameters =
  | (NacreFilmMaterialCommon & { table: NacreTable; stack?: undefined })
  | (NacreFilmMaterialCommon & { stack: NacreStack; table?: undefined });

export class NacreFilmMaterial extends MeshPhysicalMaterial {
  constructor(parameters?: NacreFilmMaterialParameters);
  readonly isNacreFilmMaterial: true;
  table: NacreTable | NacreStack;
  /** The stack, or null when the material samples a table. */
  stack: NacreStack | null;
  filmThicknessNm: number;
  filmThicknessRangeNm: [number, number];
  filmIor: number;
  harmonics: number;
  debugView: NacreDebugViewValue;
}

/** Gives an existing MeshPhysicalMaterial nacre's film; returns it. */
export function applyNacreFilm<T extends MeshPhysicalMaterial>(material: T, table: NacreTable | NacreStack, options?: NacreFilmOptions): T;
/** Throws when three.js's chunks lack the hooks; returns three's REVISION. */
export function checkThreeHooks(): string;

export class NacreGLTFPlugin {
  constructor(parser: unknown, table: NacreTable | NacreStack, options?: NacreFilmOptions);
  readonly name: 'NACRE_film';
  materials: MeshPhysicalMaterial[];
  afterRoot(result: { scene: import('three').Group; scenes: import('three').Group[] }): Promise<void>;
}
/** The callback for `GLTFLoader.register`: every KHR_materials_iridescence material gets nacre's film. */
export function nacreGLTFPlugin(table: NacreTable | NacreStack, options?: NacreFilmOptions): (parser: unknown) => NacreGLTFPlugin;

/** nacre's GLSL library (shaders/glsl/nacre.glsl). */
export const nacreGlsl: string;

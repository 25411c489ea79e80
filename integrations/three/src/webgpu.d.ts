// Types of @nacre/three/webgpu (src/webgpu.js): NacreFilmNodeMaterial for three.js's
// WebGPURenderer (three/webgpu).
import type { MeshPhysicalNodeMaterial } from 'three/webgpu';
import type { NacreFilmOptions, NacreStack, NacreTable } from './index.js';

export const NacreDebugView: Readonly<{ NONE: 0; FILM: 1; UNIT_FILM: 2 }>;
export type NacreDebugViewValue = 0 | 1 | 2;

/** Throws, naming the release, when three's node lighting model lacks the hooks; returns three's REVISION. */
export function checkThreeNodeHooks(): string;

export interface NacreFilmNodeMaterialParameters extends NacreFilmOptions {
  /** A film-lut or fourier table; or give `stack`. */
  table?: NacreTable;
  /** A multilayer stack (loadNacreStack): the film_stack technique. */
  stack?: NacreStack;
  /** Sets three's film thickness range to [d, d] (nm); a stack's top film. */
  filmThicknessNm?: number;
  /** [min, max] nm spanned by the thickness map. */
  filmThicknessRangeNm?: [number, number];
  /** The film index (three's iridescenceIOR). */
  filmIor?: number;
  /** Any MeshPhysicalNodeMaterial parameter. */
  [parameter: string]: unknown;
}

/** MeshPhysicalNodeMaterial with nacre's film in place of three's iridescence, for every light. */
export class NacreFilmNodeMaterial extends MeshPhysicalNodeMaterial {
  constructor(parameters?: NacreFilmNodeMaterialParameters);
  readonly isNacreFilmNodeMaterial: true;
  table: NacreTable | NacreStack;
  /** The stack, or null when the material samples a table. */
  stack: NacreStack | null;
  filmThicknessNm: number;
  filmThicknessRangeNm: [number, number];
  filmIor: number;
  harmonics: number;
  debugView: NacreDebugViewValue;
}

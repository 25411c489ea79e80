// Types of @nacre/three/webgpu (src/webgpu.js): NacreFilmNodeMaterial for three.js's
// WebGPURenderer (three/webgpu).
import type { MeshPhysicalNodeMaterial } from 'three/webgpu';
import type { NacreFilmOptions, NacreTable } from './index.js';

export const NacreDebugView: Readonly<{ NONE: 0; FILM: 1; UNIT_FILM: 2 }>;
export type NacreDebugViewValue = 0 | 1 | 2;

/** Throws, naming the release, when three's node lighting model lacks the hooks; returns three's REVISION. */
export function checkThreeNodeHooks(): string;

export interface NacreFilmNodeMaterialParameters extends NacreFilmOptions {
  table: NacreTable;
  /** Sets three's film thickness range to [d, d] (nm). */
  filmThicknessNm?: number;
  /** The film index (three's iridescenceIOR). */
  filmIor?: number;
  /** Any MeshPhysicalNodeMaterial parameter. */
  [parameter: string]: unknown;
}

/** MeshPhysicalNodeMaterial with nacre's film in place of three's iridescence, for every light. */
export class NacreFilmNodeMaterial extends MeshPhysicalNodeMaterial {
  constructor(parameters?: NacreFilmNodeMaterialParameters);
  readonly isNacreFilmNodeMaterial: true;
  table: NacreTable;
  filmThicknessNm: number;
  filmIor: number;
  harmonics: number;
  debugView: NacreDebugViewValue;
}

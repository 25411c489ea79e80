// A GLTFLoader plugin that gives every KHR_materials_iridescence material nacre's film.
//
// three.js's GLTFLoader already reads KHR_materials_iridescence into MeshPhysicalMaterial's
// iridescence parameters (factor, film index, thickness range, iridescence and thickness
// textures); the plugin runs after the whole asset is parsed (`afterRoot`) and calls
// applyNacreFilm on each material whose iridescence is above 0, so the extension's
// parameters keep their meaning and only the film's evaluation becomes nacre's.
import { applyNacreFilm } from './material.js';

/**
 * @param {import('./index.js').NacreTable | import('./index.js').NacreStack} table  the table every film samples: a fourier
 *   table (any base: three's F0 of each material) or a film-lut (its baked base, e.g.
 *   film-dielectric = glTF's default base of index 1.5), or a NacreStack (loadNacreStack:
 *   every film becomes that stack, its own ambient, films and base; the extension's
 *   thickness range and texture give the top film's thickness and the others' variation,
 *   material.js)
 * @param {{harmonics?: number}} [options]
 * @returns {(parser: any) => {name: string, afterRoot: (result: any) => Promise<void>}}
 *   the callback for `gltfLoader.register(...)`
 */
export function nacreGLTFPlugin(table, options = {}) {
  return (parser) => new NacreGLTFPlugin(parser, table, options);
}

export class NacreGLTFPlugin {
  constructor(parser, table, options = {}) {
    this.name = 'NACRE_film';
    this.parser = parser;
    this.table = table;
    this.options = options;
    /** The materials given nacre's film by the last load. */
    this.materials = [];
  }

  async afterRoot(result) {
    const seen = new Set();
    for (const scene of result.scenes ?? [result.scene]) {
      scene.traverse((object) => {
        const list = Array.isArray(object.material) ? object.material : object.material ? [object.material] : [];
        for (const material of list) {
          if (seen.has(material)) continue;
          seen.add(material);
          if (material.isMeshPhysicalMaterial && material.iridescence > 0) {
            applyNacreFilm(material, this.table, this.options);
            this.materials.push(material);
          }
        }
      });
    }
  }
}

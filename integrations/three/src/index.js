// @nacre/three: nacre's thin-film colour in three.js (README.md).
export { NacreFilmMaterial, NacreDebugView, applyNacreFilm, checkThreeHooks } from './material.js';
export { loadNacreTable, loadNacreRawTable, loadNacreStack, nacreStackFromJson, parseKtx2, NacreTableError } from './tables.js';
export { nacreGLTFPlugin, NacreGLTFPlugin } from './gltf.js';
export { nacreGlsl } from './nacre-glsl.js';

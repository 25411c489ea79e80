// What the browser-side test modules share (cases.js for WebGLRenderer, cases-webgpu.js for
// WebGPURenderer): the table and stack loading, cached per page, and the film parameters of a
// case of test/expected.json.
import { loadNacreRawTable, loadNacreStack, loadNacreTable } from '@nacre/three';

const loaded = {};

/** `NAME` loads tables/baked/NAME.json (KTX2); `export:NAME.QUANTITY` the raw export and its sidecar. */
export async function table(name) {
  if (!loaded[name]) {
    loaded[name] = name.startsWith('export:')
      ? await loadNacreRawTable(`/export/${name.slice('export:'.length)}.raw`)
      : await loadNacreTable(`/tables/${name}.json`);
  }
  return loaded[name];
}

/** `NAME` loads test/export/NAME.stack.json (written by `nacre export --layer …`). */
export async function stack(name) {
  const key = `stack:${name}`;
  if (!loaded[key]) loaded[key] = await loadNacreStack(`/export/${name}.stack.json`);
  return loaded[key];
}

/**
 * The film parameters of a case (test/expected.json) for NacreFilmMaterial or
 * NacreFilmNodeMaterial: a table with the film index, thickness and three's base `ior`; or a
 * stack (`c.stack`) with the top film's thickness, either `thicknessNm` or `thicknessRangeNm`
 * and a 1×1 float thickness map of green `thicknessMapG`. `THREE` is the page's three.js
 * module (three or three/webgpu), which makes the map.
 */
export async function caseFilm(THREE, c) {
  if (!c.stack) {
    return { table: await table(c.table), ior: c.baseIor, filmIor: c.filmIor, filmThicknessNm: c.thicknessNm };
  }
  const film = { stack: await stack(c.stack) };
  if (c.thicknessRangeNm) {
    const map = new THREE.DataTexture(new Float32Array([0, c.thicknessMapG, 0, 1]), 1, 1, THREE.RGBAFormat, THREE.FloatType);
    map.minFilter = map.magFilter = THREE.NearestFilter;
    map.colorSpace = THREE.NoColorSpace;
    map.needsUpdate = true;
    film.filmThicknessRangeNm = [...c.thicknessRangeNm];
    film.iridescenceThicknessMap = map;
  } else {
    film.filmThicknessNm = c.thicknessNm;
  }
  return film;
}

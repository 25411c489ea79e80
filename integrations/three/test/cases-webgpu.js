// Browser side of the WebGPURenderer tests (loaded into /page/THREE.html by run.mjs):
// renders NacreFilmNodeMaterial with three/webgpu's WebGPURenderer on the WebGPU backend
// into float render targets and reads the floats back; the same cases as cases.js.
import * as THREE from 'three/webgpu';
import { NacreDebugView, NacreFilmNodeMaterial } from '@nacre/three/webgpu';
import { caseFilm, stack, table } from './common.js';
// The package's own helper (src/thickness.js, served under /pkg/): not a public export.
import { setThicknessRange } from '/pkg/thickness.js';

/** A WebGPURenderer on the WebGPU backend (never the WebGL 2 fallback), initialised. */
async function makeRenderer(width, height) {
  if (!navigator.gpu) throw new Error('navigator.gpu is missing: no WebGPU in this browser');
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) throw new Error('navigator.gpu.requestAdapter() gave no adapter');
  const canvas = document.createElement('canvas');
  canvas.width = width;
  canvas.height = height;
  document.body.appendChild(canvas);
  const renderer = new THREE.WebGPURenderer({ canvas, antialias: false, forceWebGL: false });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, false);
  await renderer.init();
  if (!renderer.backend.isWebGPUBackend) throw new Error('WebGPURenderer fell back to WebGL 2');
  const info = adapter.info ?? {};
  return { renderer, adapter: `${info.vendor ?? ''} ${info.architecture ?? ''} ${info.description ?? ''}`.trim() };
}

/** Sets three's film thickness range to [d, d] (r187: minimum/maximum; before: the range). */
function withThickness(material, d) {
  setThicknessRange(material, [d, d]);
  return material;
}

/** A uniform white environment (radiance 1 in every direction), prefiltered by three. */
async function whiteEnvironment(renderer) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(1, 1, 1);
  const pmrem = new THREE.PMREMGenerator(renderer);
  const target = pmrem.fromScene(scene);
  return target.texture;
}

/**
 * The film cases of cases.js's filmCases, on WebGPU: for each case and angle a plane whose
 * normal makes θ with the view direction (orthographic camera: n·v = cos θ on every pixel)
 * drawn into a 1×1 RGBA32F target — the debug view FILM (film colour, n·v) and, for each
 * light (environment, directional, point), the shaded colour with the film and with a unit
 * film, whose ratio is what the film does to that light.
 */
export async function filmCases(cases) {
  const { renderer, adapter } = await makeRenderer(1, 1);
  const target = new THREE.RenderTarget(1, 1, { type: THREE.FloatType, depthBuffer: true });
  const camera = new THREE.OrthographicCamera(-2, 2, 2, -2, 0.1, 100);
  camera.position.set(0, 0, 10);
  camera.lookAt(0, 0, 0);
  const geometry = new THREE.PlaneGeometry(20, 20);
  const environment = await whiteEnvironment(renderer);
  const read = async (scene) => {
    renderer.setRenderTarget(target);
    renderer.render(scene, camera);
    const pixel = await renderer.readRenderTargetPixelsAsync(target, 0, 0, 1, 1);
    renderer.setRenderTarget(null);
    return Array.from(pixel.slice(0, 4));
  };
  const out = [];
  for (const c of cases) {
    const nacre = new NacreFilmNodeMaterial({ ...(await caseFilm(THREE, c)), harmonics: c.harmonics ?? 0, color: 0x000000, metalness: 0, roughness: 0.3 });
    const mesh = new THREE.Mesh(geometry, nacre);
    const scenes = {};
    scenes.environment = new THREE.Scene();
    scenes.environment.environment = environment;
    scenes.directional = new THREE.Scene();
    const sun = new THREE.DirectionalLight(0xffffff, 1);
    scenes.directional.add(sun, sun.target);
    scenes.point = new THREE.Scene();
    const bulb = new THREE.PointLight(0xffffff, 100, 0, 2);
    scenes.point.add(bulb);
    const result = { ...c, angles: c.anglesDeg.map((deg) => ({ deg })) };
    // One debug view at a time over every angle and light: a view change rebuilds the
    // material's nodes (see NacreFilmNodeMaterial's debugView), so it happens 3 times per case.
    const pose = (deg) => {
      const theta = (deg * Math.PI) / 180;
      mesh.rotation.set(0, theta, 0);
      mesh.updateMatrixWorld();
      // The mirror direction of the view (0, 0, 1) about the normal: the highlight's peak.
      const n = new THREE.Vector3(Math.sin(theta), 0, Math.cos(theta));
      const mirror = n.clone().multiplyScalar(2 * n.z).sub(new THREE.Vector3(0, 0, 1));
      sun.position.copy(mirror);
      bulb.position.copy(mirror).multiplyScalar(5);
    };
    nacre.debugView = NacreDebugView.FILM;
    scenes.environment.add(mesh);
    for (const row of result.angles) {
      pose(row.deg);
      row.film = await read(scenes.environment);
    }
    for (const [view, key] of [[NacreDebugView.NONE, 'lit'], [NacreDebugView.UNIT_FILM, 'unit']]) {
      nacre.debugView = view;
      for (const light of ['environment', 'directional', 'point']) {
        scenes[light].add(mesh);
        for (const row of result.angles) {
          pose(row.deg);
          row[light] = { ...row[light], [key]: await read(scenes[light]) };
        }
      }
    }
    nacre.dispose();
    out.push(result);
  }
  renderer.dispose();
  return { info: { revision: THREE.REVISION, renderer: `WebGPU: ${adapter}`, version: 'WebGPU' }, cases: out };
}

/**
 * Frame time of a sphere filling a size × size view with NacreFilmNodeMaterial (film-dielectric
 * lut, and fourier) against the same sphere with a plain MeshPhysicalNodeMaterial (no film) and
 * with three's own iridescence, same lights (environment + directional), same run, interleaved
 * rounds; each frame waits for the GPU (a 1-pixel readback).
 */
export async function frameTime(size, frames, rounds, only = null) {
  const { renderer } = await makeRenderer(size, size);
  const target = new THREE.RenderTarget(size, size, { type: THREE.HalfFloatType, depthBuffer: true });
  const scene = new THREE.Scene();
  scene.environment = await whiteEnvironment(renderer);
  const sun = new THREE.DirectionalLight(0xffffff, 2);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 10);
  camera.position.set(0, 0, 2.9);
  const geometry = new THREE.SphereGeometry(1, 64, 32);
  const common = { color: 0x202020, roughness: 0.3 };
  const materials = {
    plain: new THREE.MeshPhysicalNodeMaterial(common),
    threeIridescence: withThickness(new THREE.MeshPhysicalNodeMaterial({ ...common, iridescence: 1, iridescenceIOR: 1.33 }), 400),
    nacreLut: new NacreFilmNodeMaterial({ ...common, table: await table('film-dielectric'), filmIor: 1.33, filmThicknessNm: 400 }),
    nacreFourier: new NacreFilmNodeMaterial({ ...common, table: await table('fourier-srgb'), filmIor: 1.33, filmThicknessNm: 400 }),
  };
  // `only` (cases.js frameTime): the materials to time; the stack only when named.
  if (only?.includes('nacreStack')) {
    materials.nacreStack = new NacreFilmNodeMaterial({ ...common, stack: await stack('five-on-si'), filmThicknessNm: 120 });
  }
  if (only) for (const name of Object.keys(materials)) if (!only.includes(name)) delete materials[name];
  const mesh = new THREE.Mesh(geometry, materials.plain);
  scene.add(mesh);
  renderer.setRenderTarget(target);
  const frame = async () => {
    renderer.render(scene, camera);
    await renderer.readRenderTargetPixelsAsync(target, 0, 0, 1, 1);
  };
  const times = Object.fromEntries(Object.keys(materials).map((k) => [k, []]));
  for (const name of Object.keys(materials)) {
    mesh.material = materials[name];
    await frame(); // compile
    await frame();
  }
  for (let r = 0; r < rounds; r++) {
    for (const name of Object.keys(materials)) {
      mesh.material = materials[name];
      const t0 = performance.now();
      for (let i = 0; i < frames; i++) await frame();
      times[name].push((performance.now() - t0) / frames);
    }
  }
  const median = (a) => [...a].sort((x, y) => x - y)[Math.floor(a.length / 2)];
  renderer.dispose();
  return Object.fromEntries(Object.entries(times).map(([k, v]) => [k, median(v)]));
}

/**
 * The control for the direct-light check on WebGPU: three's own iridescence
 * (MeshPhysicalNodeMaterial, the same film and base) lit by the directional light of
 * filmCases, over nacre's unit-film render — what the check would see if the film every
 * direct light reads were three's rather than nacre's. run.mjs checks that the direct-light
 * comparison rejects it, so that comparison can fail.
 */
export async function threeFilmDirectional(c) {
  const { renderer } = await makeRenderer(1, 1);
  const target = new THREE.RenderTarget(1, 1, { type: THREE.FloatType, depthBuffer: true });
  const camera = new THREE.OrthographicCamera(-2, 2, 2, -2, 0.1, 100);
  camera.position.set(0, 0, 10);
  camera.lookAt(0, 0, 0);
  // A stack case: three's film at the stack's top-film thickness, index 1.5 over three's
  // default base (a stack has no single film index; any three film is far from it).
  const params = { color: 0x000000, metalness: 0, roughness: 0.3, ior: c.baseIor ?? 1.5, iridescence: 1, iridescenceIOR: c.filmIor ?? 1.5 };
  const [lo, hi] = c.thicknessRangeNm ?? [c.thicknessNm, c.thicknessNm];
  const three = withThickness(new THREE.MeshPhysicalNodeMaterial(params), lo + (hi - lo) * (c.thicknessMapG ?? 1));
  const nacre = new NacreFilmNodeMaterial({ ...params, ...(await caseFilm(THREE, c)), debugView: NacreDebugView.UNIT_FILM });
  const mesh = new THREE.Mesh(new THREE.PlaneGeometry(20, 20), three);
  const scene = new THREE.Scene();
  const sun = new THREE.DirectionalLight(0xffffff, 1);
  scene.add(mesh, sun, sun.target);
  const rows = [];
  for (const deg of c.anglesDeg) {
    const theta = (deg * Math.PI) / 180;
    mesh.rotation.set(0, theta, 0);
    const n = new THREE.Vector3(Math.sin(theta), 0, Math.cos(theta));
    sun.position.copy(n.clone().multiplyScalar(2 * n.z).sub(new THREE.Vector3(0, 0, 1)));
    const row = { deg };
    for (const [key, material] of [['lit', three], ['unit', nacre]]) {
      mesh.material = material;
      renderer.setRenderTarget(target);
      renderer.render(scene, camera);
      row[key] = Array.from((await renderer.readRenderTargetPixelsAsync(target, 0, 0, 1, 1)).slice(0, 4));
    }
    renderer.setRenderTarget(null);
    rows.push(row);
  }
  renderer.dispose();
  return rows;
}

/**
 * Two NacreFilmNodeMaterials over different tables in one frame (a 2 × 1 target: the left
 * pixel `a`'s material, the right `b`'s; debug view FILM at normal incidence). Their
 * programs must differ (the film's code holds each table's axes): run.mjs compares each
 * pixel with its case's CPU colour at 0°.
 */
export async function twoTables(a, b) {
  const { renderer } = await makeRenderer(2, 1);
  const target = new THREE.RenderTarget(2, 1, { type: THREE.FloatType, depthBuffer: true });
  // Far away: r171 takes the view direction from the position even for an orthographic
  // camera, and 0.5 / 1000 off axis is n·v = 1 − 1.25×10⁻⁷.
  const camera = new THREE.OrthographicCamera(-1, 1, 0.5, -0.5, 1, 2000);
  camera.position.set(0, 0, 1000);
  camera.lookAt(0, 0, 0);
  const scene = new THREE.Scene();
  // A light: without one three runs no lighting model, and the film is not evaluated.
  const sun = new THREE.DirectionalLight(0xffffff, 1);
  scene.add(sun, sun.target);
  for (const [c, x] of [[a, -0.5], [b, 0.5]]) {
    const material = new NacreFilmNodeMaterial({
      table: await table(c.table), color: 0x000000, metalness: 0, roughness: 0.3, ior: c.baseIor,
      filmIor: c.filmIor, filmThicknessNm: c.thicknessNm, debugView: NacreDebugView.FILM,
    });
    const mesh = new THREE.Mesh(new THREE.PlaneGeometry(1, 1), material);
    mesh.position.x = x;
    scene.add(mesh);
  }
  renderer.setRenderTarget(target);
  renderer.render(scene, camera);
  const px = Array.from(await renderer.readRenderTargetPixelsAsync(target, 0, 0, 2, 1));
  renderer.dispose();
  return [px.slice(0, 4), px.slice(4, 8)];
}

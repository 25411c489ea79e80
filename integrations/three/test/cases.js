// Browser side of the tests (loaded into /page/THREE.html by run.mjs): renders
// NacreFilmMaterial into float render targets and reads the floats back.
import * as THREE from 'three';
import { NacreDebugView, NacreFilmMaterial, nacreGLTFPlugin } from '@nacre/three';
import { caseFilm, stack, table } from './common.js';

function makeRenderer(width, height) {
  const canvas = document.createElement('canvas');
  canvas.width = width;
  canvas.height = height;
  document.body.appendChild(canvas);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, false);
  return renderer;
}

/** A uniform white environment (radiance 1 in every direction), prefiltered by three. */
function whiteEnvironment(renderer) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(1, 1, 1);
  const pmrem = new THREE.PMREMGenerator(renderer);
  const target = pmrem.fromScene(scene);
  pmrem.dispose();
  return target.texture;
}

/**
 * The film cases. For each case (a table, film index and thickness, three's base `ior`) and
 * each angle θ (degrees) a plane whose normal makes θ with the view direction (orthographic
 * camera: n·v = cos θ on every pixel) is drawn into a 1×1 RGBA32F target:
 *   film: the material's debug view FILM — the film colour its lit shader computed (rgb) and
 *         three's n·v (a);
 *   for each light (environment, directional, point): the shaded colour with the film and
 *         with a unit film (debugView UNIT_FILM, the same material and light with a perfect
 *         reflector in place of the film), whose ratio is what the film does to that light.
 * Base colour black: the specular lobe alone, so the ratio of a direct light is the film.
 */
export async function filmCases(cases) {
  const renderer = makeRenderer(1, 1);
  const target = new THREE.WebGLRenderTarget(1, 1, { type: THREE.FloatType, depthBuffer: true });
  const camera = new THREE.OrthographicCamera(-2, 2, 2, -2, 0.1, 100);
  camera.position.set(0, 0, 10);
  camera.lookAt(0, 0, 0);
  const geometry = new THREE.PlaneGeometry(20, 20);
  const environment = whiteEnvironment(renderer);
  const pixel = new Float32Array(4);
  const read = (scene) => {
    renderer.setRenderTarget(target);
    renderer.render(scene, camera);
    renderer.readRenderTargetPixels(target, 0, 0, 1, 1, pixel);
    renderer.setRenderTarget(null);
    return Array.from(pixel);
  };
  const out = [];
  for (const c of cases) {
    const material = new NacreFilmMaterial({ ...(await caseFilm(THREE, c)), color: 0x000000, metalness: 0, roughness: 0.3 });
    const mesh = new THREE.Mesh(geometry, material);
    const scenes = {};
    scenes.environment = new THREE.Scene();
    scenes.environment.environment = environment;
    scenes.directional = new THREE.Scene();
    const sun = new THREE.DirectionalLight(0xffffff, 1);
    scenes.directional.add(sun, sun.target);
    scenes.point = new THREE.Scene();
    const bulb = new THREE.PointLight(0xffffff, 100, 0, 2);
    scenes.point.add(bulb);
    const result = { ...c, angles: [] };
    for (const deg of c.anglesDeg) {
      const theta = (deg * Math.PI) / 180;
      mesh.rotation.set(0, theta, 0);
      mesh.updateMatrixWorld();
      // The mirror direction of the view (0, 0, 1) about the normal (sin θ, 0, cos θ): the
      // highlight's peak.
      const n = new THREE.Vector3(Math.sin(theta), 0, Math.cos(theta));
      const mirror = n.clone().multiplyScalar(2 * n.z).sub(new THREE.Vector3(0, 0, 1));
      sun.position.copy(mirror);
      bulb.position.copy(mirror).multiplyScalar(5);
      const row = { deg };
      material.debugView = NacreDebugView.FILM;
      scenes.environment.add(mesh);
      row.film = read(scenes.environment);
      for (const light of ['environment', 'directional', 'point']) {
        scenes[light].add(mesh);
        material.debugView = NacreDebugView.NONE;
        const lit = read(scenes[light]);
        material.debugView = NacreDebugView.UNIT_FILM;
        const unit = read(scenes[light]);
        row[light] = { lit, unit };
      }
      result.angles.push(row);
    }
    material.dispose();
    out.push(result);
  }
  const gl = renderer.getContext();
  const info = { revision: THREE.REVISION, renderer: gl.getParameter(gl.RENDERER), version: gl.getParameter(gl.VERSION) };
  const ext = gl.getExtension('WEBGL_debug_renderer_info');
  if (ext) info.unmasked = gl.getParameter(ext.UNMASKED_RENDERER_WEBGL);
  renderer.dispose();
  return { info, cases: out };
}

/**
 * A glTF sample with nacre's film through the GLTFLoader plugin, lit by three's
 * RoomEnvironment, drawn into the page's canvas (run.mjs takes the screenshot).
 */
export async function gltfScene(url, size, tableName) {
  const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
  const { RoomEnvironment } = await import('three/addons/environments/RoomEnvironment.js');
  const renderer = makeRenderer(size, size);
  renderer.toneMapping = THREE.ACESFilmicToneMapping;
  const loader = new GLTFLoader();
  let plugin;
  if (tableName) {
    const register = nacreGLTFPlugin(await table(tableName));
    loader.register((parser) => (plugin = register(parser)));
  }
  const gltf = await loader.loadAsync(url);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x303030);
  const pmrem = new THREE.PMREMGenerator(renderer);
  scene.environment = pmrem.fromScene(new RoomEnvironment(), 0.04).texture;
  const sun = new THREE.DirectionalLight(0xffffff, 2);
  sun.position.set(2, 3, 4);
  scene.add(sun, gltf.scene);
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const centre = box.getCenter(new THREE.Vector3());
  const radius = box.getSize(new THREE.Vector3()).length() / 2;
  const camera = new THREE.PerspectiveCamera(40, 1, radius / 100, radius * 100);
  camera.position.copy(centre).add(new THREE.Vector3(0, radius * 0.2, radius * 2.6));
  camera.lookAt(centre);
  renderer.render(scene, camera);
  let iridescent = 0;
  gltf.scene.traverse((o) => {
    for (const m of Array.isArray(o.material) ? o.material : o.material ? [o.material] : []) {
      if (m.iridescence > 0) iridescent++;
    }
  });
  const gl = renderer.getContext();
  return {
    iridescentMaterials: iridescent,
    nacreMaterials: plugin ? plugin.materials.length : 0,
    glError: gl.getError(),
    canvasIndex: document.querySelectorAll('canvas').length - 1,
  };
}

/**
 * Frame time of a sphere filling the view with NacreFilmMaterial (film-dielectric lut,
 * fourier, and — when `only` names it — `nacreStack`, the stack of five films on silicon:
 * seconds a frame on SwiftShader, so run on its own in the --bench run) against the same sphere with a plain MeshPhysicalMaterial (no film) and with
 * three's own iridescence, same lights (environment + directional), same run,
 * interleaved rounds; each frame ends with a 1-pixel readback so that the GPU work is in it.
 */
export async function frameTime(size, frames, rounds, only = null) {
  const renderer = makeRenderer(size, size);
  const scene = new THREE.Scene();
  scene.environment = whiteEnvironment(renderer);
  const sun = new THREE.DirectionalLight(0xffffff, 2);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 10);
  camera.position.set(0, 0, 2.9);
  const geometry = new THREE.SphereGeometry(1, 64, 32);
  const materials = {
    plain: new THREE.MeshPhysicalMaterial({ color: 0x202020, roughness: 0.3 }),
    threeIridescence: new THREE.MeshPhysicalMaterial({ color: 0x202020, roughness: 0.3, iridescence: 1, iridescenceIOR: 1.33, iridescenceThicknessRange: [400, 400] }),
    nacreLut: new NacreFilmMaterial({ table: await table('film-dielectric'), color: 0x202020, roughness: 0.3, filmIor: 1.33, filmThicknessNm: 400 }),
    nacreFourier: new NacreFilmMaterial({ table: await table('fourier-srgb'), color: 0x202020, roughness: 0.3, filmIor: 1.33, filmThicknessNm: 400 }),
  };
  if (only?.includes('nacreStack')) {
    materials.nacreStack = new NacreFilmMaterial({ stack: await stack('five-on-si'), color: 0x202020, roughness: 0.3, filmThicknessNm: 120 });
  }
  if (only) for (const name of Object.keys(materials)) if (!only.includes(name)) delete materials[name];
  const mesh = new THREE.Mesh(geometry, materials.plain);
  scene.add(mesh);
  const gl = renderer.getContext();
  const px = new Uint8Array(4);
  const frame = () => {
    renderer.render(scene, camera);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  };
  const times = Object.fromEntries(Object.keys(materials).map((k) => [k, []]));
  for (const name of Object.keys(materials)) {
    mesh.material = materials[name];
    frame(); // compile
    frame();
  }
  for (let r = 0; r < rounds; r++) {
    for (const name of Object.keys(materials)) {
      mesh.material = materials[name];
      const t0 = performance.now();
      for (let i = 0; i < frames; i++) frame();
      times[name].push((performance.now() - t0) / frames);
    }
  }
  const median = (a) => [...a].sort((x, y) => x - y)[Math.floor(a.length / 2)];
  renderer.dispose();
  return Object.fromEntries(Object.entries(times).map(([k, v]) => [k, median(v)]));
}

/**
 * The control for the "film lost on direct light" check: the recipe docs/engines/threejs.md
 * gave before this package (`material.specularColor = film` after lights_physical_fragment),
 * with the same plane, light and unit-film reference as filmCases. On three.js releases whose
 * direct specular reads `specularColorBlended` (r187) its highlight is as white as the unit
 * film's; run.mjs checks that its detector sees that.
 */
export async function legacyRecipeDirectional(c) {
  const { nacreGlsl } = await import('@nacre/three');
  const t = await table(c.table);
  const p = t.params;
  const renderer = makeRenderer(1, 1);
  const target = new THREE.WebGLRenderTarget(1, 1, { type: THREE.FloatType });
  const camera = new THREE.OrthographicCamera(-2, 2, 2, -2, 0.1, 100);
  camera.position.set(0, 0, 10);
  camera.lookAt(0, 0, 0);
  const unit = { value: 0 };
  const material = new THREE.MeshPhysicalMaterial({ color: 0x000000, roughness: 0.3, metalness: 0, ior: c.baseIor });
  material.onBeforeCompile = (shader) => {
    Object.assign(shader.uniforms, {
      nacreReflectance: { value: t.reflectance },
      nacreCounts: { value: new THREE.Vector3(p.cosThetaCount, p.opdCount, p.iorCount) },
      nacreThicknessRange: { value: new THREE.Vector2(p.thicknessMinNm, p.thicknessMaxNm) },
      nacreIorRange: { value: new THREE.Vector2(p.iorMin, p.iorMax) },
      nacreAmbient: { value: p.ambientIndex },
      nacreThickness: { value: c.thicknessNm },
      nacreFilmIor: { value: c.filmIor },
      nacreUnit: unit,
    });
    shader.fragmentShader = shader.fragmentShader
      .replace('#include <common>', `#include <common>
precision highp sampler3D;
precision highp sampler2DArray;
${nacreGlsl}
uniform highp sampler3D nacreReflectance;
uniform vec3 nacreCounts;
uniform vec2 nacreThicknessRange;
uniform vec2 nacreIorRange;
uniform float nacreAmbient;
uniform float nacreThickness;
uniform float nacreFilmIor;
uniform float nacreUnit;`)
      .replace('#include <lights_physical_fragment>', `#include <lights_physical_fragment>
{
  NacreFilmLutParams nacreParams = nacre_make_film_lut_params(uvec3(nacreCounts + 0.5),
      nacreThicknessRange, nacreIorRange, nacreAmbient, false);
  float nacreCos = clamp(dot(normal, normalize(vViewPosition)), 0.0, 1.0);
  NacreFilmInput nacreIn = nacre_make_film_input(nacreCos, nacreThickness, nacreFilmIor, 0.0,
      nacreAmbient, vec3(1.5), vec3(0.0));
  NacreFilmOutput nacreOut = nacre_film_lut_colour(nacreReflectance, nacreReflectance, nacreParams, nacreIn);
  material.specularColor = nacreUnit > 0.5 ? vec3(1.0) : nacreOut.reflectance;
  material.specularF90 = 1.0;
}`);
  };
  const mesh = new THREE.Mesh(new THREE.PlaneGeometry(20, 20), material);
  const scene = new THREE.Scene();
  const sun = new THREE.DirectionalLight(0xffffff, 1);
  scene.add(mesh, sun, sun.target);
  const pixel = new Float32Array(4);
  const rows = [];
  for (const deg of c.anglesDeg) {
    const theta = (deg * Math.PI) / 180;
    mesh.rotation.set(0, theta, 0);
    const n = new THREE.Vector3(Math.sin(theta), 0, Math.cos(theta));
    sun.position.copy(n.clone().multiplyScalar(2 * n.z).sub(new THREE.Vector3(0, 0, 1)));
    const row = { deg };
    for (const [key, u] of [['lit', 0], ['unit', 1]]) {
      unit.value = u;
      renderer.setRenderTarget(target);
      renderer.render(scene, camera);
      renderer.readRenderTargetPixels(target, 0, 0, 1, 1, pixel);
      row[key] = Array.from(pixel);
    }
    renderer.setRenderTarget(null);
    rows.push(row);
  }
  renderer.dispose();
  return rows;
}

// Regenerates test/expected.json: nacre's CPU colours (`nacre color`, linear sRGB) for the
// film cases of the browser tests, one `nacre color` command per case (stored beside it); and
// the multilayer stacks the stack cases load, test/export/NAME.stack.json, each written by the
// `nacre export --layer …` command stored in expected.json's `stacks`
// (crates/cli/tests/three_fixture.rs runs both kinds of command again).
//   cargo build -p nacre-cli && node test/gen-expected.mjs            (from integrations/three)
//   NACRE_BIN=/path/to/nacre node test/gen-expected.mjs
//   node test/gen-expected.mjs --check   exit 1 when expected.json differs from what the CLI gives
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = (p) => fileURLToPath(new URL(p, import.meta.url));
const bin = process.env.NACRE_BIN ?? here('../../../target/debug/nacre');
const ANGLES = '0:80:10';

// Each case: the stack air | film n@d | base (three's `ior`), and the table the GPU samples.
const CASES = [
  { name: 'lut soap-film 1.33@400 | air', table: 'soap-film', technique: 'lut', filmIor: 1.33, thicknessNm: 400, baseIor: 1.0, method: 'lut:soap-film' },
  { name: 'lut soap-film from nacre export (raw + sidecar) 1.33@400 | air', table: 'export:soap-film.reflectance', technique: 'lut', filmIor: 1.33, thicknessNm: 400, baseIor: 1.0, method: 'lut:soap-film' },
  { name: 'lut film-dielectric 1.6@300 | 1.5', table: 'film-dielectric', technique: 'lut', filmIor: 1.6, thicknessNm: 300, baseIor: 1.5, method: 'lut:film-dielectric' },
  { name: 'fourier 1.33@400 | air', table: 'fourier-srgb', technique: 'fourier', filmIor: 1.33, thicknessNm: 400, baseIor: 1.0, method: 'fourier' },
  { name: 'fourier 1.6@300 | 1.5', table: 'fourier-srgb', technique: 'fourier', filmIor: 1.6, thicknessNm: 300, baseIor: 1.5, method: 'fourier' },
  { name: 'fourier 2.2@700 | 1.5', table: 'fourier-srgb', technique: 'fourier', filmIor: 2.2, thicknessNm: 700, baseIor: 1.5, method: 'fourier' },
];

// The multilayer stacks (film_stack): films [material, d⁰ nm, relative r nm] top first, on a
// base, in air; `nacre export` writes test/export/NAME.stack.json.
const STACKS = {
  'mgf2-tio2-ag': { films: [['mgf2', 100, 0], ['tio2', 60, 20]], base: 'ag' },
  'five-on-si': { films: [['sio2', 120, 0], ['tio2', 70, 0], ['sio2', 140, 0], ['tio2', 90, 0], ['sio2', 60, 0]], base: 'si' },
};
// Each stack case: the stack, and three's thickness: `thicknessNm` (range [d, d], no map) or
// `thicknessRangeNm` with a 1×1 thickness map of green `thicknessMapG`. The CPU stack is the
// one the material evaluates (src/material.js): top film d, film j ≥ 2 at d_j⁰ + r_j (2g − 1).
const STACK_CASES = [
  { name: 'stack MgF₂ 100 | TiO₂ 60 (+20 relative) | Ag, no map (s = 1)', stack: 'mgf2-tio2-ag', thicknessNm: 100 },
  { name: 'stack SiO₂/TiO₂ ×5 | Si', stack: 'five-on-si', thicknessNm: 120 },
  { name: 'stack MgF₂ | TiO₂ | Ag, thickness map g = 0.25 over [60, 160] nm', stack: 'mgf2-tio2-ag', thicknessRangeNm: [60, 160], thicknessMapG: 0.25 },
];

function stackCase(c) {
  const { films, base } = STACKS[c.stack];
  const [lo, hi] = c.thicknessRangeNm ?? [c.thicknessNm, c.thicknessNm];
  const g = c.thicknessMapG ?? 1;
  const d = lo + (hi - lo) * g;
  const s = hi > lo ? 2 * g - 1 : 1;
  const layers = films.flatMap(([m, d0, r], j) => ['--layer', `${m}@${j === 0 ? d : Math.max(0, d0 + r * s)}`]);
  return { ...c, technique: 'stack', args: ['color', '--ambient', '1.0', ...layers, '--substrate', base, '--angles', ANGLES, '--method', 'stack'] };
}

const out = { generated_by: 'node test/gen-expected.mjs (integrations/three) from `nacre color` and `nacre export`; do not edit', stacks: [], cases: [] };
const check = process.argv.includes('--check');
const scratch = mkdtempSync(join(tmpdir(), 'nacre-three-stacks-'));
let stale = false;
for (const [name, { films, base }] of Object.entries(STACKS)) {
  const file = `test/export/${name}.stack.json`;
  const args = ['export', '--ambient', '1.0', ...films.flatMap(([m, d0]) => ['--layer', `${m}@${d0}`]), '--substrate', base,
    ...films.flatMap(([, , r]) => ['--relative', String(r)]), '--out', file];
  const target = check ? join(scratch, `${name}.stack.json`) : here(`export/${name}.stack.json`);
  execFileSync(bin, [...args.slice(0, -1), target], { stdio: ['ignore', 'ignore', 'pipe'] });
  if (check && readFileSync(target, 'utf8') !== readFileSync(here(`export/${name}.stack.json`), 'utf8')) {
    console.error(`${file} is stale: run \`node test/gen-expected.mjs\` in integrations/three`);
    stale = true;
  }
  out.stacks.push({ name, command: `nacre ${args.join(' ')}` });
}
rmSync(scratch, { recursive: true, force: true });
const cases = [
  ...CASES.map(({ method, ...c }) => ({ ...c, args: ['color', '--ambient', '1.0', '--layer', `${c.filmIor}@${c.thicknessNm}`, '--substrate', String(c.baseIor), '--angles', ANGLES, '--method', method] })),
  ...STACK_CASES.map(stackCase),
];
for (const { args, ...c } of cases) {
  const csv = execFileSync(bin, args, { encoding: 'utf8' }).trim().split('\n');
  const header = csv[0].split(',');
  const col = (name) => header.indexOf(name);
  const rows = csv.slice(1).map((l) => l.split(',').map(Number));
  out.cases.push({
    ...c,
    command: `nacre ${args.join(' ')}`,
    anglesDeg: rows.map((r) => r[col('angle_deg')]),
    expected: rows.map((r) => [r[col('R')], r[col('G')], r[col('B')]]),
  });
}
const text = `${JSON.stringify(out, null, 1)}\n`;
const path = here('expected.json');
if (check) {
  if (readFileSync(path, 'utf8') !== text) {
    console.error('test/expected.json is stale: run `node test/gen-expected.mjs` in integrations/three');
    stale = true;
  }
  if (stale) process.exit(1);
  console.log('test/expected.json matches `nacre color`, test/export/*.stack.json `nacre export`');
} else {
  writeFileSync(path, text);
}

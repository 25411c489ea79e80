// Regenerates test/expected.json: nacre's CPU colours (`nacre color`, linear sRGB) for the
// film cases of the browser tests, one `nacre color` command per case (stored beside it).
//   cargo build -p nacre-cli && node test/gen-expected.mjs            (from integrations/three)
//   NACRE_BIN=/path/to/nacre node test/gen-expected.mjs
//   node test/gen-expected.mjs --check   exit 1 when expected.json differs from what the CLI gives
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
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

const out = { generated_by: 'node test/gen-expected.mjs (integrations/three) from `nacre color`; do not edit', cases: [] };
for (const { method, ...c } of CASES) {
  const args = ['color', '--ambient', '1.0', '--layer', `${c.filmIor}@${c.thicknessNm}`, '--substrate', String(c.baseIor), '--angles', ANGLES, '--method', method];
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
if (process.argv.includes('--check')) {
  if (readFileSync(path, 'utf8') !== text) {
    console.error('test/expected.json is stale: run `node test/gen-expected.mjs` in integrations/three');
    process.exit(1);
  }
  console.log('test/expected.json matches `nacre color`');
} else {
  writeFileSync(path, text);
}

#!/usr/bin/env node
// Writes a run folder that follows the view-folder contract (docs/viewer.md): DIR/report.json,
// DIR/view/manifest.json and DIR/view/NNN.bin, for the viewer's development and its e2e test.
// No dependencies. Usage: node e2e/make_fixture.mjs DIR
//
// Two surfaces, with positions, normals and curvatures in closed form:
// - "hood": a bumpy sheet z = a*sin(pi x/Lx)*sin(pi y/Ly) + c*x^2 over [0,Lx]x[0,Ly] (Monge patch),
//   one refitted lattice stage (amplitude 4 mm -> 18 mm), its after mesh carrying a made-up
//   deviation field, a control net and the stage's bound and target curves;
// - "dome": a spherical patch of radius 60 mm (K = 1/R^2, H = -1/R with the outward normal) and no
//   stage.
import { mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

export const HOOD = { Lx: 200, Ly: 120, c: 0.0008, before: 4, after: 18, rows: 81, cols: 49 };
export const DOME = { R: 60, center: [100, 220, -20], rows: 41, cols: 41, theta: [0.25, 1.2], phi: [-0.9, 0.9] };
export const DEVIATION_MAX = 2.5e-3; // mm

/** Monge patch z = f(x, y): position, normal (S_u x S_v with u = x, v = y), K and H. */
function mongePoint(f, x, y) {
  const { z, fx, fy, fxx, fyy, fxy } = f(x, y);
  const w2 = 1 + fx * fx + fy * fy;
  const w = Math.sqrt(w2);
  return {
    p: [x, y, z],
    n: [-fx / w, -fy / w, 1 / w],
    K: (fxx * fyy - fxy * fxy) / (w2 * w2),
    // positive when the surface bends towards its normal (the +z side here)
    H: ((1 + fx * fx) * fyy - 2 * fx * fy * fxy + (1 + fy * fy) * fxx) / (2 * w2 * w),
  };
}

export function hoodFunction(a) {
  const { Lx, Ly, c } = HOOD;
  const kx = Math.PI / Lx;
  const ky = Math.PI / Ly;
  return (x, y) => {
    const sx = Math.sin(kx * x), cx = Math.cos(kx * x), sy = Math.sin(ky * y), cy = Math.cos(ky * y);
    return {
      z: a * sx * sy + c * x * x,
      fx: a * kx * cx * sy + 2 * c * x,
      fy: a * ky * sx * cy,
      fxx: -a * kx * kx * sx * sy + 2 * c,
      fyy: -a * ky * ky * sx * sy,
      fxy: a * kx * ky * cx * cy,
    };
  };
}

/** The made-up refit deviation of the hood's after mesh (mm), largest in the middle. */
export function hoodDeviation(x, y) {
  return DEVIATION_MAX * Math.sin((Math.PI * x) / HOOD.Lx) ** 2 * Math.sin((Math.PI * y) / HOOD.Ly) ** 2;
}

/** Grid samples: vertex (i, j) at u_i (rows), v_j (columns). Returns {rows, cols, vertices}. */
function grid(rows, cols, at) {
  const vertices = [];
  for (let i = 0; i < rows; i++) for (let j = 0; j < cols; j++) vertices.push(at(i / (rows - 1), j / (cols - 1)));
  return { rows, cols, vertices };
}

export function hoodMesh(a, withDeviation) {
  const f = hoodFunction(a);
  return grid(HOOD.rows, HOOD.cols, (s, t) => {
    const x = s * HOOD.Lx, y = t * HOOD.Ly;
    return { ...mongePoint(f, x, y), d: withDeviation ? hoodDeviation(x, y) : 0 };
  });
}

export function domeMesh() {
  const { R, center, rows, cols, theta, phi } = DOME;
  return grid(rows, cols, (s, t) => {
    const th = theta[0] + s * (theta[1] - theta[0]);
    const ph = phi[0] + t * (phi[1] - phi[0]);
    const n = [Math.sin(th) * Math.cos(ph), Math.sin(th) * Math.sin(ph), Math.cos(th)]; // S_th x S_ph: outward
    return { p: n.map((c, k) => center[k] + R * c), n, K: 1 / (R * R), H: -1 / R, d: 0 };
  });
}

/** The MESH file bytes: position, normal, gaussian, mean, deviation, each for every vertex. */
export function meshBytes({ vertices }) {
  const n = vertices.length;
  const a = new Float32Array(9 * n);
  vertices.forEach((v, k) => {
    a.set(v.p, 3 * k);
    a.set(v.n, 3 * n + 3 * k);
    a[6 * n + k] = v.K;
    a[7 * n + k] = v.H;
    a[8 * n + k] = v.d;
  });
  return Buffer.from(a.buffer); // little-endian on every platform Node runs on here
}

function hoodNet(a) {
  const f = hoodFunction(a);
  const rows = 6, cols = 5, points = [];
  for (let i = 0; i < rows; i++)
    for (let j = 0; j < cols; j++) {
      const x = (HOOD.Lx * i) / (rows - 1), y = (HOOD.Ly * j) / (cols - 1);
      // control points lie off the surface, as they do: lifted by a third of the local bump
      points.push([x, y, f(x, y).z * 1.3]);
    }
  return { rows, cols, points };
}

function curve(name, at) {
  const points = [];
  for (let k = 0; k < 200; k++) points.push(at(k / 199));
  return { name, points };
}

export function makeFixture(dir) {
  const view = join(dir, 'view');
  mkdirSync(view, { recursive: true });
  const files = [];
  const add = (mesh) => {
    const file = `${String(files.length).padStart(3, '0')}.bin`;
    files.push(file);
    writeFileSync(join(view, file), meshBytes(mesh));
    return { file, rows: mesh.rows, cols: mesh.cols };
  };
  const hoodAfter = hoodMesh(HOOD.after, true);
  const hoodBefore = hoodMesh(HOOD.before, false);
  const dome = domeMesh();
  const fAfter = hoodFunction(HOOD.after);
  const figures = {
    degree_u: 3, degree_v: 3, control_points: 30, composition: 'refit', exact: false, certified: true,
    tolerance_mm: 0.02, max_deviation_mm: DEVIATION_MAX, max_deviation: DEVIATION_MAX / 233.2, size: 233.2,
  };
  const manifest = {
    format: 'clayform.view', version: 1, recipe: 'fixture', report: '../report.json',
    surfaces: [
      {
        name: 'hood', export: 'body', figures,
        mesh: add(hoodAfter), net: hoodNet(HOOD.after),
        stages: [
          {
            step: 'surfaces.hood.steps[0]', kind: 'bspline_lattice', label: "bspline_lattice 'raise'",
            before: add(hoodBefore), after: add(hoodAfter),
            net_before: hoodNet(HOOD.before), net_after: hoodNet(HOOD.after),
            curves: [
              curve('raise_bound', (t) => [HOOD.Lx * t, HOOD.Ly / 2, 0]),
              curve('raise_target', (t) => [HOOD.Lx * t, HOOD.Ly / 2, fAfter(HOOD.Lx * t, HOOD.Ly / 2).z]),
            ],
            figures,
          },
        ],
      },
      {
        name: 'dome', export: 'body',
        figures: { degree_u: 2, degree_v: 2, control_points: 9, rational: true, exact: true, max_deviation: 0 },
        mesh: add(dome), net: null, stages: [],
      },
    ],
  };
  const all = [hoodAfter, dome].flatMap((m) => m.vertices.map((v) => v.p));
  manifest.box = {
    min: [0, 1, 2].map((k) => Math.min(...all.map((p) => p[k]))),
    max: [0, 1, 2].map((k) => Math.max(...all.map((p) => p[k]))),
  };
  manifest.surfaces[1].net = {
    rows: 2, cols: 2,
    points: [dome.vertices[0], dome.vertices[DOME.cols - 1], dome.vertices[dome.vertices.length - DOME.cols], dome.vertices.at(-1)].map((v) => v.p),
  };
  writeFileSync(join(view, 'manifest.json'), JSON.stringify(manifest, null, 1));
  writeFileSync(
    join(dir, 'report.json'),
    JSON.stringify({ format: 'clayform.report', version: 1, recipe: 'fixture', clayform: 'fixture', ok: true, warnings: false, seconds: 0.01, steps: [], exports: [] }),
  );
  return manifest;
}

/**
 * A run with one flat plate z = 0 over [0, 200] x [0, 200] (K = H = 0, normal +z) and no net: on a
 * plane the reflection lines of an environment at infinity depend on the view direction only, so
 * under a pure camera translation they stay put on the screen while the plate moves.
 */
export function makePlate(dir) {
  const view = join(dir, 'view');
  mkdirSync(view, { recursive: true });
  const mesh = grid(9, 9, (s, t) => ({ p: [200 * s, 200 * t, 0], n: [0, 0, 1], K: 0, H: 0, d: 0 }));
  writeFileSync(join(view, '000.bin'), meshBytes(mesh));
  const manifest = {
    format: 'clayform.view', version: 1, recipe: 'plate', report: '../report.json',
    surfaces: [{ name: 'plate', export: 'plate', figures: {}, mesh: { file: '000.bin', rows: 9, cols: 9 }, net: null, stages: [] }],
    box: { min: [0, 0, 0], max: [200, 200, 0] },
  };
  writeFileSync(join(view, 'manifest.json'), JSON.stringify(manifest));
  writeFileSync(join(dir, 'report.json'), JSON.stringify({ format: 'clayform.report', version: 1, recipe: 'plate', ok: true, warnings: false, steps: [], exports: [] }));
  return manifest;
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const dir = process.argv[2];
  if (!dir) {
    console.error('usage: node e2e/make_fixture.mjs DIR');
    process.exit(2);
  }
  const m = makeFixture(dir);
  console.log(`wrote ${dir}/view/manifest.json (${m.surfaces.length} surfaces) and ${dir}/report.json`);
}

// Three.js geometry of the nets the kernel sends: a surface sampled on a grid (positions, normals,
// mean and Gaussian curvature from nurbs.js, the kernel's deviation map interpolated at the
// samples, each sample's (u, v) for picking), a net's control polygon, a model's mesh.
import * as THREE from 'three';
import { surfaceGrid, domain, sampleParameters } from './nurbs.js';
import { metrics } from './store.js';

/** Samples along one direction of a net: about 8 per span (more for high degrees), 33 to 129. */
export function surfaceResolution(net, direction) {
  const knots = direction === 0 ? net.knots_u : net.knots_v;
  const p = net.degrees[direction];
  const [a, b] = domain(knots, p);
  const spans = new Set(knots.filter((t) => t > a && t < b)).size + 1;
  return Math.max(33, Math.min(129, 8 * spans * Math.max(1, Math.ceil(p / 3)) + 1));
}

/**
 * The kernel's deviation map of a surface (a rows x cols grid evenly over its domain), at the
 * mesh's samples: bilinear in the samples' fractions of the domain.
 */
function fillDeviation(geometry, net, map, us, vs) {
  const out = geometry.getAttribute('deviation').array;
  const [u0, u1] = domain(net.knots_u, net.degrees[0]);
  const [v0, v1] = domain(net.knots_v, net.degrees[1]);
  const { rows, cols } = map.header;
  const at = (r, c) => map.values[r * cols + c];
  for (let r = 0; r < us.length; r++) {
    const x = ((us[r] - u0) / (u1 - u0)) * (rows - 1);
    const i = Math.min(rows - 2, Math.floor(x));
    const a = x - i;
    for (let c = 0; c < vs.length; c++) {
      const y = ((vs[c] - v0) / (v1 - v0)) * (cols - 1);
      const j = Math.min(cols - 2, Math.floor(y));
      const b = y - j;
      out[r * vs.length + c] = (1 - a) * ((1 - b) * at(i, j) + b * at(i, j + 1)) + a * ((1 - b) * at(i + 1, j) + b * at(i + 1, j + 1));
    }
  }
}

export function meshOf(net, deviation) {
  const t0 = performance.now();
  const rows = surfaceResolution(net, 0);
  const cols = surfaceResolution(net, 1);
  const g = surfaceGrid(net, rows, cols);
  metrics.evaluate.push(performance.now() - t0);
  const geometry = gridGeometry(g);
  // each sample's (u, v), so a pick on the surface knows its parameters (direct manipulation)
  const us = sampleParameters(net.knots_u, net.degrees[0], rows);
  const vs = sampleParameters(net.knots_v, net.degrees[1], cols);
  const uv = new Float64Array(2 * rows * cols);
  for (let r = 0; r < rows; r++)
    for (let c = 0; c < cols; c++) {
      uv[2 * (r * cols + c)] = us[r];
      uv[2 * (r * cols + c) + 1] = vs[c];
    }
  geometry.userData.parameters = uv;
  if (deviation) fillDeviation(geometry, net, deviation, us, vs);
  return geometry;
}

/** The (u, v) of a raycast hit on a surface mesh: its triangle's corners' parameters, blended. */
export function hitParameters(hit) {
  const uv = hit.object.geometry.userData.parameters;
  if (!uv || !hit.face) return null;
  const { a, b, c } = hit.face;
  const bary = new THREE.Triangle(
    new THREE.Vector3().fromBufferAttribute(hit.object.geometry.getAttribute('position'), a),
    new THREE.Vector3().fromBufferAttribute(hit.object.geometry.getAttribute('position'), b),
    new THREE.Vector3().fromBufferAttribute(hit.object.geometry.getAttribute('position'), c),
  ).getBarycoord(hit.point, new THREE.Vector3());
  return [0, 1].map((e) => bary.x * uv[2 * a + e] + bary.y * uv[2 * b + e] + bary.z * uv[2 * c + e]);
}

export function gridGeometry(g) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(g.position, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(g.normal, 3));
  geometry.setAttribute('mean', new THREE.BufferAttribute(g.mean, 1));
  geometry.setAttribute('gaussian', new THREE.BufferAttribute(g.gaussian, 1));
  geometry.setAttribute('deviation', new THREE.BufferAttribute(new Float32Array(g.rows * g.cols), 1));
  const index = [];
  for (let r = 0; r + 1 < g.rows; r++)
    for (let c = 0; c + 1 < g.cols; c++) {
      const k = r * g.cols + c;
      index.push(k, k + g.cols, k + 1, k + 1, k + g.cols, k + g.cols + 1);
    }
  geometry.setIndex(index);
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  geometry.userData = { rows: g.rows, cols: g.cols };
  return geometry;
}

export function netLines(net) {
  const [nu, nv] = net.counts;
  const pts = [];
  const at = (i, j) => net.points.slice(3 * (i * nv + j), 3 * (i * nv + j) + 3);
  for (let i = 0; i < nu; i++) for (let j = 0; j + 1 < nv; j++) pts.push(...at(i, j), ...at(i, j + 1));
  for (let j = 0; j < nv; j++) for (let i = 0; i + 1 < nu; i++) pts.push(...at(i, j), ...at(i + 1, j));
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xffd166, transparent: true, opacity: 0.45 }));
}

/** A whole model's trimmed faces, meshed by the kernel (no curvature: zero in those modes). */
export function modelGeometry(m) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(m.positions), 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(m.normals), 3));
  geometry.setAttribute('mean', new THREE.BufferAttribute(new Float32Array(m.positions.length / 3), 1));
  geometry.setAttribute('gaussian', new THREE.BufferAttribute(new Float32Array(m.positions.length / 3), 1));
  geometry.setAttribute('deviation', new THREE.BufferAttribute(new Float32Array(m.positions.length / 3), 1));
  geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(m.triangles), 1));
  geometry.computeBoundingSphere();
  return geometry;
}

// Reading the view folder a run writes (docs/viewer.md, "The view folder"): manifest.json and the
// MESH .bin files (little-endian float32, attribute after attribute, vertex (i, j) at i*cols + j).
import * as THREE from 'three';

/** The attributes of a MESH file, in file order, with their float count per vertex. */
export const MESH_ATTRIBUTES = [
  ['position', 3],
  ['normal', 3],
  ['gaussian', 1],
  ['mean', 1],
  ['deviation', 1],
];
const FLOATS_PER_VERTEX = MESH_ATTRIBUTES.reduce((n, [, k]) => n + k, 0); // 9

export async function fetchJson(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  return response.json();
}

/** Checks the parts of the manifest the page relies on; throws naming the first problem. */
export function checkManifest(manifest) {
  if (!manifest || manifest.format !== 'clayform.view') throw new Error('manifest: format is not "clayform.view"');
  if (manifest.version !== 1) throw new Error(`manifest: version ${manifest.version} is not 1`);
  if (!Array.isArray(manifest.surfaces)) throw new Error('manifest: no "surfaces" array');
  const checkMesh = (mesh, where) => {
    if (!mesh || typeof mesh.file !== 'string') throw new Error(`${where}: no mesh file`);
    if (!(mesh.rows >= 2 && mesh.cols >= 2)) throw new Error(`${where}: rows and cols must be at least 2`);
  };
  manifest.surfaces.forEach((s, i) => {
    const where = `surfaces[${i}]`;
    checkMesh(s.mesh, `${where}.mesh`);
    (s.stages || []).forEach((st, k) => {
      checkMesh(st.before, `${where}.stages[${k}].before`);
      checkMesh(st.after, `${where}.stages[${k}].after`);
    });
  });
  return manifest;
}

/** Splits a MESH file's bytes into its attributes (Float32Array views, no copy on little-endian). */
export function parseMesh(buffer, rows, cols, name = 'mesh') {
  const n = rows * cols;
  const expected = 4 * FLOATS_PER_VERTEX * n;
  if (buffer.byteLength !== expected) {
    throw new Error(`${name}: ${buffer.byteLength} bytes, expected ${expected} for ${rows} x ${cols} vertices`);
  }
  let floats;
  if (new Uint8Array(new Uint16Array([1]).buffer)[0] === 1) {
    floats = new Float32Array(buffer);
  } else {
    const view = new DataView(buffer);
    floats = new Float32Array(FLOATS_PER_VERTEX * n);
    for (let i = 0; i < floats.length; i++) floats[i] = view.getFloat32(4 * i, true);
  }
  const mesh = { rows, cols };
  let offset = 0;
  for (const [attr, k] of MESH_ATTRIBUTES) {
    mesh[attr] = floats.subarray(offset, offset + k * n);
    offset += k * n;
  }
  return mesh;
}

const indexCache = new Map();

/** Two triangles per grid cell: (i,j),(i+1,j),(i+1,j+1) and (i,j),(i+1,j+1),(i,j+1). */
export function gridIndex(rows, cols) {
  const key = `${rows}x${cols}`;
  let index = indexCache.get(key);
  if (index) return index;
  const cells = (rows - 1) * (cols - 1);
  const Array_ = rows * cols > 65535 ? Uint32Array : Uint16Array;
  const a = new Array_(6 * cells);
  let t = 0;
  for (let i = 0; i + 1 < rows; i++) {
    for (let j = 0; j + 1 < cols; j++) {
      const p = i * cols + j;
      const q = (i + 1) * cols + j;
      a[t++] = p; a[t++] = q; a[t++] = q + 1;
      a[t++] = p; a[t++] = q + 1; a[t++] = p + 1;
    }
  }
  index = new THREE.BufferAttribute(a, 1);
  indexCache.set(key, index);
  return index;
}

export function meshGeometry(mesh) {
  const g = new THREE.BufferGeometry();
  g.setIndex(gridIndex(mesh.rows, mesh.cols));
  for (const [attr, k] of MESH_ATTRIBUTES) g.setAttribute(attr, new THREE.BufferAttribute(mesh[attr], k));
  g.computeBoundingBox();
  g.computeBoundingSphere();
  return g;
}

/** Loads MESH files once each (keyed by URL). */
export class MeshStore {
  constructor(base) {
    this.base = base;
    this.pending = new Map();
  }
  url(mesh) {
    return new URL(mesh.file, this.base).href;
  }
  load(mesh) {
    const url = this.url(mesh);
    let p = this.pending.get(url);
    if (!p) {
      p = fetch(url)
        .then((r) => {
          if (!r.ok) throw new Error(`${mesh.file}: HTTP ${r.status}`);
          return r.arrayBuffer();
        })
        .then((buf) => {
          const m = parseMesh(buf, mesh.rows, mesh.cols, mesh.file);
          m.geometry = meshGeometry(m);
          return m;
        });
      this.pending.set(url, p);
    }
    return p;
  }
}

/** Line segments along the rows and the columns of a control net. */
export function netGeometry(net) {
  const { rows, cols, points } = net;
  const seg = [];
  const push = (a, b) => seg.push(...points[a], ...points[b]);
  for (let i = 0; i < rows; i++) for (let j = 0; j + 1 < cols; j++) push(i * cols + j, i * cols + j + 1);
  for (let j = 0; j < cols; j++) for (let i = 0; i + 1 < rows; i++) push(i * cols + j, (i + 1) * cols + j);
  const lines = new THREE.BufferGeometry();
  lines.setAttribute('position', new THREE.Float32BufferAttribute(seg, 3));
  const dots = new THREE.BufferGeometry();
  dots.setAttribute('position', new THREE.Float32BufferAttribute(points.flat(), 3));
  return { lines, dots };
}

export function polylineGeometry(points) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(points.flat(), 3));
  return g;
}

// Reading the view folder a run writes (docs/viewer.md, "The view folder"): manifest.json and the
// MESH .bin files (little-endian float32, attribute after attribute, vertex (i, j) at i*cols + j;
// a whole model's triangle mesh then has its uint32 triangle indices).
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
    if (isTriangleMesh(mesh)) {
      if (!(mesh.vertices >= 3 && mesh.triangles >= 1)) throw new Error(`${where}: a triangle mesh needs vertices >= 3 and triangles >= 1`);
    } else if (!(mesh.rows >= 2 && mesh.cols >= 2)) {
      throw new Error(`${where}: rows and cols must be at least 2`);
    }
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

/** A whole model's MESH: a triangle mesh (vertices, triangles) instead of a grid (rows, cols). */
export function isTriangleMesh(mesh) {
  return mesh && mesh.triangles !== undefined;
}

/** The number of vertices of a MESH entry of the manifest. */
export function vertexCount(mesh) {
  return isTriangleMesh(mesh) ? mesh.vertices : mesh.rows * mesh.cols;
}

/**
 * Splits a MESH file's bytes into its attributes (Float32Array views, no copy on little-endian).
 * `shape` is the manifest's entry: {rows, cols} for a grid, {vertices, triangles} for a model's
 * triangle mesh, whose file then holds 3 uint32 node indices per triangle after the floats.
 */
export function parseMesh(buffer, shape, name = 'mesh') {
  const triangles = isTriangleMesh(shape) ? shape.triangles : 0;
  const n = vertexCount(shape);
  const expected = 4 * FLOATS_PER_VERTEX * n + 12 * triangles;
  if (buffer.byteLength !== expected) {
    const what = triangles ? `${n} vertices and ${triangles} triangles` : `${shape.rows} x ${shape.cols} vertices`;
    throw new Error(`${name}: ${buffer.byteLength} bytes, expected ${expected} for ${what}`);
  }
  const littleEndian = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;
  let floats;
  if (littleEndian) {
    floats = new Float32Array(buffer, 0, FLOATS_PER_VERTEX * n);
  } else {
    const view = new DataView(buffer);
    floats = new Float32Array(FLOATS_PER_VERTEX * n);
    for (let i = 0; i < floats.length; i++) floats[i] = view.getFloat32(4 * i, true);
  }
  const mesh = { rows: shape.rows, cols: shape.cols, vertices: n };
  if (triangles) {
    const offset = 4 * FLOATS_PER_VERTEX * n;
    if (littleEndian) {
      mesh.index = new Uint32Array(buffer, offset, 3 * triangles);
    } else {
      const view = new DataView(buffer);
      mesh.index = new Uint32Array(3 * triangles);
      for (let i = 0; i < mesh.index.length; i++) mesh.index[i] = view.getUint32(offset + 4 * i, true);
    }
    for (const k of mesh.index) if (k >= n) throw new Error(`${name}: a triangle refers to vertex ${k} of ${n}`);
  }
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
  g.setIndex(mesh.index ? new THREE.BufferAttribute(mesh.index, 1) : gridIndex(mesh.rows, mesh.cols));
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
          const m = parseMesh(buf, mesh, mesh.file);
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

// The analysis views (docs/studio.md § Analysis): every final surface and model drawn shaded, with
// reflection lines (zebra), mean or Gaussian curvature, or the kernel's deviation map, and the
// legend that says the range; Before shows each deformed surface's parent; every named curve
// drawn (a sketch's solved curve in place of its strokes).
import * as THREE from 'three';
import { shadedMaterial, zebraMaterial, scalarMaterial } from '../materials.js';
import { curvePolyline } from './nurbs.js';
import { $, body } from './ui.js';
import { doc, state } from './store.js';
import { surfaceGroup, curveGroup, disposeGroup, dirty } from './scene.js';
import { meshOf, netLines, modelGeometry } from './meshes.js';
import { previews } from './lattice_preview.js';

const materials = {
  shaded: shadedMaterial(),
  zebra: zebraMaterial(),
  mean: scalarMaterial('mean', true),
  gaussian: scalarMaterial('gaussian', true),
  deviation: scalarMaterial('deviation', false),
};
const selectedMaterial = shadedMaterial();
selectedMaterial.color.set(0x9fc2ea);

function scalarRange(attr) {
  const values = [];
  surfaceGroup.traverse((o) => {
    if (o.isMesh && o.geometry.getAttribute(attr)) values.push(...o.geometry.getAttribute(attr).array);
  });
  const finite = values.filter(Number.isFinite).sort((a, b) => a - b);
  if (!finite.length) return [-1, 1];
  const q = (x) => finite[Math.floor(x * (finite.length - 1))];
  const r = Math.max(Math.abs(q(0.02)), Math.abs(q(0.98))) || Math.max(Math.abs(finite[0]), Math.abs(finite[finite.length - 1])) || 1;
  return [-r, r];
}

export function applyMode() {
  const { mode } = state;
  const material = materials[mode];
  if (mode === 'mean' || mode === 'gaussian') {
    const [lo, hi] = scalarRange(mode);
    material.uniforms.lo.value = lo;
    material.uniforms.hi.value = hi;
    showLegend(`${mode === 'mean' ? 'mean curvature H (1/mm)' : 'Gaussian curvature K (1/mm²)'}: ${lo.toPrecision(3)} … ${hi.toPrecision(3)}`);
  } else if (mode === 'deviation') {
    // sequential, from 0 to the largest deviation of the surfaces shown (the kernel's own figure)
    const maps = [...doc.deviations.values()];
    const hi = Math.max(0, ...maps.map((d) => d.header.max));
    material.uniforms.lo.value = 0;
    material.uniforms.hi.value = hi || 1;
    showLegend(
      maps.length
        ? `deviation from the pointwise deformation (mm): 0 … ${hi.toPrecision(3)} (${maps.map((d) => `${d.header.name} ${d.header.max.toExponential(1)}`).join(', ')})${previews.size ? '; while a drag is drawn, the page shows the pointwise FFD itself' : ''}`
        : 'deviation from the pointwise deformation: no surface shown has a lattice, taper, twist or bend as its last step (a style moves control points: no pointwise map)',
    );
  } else showLegend('');
  surfaceGroup.traverse((o) => {
    if (o.isMesh) o.material = o.userData.selected && mode === 'shaded' ? selectedMaterial : material;
  });
  document.querySelectorAll('[data-mode]').forEach((b) => b.setAttribute('aria-pressed', String(b.dataset.mode === mode)));
  body.dataset.mode = mode;
  dirty();
}
function showLegend(text) {
  $('legend').hidden = !text;
  $('legend').textContent = text;
}

// Each net's drawing, kept while the net is (a reply the kernel did not send again keeps its
// objects): a stroke's reply re-evaluates nothing of the styled surfaces beside it.
const drawn = new Map(); // name -> {net, deviation, geometry}
function geometryOf(name, net, deviation) {
  const known = drawn.get(name);
  if (known && known.net === net && known.deviation === deviation) return known.geometry;
  if (known) known.geometry.dispose();
  const geometry = meshOf(net, deviation);
  geometry.userData.kept = true; // disposed here, when its net goes, not by disposeGroup
  drawn.set(name, { net, deviation, geometry });
  return geometry;
}

export function rebuildSurfaces() {
  const { selection, showBefore } = state;
  disposeGroup(surfaceGroup);
  const nets = showBefore ? new Map([...doc.surfaces].map(([n, net]) => [n, doc.befores.get(n) || net])) : doc.surfaces;
  for (const [name, known] of drawn)
    if (nets.get(name) !== known.net) {
      known.geometry.dispose();
      drawn.delete(name);
    }
  for (const [name, net] of nets) {
    const preview = previews.get(name);
    const mesh = new THREE.Mesh(preview && !showBefore ? preview.geometry : geometryOf(name, net, (!showBefore && doc.deviations.get(name)) || null), materials.shaded);
    mesh.name = name;
    mesh.userData = { kind: 'surface', name, selected: selection.some((s) => s.kind === 'surface' && s.name === name) };
    surfaceGroup.add(mesh);
    if ($('show-net').checked && net.points.length / 3 <= 20000) surfaceGroup.add(netLines(net));
  }
  for (const [name, m] of doc.models) {
    const mesh = new THREE.Mesh(modelGeometry(m), materials.shaded);
    mesh.name = name;
    mesh.userData = { kind: 'model', name, selected: selection.some((s) => s.kind === 'model' && s.name === name) };
    surfaceGroup.add(mesh);
  }
  applyMode();
}

const CURVE_COLOUR = 0xff9b3d;
const SELECTED_COLOUR = 0x4fd1ff;
/** Strokes that are entities of a sketch: the sketch's solved curve ("SKETCH.NAME") is drawn instead. */
function inSketches() {
  const out = new Set();
  for (const [sketch, def] of Object.entries(doc.recipe.sketches || {}))
    for (const [name, e] of Object.entries(def.entities || {})) {
      if (e.curve) out.add(e.curve);
      // a construction chord between a curve's ends (horizontal, vertical) is not drawn
      if (Array.isArray(e.line) && e.line.every((p) => /\.(start|end)$/.test(p))) out.add(`${sketch}.${name}`);
    }
  return out;
}
// Each curve's polyline, kept while the curve object is (as the surfaces' drawings above).
const polylines = new WeakMap();
function polylineOf(curve, samples) {
  if (!polylines.has(curve)) polylines.set(curve, curvePolyline(curve, samples));
  return polylines.get(curve);
}

export function rebuildCurves() {
  disposeGroup(curveGroup);
  const hidden = inSketches();
  for (const [name, curve] of doc.curves) {
    if (hidden.has(name)) continue;
    const samples = Math.min(400, 24 * (curve.knots.length - 2 * curve.degree) + 40);
    const line = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: state.selection.some((s) => s.kind === 'curve' && s.name === name) ? SELECTED_COLOUR : CURVE_COLOUR, depthTest: false }));
    line.geometry.setAttribute('position', new THREE.BufferAttribute(polylineOf(curve, samples), 3));
    line.renderOrder = 2;
    line.name = name;
    line.userData = { kind: 'curve', name };
    curveGroup.add(line);
  }
  dirty();
}

export function toggleBefore() {
  state.showBefore = !state.showBefore;
  $('before-after').setAttribute('aria-pressed', String(state.showBefore));
  rebuildSurfaces();
}

/** The mode buttons, Before, and the control net's checkbox. */
export function wireDisplay() {
  document.querySelectorAll('button[data-mode]').forEach((b) =>
    b.addEventListener('click', () => {
      state.mode = b.dataset.mode;
      applyMode();
    }),
  );
  $('before-after').addEventListener('click', toggleBefore);
  $('show-net').addEventListener('change', rebuildSurfaces);
}

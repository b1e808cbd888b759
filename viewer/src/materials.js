// The surface materials of each display mode.
import * as THREE from 'three';
import { DIVERGING, SEQUENTIAL } from './colormap.js';

// Lines (net, curves) drawn on the surface win the depth test.
const offset = { polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 };

/** Shaded: physically based, lit by a key light at the camera plus a sky/ground fill (main.js). */
export function shadedMaterial() {
  return new THREE.MeshStandardMaterial({
    color: 0xb9c3cc,
    metalness: 0.15,
    roughness: 0.32,
    side: THREE.DoubleSide,
    ...offset,
  });
}

const worldVertex = /* glsl */ `
varying vec3 vWorldPos;
varying vec3 vWorldNormal;
void main() {
  vec4 wp = modelMatrix * vec4(position, 1.0);
  vWorldPos = wp.xyz;
  vWorldNormal = normalize(mat3(modelMatrix) * normal);
  gl_Position = projectionMatrix * viewMatrix * wp;
}
`;

/**
 * Zebra: reflection lines. The surface is a mirror in a room lit by an infinite set of parallel
 * light tubes along `axis`; the fragment's colour is the tube seen along the reflection of the
 * view ray about the normal, r = reflect(v, n): stripe phase = stripes * angle(r around axis) / 2pi.
 * So the stripes depend on the normal (G1) and move with the eye like reflections do; their
 * smoothness shows curvature continuity (G2).
 */
export function zebraMaterial() {
  return new THREE.ShaderMaterial({
    uniforms: {
      axisA: { value: new THREE.Vector3(1, 0, 0) },
      axisB: { value: new THREE.Vector3(0, 1, 0) },
      axisC: { value: new THREE.Vector3(0, 0, 1) },
      stripes: { value: 24 },
    },
    vertexShader: worldVertex,
    fragmentShader: /* glsl */ `
uniform vec3 axisB;
uniform vec3 axisC;
uniform float stripes;
varying vec3 vWorldPos;
varying vec3 vWorldNormal;
void main() {
  vec3 n = normalize(vWorldNormal);
  vec3 v = normalize(vWorldPos - cameraPosition);
  if (dot(n, v) > 0.0) n = -n; // the side facing the eye
  vec3 r = reflect(v, n);
  float phase = stripes * atan(dot(r, axisC), dot(r, axisB)) / 6.28318531;
  float s = sin(6.28318531 * phase);
  float aa = max(fwidth(s), 1e-4);
  float white = smoothstep(-aa, aa, s);
  gl_FragColor = vec4(vec3(0.04 + 0.92 * white), 1.0);
}
`,
    side: THREE.DoubleSide,
    ...offset,
  });
}

/** Sets the zebra's tube axis to a world axis ('x', 'y' or 'z'). */
export function setZebraAxis(material, axis) {
  const e = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };
  const a = new THREE.Vector3(...e[axis]);
  const b = new THREE.Vector3(...e[axis === 'x' ? 'y' : axis === 'y' ? 'z' : 'x']);
  material.uniforms.axisA.value.copy(a);
  material.uniforms.axisB.value.copy(b);
  material.uniforms.axisC.value.crossVectors(a, b);
}

/**
 * A scalar field (attribute `attr`: gaussian, mean or deviation) through a colour map over
 * [lo, hi] (uniforms), with thin contour lines at tenths of the range, and a headlight so the shape
 * still reads.
 */
export function scalarMaterial(attr, diverging) {
  const stops = (diverging ? DIVERGING : SEQUENTIAL).map((c) => new THREE.Vector3(...c));
  return new THREE.ShaderMaterial({
    uniforms: {
      lo: { value: diverging ? -1 : 0 },
      hi: { value: 1 },
      stops: { value: stops },
      contours: { value: 1 },
    },
    vertexShader: /* glsl */ `
attribute float ${attr};
varying float vValue;
varying vec3 vViewNormal;
void main() {
  vValue = ${attr};
  vViewNormal = normalize(normalMatrix * normal);
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}
`,
    fragmentShader: /* glsl */ `
uniform float lo;
uniform float hi;
uniform vec3 stops[5];
uniform float contours;
varying float vValue;
varying vec3 vViewNormal;
vec3 colourMap(float t) {
  float x = clamp(t, 0.0, 1.0) * 4.0;
  if (x < 1.0) return mix(stops[0], stops[1], x);
  if (x < 2.0) return mix(stops[1], stops[2], x - 1.0);
  if (x < 3.0) return mix(stops[2], stops[3], x - 2.0);
  return mix(stops[3], stops[4], x - 3.0);
}
void main() {
  float t = (vValue - lo) / (hi - lo);
  vec3 c = colourMap(t);
  // contour lines at the inner tenths of the range, only where the field varies across the
  // pixel (not on regions where it is constant, e.g. zero deviation or a flat part)
  float q = t * 10.0;
  float d = abs(fract(q + 0.5) - 0.5);
  float fw = fwidth(q);
  float w = max(fw, 1e-5);
  float inside = step(0.05, q) * step(q, 9.95) * step(1e-3, fw);
  float line = contours * inside * (1.0 - smoothstep(0.5 * w, 1.5 * w, d));
  c = mix(c, c * 0.45, 0.7 * line);
  float light = 0.62 + 0.38 * abs(normalize(vViewNormal).z);
  gl_FragColor = vec4(c * light, 1.0);
}
`,
    side: THREE.DoubleSide,
    ...offset,
  });
}

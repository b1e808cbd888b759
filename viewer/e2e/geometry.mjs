// Geometry for Clayform Studio's end-to-end test and walkthrough, computed here and not by the
// page: de Boor's algorithm for the nets the kernel sent, Sederberg–Parry's FFD, point in polygon,
// the back-projection of a screen point through the page's camera matrices. A lattice step's knots
// and control points come from the page's lattice_math.js (one module, checked against the
// kernel's values by tests/python/test_page_math.py); the sums over them are written here.
import { latticeKnots, latticePoints, bsplineLatticePoints } from '../src/studio/lattice_math.js';

export { latticePoints, bsplineLatticePoints };
// Evaluated here with de Boor's algorithm (The NURBS Book A3.1 / A4.1 style, written apart from the
// page's basis-function code), so the page's own evaluation is not what checks it.
export function deBoor(knots, degree, ctrl, t) {
  // ctrl: array of [x, y, z, w] (homogeneous); returns the homogeneous point
  const n = ctrl.length;
  let k = degree;
  if (t >= knots[n]) k = n - 1;
  else while (k < n - 1 && !(t >= knots[k] && t < knots[k + 1])) k++;
  const d = [];
  for (let j = 0; j <= degree; j++) d.push(ctrl[k - degree + j].slice());
  for (let r = 1; r <= degree; r++)
    for (let j = degree; j >= r; j--) {
      const i = k - degree + j;
      const den = knots[i + degree - r + 1] - knots[i];
      const a = den === 0 ? 0 : (t - knots[i]) / den;
      for (let e = 0; e < 4; e++) d[j][e] = (1 - a) * d[j - 1][e] + a * d[j][e];
    }
  return d[degree];
}
const dehom = (h) => [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
export function curveAt(c, t) {
  const ctrl = c.weights.map((w, i) => [c.points[3 * i] * w, c.points[3 * i + 1] * w, c.points[3 * i + 2] * w, w]);
  return dehom(deBoor(c.knots, c.degree, ctrl, t));
}
export function curveDomain(c) {
  return [c.knots[c.degree], c.knots[c.knots.length - c.degree - 1]];
}
export function surfaceAt(s, u, v) {
  const [p, q] = s.degrees;
  const [nu, nv] = s.counts;
  const rows = [];
  for (let i = 0; i < nu; i++) {
    const ctrl = [];
    for (let j = 0; j < nv; j++) {
      const k = i * nv + j;
      const w = s.weights[k];
      ctrl.push([s.points[3 * k] * w, s.points[3 * k + 1] * w, s.points[3 * k + 2] * w, w]);
    }
    rows.push(deBoor(s.knots_v, q, ctrl, v));
  }
  return dehom(deBoor(s.knots_u, p, rows, u));
}
export function surfaceDomain(s) {
  const [p, q] = s.degrees;
  return [
    [s.knots_u[p], s.knots_u[s.knots_u.length - p - 1]],
    [s.knots_v[q], s.knots_v[s.knots_v.length - q - 1]],
  ];
}
export const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
/** Distance from a point to a curve: dense samples, then golden-section refinement. */
export function distanceToCurve(c, x) {
  const [a, b] = curveDomain(c);
  const n = 800;
  let best = 0;
  let bestD = Infinity;
  for (let k = 0; k <= n; k++) {
    const t = a + ((b - a) * k) / n;
    const d = dist(curveAt(c, t), x);
    if (d < bestD) [best, bestD] = [k, d];
  }
  let lo = a + ((b - a) * Math.max(0, best - 1)) / n;
  let hi = a + ((b - a) * Math.min(n, best + 1)) / n;
  const g = (Math.sqrt(5) - 1) / 2;
  for (let it = 0; it < 80; it++) {
    const m1 = hi - g * (hi - lo);
    const m2 = lo + g * (hi - lo);
    if (dist(curveAt(c, m1), x) < dist(curveAt(c, m2), x)) hi = m2;
    else lo = m1;
  }
  return Math.min(bestD, dist(curveAt(c, (lo + hi) / 2), x));
}
/** Sederberg–Parry eq. (2): the trivariate Bernstein sum of the lattice's points at (s, t, u). */
export function ffd(step, points, x) {
  const [l, m, n] = step.degrees;
  const { origin, s: S, t: T, u: U } = step.frame;
  // local coordinates: solve X = X0 + s S + t T + u U (Cramer's rule, eq. (1))
  const d = [0, 1, 2].map((e) => x[e] - origin[e]);
  const det3 = (a, b, c) => a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  const D = det3(S, T, U);
  const s = det3(d, T, U) / D;
  const t = det3(S, d, U) / D;
  const u = det3(S, T, d) / D;
  const binom = (N, k) => {
    let r = 1;
    for (let i = 1; i <= k; i++) r = (r * (N - k + i)) / i;
    return r;
  };
  const B = (N, i, y) => binom(N, i) * (1 - y) ** (N - i) * y ** i;
  const out = [0, 0, 0];
  for (let i = 0; i <= l; i++)
    for (let j = 0; j <= m; j++)
      for (let k = 0; k <= n; k++) {
        const f = B(l, i, s) * B(m, j, t) * B(n, k, u);
        const P = points[(i * (m + 1) + j) * (n + 1) + k];
        for (let e = 0; e < 3; e++) out[e] += f * P[e];
      }
  return out;
}
export function insidePolygon(poly, x, y) {
  let inside = false;
  for (let i = 0, j = poly.length - 1; i < poly.length; j = i++) {
    const [xi, yi] = poly[i];
    const [xj, yj] = poly[j];
    if (yi > y !== yj > y && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}
export const quantile = (values, q) => {
  const s = [...values].sort((a, b) => a - b);
  if (!s.length) return NaN;
  return s[Math.min(s.length - 1, Math.floor(q * (s.length - 1) + 0.5))];
};

/** The back-projection of a screen point onto the plane z = z0 through the page's camera matrices. */
export function backProject(cam, clientX, clientY, z0) {
  const ndc = [((clientX - cam.rect.left) / cam.rect.width) * 2 - 1, -((clientY - cam.rect.top) / cam.rect.height) * 2 + 1];
  const apply = (m, v) => {
    const x = m[0] * v[0] + m[4] * v[1] + m[8] * v[2] + m[12] * v[3];
    const y = m[1] * v[0] + m[5] * v[1] + m[9] * v[2] + m[13] * v[3];
    const z = m[2] * v[0] + m[6] * v[1] + m[10] * v[2] + m[14] * v[3];
    const w = m[3] * v[0] + m[7] * v[1] + m[11] * v[2] + m[15] * v[3];
    return [x / w, y / w, z / w, 1];
  };
  const near = apply(cam.matrixWorld, apply(cam.projectionInverse, [ndc[0], ndc[1], -1, 1]));
  const far = apply(cam.matrixWorld, apply(cam.projectionInverse, [ndc[0], ndc[1], 1, 1]));
  const t = (z0 - near[2]) / (far[2] - near[2]);
  return [0, 1, 2].map((e) => near[e] + t * (far[e] - near[e]));
}


/** Hsu–Hughes–Kaufman eq. (1): the trivariate B-spline sum of a lattice step (cells, degrees, knots) at x. */
export function bsplineFfd(step, points, x) {
  const { origin, s: S, t: T, u: U } = step.frame;
  const d = [0, 1, 2].map((e) => x[e] - origin[e]);
  const det3 = (a, b, c) => a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  const D = det3(S, T, U);
  const local = [det3(d, T, U) / D, det3(S, d, U) / D, det3(S, T, d) / D];
  const counts = [0, 1, 2].map((e) => step.cells[e] + step.degrees[e]);
  const knots = [0, 1, 2].map((e) => latticeKnots(step.cells[e], step.degrees[e], step.knots || 'clamped'));
  const [nl, nm, nn] = counts;
  const rows = [];
  for (let i = 0; i < nl; i++) {
    const cols = [];
    for (let j = 0; j < nm; j++) {
      const line = [];
      for (let k = 0; k < nn; k++) line.push([...points[(i * nm + j) * nn + k], 1]);
      cols.push(deBoor(knots[2], step.degrees[2], line, local[2]));
    }
    rows.push(deBoor(knots[1], step.degrees[1], cols, local[1]));
  }
  return dehom(deBoor(knots[0], step.degrees[0], rows, local[0]));
}

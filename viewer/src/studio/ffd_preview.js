// The picture of a lattice drag before the kernel answers: Sederberg–Parry's FFD (eq. (2)) of the
// parent surface's sampled points, on the page, or for a B-spline lattice Hsu–Hughes–Kaufman's
// (eq. (1): the same sum with B-spline basis functions). A deformed surface composed exactly with
// the lattice is, at each (u, v), the lattice's map of the parent's point there, so these
// vertices are the exact result's at the same parameters (to rounding; a refitted one's within
// its tolerance); the normals come from the tangents carried by the map's Jacobian,
// n = (J S_u) x (J S_v). The kernel's net replaces the picture when it arrives.
import { basisDerivatives, findSpan } from './nurbs.js';
import { latticeCounts, latticeKnots } from './lattice_math.js';

/** Bernstein polynomials of degree n at x and their derivatives: [values, derivatives]. */
function bernstein(n, x) {
  const b = new Float64Array(n + 1);
  const d = new Float64Array(n + 1);
  // values of degree n - 1 first (for the derivative), then degree n
  const lower = new Float64Array(Math.max(n, 1));
  lower[0] = 1;
  for (let k = 1; k < n; k++) {
    for (let i = k; i >= 0; i--) lower[i] = (i < k ? (1 - x) * lower[i] : 0) + (i > 0 ? x * lower[i - 1] : 0);
  }
  for (let i = 0; i <= n; i++) {
    b[i] = (i < n ? (1 - x) * lower[i] : 0) + (i > 0 ? x * lower[i - 1] : 0);
    if (n > 0) d[i] = n * ((i > 0 ? lower[i - 1] : 0) - (i < n ? lower[i] : 0));
  }
  if (n === 0) b[0] = 1;
  return [b, d];
}

/**
 * The p + 1 B-spline basis functions of one lattice direction that do not vanish at x, their
 * derivatives, and the index of the first: [values, derivatives, first].
 */
function bsplineBasis(knots, p, count, x) {
  const span = findSpan(knots, p, count, x);
  const ders = basisDerivatives(knots, p, span, x, 1);
  return [ders[0], ders[1], span - p];
}

/** 3 x 3 inverse (row-major array of 9), for the frame's local coordinates. */
function inverse3(m) {
  const [a, b, c, d, e, f, g, h, i] = m;
  const A = e * i - f * h;
  const B = -(d * i - f * g);
  const C = d * h - e * g;
  const det = a * A + b * B + c * C;
  return [A / det, -(b * i - c * h) / det, (b * f - c * e) / det, B / det, (a * i - c * g) / det, -(a * f - c * d) / det, C / det, -(a * h - b * g) / det, (a * e - b * d) / det];
}

/**
 * What a drag of `step` (a bezier_lattice or bspline_lattice recipe step) needs of the parent's
 * samples `grid` (surfaceGrid): each vertex's basis values and derivatives in the lattice's local
 * coordinates (s, t, u), computed once per drag (eq. (1): X = X0 + s S + t T + u U). Each
 * direction keeps only the functions that do not vanish there and the index of the first (0 for
 * Bernstein's), so one sum serves both lattices and a B-spline's costs (p+1)^3 per vertex.
 */
export function prepareFfd(grid, step) {
  const bspline = step.kind === 'bspline_lattice';
  const counts = latticeCounts(step);
  const knots = bspline ? [0, 1, 2].map((e) => latticeKnots(step.cells[e], step.degrees[e], step.knots || 'clamped')) : null;
  const basisOf = (e, x) => (bspline ? bsplineBasis(knots[e], step.degrees[e], counts[e], x) : [...bernstein(step.degrees[e], x), 0]);
  const { origin, s: S, t: T, u: U } = step.frame;
  // columns S, T, U: world = X0 + M [s t u]
  const Minv = inverse3([S[0], T[0], U[0], S[1], T[1], U[1], S[2], T[2], U[2]]);
  const count = grid.rows * grid.cols;
  const basis = [];
  for (let k = 0; k < count; k++) {
    const d = [0, 1, 2].map((e) => grid.position[3 * k + e] - origin[e]);
    const local = [0, 1, 2].map((r) => Minv[3 * r] * d[0] + Minv[3 * r + 1] * d[1] + Minv[3 * r + 2] * d[2]);
    basis.push([basisOf(0, local[0]), basisOf(1, local[1]), basisOf(2, local[2])]);
  }
  return { grid, counts, Minv, basis };
}

/**
 * Writes the deformed vertices and unit normals into `position` and `normal` (Float32Arrays of
 * the grid's size) for the lattice's control points `points` (s-major, [x, y, z] each). Returns
 * the smallest and largest volume ratio det(dX'/dX) at the samples: where the map would fold the
 * surface's neighbourhood (<= 0), as the drag goes.
 */
export function applyFfd(prepared, points, position, normal) {
  const { grid, counts, Minv, basis } = prepared;
  const [, nt, nu] = counts;
  const count = grid.rows * grid.cols;
  let lo = Infinity;
  let hi = -Infinity;
  // scratch, once per call: this runs for every vertex at every pointer move
  const J = new Float64Array(9); // dX/ds, dX/dt, dX/du as columns, row-major
  const W = new Float64Array(9); // the world Jacobian J M^-1
  const a = new Float64Array(3);
  const b = new Float64Array(3);
  for (let k = 0; k < count; k++) {
    const [[bs, ds, s0], [bt, dt, t0], [bu, du, u0]] = basis[k];
    let x = 0;
    let y = 0;
    let z = 0;
    J.fill(0);
    for (let i = 0; i < bs.length; i++)
      for (let j = 0; j < bt.length; j++)
        for (let h = 0; h < bu.length; h++) {
          const P = points[((s0 + i) * nt + t0 + j) * nu + u0 + h];
          const f = bs[i] * bt[j] * bu[h];
          const fs = ds[i] * bt[j] * bu[h];
          const ft = bs[i] * dt[j] * bu[h];
          const fu = bs[i] * bt[j] * du[h];
          x += f * P[0];
          y += f * P[1];
          z += f * P[2];
          for (let e = 0; e < 3; e++) {
            J[3 * e] += fs * P[e];
            J[3 * e + 1] += ft * P[e];
            J[3 * e + 2] += fu * P[e];
          }
        }
    position[3 * k] = x;
    position[3 * k + 1] = y;
    position[3 * k + 2] = z;
    // world Jacobian J M^-1, applied to the parent's tangents
    a.fill(0);
    b.fill(0);
    for (let e = 0; e < 3; e++) {
      for (let c = 0; c < 3; c++) {
        const w = J[3 * e] * Minv[c] + J[3 * e + 1] * Minv[3 + c] + J[3 * e + 2] * Minv[6 + c];
        W[3 * e + c] = w;
        a[e] += w * grid.su[3 * k + c];
        b[e] += w * grid.sv[3 * k + c];
      }
    }
    const det = W[0] * (W[4] * W[8] - W[5] * W[7]) - W[1] * (W[3] * W[8] - W[5] * W[6]) + W[2] * (W[3] * W[7] - W[4] * W[6]);
    lo = Math.min(lo, det);
    hi = Math.max(hi, det);
    let nx = a[1] * b[2] - a[2] * b[1];
    let ny = a[2] * b[0] - a[0] * b[2];
    let nz = a[0] * b[1] - a[1] * b[0];
    const len = Math.hypot(nx, ny, nz) || 1;
    nx /= len;
    ny /= len;
    nz /= len;
    normal[3 * k] = nx;
    normal[3 * k + 1] = ny;
    normal[3 * k + 2] = nz;
  }
  return [lo, hi];
}

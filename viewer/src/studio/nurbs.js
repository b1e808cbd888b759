// Evaluation of the nets the studio's kernel sends (docs/studio.md, "A net frame"): B-spline and
// NURBS curves and surfaces, on the page, so a drag that only moves control points costs the
// kernel a net, not a mesh. The basis functions and their derivatives are The NURBS Book's
// algorithms A2.1 (FindSpan) and A2.3 (DersBasisFuns); rational points and derivatives follow
// its eq. (4.8) and (4.20): S = A / w, S' = (A' - w' S) / w, S'' = (A'' - 2 w' S' - w'' S) / w.

/** The knot span of `t` (A2.1): the index i with knots[i] <= t < knots[i+1], clamped to the domain. */
export function findSpan(knots, degree, count, t) {
  if (t >= knots[count]) return count - 1;
  if (t <= knots[degree]) return degree;
  let lo = degree;
  let hi = count;
  let mid = (lo + hi) >> 1;
  while (t < knots[mid] || t >= knots[mid + 1]) {
    if (t < knots[mid]) hi = mid;
    else lo = mid;
    mid = (lo + hi) >> 1;
  }
  return mid;
}

/**
 * The non-zero basis functions at `t` in span `span` and their derivatives up to `n` (A2.3):
 * out[k][j] is the k-th derivative of N_{span-degree+j}.
 */
export function basisDerivatives(knots, degree, span, t, n) {
  const p = degree;
  const ndu = Array.from({ length: p + 1 }, () => new Float64Array(p + 1));
  const left = new Float64Array(p + 1);
  const right = new Float64Array(p + 1);
  ndu[0][0] = 1;
  for (let j = 1; j <= p; j++) {
    left[j] = t - knots[span + 1 - j];
    right[j] = knots[span + j] - t;
    let saved = 0;
    for (let r = 0; r < j; r++) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  const out = Array.from({ length: n + 1 }, () => new Float64Array(p + 1));
  for (let j = 0; j <= p; j++) out[0][j] = ndu[j][p];
  const a = [new Float64Array(p + 1), new Float64Array(p + 1)];
  for (let r = 0; r <= p; r++) {
    let s1 = 0;
    let s2 = 1;
    a[0][0] = 1;
    for (let k = 1; k <= n; k++) {
      let d = 0;
      const rk = r - k;
      const pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const j1 = rk >= -1 ? 1 : -rk;
      const j2 = r - 1 <= pk ? k - 1 : p - r;
      for (let j = j1; j <= j2; j++) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      out[k][r] = d;
      const swap = s1;
      s1 = s2;
      s2 = swap;
    }
  }
  let f = p;
  for (let k = 1; k <= n; k++) {
    for (let j = 0; j <= p; j++) out[k][j] *= f;
    f *= p - k;
  }
  return out;
}

/** The domain [first, last] of a knot vector for `degree`. */
export function domain(knots, degree) {
  return [knots[degree], knots[knots.length - degree - 1]];
}

/** Point of a curve net ({degree, knots, points: Float64Array xyz, weights}) at t: [x, y, z]. */
export function curvePoint(curve, t) {
  const { degree: p, knots, points, weights } = curve;
  const count = weights.length;
  const span = findSpan(knots, p, count, t);
  const N = basisDerivatives(knots, p, span, t, 0)[0];
  let x = 0;
  let y = 0;
  let z = 0;
  let w = 0;
  for (let j = 0; j <= p; j++) {
    const i = span - p + j;
    const nw = N[j] * weights[i];
    x += nw * points[3 * i];
    y += nw * points[3 * i + 1];
    z += nw * points[3 * i + 2];
    w += nw;
  }
  return [x / w, y / w, z / w];
}

/** `samples` points of a curve, evenly in its parameter, as a Float32Array xyz (for drawing). */
export function curvePolyline(curve, samples) {
  const [a, b] = domain(curve.knots, curve.degree);
  const out = new Float32Array(3 * samples);
  for (let k = 0; k < samples; k++) {
    const q = curvePoint(curve, a + ((b - a) * k) / (samples - 1));
    out.set(q, 3 * k);
  }
  return out;
}

/** The basis of one direction at every sample: spans and derivatives up to 2. */
function directionTable(knots, degree, count, params) {
  return params.map((t) => {
    const span = findSpan(knots, degree, count, t);
    return { span, d: basisDerivatives(knots, degree, span, t, 2) };
  });
}

/** Parameters for `n` samples of a direction: evenly spread, every knot of the domain hit. */
export function sampleParameters(knots, degree, n) {
  const [a, b] = domain(knots, degree);
  const out = new Float64Array(n);
  for (let k = 0; k < n; k++) out[k] = a + ((b - a) * k) / (n - 1);
  out[n - 1] = b;
  return out;
}

/**
 * The surface of a net ({degrees: [p, q], counts: [nu, nv], knots_u, knots_v, points, weights};
 * point (i, j) at i * nv + j) sampled on a rows x cols grid: positions, unit normals (S_u x S_v),
 * Gaussian and mean curvature (first and second fundamental forms), as Float32Arrays with vertex
 * (r, c) at r * cols + c, and the tangents S_u, S_v (Float64Arrays). Rows follow u, columns v.
 * `Float` is the array type of the positions, normals and curvatures (Float64Array: the full
 * doubles, as tests/python/test_page_math.py compares them with the kernel's).
 */
export function surfaceGrid(net, rows, cols, Float = Float32Array) {
  const [p, q] = net.degrees;
  const [nu, nv] = net.counts;
  const U = directionTable(net.knots_u, p, nu, Array.from(sampleParameters(net.knots_u, p, rows)));
  const V = directionTable(net.knots_v, q, nv, Array.from(sampleParameters(net.knots_v, q, cols)));
  const n = rows * cols;
  const position = new Float(3 * n);
  const normal = new Float(3 * n);
  const gaussian = new Float(n);
  const mean = new Float(n);
  const su = new Float64Array(3 * n);
  const sv = new Float64Array(3 * n);
  // Homogeneous control points (w x, w y, w z, w).
  const Pw = new Float64Array(4 * nu * nv);
  for (let k = 0; k < nu * nv; k++) {
    const w = net.weights[k];
    Pw[4 * k] = net.points[3 * k] * w;
    Pw[4 * k + 1] = net.points[3 * k + 1] * w;
    Pw[4 * k + 2] = net.points[3 * k + 2] * w;
    Pw[4 * k + 3] = w;
  }
  // Two stages: per row, the u-derivatives 0..2 of the curves along v (C[ku][j], one per column
  // of the net), then per column their v-derivatives: (p+1) nv + (q+1) sums per vertex instead
  // of (p+1)(q+1).
  const C = [new Float64Array(4 * nv), new Float64Array(4 * nv), new Float64Array(4 * nv)];
  const A = new Float64Array(6 * 4); // (0,0) (1,0) (0,1) (2,0) (1,1) (0,2), each (x, y, z, w)
  const S = Array.from({ length: 6 }, () => [0, 0, 0]);
  const ORDERS = [
    [0, 0],
    [1, 0],
    [0, 1],
    [2, 0],
    [1, 1],
    [0, 2],
  ];
  for (let r = 0; r < rows; r++) {
    const bu = U[r];
    for (let ku = 0; ku < 3; ku++) {
      const c = C[ku];
      c.fill(0);
      const N = bu.d[ku];
      for (let a = 0; a <= p; a++) {
        const f = N[a];
        if (f === 0) continue;
        const row = 4 * (bu.span - p + a) * nv;
        for (let j = 0; j < 4 * nv; j++) c[j] += f * Pw[row + j];
      }
    }
    for (let col = 0; col < cols; col++) {
      const bv = V[col];
      const first = bv.span - q;
      for (let s = 0; s < 6; s++) {
        const [ku, kv] = ORDERS[s];
        const c = C[ku];
        const N = bv.d[kv];
        let x = 0;
        let y = 0;
        let z = 0;
        let w = 0;
        for (let b = 0; b <= q; b++) {
          const f = N[b];
          const o = 4 * (first + b);
          x += f * c[o];
          y += f * c[o + 1];
          z += f * c[o + 2];
          w += f * c[o + 3];
        }
        A[4 * s] = x;
        A[4 * s + 1] = y;
        A[4 * s + 2] = z;
        A[4 * s + 3] = w;
      }
      // rational derivatives (The NURBS Book eq. 4.20)
      const w0 = A[3];
      for (let e = 0; e < 3; e++) {
        const s0 = A[e] / w0;
        const su = (A[4 + e] - A[7] * s0) / w0;
        const sv = (A[8 + e] - A[11] * s0) / w0;
        S[0][e] = s0;
        S[1][e] = su;
        S[2][e] = sv;
        S[3][e] = (A[12 + e] - 2 * A[7] * su - A[15] * s0) / w0;
        S[4][e] = (A[16 + e] - A[11] * su - A[7] * sv - A[19] * s0) / w0;
        S[5][e] = (A[20 + e] - 2 * A[11] * sv - A[23] * s0) / w0;
      }
      const k = r * cols + col;
      position[3 * k] = S[0][0];
      position[3 * k + 1] = S[0][1];
      position[3 * k + 2] = S[0][2];
      const [Su, Sv, Suu, Suv, Svv] = [S[1], S[2], S[3], S[4], S[5]];
      let nx = Su[1] * Sv[2] - Su[2] * Sv[1];
      let ny = Su[2] * Sv[0] - Su[0] * Sv[2];
      let nz = Su[0] * Sv[1] - Su[1] * Sv[0];
      const len = Math.hypot(nx, ny, nz);
      if (len > 0) {
        nx /= len;
        ny /= len;
        nz /= len;
      }
      normal[3 * k] = nx;
      normal[3 * k + 1] = ny;
      normal[3 * k + 2] = nz;
      su.set(Su, 3 * k);
      sv.set(Sv, 3 * k);
      // curvatures from the fundamental forms (do Carmo §3-3)
      const E = Su[0] * Su[0] + Su[1] * Su[1] + Su[2] * Su[2];
      const F = Su[0] * Sv[0] + Su[1] * Sv[1] + Su[2] * Sv[2];
      const G = Sv[0] * Sv[0] + Sv[1] * Sv[1] + Sv[2] * Sv[2];
      const L = Suu[0] * nx + Suu[1] * ny + Suu[2] * nz;
      const M = Suv[0] * nx + Suv[1] * ny + Suv[2] * nz;
      const N = Svv[0] * nx + Svv[1] * ny + Svv[2] * nz;
      const det = E * G - F * F;
      gaussian[k] = det > 0 ? (L * N - M * M) / det : 0;
      mean[k] = det > 0 ? (E * N - 2 * F * M + G * L) / (2 * det) : 0;
    }
  }
  return { rows, cols, position, normal, gaussian, mean, su, sv };
}

/**
 * Point and first derivatives of a surface net at (u, v): {p, su, sv} as [x, y, z] (rational
 * nets by eq. (4.20)). For points scattered in (u, v), such as a model's mesh nodes.
 */
export function surfacePoint(net, u, v) {
  const [p, q] = net.degrees;
  const [nu, nv] = net.counts;
  const spanU = findSpan(net.knots_u, p, nu, u);
  const spanV = findSpan(net.knots_v, q, nv, v);
  const Nu = basisDerivatives(net.knots_u, p, spanU, u, 1);
  const Nv = basisDerivatives(net.knots_v, q, spanV, v, 1);
  // A[ku][kv] = (w x, w y, w z, w) differentiated ku times in u and kv times in v
  const A = [new Float64Array(4), new Float64Array(4), new Float64Array(4)]; // (0,0) (1,0) (0,1)
  for (let a = 0; a <= p; a++) {
    const i = spanU - p + a;
    for (let b = 0; b <= q; b++) {
      const k = i * nv + spanV - q + b;
      const w = net.weights[k];
      const P = [net.points[3 * k] * w, net.points[3 * k + 1] * w, net.points[3 * k + 2] * w, w];
      const f00 = Nu[0][a] * Nv[0][b];
      const f10 = Nu[1][a] * Nv[0][b];
      const f01 = Nu[0][a] * Nv[1][b];
      for (let e = 0; e < 4; e++) {
        A[0][e] += f00 * P[e];
        A[1][e] += f10 * P[e];
        A[2][e] += f01 * P[e];
      }
    }
  }
  const w0 = A[0][3];
  const pt = [0, 0, 0];
  const su = [0, 0, 0];
  const sv = [0, 0, 0];
  for (let e = 0; e < 3; e++) {
    pt[e] = A[0][e] / w0;
    su[e] = (A[1][e] - A[1][3] * pt[e]) / w0;
    sv[e] = (A[2][e] - A[2][3] * pt[e]) / w0;
  }
  return { p: pt, su, sv };
}

/**
 * A model's mesh moved onto its faces' new nets (a "model_nets" frame): each node evaluated at its
 * (u, v) on its face, its normal S_u x S_v (turned on reversed faces). Where S_u x S_v vanishes (a
 * pole), the node takes the mean normal of its triangles, as the kernel's mesher does.
 * Returns {positions, normals} as Float64Arrays.
 */
export function meshOnNets(mesh, faces) {
  const n = mesh.nodeFace.length;
  const positions = new Float64Array(3 * n);
  const normals = new Float64Array(3 * n);
  const poles = [];
  for (let k = 0; k < n; k++) {
    const face = faces[mesh.nodeFace[k]];
    const { p, su, sv } = surfacePoint(face, mesh.uv[2 * k], mesh.uv[2 * k + 1]);
    positions.set(p, 3 * k);
    let nx = su[1] * sv[2] - su[2] * sv[1];
    let ny = su[2] * sv[0] - su[0] * sv[2];
    let nz = su[0] * sv[1] - su[1] * sv[0];
    const len = Math.hypot(nx, ny, nz);
    const scale = Math.hypot(...su) * Math.hypot(...sv);
    if (!(len > 1e-12 * scale) || len === 0) {
      poles.push(k);
      continue;
    }
    const sign = face.reversed ? -1 : 1;
    normals[3 * k] = (sign * nx) / len;
    normals[3 * k + 1] = (sign * ny) / len;
    normals[3 * k + 2] = (sign * nz) / len;
  }
  if (poles.length) {
    const pole = new Set(poles);
    const t = mesh.triangles;
    for (let i = 0; i < t.length; i += 3) {
      const [a, b, c] = [t[i], t[i + 1], t[i + 2]];
      if (!pole.has(a) && !pole.has(b) && !pole.has(c)) continue;
      const e1 = [0, 1, 2].map((e) => positions[3 * b + e] - positions[3 * a + e]);
      const e2 = [0, 1, 2].map((e) => positions[3 * c + e] - positions[3 * a + e]);
      const cross = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
      for (const node of [a, b, c]) if (pole.has(node)) for (let e = 0; e < 3; e++) normals[3 * node + e] += cross[e];
    }
    for (const k of poles) {
      const len = Math.hypot(normals[3 * k], normals[3 * k + 1], normals[3 * k + 2]) || 1;
      for (let e = 0; e < 3; e++) normals[3 * k + e] /= len;
    }
  }
  return { positions, normals };
}

// The lattice math the page shares with its end-to-end test (e2e/geometry.mjs): a B-spline
// lattice direction's knots and Greville abscissae, and a lattice step's control points
// (Sederberg–Parry's Bézier lattice, Hsu–Hughes–Kaufman's B-spline lattice) as the recipe gives
// them (docs/recipe.md: frame, degrees, cells, knots, moves). Pure functions, no three.js, so Node
// runs them too: tests/python/test_page_math.py checks them against the kernel's own values.

/**
 * The knot vector of one direction of a B-spline lattice (docs/recipe.md, bspline_lattice) on its
 * local coordinate [0, 1]: `cells` spans of degree `p`, "clamped" (end knots p + 1 times) or
 * "uniform" (knots (i - p) / cells).
 */
export function latticeKnots(cells, p, kind = 'clamped') {
  const n = cells + p;
  const knots = [];
  if (kind === 'uniform') for (let i = 0; i <= n + p; i++) knots.push((i - p) / cells);
  else {
    for (let i = 0; i <= p; i++) knots.push(0);
    for (let i = 1; i < cells; i++) knots.push(i / cells);
    for (let i = 0; i <= p; i++) knots.push(1);
  }
  return knots;
}

/** The Greville abscissae of a knot vector for degree p: (t_{i+1} + ... + t_{i+p}) / p, one per control point. */
export function grevilleAbscissae(knots, p) {
  const n = knots.length - p - 1;
  return Array.from({ length: n }, (_, i) => {
    let sum = 0;
    for (let k = 1; k <= p; k++) sum += knots[i + k];
    return sum / p;
  });
}

/** A lattice step's control point counts per direction. */
export function latticeCounts(step) {
  return step.kind === 'bspline_lattice' ? [0, 1, 2].map((e) => step.cells[e] + step.degrees[e]) : step.degrees.map((d) => d + 1);
}

/** `moves` applied to control points s-major with n[1] x n[2] per slice ("to" a position or "by" an offset). */
function applyMoves(out, moves, m, n) {
  for (const move of moves || []) {
    const [i, j, k] = move.index;
    const at = (i * m + j) * n + k;
    out[at] = move.to ? move.to.slice() : out[at].map((c, e) => c + move.by[e]);
  }
  return out;
}

/**
 * A Bézier lattice step's control points, s-major ((i (m+1) + j)(n+1) + k): the undisplaced
 * lattice P_ijk = X0 + i/l S + j/m T + k/n U (Sederberg–Parry §2), or its `points`, with its
 * `moves` applied ("to" a position or "by" an offset).
 */
export function latticePoints(step) {
  const [l, m, n] = step.degrees;
  const { origin, s, t, u } = step.frame;
  const out = [];
  if (Array.isArray(step.points)) out.push(...step.points.map((p) => p.slice()));
  else
    for (let i = 0; i <= l; i++)
      for (let j = 0; j <= m; j++)
        for (let k = 0; k <= n; k++) out.push([0, 1, 2].map((e) => origin[e] + (i / l) * s[e] + (j / m) * t[e] + (k / n) * u[e]));
  return applyMoves(out, step.moves, m + 1, n + 1);
}

/**
 * A B-spline lattice step's control points (docs/recipe.md: `cells`, `degrees`, `knots` "clamped"
 * or "uniform"), s-major like latticePoints: the undisplaced lattice at the Greville abscissae of
 * each direction's knots (Hsu–Hughes–Kaufman: the identity), with `moves` applied.
 */
export function bsplineLatticePoints(step) {
  const [xs, ys, zs] = [0, 1, 2].map((e) => grevilleAbscissae(latticeKnots(step.cells[e], step.degrees[e], step.knots || 'clamped'), step.degrees[e]));
  const { origin, s, t, u } = step.frame;
  const out = [];
  for (const a of xs) for (const b of ys) for (const c of zs) out.push([0, 1, 2].map((e) => origin[e] + a * s[e] + b * t[e] + c * u[e]));
  return applyMoves(out, step.moves, ys.length, zs.length);
}

/** Either lattice step's control points. */
export function stepLatticePoints(step) {
  return step.kind === 'bspline_lattice' ? bsplineLatticePoints(step) : latticePoints(step);
}

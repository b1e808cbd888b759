// The recipe edits the studio's actions make (docs/recipe.md): new names, a lattice around a
// surface, a lattice control point moved, a curve's control point moved, the global taper,
// twist and bend. Pure functions of the recipe (as JSON) and the nets the kernel sent. (A lattice's
// knots and control points: lattice_math.js.)

const SECTIONS = ['strokes', 'curves', 'sketches', 'surfaces', 'deformations', 'exports', 'models'];

/** A name not used in the recipe: `base` followed by the first free number (s1, s2, ...). */
export function free(recipe, base) {
  const used = new Set(SECTIONS.flatMap((s) => Object.keys(recipe[s] || {})));
  const stem = base.replace(/[^A-Za-z0-9_-]/g, '_').slice(0, 56) || 'x';
  for (let k = 1; ; k++) if (!used.has(`${stem}${k}`)) return `${stem}${k}`;
}

/** The box of control points (a B-spline surface lies in their convex hull). */
export function bounds(points) {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let k = 0; k < points.length; k += 3)
    for (let e = 0; e < 3; e++) {
      lo[e] = Math.min(lo[e], points[k + e]);
      hi[e] = Math.max(hi[e], points[k + e]);
    }
  return { lo, hi };
}

/**
 * A lattice frame around a net's control points: their box grown by 5 % of its diagonal on every
 * side, and at least 10 % of the diagonal thick in each direction (a flat patch gets a slab), so
 * the surface lies inside the lattice as exact composition needs.
 */
export function boxFrame(points) {
  const { lo, hi } = bounds(points);
  const diagonal = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  const origin = [];
  const size = [];
  for (let e = 0; e < 3; e++) {
    const extent = Math.max(hi[e] - lo[e] + 0.1 * diagonal, 0.1 * diagonal);
    const mid = (lo[e] + hi[e]) / 2;
    origin.push(round(mid - extent / 2));
    size.push(round(extent));
  }
  return { origin, s: [size[0], 0, 0], t: [0, size[1], 0], u: [0, 0, size[2]] };
}
const round = (x) => Number(x.toPrecision(6));

/** A lattice's moves with the point at `index` moved to `to` (replacing an earlier move of it). */
export function withMove(moves, index, to) {
  const same = (m) => m.index.every((x, e) => x === index[e]);
  return [...moves.filter((m) => !same(m)), { index: index.slice(), to }];
}

/**
 * The changes that move control point `index` of the curve `name` to `to`. A curve given as a
 * B-spline changes that point; any other (a fitted stroke, a line, an arc) becomes the B-spline
 * the kernel built for it, bit for bit, with the point moved, under the same name (the stroke
 * is removed), so what refers to it follows.
 */
export function curvePointChanges(recipe, net, name, index, to) {
  const def = (recipe.curves || {})[name];
  if (def && def.bspline) return [{ path: `curves.${name}.bspline.points[${index}]`, value: to }];
  const points = [];
  for (let i = 0; i < net.weights.length; i++) points.push(i === index ? to : [net.points[3 * i], net.points[3 * i + 1], net.points[3 * i + 2]]);
  const bspline = { degree: net.degree, knots: Array.from(net.knots), points };
  if (Array.from(net.weights).some((w) => w !== 1)) bspline.weights = Array.from(net.weights);
  const changes = [];
  if ((recipe.strokes || {})[name]) changes.push({ path: `strokes.${name}`, remove: true });
  changes.push({ path: `curves.${name}`, value: { bspline }, create: true });
  return changes;
}

/**
 * The stroke a curve comes from: the stroke of that name, or for a piece "NAME.k" of a stroke split
 * at its corners ("pieces"), NAME; null for any other curve.
 */
export function strokeOf(recipe, curve) {
  const strokes = recipe.strokes || {};
  if (strokes[curve]) return curve;
  const m = /^(.+)\.(\d+)$/.exec(curve);
  return m && strokes[m[1]] && Number(m[2]) >= 1 && Number(m[2]) <= (strokes[m[1]].pieces || 0) ? m[1] : null;
}

/**
 * Barr's taper, twist and bend about the longest direction of the net's box, through its centre:
 * `taper` is the scale change at the ends (profile 1 + taper y / half), `twist` the angle in
 * degrees at the ends, `bend` the whole bend angle in degrees over the box's length.
 */
export function globalSteps(points, taper, twist, bend) {
  const { lo, hi } = bounds(points);
  const extent = [0, 1, 2].map((e) => hi[e] - lo[e]);
  const along = extent.indexOf(Math.max(...extent));
  const axis = [0, 0, 0];
  axis[along] = 1;
  const reference = [0, 0, 0];
  reference[(along + 1) % 3] = 1;
  const origin = [0, 1, 2].map((e) => round((lo[e] + hi[e]) / 2));
  const half = round(Math.max(extent[along] / 2, 1e-3));
  const frame = { origin, axis, reference };
  return withGlobal(
    [
      { kind: 'taper', name: 'taper', frame, profile: [1, 0] },
      { kind: 'twist', name: 'twist', frame, angle: [0, 0] },
      { kind: 'bend', name: 'bend', frame, y_min: -half, y_max: half, center: 0, rate: 0 },
    ],
    taper,
    twist,
    bend,
  );
}

/** The three steps of globalSteps with new slider values (frames kept). */
export function withGlobal(steps, taper, twist, bend) {
  const half = steps[2].y_max;
  const [t, w, b] = steps.map((s) => ({ ...s }));
  t.profile = [1, taper / half];
  w.angle = [0, (twist * Math.PI) / 180 / half];
  b.rate = (bend * Math.PI) / 180 / (2 * half);
  return [t, w, b];
}

/** The slider values of globalSteps' three steps. */
export function globalValues(steps) {
  const half = steps[2].y_max;
  return {
    taper: round(steps[0].profile[1] * half),
    twist: round((steps[1].angle[1] * half * 180) / Math.PI),
    bend: round((steps[2].rate * 2 * half * 180) / Math.PI),
  };
}

/**
 * Moves the stroke's end `end` (0 or the last index) to `to`, and its neighbours with it, less
 * and less over the first fifth of the stroke's length (weight 1 - smoothstep), so a snapped end
 * does not leave a hook the fit would have to follow. Exact at the end itself.
 */
export function moveEnd(points, end, to) {
  const delta = to.map((c, e) => c - points[end][e]);
  const order = end === 0 ? points.map((_, k) => k) : points.map((_, k) => points.length - 1 - k);
  const lengths = [0];
  for (let k = 1; k < order.length; k++) {
    const a = points[order[k - 1]];
    const b = points[order[k]];
    lengths.push(lengths[k - 1] + Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
  }
  const fade = 0.2 * lengths[lengths.length - 1];
  order.forEach((k, i) => {
    const x = fade > 0 ? Math.min(1, lengths[i] / fade) : 1;
    const w = i === 0 ? 1 : 1 - x * x * (3 - 2 * x);
    if (w > 0) points[k] = points[k].map((c, e) => c + w * delta[e]);
  });
  points[end] = to.slice();
}

/**
 * The sketch a selection of curves is constrained in (docs/recipe.md § sketches): each curve a
 * drawn stroke with a plane (the same plane for all), or an entity of one sketch ("SKETCH.NAME").
 * Returns {sketch, create, entities: [entity names], changes} where changes make the sketch (on
 * the strokes' plane, each stroke a {curve} entity the solver moves) or add the missing entities;
 * null with a reason when the curves cannot be constrained together.
 */
export function sketchFor(recipe, curves) {
  const sketches = recipe.sketches || {};
  const strokes = recipe.strokes || {};
  let sketch = null;
  const entities = [];
  const missing = [];
  let plane = null;
  for (const c of curves) {
    const dot = c.indexOf('.');
    if (dot > 0 && sketches[c.slice(0, dot)]) {
      const s = c.slice(0, dot);
      if (sketch && sketch !== s) return { reason: 'the curves are in two sketches; constrain curves of one sketch' };
      sketch = s;
      entities.push(c.slice(dot + 1));
      continue;
    }
    // a stroke, or a piece "NAME.k" of one split at its corners (entity NAME_k: no dots there)
    const stroke = strokes[strokeOf(recipe, c)];
    if (!stroke || !stroke.plane) return { reason: `"${c}" is not a stroke drawn on a plane (constraints hold on planar sketches: draw it on a plane)` };
    if (plane && JSON.stringify(plane) !== JSON.stringify(stroke.plane)) return { reason: 'the strokes are on different planes; constrain strokes of one plane' };
    plane = stroke.plane;
    missing.push({ entity: c.replace('.', '_'), curve: c });
    entities.push(c.replace('.', '_'));
  }
  if (sketch && plane && JSON.stringify(sketches[sketch].plane) !== JSON.stringify(plane)) return { reason: `the strokes are not on the plane of sketch "${sketch}"` };
  const changes = [];
  let create = false;
  if (!sketch) {
    // a stroke already in a sketch is constrained there
    for (const [name, def] of Object.entries(sketches))
      if (missing.every((m) => def.entities && def.entities[m.entity] && def.entities[m.entity].curve === m.curve)) {
        sketch = name;
        missing.length = 0;
        break;
      }
  }
  if (!sketch) {
    sketch = free(recipe, 'sketch');
    create = true;
    changes.push({ path: `sketches.${sketch}`, value: { plane, points: {}, entities: Object.fromEntries(missing.map((m) => [m.entity, { curve: m.curve }])), constraints: [] }, create: true });
  } else
    for (const m of missing) if (!(sketches[sketch].entities || {})[m.entity]) changes.push({ path: `sketches.${sketch}.entities.${m.entity}`, value: { curve: m.curve }, create: true });
  return { sketch, create, entities, changes };
}

/** The pair of ends, one of each curve net, that lie nearest each other: [["start"|"end", ...], distance]. */
export function nearestEnds(a, b) {
  const end = (c, which) => {
    const n = c.weights.length;
    const k = which === 'start' ? 0 : n - 1;
    return [c.points[3 * k], c.points[3 * k + 1], c.points[3 * k + 2]];
  };
  let best = null;
  for (const ea of ['start', 'end'])
    for (const eb of ['start', 'end']) {
      const p = end(a, ea);
      const q = end(b, eb);
      const d = Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
      if (!best || d < best[1]) best = [[ea, eb], d];
    }
  return best;
}

/**
 * The tokens of a recipe path ("deformations.lift[0].moves[1].by[2]": keys and list indices as
 * numbers), in the kernel's grammar (recipe::parse_path); null for a path it refuses.
 */
export function pathTokens(path) {
  const tokens = [];
  let expectKey = true; // at the start or after '.': a key must come
  for (let i = 0; i < path.length; ) {
    const c = path[i];
    if (c === '[') {
      const close = path.indexOf(']', i);
      const digits = close < 0 ? '' : path.slice(i + 1, close);
      if (!tokens.length || expectKey || !/^[0-9]+$/.test(digits)) return null;
      tokens.push(Number(digits));
      i = close + 1;
    } else if (c === '.') {
      if (expectKey) return null;
      expectKey = true;
      i++;
    } else {
      if (c === ']' || !expectKey) return null;
      let end = i;
      while (end < path.length && !'.[]'.includes(path[end])) end++;
      tokens.push(path.slice(i, end));
      i = end;
      expectKey = false;
    }
  }
  return tokens.length && !expectKey ? tokens : null;
}

/**
 * The recipe with an edit's changes applied as the kernel applied them (studio_session.cpp
 * apply_change: {path, value, create?} sets, {path, remove: true} removes), or null when one
 * does not apply (the page's copy is not the kernel's: ask for the text). The recipe is not
 * changed: the objects along each path are copied, the rest shared, so what another part of the
 * page holds of the old recipe stays as it was.
 */
export function applyChanges(recipe, changes) {
  let root = recipe;
  for (const change of changes) {
    const tokens = pathTokens(String(change.path));
    if (!tokens || tokens.includes('__proto__')) return null; // an assignment would not make that key
    root = { ...root };
    let node = root;
    for (let k = 0; k < tokens.length - 1; k++) {
      const t = tokens[k];
      const child = node[t];
      const has = Object.hasOwn(node, t) && child !== null && typeof child === 'object';
      if (!has && (change.remove || !change.create || typeof t === 'number')) return null;
      node[t] = has ? (Array.isArray(child) ? [...child] : { ...child }) : {};
      node = node[t];
    }
    const last = tokens[tokens.length - 1];
    const present = Array.isArray(node) ? typeof last === 'number' && last < node.length : Object.hasOwn(node, last);
    if (change.remove) {
      if (!present) return null;
      if (Array.isArray(node)) node.splice(last, 1);
      else delete node[last];
    } else {
      if (!present && (!change.create || Array.isArray(node))) return null;
      node[last] = change.value;
    }
  }
  return root;
}

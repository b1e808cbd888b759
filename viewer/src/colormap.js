// Colour maps shared by the shaders and the legend (sRGB stops, linear interpolation between them)
// and the robust, symmetric colour range.

/** Diverging, blue (negative) - white (zero) - red (positive), ColorBrewer RdBu reversed. */
export const DIVERGING = [
  [0.129, 0.4, 0.675],
  [0.404, 0.663, 0.812],
  [0.969, 0.969, 0.969],
  [0.937, 0.541, 0.384],
  [0.698, 0.094, 0.169],
];

/** Sequential, dark (zero) to yellow (largest), viridis. */
export const SEQUENTIAL = [
  [0.267, 0.005, 0.329],
  [0.229, 0.322, 0.546],
  [0.128, 0.567, 0.551],
  [0.369, 0.789, 0.383],
  [0.993, 0.906, 0.144],
];

export function sample(stops, t) {
  const x = Math.min(1, Math.max(0, t)) * (stops.length - 1);
  const i = Math.min(stops.length - 2, Math.floor(x));
  const f = x - i;
  return stops[i].map((c, k) => c + (stops[i + 1][k] - c) * f);
}

export function cssGradient(stops, n = 16) {
  const parts = [];
  for (let i = 0; i <= n; i++) {
    const [r, g, b] = sample(stops, i / n).map((c) => Math.round(255 * c));
    parts.push(`rgb(${r}, ${g}, ${b}) ${((100 * i) / n).toFixed(1)}%`);
  }
  return `linear-gradient(to right, ${parts.join(', ')})`;
}

/** The q-quantile (0..1) of sorted values, linear between order statistics. */
export function quantile(sorted, q) {
  if (sorted.length === 0) return 0;
  const x = q * (sorted.length - 1);
  const i = Math.floor(x);
  const j = Math.min(sorted.length - 1, i + 1);
  return sorted[i] + (sorted[j] - sorted[i]) * (x - i);
}

/** Robust percentiles used for the colour range (2% and 98%): a few spikes do not wash out the map. */
export const ROBUST_LOW = 0.02;
export const ROBUST_HIGH = 0.98;

/**
 * The colour range of a set of Float32Arrays.
 * diverging: symmetric about zero, [-R, R] with R = max(|p2|, |p98|), so white is always zero.
 * sequential (deviation, never negative): [0, max], the largest value is the figure that matters.
 * Non-finite values are left out. Returns {lo, hi, min, max, zero} (zero: every value is 0).
 */
export function colourRange(arrays, diverging) {
  let n = 0;
  for (const a of arrays) n += a.length;
  let all = new Float32Array(n);
  let o = 0;
  for (const a of arrays) {
    all.set(a, o);
    o += a.length;
  }
  if (!all.every(Number.isFinite)) all = all.filter(Number.isFinite); // never NaN ends
  n = all.length;
  all.sort();
  const min = n ? all[0] : 0;
  const max = n ? all[n - 1] : 0;
  const zero = min === 0 && max === 0;
  if (diverging) {
    let r = Math.max(Math.abs(quantile(all, ROBUST_LOW)), Math.abs(quantile(all, ROBUST_HIGH)));
    if (!(r > 0)) r = Math.max(Math.abs(min), Math.abs(max));
    if (!(r > 0)) r = 1;
    return { lo: -r, hi: r, min, max, zero };
  }
  let hi = max > 0 ? max : 1;
  return { lo: 0, hi, min, max, zero };
}

/** Short numbers for figures and legends: 3 significant digits, exponent when very small or large. */
export function formatNumber(x) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return String(x);
  if (x === 0) return '0';
  if (Number.isInteger(x) && Math.abs(x) < 1e7) return String(x);
  const a = Math.abs(x);
  if (a < 1e-3 || a >= 1e5) return x.toExponential(2).replace('e', '\u2009e');
  return String(Number(x.toPrecision(4)));
}

// Which form the view shows (issue #38): read from the last run's step reports, no DOM, so Node
// tests it against the kernel's report (tests/python/test_page_form.py).
/**
 * Which form each deformed surface has, from the last run's steps: "exact", or "light" with how
 * far it may be from the exact (its bound ledger) and the exact form's size it stands for, or a
 * drag's uncertified preview.
 */
export function formShown(steps) {
  const last = new Map();
  for (const s of steps) {
    const m = /^surfaces\.([^.]+)\.(steps\[\d+\]|composition\.budget)$/.exec(s.path);
    if (m && (s.figures.composition !== undefined || s.kind === 'light')) last.set(m[1], s);
  }
  return [...last.entries()]
    .map(([name, s]) => {
      const f = s.figures;
      // a drag update: the light form on its last knots, one product of the lattice's points
      if (f.preview) return `${name}: light form (drag preview, certified when let go)`;
      if (f.composition === 'exact' && f.accumulated_bound_mm === undefined) return `${name}: exact`;
      const bound = f.accumulated_bound_mm !== undefined ? `within ${f.accumulated_bound_mm.toPrecision(2)} mm of the exact` : 'distance from the exact unbounded';
      const size = f.exact_control_points !== undefined ? ` (exact: degree ${f.exact_degree_u}, ${f.exact_control_points} control points)` : '';
      return `${name}: ${f.composition === 'refit' ? 'refit' : 'light form'}, ${bound}${size}`;
    })
    .join('; ');
}

/** The most curvature waves a calm style shows (deform::curvature_waves_calm; docs/deform.md § Rings). */
export const calmWaves = 4;

/**
 * The Style panel's figures from a style step's report figures: how near the target, the join at
 * the bound, the mean curvature inside the region, the net's convergence; and a warning when the
 * result shows rings (its change of mean curvature turns more often than a calm push's along a
 * section of the region: `curvature_waves`).
 */
export function styleSummary(f) {
  const finite = (x) => typeof x === 'number' && Number.isFinite(x);
  const lines = [];
  if (finite(f.target_curve_distance)) lines.push(`target curve within ${f.target_curve_distance.toPrecision(2)} mm`);
  if (finite(f.boundary_tangent_angle)) lines.push(`at the bound: ${f.boundary_position_jump.toPrecision(2)} mm, ${f.boundary_tangent_angle.toPrecision(2)}°`);
  if (finite(f.mean_curvature_min)) lines.push(`mean curvature ${f.mean_curvature_min.toPrecision(2)} … ${f.mean_curvature_max.toPrecision(2)} /mm`);
  if (finite(f.net_change)) lines.push(`net convergence: last halving ${(100 * f.net_change).toPrecision(2)} %`);
  if (finite(f.curvature_waves) && f.curvature_waves >= 0) lines.push(`curvature waves ${f.curvature_waves} (calm: up to ${calmWaves})`);
  const rings = finite(f.curvature_waves) && f.curvature_waves > calmWaves;
  return {
    text: lines.join('\n'),
    warning: rings ? `rings: the curvature turns ${f.curvature_waves} times across the region; try net convergence or paper mode, or a target farther from the bound` : '',
  };
}

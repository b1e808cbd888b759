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

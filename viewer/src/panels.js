// The side panels: one per surface (class surface-panel) with its name, the figures of the step
// that made it, its stages with their before/after toggles and figures, and the current mode's range.
import { formatNumber } from './colormap.js';

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) if (c != null) e.append(c);
  return e;
}

function formatValue(v) {
  if (typeof v === 'number') return formatNumber(v);
  if (typeof v === 'boolean') return v ? 'yes' : 'no';
  if (Array.isArray(v)) return v.map(formatValue).join(', ');
  if (v && typeof v === 'object') return JSON.stringify(v);
  return String(v);
}

// Units of the report's figures (docs/recipe.md, "Figures per kind").
const UNITS = {
  max_deviation_mm: 'mm', sampled_max_mm: 'mm', tolerance_mm: 'mm', rms_deviation_mm: 'mm',
  max_displacement: 'mm', target_deviation: 'mm', target_curve_deviation: 'mm',
  boundary_position_jump: 'mm', boundary_tangent_angle: '°', size: 'mm', seconds: 's',
};

export function figuresTable(figures) {
  const table = el('table', { class: 'figures' });
  const entries = Object.entries(figures || {});
  if (entries.length === 0) {
    table.append(el('tr', {}, el('td', { class: 'none', text: 'no figures' })));
    return table;
  }
  for (const [k, v] of entries) {
    const unit = UNITS[k] && typeof v === 'number' ? ` ${UNITS[k]}` : '';
    const td = el('td', { text: formatValue(v) + unit });
    if (v === false && /^(exact|fold_free|feasible|certified|valid)$/.test(k)) td.className = 'warn';
    table.append(el('tr', {}, el('th', { scope: 'row', text: k.replace(/_/g, ' ') }), td));
  }
  return table;
}

// The class-A figures an edge is held to (issue #38): fillets' tangent angle, curvature matched
// within 1 % where the source was G2, and the positional gap.
const CLASS_A = { angle_deg: 0.016, relative_curvature_jump: 0.01, gap_mm: 0.01 };

/** Whether a model's edge (manifest continuity entry) misses the class-A figures for its class. */
export function edgeMisses(e) {
  if (e.gap_mm > CLASS_A.gap_mm) return true;
  if ((e.class === 'G1' || e.class === 'G2') && e.angle_deg > CLASS_A.angle_deg) return true;
  return e.class === 'G2' && e.relative_curvature_jump > CLASS_A.relative_curvature_jump;
}

/**
 * A model's continuity (manifest `continuity`): a summary line, then its shared edges, worst
 * first (those missing the class-A figures for their class, then by angle), at most `limit`, each
 * with the source's class and figures before. Cells missing a figure are marked `warn`.
 */
export function continuityTable(continuity, limit = 20) {
  const edges = [...(continuity.edges || [])];
  const severity = (e) => (edgeMisses(e) ? 1e9 : 0) + (e.class === 'G0' ? 0 : e.angle_deg);
  edges.sort((a, b) => severity(b) - severity(a));
  const misses = edges.filter(edgeMisses).length;
  const root = el('details', { class: 'continuity', 'data-misses': String(misses) });
  root.open = misses > 0;
  root.append(el('summary', {
    text: `edges: ${continuity.shared_edges} shared, ${misses} off the class-A figures · ` +
      `gap ≤ ${formatNumber(continuity.max_gap_mm)} mm`,
  }));
  const table = el('table', { class: 'figures continuity-edges' });
  table.append(el('tr', {}, ...['edge', 'class', 'gap mm', 'angle °', 'κ jump %', 'before °'].map(
    (t) => el('th', { scope: 'col', text: t }))));
  for (const e of edges.slice(0, limit)) {
    const cell = (text, bad) => el('td', { class: bad ? 'warn' : '', text });
    const tangent = e.class === 'G1' || e.class === 'G2';
    table.append(el('tr', { 'data-edge': String(e.edge) },
      el('th', { scope: 'row', text: `${e.edge} (${e.faces.join('–')})` }),
      cell(e.class || '—', false),
      cell(formatNumber(e.gap_mm), e.gap_mm > CLASS_A.gap_mm),
      cell(formatNumber(e.angle_deg), tangent && e.angle_deg > CLASS_A.angle_deg),
      cell(formatNumber(100 * e.relative_curvature_jump),
        e.class === 'G2' && e.relative_curvature_jump > CLASS_A.relative_curvature_jump),
      cell(e.before ? formatNumber(e.before.angle_deg) : '—', false)));
  }
  if (edges.length > limit) {
    table.append(el('tr', {}, el('td', { class: 'none', text: `… ${edges.length - limit} more in report.json` })));
  }
  root.append(table);
  return root;
}

/**
 * Builds the panel of `surface` (manifest entry) number `index`. `actions`:
 * onToggle(index, stage), onFocus(index), onVisible(index, shown). Returns {root, update(state, stats)}.
 */
export function surfacePanel(surface, index, actions) {
  const name = el('button', { class: 'surface-name', title: 'Fit the camera to this surface', text: surface.name });
  name.addEventListener('click', () => actions.onFocus(index));
  const visible = el('input', { type: 'checkbox', class: 'surface-visible', title: 'Show this surface', checked: '' });
  visible.addEventListener('change', () => actions.onVisible(index, visible.checked));
  const meta = el('div', { class: 'meta' });
  const showing = el('div', { class: 'showing' });
  const stats = el('div', { class: 'stats' });
  const root = el(
    'section',
    { class: 'surface-panel', 'data-surface': String(index) },
    el('h2', {}, visible, name, el('span', { class: 'export', text: surface.export ? ` ${surface.export}` : '' })),
    meta,
    showing,
    stats,
    figuresTable(surface.figures),
    surface.continuity ? continuityTable(surface.continuity) : null,
  );
  meta.textContent =
    surface.mesh.triangles !== undefined
      ? `whole model: ${surface.mesh.triangles} triangles (trimmed faces) · ${surface.mesh.vertices} vertices`
      : `${surface.mesh.rows} × ${surface.mesh.cols} samples · net ${
          surface.net ? `${surface.net.rows} × ${surface.net.cols}` : '—'
        }`;

  const toggles = [];
  const stages = surface.stages || [];
  if (stages.length) {
    const list = el('ol', { class: 'stages' });
    stages.forEach((stage, k) => {
      const toggle = el('button', {
        class: 'stage-toggle',
        'data-surface': String(index),
        'data-stage': String(k),
        'aria-pressed': 'false',
        title: 'Show this step\'s surface before / after it',
        text: 'after',
      });
      toggle.addEventListener('click', () => actions.onToggle(index, k));
      toggles.push(toggle);
      const curves = (stage.curves || []).map((c) => c.name).join(', ');
      list.append(
        el(
          'li',
          {},
          el('div', { class: 'stage-head' },
            el('span', { class: 'stage-label', text: stage.label || stage.step || `stage ${k + 1}` }),
            el('span', { class: 'kind', text: stage.kind ? ` ${stage.kind}` : '' }),
            toggle),
          curves ? el('div', { class: 'curves', text: `curves: ${curves}` }) : null,
          el('details', {}, el('summary', { text: 'figures' }), figuresTable(stage.figures)),
        ),
      );
    });
    root.append(el('h3', { text: 'deformation steps' }), list);
  }

  function update(state, stat) {
    toggles.forEach((t, k) => {
      const before = state.stage === k && state.side === 'before';
      const shown = state.stage === k || (state.stage < 0 && k === toggles.length - 1);
      t.setAttribute('aria-pressed', before ? 'true' : 'false');
      t.textContent = before ? 'before' : 'after';
      t.classList.toggle('shown', shown);
    });
    showing.textContent =
      state.stage < 0 ? 'showing: final surface' : `showing: step ${state.stage + 1} ${state.side}`;
    stats.textContent = stat ? stat.text : '';
    if (stat) {
      stats.dataset.min = String(stat.min);
      stats.dataset.max = String(stat.max);
    } else {
      delete stats.dataset.min;
      delete stats.dataset.max;
    }
  }
  return { root, update };
}

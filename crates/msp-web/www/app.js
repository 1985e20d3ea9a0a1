// The msp tuner: the page's state is a list of pairs keyed by `msp run`'s long
// flags (the URL's query); every number comes from msp's engine (msp_web.js).

import init, { plant as enginePlant, design as engineDesign, draft as engineDraft, tradeoff as engineTradeoff, csv as engineCsv } from './msp_web.js';
import { panel, standalone } from './plot.js';

const $ = (id) => document.getElementById(id);
const NUMBER_FIELDS = ['ts', 'duration', 'noise', 'seed', 'umin', 'umax'];
const LIST_FIELDS = ['setpoint', 'disturbance', 'event'];
// the ids of the shown numbers: the report's controller.params and robustness
const PARAM_IDS = ['kp', 'ti', 'td', 'lambda'];
const MARGIN_IDS = ['ms', 'pm', 'gm', 'dm'];
// the robustness slider's range of the sensitivity peak (one-parameter
// schemes, before their trade-off curve is known) and of the phase margin
// (PI/PID, with the crossover)
const MS_RANGE = [2.6, 1.2];
const PM_RANGE = [30, 80];

/** The trade-off curve's stable points, λ increasing, and its range of Ms. */
function curve() {
  const pts = state.tradeoff ? state.tradeoff.points.filter((p) => p.stable && Number.isFinite(p.ms)) : [];
  if (pts.length < 2) return null;
  const ms = pts.map((p) => p.ms);
  return { pts, hi: Math.max(...ms), lo: Math.min(...ms) };
}

/** The λ at which the curve reaches `ms` (log-λ interpolation, the first crossing from the fast end). */
function lambdaAt(c, ms) {
  for (let i = 1; i < c.pts.length; i++) {
    const a = c.pts[i - 1], b = c.pts[i];
    if ((a.ms - ms) * (b.ms - ms) <= 0 && a.ms !== b.ms) {
      const t = (ms - a.ms) / (b.ms - a.ms);
      return a.lambda * Math.pow(b.lambda / a.lambda, t);
    }
  }
  return ms >= c.hi ? c.pts.reduce((x, p) => (p.ms > x.ms ? p : x)).lambda : c.pts.reduce((x, p) => (p.ms < x.ms ? p : x)).lambda;
}

const state = {
  info: null, // the plant's kind and schemes
  base: null, // the scheme's own design: λ0, the crossover and phase margin
  last: null, // the last design
  tradeoff: null,
  lambda: null, // the tuning given (at most one of lambda and target)
  target: null,
  extra: [], // pairs from the URL the page has no field for (rule, set, …)
  timing: NaN, // ms of the last re-tune, re-run and redraw
  designs: 0,
};

const sig = (x, n = 4) => Number(x.toPrecision(n));
const plain = (x) => (typeof x === 'number' && Number.isFinite(x) ? String(x) : '');
const mode = () => document.querySelector('input[name=mode]:checked').value;

/** The scenario's pairs; `own`: the scheme's own tuning (no λ, no target). */
function pairs(own = false) {
  const p = [['plant', $('plant').value.trim()]];
  const c = $('controller').value;
  if (c) p.push(['controller', c]);
  if (!own && state.lambda !== null) p.push(['lambda', String(state.lambda)]);
  else if (!own && state.target) p.push(['target', state.target]);
  for (const f of NUMBER_FIELDS) {
    const v = $(f).value.trim();
    if (v) p.push([f, v]);
  }
  for (const f of LIST_FIELDS) {
    for (const v of $(f).value.split(';').map((s) => s.trim()).filter(Boolean)) p.push([f, v]);
  }
  return p.concat(state.extra);
}

function pidLike() {
  const c = $('controller').value || (state.info && state.info.default);
  return c === 'pi' || c === 'pid';
}

function call(fn, p) {
  return JSON.parse(fn(JSON.stringify(p)));
}

function showError(id, text) {
  const el = $(id);
  el.hidden = !text;
  el.textContent = text || '';
}

function clearErrors() {
  for (const id of ['plant-error', 'tuning-error', 'scenario-error']) showError(id, '');
  for (const el of document.querySelectorAll('[aria-invalid=true]')) el.removeAttribute('aria-invalid');
}

/** A failure at its field: the plant's with a caret under the column. */
function fail(e) {
  const field = { plant: 'plant', lambda: 'lambda-input', target: 'target-input', controller: 'controller' }[e.key] || $(e.key) && e.key;
  if (field && $(field)) $(field).setAttribute('aria-invalid', 'true');
  if (e.key === 'plant' && e.column) {
    const text = $('plant').value;
    showError('plant-error', `${e.message} at column ${e.column}\n${text}\n${' '.repeat(e.column - 1)}^`);
  } else if (['lambda', 'target', 'controller', 'rule', 'set'].includes(e.key)) {
    showError('tuning-error', e.message);
  } else if (e.key === 'plant') {
    showError('plant-error', e.message);
  } else {
    showError('scenario-error', e.message);
  }
  $('status').textContent = e.message;
  $('status').className = 'bad';
  // no number stands for a design that failed
  state.last = null;
  for (const k of [...PARAM_IDS, ...MARGIN_IDS]) $(k).textContent = '';
  $('other-params').textContent = '';
  $('warnings').innerHTML = '';
  $('command').value = '';
}

/** The plant read: the controller list for its kind. */
function readPlant() {
  const info = JSON.parse(enginePlant($('plant').value));
  if (!info.ok) {
    state.info = null;
    return info;
  }
  const sel = $('controller');
  const keep = sel.value;
  const names = info.schemes.map((s) => s.name);
  const kindChanged = !state.info || state.info.kind !== info.kind;
  if (kindChanged || sel.options.length !== names.length + 1) {
    sel.innerHTML = '';
    sel.append(new Option(`msp's choice (${info.default})`, ''));
    for (const s of info.schemes) sel.append(new Option(s.name, s.name));
  }
  sel.value = names.includes(keep) ? keep : '';
  state.info = info;
  showSummary();
  return info;
}

function showSummary() {
  const name = $('controller').value || (state.info && state.info.default);
  const s = state.info && state.info.schemes.find((q) => q.name === name);
  $('controller-summary').textContent = s ? s.summary : '';
}

/** The scheme's own design (the sliders' centre) and its trade-off. */
function rebase() {
  const base = call(engineDesign, pairs(true));
  state.base = base.ok
    ? {
        lambda: base.report.controller.params.lambda,
        wc: base.report.robustness && base.report.robustness.wcp,
        pm: base.report.robustness && base.report.robustness.pm,
      }
    : null;
  state.tradeoff = null;
  document.body.dataset.state = 'busy';
  drawTradeoff();
  setTimeout(() => {
    const tr = call(engineTradeoff, pairs(true));
    state.tradeoff = tr.ok ? tr : null;
    $('tradeoff-caption').textContent = tr.ok
      ? `Trade-off of ${tr.points[0] ? tr.points[0].scheme : ''}: λ from ⅛ to 8 times the scheme's own, the current design marked`
      : `Trade-off: ${tr.message}`;
    drawTradeoff();
    if (state.last) syncSliders(state.last);
    document.body.dataset.state = 'ready';
  }, 0);
}

/**
 * Re-tunes, re-runs and redraws; the time it took is `state.timing`.
 * `draft`: a slider moving, the robustness warning without its search for
 * a better tuning (retunings and four priced runs wait for the release).
 */
function update(draft = false) {
  const t0 = performance.now();
  clearErrors();
  const p = pairs();
  const d = call(draft ? engineDraft : engineDesign, p);
  const t1 = performance.now();
  history.replaceState(null, '', '?' + new URLSearchParams(p).toString());
  if (!d.ok) {
    fail(d);
    return;
  }
  state.last = d;
  state.designs++;
  showNumbers(d);
  syncSliders(d);
  drawResponse(d);
  drawBode(d);
  drawNyquist(d);
  drawTradeoff();
  $('command').value = d.command;
  state.timing = performance.now() - t0;
  state.engine = t1 - t0;
}

function showNumbers(d) {
  const params = d.report.controller.params;
  const rob = d.report.robustness || {};
  for (const k of PARAM_IDS) $(k).textContent = plain(params[k]);
  for (const k of MARGIN_IDS) $(k).textContent = plain(rob[k]);
  const others = Object.entries(params).filter(([k]) => !PARAM_IDS.includes(k));
  $('other-params').textContent = others.length
    ? `${d.report.controller.name}: ` + others.map(([k, v]) => `${k} = ${sig(v, 6)}`).join(', ')
    : d.report.controller.name;
  const st = $('status');
  const stable = d.report.stable;
  st.className = stable === false ? 'bad' : '';
  st.textContent = `${d.report.controller.name} on ${d.report.plant}, ts = ${d.report.ts} s, ${d.report.samples} samples: ` +
    (stable === true ? 'stable' : stable === false ? 'UNSTABLE' : 'stability undecided') +
    ` (${d.report.stability.reason})`;
  const ul = $('warnings');
  ul.innerHTML = '';
  for (const w of d.report.warnings || []) {
    const li = document.createElement('li');
    li.textContent = w;
    ul.append(li);
  }
}

/** The sliders follow the design (one slider moved, the other shows where it went). */
function syncSliders(d) {
  const b = state.base;
  if (!b) return;
  const params = d.report.controller.params;
  const rob = d.report.robustness || {};
  if (pidLike() && b.wc > 0) {
    if (rob.wcp > 0) $('speed').value = -Math.log2(rob.wcp / b.wc);
    if (Number.isFinite(rob.pm)) $('robustness').value = (rob.pm - PM_RANGE[0]) / (PM_RANGE[1] - PM_RANGE[0]);
  } else {
    if (params.lambda > 0 && b.lambda > 0) $('speed').value = Math.log2(params.lambda / b.lambda);
    const c = curve();
    const [hi, lo] = c && c.hi > c.lo ? [c.hi, c.lo] : MS_RANGE;
    if (Number.isFinite(rob.ms)) $('robustness').value = (hi - rob.ms) / (hi - lo);
  }
  $('speed-value').textContent = params.lambda ? `λ = ${sig(params.lambda, 3)} s` : rob.wcp ? `ωc = ${sig(rob.wcp, 3)} rad/s` : '';
  $('robustness-value').textContent = Number.isFinite(rob.ms) ? `Ms = ${sig(rob.ms, 3)}, pm = ${sig(rob.pm, 3)}°` : '';
}

/** A slider moved: the tuning it stands for. */
function fromSliders(which) {
  const b = state.base;
  if (!b) return;
  const v = Number($('speed').value);
  const r = Number($('robustness').value);
  if (pidLike() && b.wc > 0) {
    const wc = sig(b.wc * Math.pow(2, -v));
    const pm = sig(PM_RANGE[0] + r * (PM_RANGE[1] - PM_RANGE[0]), 3);
    state.lambda = null;
    state.target = `wc=${wc},pm=${pm}`;
  } else if (which === 'speed' && b.lambda > 0) {
    state.lambda = sig(b.lambda * Math.pow(2, v));
    state.target = null;
  } else if (curve() && curve().hi > curve().lo) {
    // along the trade-off curve: the λ whose Ms the slider asks for (a
    // design as cheap as λ's; the curve's own range, always reachable)
    const c = curve();
    state.lambda = sig(lambdaAt(c, c.hi - r * (c.hi - c.lo)));
    state.target = null;
  } else {
    state.lambda = null;
    state.target = `ms=${sig(MS_RANGE[0] + r * (MS_RANGE[1] - MS_RANGE[0]), 3)}`;
  }
}

function fromMode() {
  const m = mode();
  for (const k of ['sliders', 'lambda', 'target']) $(`mode-${k}`).hidden = k !== m;
  if (m === 'lambda') {
    const v = $('lambda-input').value.trim();
    state.lambda = v ? Number(v) : null;
    state.target = null;
  } else if (m === 'target') {
    state.lambda = null;
    state.target = $('target-input').value.trim() || null;
  } else {
    state.lambda = null;
    state.target = null;
  }
}

const BLUE = '#0b5cad', ORANGE = '#c25400', GREY = '#6b7580', GREEN = '#1d7a3a';

function drawResponse(d) {
  const s = d.signals;
  const svg = $('plot-response');
  svg.innerHTML =
    panel([60, 10, 565, 215], [
      { x: s.t, y: s.r, color: GREY, label: 'r', dash: '5 3' },
      { x: s.t, y: s.y, color: BLUE, label: 'y' },
    ], { ylabel: 'output' }) +
    panel([60, 250, 565, 130], [{ x: s.t, y: s.u, color: ORANGE, label: 'u' }], { ylabel: 'control', xlabel: 'time (s)' });
  svg.setAttribute('aria-label', `Responses of ${d.report.controller.name}: y from ${sig(Math.min(...s.y), 3)} to ${sig(Math.max(...s.y), 3)}`);
}

function drawBode(d) {
  const f = d.response;
  const svg = $('plot-bode');
  // the delay turns the phase without end: the plot keeps the first two and a half turns
  const finite = f.phase.filter(Number.isFinite);
  const top = finite.length ? Math.max(...finite) : 0;
  const phaseLim = [Math.max(Math.min(...finite, top - 1), top - 900), top + 10];
  svg.innerHTML =
    panel([60, 10, 565, 180], [{ x: f.w, y: f.magnitude_db, color: BLUE }], { xlog: true, ylabel: '|L| (dB)', hlines: [{ at: 0 }] }) +
    panel([60, 215, 565, 165], [{ x: f.w, y: f.phase, color: ORANGE }], { xlog: true, ylim: phaseLim, ylabel: 'phase (°)', xlabel: 'ω (rad/s)', hlines: [{ at: -180 }] });
  const rob = d.report.robustness || {};
  svg.setAttribute('aria-label', `Bode diagram: gain margin ${plain(rob.gm)}, phase margin ${plain(rob.pm)} degrees`);
}

function drawNyquist(d) {
  const f = d.response;
  const rob = d.report.robustness || {};
  const svg = $('plot-nyquist');
  const circles = [{ cx: -1, cy: 0, r: 1 / (rob.ms || Infinity) || 0, color: GREEN }];
  svg.innerHTML = panel([60, 10, 565, 370], [
    { x: f.re, y: f.im, color: BLUE, label: 'L(jω)' },
    { x: f.re, y: f.im.map((v) => -v), color: BLUE, dash: '3 3' },
  ], {
    xlim: [-3, 1.5], ylim: [-2.2, 2.2], xlabel: 'Re L', ylabel: 'Im L', circles,
    marks: [{ x: -1, y: 0, color: '#a4001d' }],
  });
  svg.setAttribute('aria-label', `Nyquist diagram: Ms ${plain(rob.ms)}`);
}

/** Where the current design's λ sits on the trade-off curve (log-λ interpolation). */
function onCurve(points, lambda, key) {
  for (let i = 1; i < points.length; i++) {
    const a = points[i - 1], b = points[i];
    if (lambda >= a.lambda && lambda <= b.lambda) {
      const t = Math.log(lambda / a.lambda) / Math.log(b.lambda / a.lambda);
      return [a.ms + t * (b.ms - a.ms), a[key] + t * (b[key] - a[key])];
    }
  }
  return [NaN, NaN];
}

function drawTradeoff() {
  const svg = $('plot-tradeoff');
  const tr = state.tradeoff;
  if (!tr) {
    svg.innerHTML = `<text x="320" y="210" text-anchor="middle" font-family="system-ui, sans-serif" font-size="14" fill="#4d5560">${document.body.dataset.state === 'busy' ? 'computing the trade-off…' : 'no trade-off for this design'}</text>`;
    return;
  }
  const pts = tr.points.filter((p) => p.stable && Number.isFinite(p.ms));
  if (!pts.length) {
    svg.innerHTML = '<text x="320" y="210" text-anchor="middle" font-family="system-ui, sans-serif" font-size="14" fill="#4d5560">no stable tuning on the trade-off curve</text>';
    return;
  }
  const lambda = state.last && state.last.report.controller.params.lambda;
  const [sx, sy] = lambda ? onCurve(pts, lambda, 'iae_setpoint') : [NaN, NaN];
  const [lx, ly] = lambda ? onCurve(pts, lambda, 'iae_load') : [NaN, NaN];
  const load = pts.filter((p) => Number.isFinite(p.iae_load));
  svg.innerHTML =
    panel([60, 10, 565, 170], [{ x: pts.map((p) => p.ms), y: pts.map((p) => p.iae_setpoint), color: BLUE, dots: true, label: 'IAE, unit set-point step' }],
      { ylabel: 'IAE', marks: [{ x: sx, y: sy, color: '#a4001d' }] }) +
    panel([60, 210, 565, 170], [{ x: load.map((p) => p.ms), y: load.map((p) => p.iae_load), color: ORANGE, dots: true, label: 'IAE, unit input load' }],
      { ylabel: 'IAE', xlabel: 'Ms (robustness: smaller is more robust)', marks: [{ x: lx, y: ly, color: '#a4001d' }] });
  svg.setAttribute('aria-label', `Trade-off curve of ${pts.length} tunings, the current design marked`);
}

function download(name, type, text) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([text], { type }));
  a.download = name;
  document.body.append(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 0);
}

/** The state of a URL: each field from its flag's key. */
function fromUrl() {
  const q = new URLSearchParams(location.search);
  const lists = Object.fromEntries(LIST_FIELDS.map((f) => [f, []]));
  for (const [k, v] of q) {
    if (k === 'plant') $('plant').value = v;
    else if (k === 'controller') state.pendingController = v;
    else if (k === 'lambda') {
      document.querySelector('input[name=mode][value=lambda]').checked = true;
      $('lambda-input').value = v;
    } else if (k === 'target') {
      document.querySelector('input[name=mode][value=target]').checked = true;
      $('target-input').value = v;
    } else if (NUMBER_FIELDS.includes(k)) $(k).value = v;
    else if (LIST_FIELDS.includes(k)) lists[k].push(v);
    else state.extra.push([k, v]);
  }
  for (const f of LIST_FIELDS) if (lists[f].length) $(f).value = lists[f].join('; ');
}

function replot() {
  clearErrors();
  const info = readPlant();
  if (!info.ok) {
    fail(info);
    return;
  }
  fromMode();
  rebase();
  update();
}

async function main() {
  await init();
  fromUrl();
  const info = readPlant();
  if (info.ok && state.pendingController) $('controller').value = state.pendingController;
  if (state.pendingController && $('controller').value !== state.pendingController) {
    // a scheme the plant's kind does not take: the engine says why
    state.extra.push(['controller', state.pendingController]);
  }
  showSummary();
  replot();
  $('plant').addEventListener('change', replot);
  $('controller').addEventListener('change', () => { state.extra = state.extra.filter(([k]) => k !== 'controller'); showSummary(); replot(); });
  for (const r of document.querySelectorAll('input[name=mode]')) r.addEventListener('change', () => { fromMode(); update(); });
  $('lambda-input').addEventListener('change', () => { fromMode(); update(); });
  $('target-input').addEventListener('change', () => { fromMode(); update(); });
  for (const id of ['speed', 'robustness']) {
    $(id).addEventListener('input', () => { fromSliders(id); update(true); });
    $(id).addEventListener('change', () => update());
  }
  for (const f of [...NUMBER_FIELDS, ...LIST_FIELDS]) {
    $(f).addEventListener('change', f === 'ts' ? replot : update);
  }
  $('export-csv').addEventListener('click', () => {
    const text = engineCsv(JSON.stringify(pairs()));
    if (text.startsWith('{')) fail(JSON.parse(text));
    else download('msp-run.csv', 'text/csv', text);
  });
  $('export-json').addEventListener('click', () => {
    if (state.last) download('msp-report.json', 'application/json', JSON.stringify(state.last.report, null, 2) + '\n');
  });
  $('export-svg').addEventListener('click', () => download('msp-run.svg', 'image/svg+xml', standalone($('plot-response'))));
  $('copy-command').addEventListener('click', async () => {
    $('command').select();
    try {
      await navigator.clipboard.writeText($('command').value);
      $('status').textContent = 'command copied';
    } catch {
      document.execCommand('copy');
    }
  });
  $('form').addEventListener('submit', (e) => e.preventDefault());
}

// for scripts and the browser test: the engine's answers as the page has them
window.msp = {
  pairs: () => pairs(),
  last: () => state.last,
  timing: () => state.timing,
  engine: () => state.engine,
  designs: () => state.designs,
  csv: () => engineCsv(JSON.stringify(pairs())),
};

main().catch((e) => {
  document.body.dataset.state = 'failed';
  $('status').textContent = `the engine did not load: ${e}`;
  $('status').className = 'bad';
});

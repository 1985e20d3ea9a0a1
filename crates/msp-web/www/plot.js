// Plots as SVG text: panels of lines on linear or logarithmic axes, every
// style an attribute so that an exported SVG stands alone.

const FONT = 'font-family="system-ui, sans-serif" font-size="12" fill="#1b1f24"';

/** Ticks at 1, 2, 5 times a power of ten covering [lo, hi]. */
function ticks(lo, hi, n = 5) {
  const span = hi - lo;
  if (!(span > 0)) return [lo];
  const raw = span / n;
  const p = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 5, 10].map((m) => m * p).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) {
    out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  }
  return out;
}

/** Decades of a logarithmic axis. */
function decades(lo, hi) {
  const out = [];
  for (let e = Math.ceil(Math.log10(lo)); e <= Math.floor(Math.log10(hi)); e++) out.push(Math.pow(10, e));
  return out;
}

function label(v) {
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e4 || a < 1e-3) return v.toExponential(0).replace('e+', 'e');
  return String(Number(v.toPrecision(4)));
}

function extent(series, key, positive) {
  let lo = Infinity, hi = -Infinity;
  for (const s of series) {
    for (const v of s[key]) {
      if (Number.isFinite(v) && (!positive || v > 0)) {
        if (v < lo) lo = v;
        if (v > hi) hi = v;
      }
    }
  }
  if (!Number.isFinite(lo)) return [0, 1];
  if (lo === hi) return positive ? [lo / 2, hi * 2] : [lo - 1, hi + 1];
  return [lo, hi];
}

/**
 * One panel: `box` = [x, y, w, h] in the SVG's user units; `series` =
 * [{x, y, color, label, dash}]; options xlog, ylog, xlim, ylim, xlabel,
 * ylabel, marks = [{x, y, color, label}], hlines/vlines = [{at, color}].
 */
export function panel(box, series, o = {}) {
  const [bx, by, bw, bh] = box;
  const xl = o.xlim || extent(series, 'x', o.xlog);
  let yl = o.ylim || extent(series, 'y', o.ylog);
  if (!o.ylim && !o.ylog) {
    const pad = 0.06 * (yl[1] - yl[0]);
    yl = [yl[0] - pad, yl[1] + pad];
  }
  const fx = o.xlog
    ? (v) => bx + (bw * (Math.log10(v) - Math.log10(xl[0]))) / (Math.log10(xl[1]) - Math.log10(xl[0]))
    : (v) => bx + (bw * (v - xl[0])) / (xl[1] - xl[0]);
  const fy = o.ylog
    ? (v) => by + bh - (bh * (Math.log10(v) - Math.log10(yl[0]))) / (Math.log10(yl[1]) - Math.log10(yl[0]))
    : (v) => by + bh - (bh * (v - yl[0])) / (yl[1] - yl[0]);
  const inside = (px, py) => px >= bx - 0.5 && px <= bx + bw + 0.5 && py >= by - 0.5 && py <= by + bh + 0.5;
  let s = `<rect x="${bx}" y="${by}" width="${bw}" height="${bh}" fill="#fff" stroke="#8a939e"/>`;
  const xt = o.xlog ? decades(xl[0], xl[1]) : ticks(xl[0], xl[1]);
  const yt = o.ylog ? decades(yl[0], yl[1]) : ticks(yl[0], yl[1], 4);
  for (const v of xt) {
    const px = fx(v).toFixed(1);
    s += `<line x1="${px}" x2="${px}" y1="${by}" y2="${by + bh}" stroke="#e3e7ec"/>`;
    s += `<text x="${px}" y="${by + bh + 14}" text-anchor="middle" ${FONT}>${label(v)}</text>`;
  }
  for (const v of yt) {
    const py = fy(v).toFixed(1);
    s += `<line x1="${bx}" x2="${bx + bw}" y1="${py}" y2="${py}" stroke="#e3e7ec"/>`;
    s += `<text x="${bx - 5}" y="${(+py + 4).toFixed(1)}" text-anchor="end" ${FONT}>${label(v)}</text>`;
  }
  for (const h of o.hlines || []) {
    if (h.at < yl[0] || h.at > yl[1]) continue;
    const py = fy(h.at).toFixed(1);
    s += `<line x1="${bx}" x2="${bx + bw}" y1="${py}" y2="${py}" stroke="${h.color || '#8a939e'}" stroke-dasharray="4 3"/>`;
  }
  const clip = `clip${Math.round(bx)}_${Math.round(by)}`;
  s += `<clipPath id="${clip}"><rect x="${bx}" y="${by}" width="${bw}" height="${bh}"/></clipPath><g clip-path="url(#${clip})">`;
  for (const c of o.circles || []) {
    const r = Math.abs(fx(c.cx + c.r) - fx(c.cx));
    s += `<ellipse cx="${fx(c.cx).toFixed(1)}" cy="${fy(c.cy).toFixed(1)}" rx="${r.toFixed(1)}" ry="${Math.abs(fy(c.cy + c.r) - fy(c.cy)).toFixed(1)}" fill="none" stroke="${c.color}" stroke-dasharray="4 3"/>`;
  }
  for (const ser of series) {
    let pts = '';
    const parts = [];
    for (let i = 0; i < ser.x.length; i++) {
      const x = ser.x[i], y = ser.y[i];
      const ok = Number.isFinite(x) && Number.isFinite(y) && (!o.xlog || x > 0) && (!o.ylog || y > 0);
      if (ok) {
        const px = fx(x), py = fy(y);
        // far outside the panel a point only breaks the line
        if (Math.abs(px - bx) < 20 * bw && Math.abs(py - by) < 20 * bh) {
          pts += `${px.toFixed(1)},${py.toFixed(1)} `;
          continue;
        }
      }
      if (pts) parts.push(pts);
      pts = '';
    }
    if (pts) parts.push(pts);
    const dash = ser.dash ? ` stroke-dasharray="${ser.dash}"` : '';
    for (const p of parts) {
      s += `<polyline points="${p.trim()}" fill="none" stroke="${ser.color}" stroke-width="1.6"${dash}/>`;
    }
    if (ser.dots) {
      for (let i = 0; i < ser.x.length; i++) {
        if (!Number.isFinite(ser.x[i]) || !Number.isFinite(ser.y[i])) continue;
        const px = fx(ser.x[i]), py = fy(ser.y[i]);
        if (inside(px, py)) s += `<circle cx="${px.toFixed(1)}" cy="${py.toFixed(1)}" r="2.5" fill="${ser.color}"/>`;
      }
    }
  }
  for (const m of o.marks || []) {
    if (!Number.isFinite(m.x) || !Number.isFinite(m.y)) continue;
    const px = fx(m.x), py = fy(m.y);
    s += `<circle cx="${px.toFixed(1)}" cy="${py.toFixed(1)}" r="5.5" fill="none" stroke="${m.color}" stroke-width="2.2"/>`;
  }
  s += '</g>';
  let lx = bx + 8;
  for (const ser of series.filter((q) => q.label)) {
    s += `<line x1="${lx}" x2="${lx + 16}" y1="${by + 10}" y2="${by + 10}" stroke="${ser.color}" stroke-width="2"/>`;
    s += `<text x="${lx + 20}" y="${by + 14}" ${FONT}>${ser.label}</text>`;
    lx += 28 + 7 * ser.label.length;
  }
  if (o.ylabel) s += `<text transform="translate(${bx - 44},${by + bh / 2}) rotate(-90)" text-anchor="middle" ${FONT}>${o.ylabel}</text>`;
  if (o.xlabel) s += `<text x="${bx + bw / 2}" y="${by + bh + 30}" text-anchor="middle" ${FONT}>${o.xlabel}</text>`;
  return s;
}

/** A whole SVG document of `body` (standalone: namespace and size). */
export function standalone(svg) {
  const [, , w, h] = svg.getAttribute('viewBox').split(' ');
  return `<svg xmlns="http://www.w3.org/2000/svg" width="${w}" height="${h}" viewBox="0 0 ${w} ${h}">${svg.innerHTML}</svg>\n`;
}

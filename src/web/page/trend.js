// The trend: up to 8 tags, each its own small WebSocket subscription of raw words,
// sampled into a ring of (time, value) and drawn on one canvas over the last 2 minutes
// (steps: a PLC value holds until it changes). Nothing is drawn while nothing changes
// but the clock, and then only once a second.
import {toNumber, view} from './values.js';

const MAX_TAGS = 8;
const WINDOW_MS = 120000;
const MAX_POINTS = 4000;
const COLORS = ['#3b82f6', '#f59e0b', '#10b981', '#ef4444', '#8b5cf6', '#06b6d4', '#ec4899', '#84cc16'];

// 1, 2 or 5 times a power of ten, at least `raw`.
function niceStep(raw) {
  const p = 10 ** Math.floor(Math.log10(raw));
  for (const m of [1, 2, 5, 10]) if (m * p >= raw) return m * p;
  return 10 * p;
}

export class Trend {
  constructor(canvas, list, app) {
    this.canvas = canvas;
    this.list = list;
    this.app = app;
    this.tags = [];
    this.counter = 0;
    this.dirty = true;
    new ResizeObserver(() => { this.dirty = true; this.draw(); }).observe(canvas);
    setInterval(() => { if (this.tags.length && !document.hidden) this.draw(); }, 1000);
    this.renderList();
  }

  add(tag) {
    if (this.tags.some((t) => t.address === tag.address && t.as === tag.as && t.plc === tag.plc)) return;
    if (this.tags.length >= MAX_TAGS) {
      this.app.toast(`The trend holds ${MAX_TAGS} tags: remove one first`);
      return;
    }
    const used = new Set(this.tags.map((t) => t.color));
    const t = {...tag, id: `t${++this.counter}`, color: COLORS.find((c) => !used.has(c)) ?? COLORS[0],
               words: [], points: [], value: null};
    this.tags.push(t);
    this.app.live.subscribe({op: 'subscribe', id: t.id, plc: t.plc, address: t.address,
                             count: view(t.as).words, as: 'uint16'});
    this.renderList();
  }

  remove(id) {
    this.tags = this.tags.filter((t) => t.id !== id);
    this.app.live.unsubscribe(id);
    this.renderList();
    this.draw();
  }

  onMessage(msg) {
    const t = this.tags.find((x) => x.id === msg.id);
    if (!t) return false;
    if (msg.type === 'error') {
      this.app.toast(`${t.address}: ${msg.error}`);
      this.remove(t.id);
      return true;
    }
    if (msg.type === 'snapshot') t.words = (msg.values ?? []).slice();
    else for (const [offset, value] of msg.changes ?? []) t.words[offset] = value;
    const v = toNumber(t.as, t.words);
    if (v !== null && v !== t.value) {
      t.value = v;
      t.points.push([Date.now(), v]);
      if (t.points.length > MAX_POINTS) t.points.splice(0, t.points.length - MAX_POINTS);
      this.renderList();
      this.draw();
    }
    return true;
  }

  renderList() {
    this.list.textContent = '';
    for (const t of this.tags) {
      const li = document.createElement('li');
      const sw = document.createElement('span');
      sw.className = 'swatch';
      sw.style.background = t.color;
      const name = document.createElement('span');
      name.className = 'tag-name';
      name.textContent = `${t.address}`;
      const as = document.createElement('span');
      as.className = 'dim';
      as.textContent = t.as;
      const value = document.createElement('span');
      value.className = 'tag-value';
      value.textContent = t.value === null ? '' : String(Number.isInteger(t.value) ? t.value : Number(t.value.toPrecision(7)));
      const x = document.createElement('button');
      x.className = 'icon-button small';
      x.title = `Remove ${t.address}`;
      x.textContent = '×';
      x.addEventListener('click', () => this.remove(t.id));
      li.append(sw, name, as, value, x);
      this.list.append(li);
    }
    // No series: the trend folds to its hint line and the grid gets the room.
    document.getElementById('lower')?.classList.toggle('trend-empty', !this.tags.length);
    if (!this.tags.length) {
      const li = document.createElement('li');
      li.className = 'hint';
      li.textContent = 'Select a value in the grid and press t to trend it.';
      this.list.append(li);
    }
  }

  draw() {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = c.clientWidth;
    const h = c.clientHeight;
    c.classList.toggle('empty', !this.tags.length);
    if (!w || !h || !this.tags.length) return;
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = Math.round(w * dpr);
      c.height = Math.round(h * dpr);
    }
    const g = c.getContext('2d');
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, w, h);
    const css = getComputedStyle(document.documentElement);
    const grid = css.getPropertyValue('--line').trim() || '#ccc';
    const text = css.getPropertyValue('--dim').trim() || '#888';
    g.font = '11px ' + (css.getPropertyValue('--mono').trim() || 'monospace');
    const now = Date.now();
    const t0 = now - WINDOW_MS;
    let lo = Infinity;
    let hi = -Infinity;
    for (const t of this.tags) {
      for (let i = 0; i < t.points.length; i++) {
        const [tt, v] = t.points[i];
        if (tt < t0 && i + 1 < t.points.length && t.points[i + 1][0] < t0) continue;
        lo = Math.min(lo, v);
        hi = Math.max(hi, v);
      }
    }
    if (lo === Infinity) { lo = 0; hi = 1; }
    if (lo === hi) { lo -= 1; hi += 1; }
    // As many value lines as fit 18 px apart (at most 5), labels as wide as the widest.
    const top = 8;
    const bottom = 18;
    const right = 8;
    const lines = Math.max(1, Math.min(4, Math.floor((h - top - bottom) / 18)));
    const step = niceStep((hi - lo) / lines);
    lo = Math.floor(lo / step) * step;
    hi = Math.ceil(hi / step) * step;
    if (hi === lo) hi = lo + step;
    const labels = [];
    for (let v = lo; v <= hi + step / 2; v += step) labels.push([v, Number(v.toPrecision(6)).toString()]);
    const left = Math.min(Math.max(40, ...labels.map(([, t]) => g.measureText(t).width + 12)), w / 3);
    const pw = w - left - right;
    const ph = h - top - bottom;
    const x = (tt) => left + ((tt - t0) / WINDOW_MS) * pw;
    const y = (v) => top + (1 - (v - lo) / (hi - lo)) * ph;
    g.strokeStyle = grid;
    g.fillStyle = text;
    g.lineWidth = 1;
    g.textAlign = 'right';
    g.textBaseline = 'middle';
    let lastLabel = -Infinity;  // a label closer than 14 px to the one below is skipped
    for (const [v, label] of labels) {
      const yy = Math.round(y(v)) + 0.5;
      g.beginPath();
      g.moveTo(left, yy);
      g.lineTo(w - right, yy);
      g.stroke();
      if (Math.abs(lastLabel - yy) < 14) continue;
      g.fillText(label, left - 6, yy);
      lastLabel = yy;
    }
    // Time labels: the smallest of 10, 20, 30, 60 or 120 s whose labels keep a gap.
    const widest = g.measureText('-120s').width + 10;
    const every = [10, 20, 30, 60, 120].find((s) => (s / (WINDOW_MS / 1000)) * pw >= widest) ?? 120;
    g.textAlign = 'center';
    g.textBaseline = 'top';
    // From "now" leftwards; a label that would touch the one drawn before is skipped.
    let edge = Infinity;
    for (let s = 0; s <= WINDOW_MS / 1000; s += every) {
      const xx = Math.round(x(now - s * 1000)) + 0.5;
      const label = s === 0 ? 'now' : `-${s}s`;
      const half = g.measureText(label).width / 2;
      const cx = Math.max(left + half, Math.min(xx, w - right - half));
      if (cx + half + 6 > edge) continue;
      g.fillText(label, cx, h - bottom + 4);
      edge = cx - half;
    }
    g.lineWidth = 1.5;
    for (const t of this.tags) {
      if (!t.points.length) continue;
      g.strokeStyle = t.color;
      g.beginPath();
      let started = false;
      let prev = null;
      for (const [tt, v] of t.points) {
        const xx = Math.max(left, x(tt));
        if (!started) { g.moveTo(xx, y(v)); started = true; }
        else { g.lineTo(xx, y(prev)); g.lineTo(xx, y(v)); }
        prev = v;
      }
      g.lineTo(x(now), y(prev));
      g.stroke();
    }
  }
}

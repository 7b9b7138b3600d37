// The Scenario panel: the running scenario's tags (GET /api/scenario), each shown in its
// own type with a trend button; its status and events (the WebSocket's status topic); and
// pause / resume / advance / trigger (POST /api/control {"cmd":"scenario"}) when control
// is on. The tags' words come over the WebSocket as raw words, a few subscriptions of
// neighbouring words (not one per tag: a connection has 64), decoded here like the grid's.
import {getJson, ApiError} from './api.js';
import {format, toNumber} from './values.js';

const $ = (id) => document.getElementById(id);

// A subscription covers at most this many words; the panel uses at most MAX_SUBS of them.
const SPAN = 512;
const MAX_SUBS = 24;
const MAX_ROWS = 500;  // tags shown in the table

// The scenario's types (src/scenario/definition.hpp) -> the page's views (values.js).
const VIEW_OF = {int16: 'int16', uint16: 'uint16', int32: 'int32', uint32: 'uint32', float: 'float',
                 double: 'double', bcd: 'bcd', bool: 'bool'};
const WORDS_OF = {int16: 1, uint16: 1, int32: 2, uint32: 2, float: 2, double: 4, bcd: 1, bool: 1};

function el(tag, className, text) {
  const e = document.createElement(tag);
  if (className) e.className = className;
  if (text !== undefined && text !== null) e.textContent = String(text);
  return e;
}

function seconds(s) {
  if (typeof s !== 'number' || !Number.isFinite(s)) return '—';
  if (Math.abs(s) < 120) return `${Number(s.toFixed(1))} s`;
  if (Math.abs(s) < 7200) return `${Math.floor(s / 60)} min ${Math.round(s % 60)} s`;
  return `${(s / 3600).toFixed(1)} h`;
}

export class ScenarioPanel {
  // app: {live, plc(), control(), control_(cmd) -> Promise, toast, addTrend(tag)};
  // locate(text) -> {area, word} or {error}, with the bit of "D100.03" as `bit`.
  constructor(app, locate, onTags) {
    this.app = app;
    this.locate = locate;
    this.onTags = onTags;  // the grid repaints its tagged cells
    this.plc = undefined;
    this.def = null;       // the GET /api/scenario answer
    this.key = '';         // what the definition was loaded for (plc, source, reloads)
    this.tags = [];        // [{address, type, view, words, kind, area, word, bit, sub}]
    this.subs = [];        // [{id, kind, prefix, first, count, values: []} or a typed one]
    this.byWord = new Map();  // "D:100" -> the tags whose words include D100
    this.status = null;
    this.frame = 0;
    this.loading = false;
    this.eventNames = null;  // the events the rows were made for
    this.eventRows = [];
    const form = $('scenario-advance');
    form.addEventListener('submit', (e) => {
      e.preventDefault();
      const s = Number($('scenario-seconds').value);
      this.act({action: 'advance', seconds: s});
    });
    $('scenario-pause').addEventListener('click', () => {
      this.act({action: this.status && this.status.paused ? 'resume' : 'pause'});
    });
  }

  // The status object's "scenario" (null: none) for the CPU Unit `plc`.
  update(plc, sc) {
    const panel = $('scenario-panel');
    if (plc !== this.plc) {
      this.clear();
      this.plc = plc;
    }
    panel.hidden = !sc;
    this.status = sc ?? null;
    if (!sc) {
      if (this.def) this.clear();
      return;
    }
    const key = `${plc}|${sc.source ?? ''}|${sc.reloads ?? 0}`;
    if (key !== this.key && !this.loading) this.load(key);
    this.renderStatus();
    this.renderEvents();
    this.markControls();
  }

  clear() {
    for (const s of this.subs) this.app.live.unsubscribe(s.id);
    this.subs = [];
    this.tags = [];
    this.byWord.clear();
    this.def = null;
    this.key = '';
    this.eventNames = null;
    $('scenario-tags').textContent = '';
    if (this.onTags) this.onTags();
  }

  async load(key) {
    this.loading = true;
    try {
      const plc = this.plc;
      const def = await getJson('/api/scenario', {plc});
      if (plc !== this.plc) return;
      this.clear();
      this.def = def;
      this.key = key;
      this.build(def);
    } catch (e) {
      this.key = key;  // asked again only when the scenario changes (reload, another file)
      if (!(e instanceof ApiError && e.status === 404)) this.app.toast(`scenario: ${e.message}`);
    } finally {
      this.loading = false;
    }
  }

  // Tags -> the fewest subscriptions of raw words that cover them (SPAN words each).
  build(def) {
    const tags = (def.tags ?? []).slice(0, MAX_ROWS).map((t) => {
      const type = String(t.type);
      const bit = /\.([0-9]+)$/.exec(String(t.address));
      // A bool without a bit number is a completion or task flag (T5, TK2): not a word.
      const r = type === 'bool' && !bit ? null : this.locate(String(t.address));
      return {address: String(t.address), type, kind: t.kind ?? '', view: VIEW_OF[type] ?? 'uint16',
              words: type === 'bool' ? 1 : (t.words ?? WORDS_OF[type] ?? 1),
              area: r && !r.error ? r.area : null, word: r && !r.error ? r.word : null,
              bit: bit ? Number(bit[1]) : null, sub: null};
    });
    const located = tags.filter((t) => t.area).sort((a, b) =>
      a.area.prefix === b.area.prefix ? a.word - b.word : (a.area.prefix < b.area.prefix ? -1 : 1));
    let n = 0;
    for (const t of located) {
      const last = this.subs[this.subs.length - 1];
      const end = t.word + t.words;
      if (last && last.prefix === t.area.prefix && end - last.first <= SPAN && last.kind === 'words') {
        last.count = Math.max(last.count, end - last.first);
        t.sub = last;
        continue;
      }
      if (this.subs.length >= MAX_SUBS) continue;
      const s = {id: `sc${++n}`, kind: 'words', prefix: t.area.prefix, first: t.word,
                 count: Math.min(t.words, t.area.words - t.word), values: []};
      this.subs.push(s);
      t.sub = s;
    }
    // Addresses the grid's areas do not hold (a timer's completion flag T5, TK2): one
    // subscription each, in the tag's own type.
    for (const t of tags) {
      if (t.area || this.subs.length >= MAX_SUBS) continue;
      const s = {id: `sc${++n}`, kind: 'typed', address: t.address, values: [],
                 as: t.type === 'bool' ? 'bits' : t.view};
      this.subs.push(s);
      t.sub = s;
    }
    for (const s of this.subs) {
      const sub = s.kind === 'words'
        ? {op: 'subscribe', id: s.id, plc: this.plc, address: `${s.prefix}${s.first}`, count: s.count, as: 'uint16'}
        : {op: 'subscribe', id: s.id, plc: this.plc, address: s.address, count: 1, as: s.as};
      this.app.live.subscribe(sub);
    }
    this.tags = tags;
    for (const t of tags) {
      if (!t.area) continue;
      for (let i = 0; i < t.words; i++) {
        const k = `${t.area.prefix}:${t.word + i}`;
        if (!this.byWord.has(k)) this.byWord.set(k, []);
        this.byWord.get(k).push(t);
      }
    }
    this.renderTags();
    if (this.onTags) this.onTags();
  }

  onMessage(msg) {
    const s = this.subs.find((x) => x.id === msg.id);
    if (!s) return false;
    if (msg.type === 'error') {
      s.error = msg.error;
    } else if (msg.type === 'snapshot') {
      s.values = (msg.values ?? []).slice();
    } else {
      for (const [offset, value] of msg.changes ?? []) s.values[offset] = value;
    }
    if (!this.frame) this.frame = requestAnimationFrame(() => { this.frame = 0; this.paintValues(); });
    return true;
  }

  // The words of tag `t` (lowest address first), undefined while unknown.
  wordsOf(t) {
    const s = t.sub;
    if (!s) return [];
    if (s.kind === 'typed') return [s.values[0]];
    const out = [];
    for (let i = 0; i < t.words; i++) out.push(s.values[t.word - s.first + i]);
    return out;
  }

  // {text, number} of tag `t` in its type.
  value(t) {
    const w = this.wordsOf(t);
    if (!w.length || w.some((x) => x === undefined)) return {text: t.sub && t.sub.error ? t.sub.error : '', number: null};
    if (t.sub.kind === 'typed' && t.type !== 'bool') {
      const x = Number(w[0]);
      return {text: String(w[0]), number: Number.isFinite(x) ? x : null};
    }
    if (t.type === 'bool') {
      const v = t.sub.kind === 'typed' || t.bit === null ? (w[0] ? 1 : 0) : (w[0] >> t.bit) & 1;
      return {text: v ? 'ON (1)' : 'OFF (0)', number: v};
    }
    return {text: format(t.view, w), number: toNumber(t.view, w)};
  }

  // The tag whose words include `word` of the area `prefix`, for the grid.
  tagsAt(prefix, word) {
    return this.byWord.get(`${prefix}:${word}`) ?? [];
  }

  renderTags() {
    const table = $('scenario-tags');
    table.textContent = '';
    const head = el('tr');
    for (const h of ['tag', 'type', 'value', '']) head.append(el('th', '', h));
    table.append(head);
    for (const t of this.tags) {
      const tr = el('tr');
      tr.dataset.address = t.address;
      tr.dataset.test = `scenario-tag-${t.address}`;
      const addr = el('td', 'tag-address', t.address);
      addr.title = `${t.kind} signal`;
      const value = el('td', 'tag-value');
      value.dataset.test = 'scenario-value';
      const b = el('button', 'icon-button small trend-button', '↗');
      b.title = `Add ${t.address} (${t.type}) to the trend`;
      b.dataset.test = 'scenario-trend';
      b.addEventListener('click', () => this.trend(t));
      const cell = el('td');
      cell.append(b);
      tr.append(addr, el('td', 'dim tag-type', t.type), value, cell);
      table.append(tr);
      t.row = value;
    }
    const total = this.def ? this.def.tags_total ?? this.tags.length : 0;
    if (total > this.tags.length) {
      const tr = el('tr', 'empty');
      const td = el('td', 'dim', `${total - this.tags.length} more tags not shown`);
      td.colSpan = 4;
      tr.append(td);
      table.append(tr);
    }
    if (!this.tags.length) {
      const tr = el('tr', 'empty');
      const td = el('td', 'dim', 'no tags');
      td.colSpan = 4;
      tr.append(td);
      table.append(tr);
    }
    this.paintValues();
  }

  paintValues() {
    for (const t of this.tags) {
      if (!t.row) continue;
      const {text} = this.value(t);
      if (t.row.textContent !== text) t.row.textContent = text;
    }
    if (this.onTags) this.onTags(true);
  }

  trend(t) {
    // A bit as the trend's one word read at the bit address (0 or 1); else the type's view.
    this.app.addTrend({plc: this.plc, address: t.address,
                       as: t.type === 'bool' ? 'uint16' : t.view});
  }

  renderStatus() {
    const sc = this.status;
    const dl = $('scenario-facts');
    dl.textContent = '';
    const state = sc.paused ? 'paused' : 'running';
    const facts = [
      ['state', `${state} · ${sc.time ?? ''} time${sc.time === 'real' && sc.time_scale !== 1 ? ` ×${sc.time_scale}` : ''}`],
      ['time', `${seconds(sc.time_s)} · ${Number(sc.ticks ?? 0).toLocaleString('en')} ticks of ${sc.tick_ms} ms`],
      ['writes', `${Number(sc.writes ?? 0).toLocaleString('en')}${sc.skipped_writes ? ` (${sc.skipped_writes} skipped)` : ''}`],
      ['source', sc.source ?? ''],
    ];
    for (const [k, v] of facts) {
      const dd = el('dd', '', v);
      dd.dataset.test = `scenario-${k}`;
      dl.append(el('dt', '', k), dd);
    }
    const pause = $('scenario-pause');
    pause.textContent = sc.paused ? 'Resume' : 'Pause';
    pause.setAttribute('aria-pressed', String(!!sc.paused));
  }

  // The events' rows are made once per list of names and then only their text changes
  // (the status comes twice a second: a button must not be replaced under the pointer).
  renderEvents() {
    const table = $('scenario-events');
    const events = this.status.events ?? [];
    $('scenario-events-title').hidden = !events.length;
    const names = events.map((e) => e.name).join('\n') + `|${this.def ? 'def' : ''}`;
    if (names !== this.eventNames) {
      this.eventNames = names;
      table.textContent = '';
      if (events.length) {
        const head = el('tr');
        for (const h of ['event', 'state', 'next start', '']) head.append(el('th', '', h));
        table.append(head);
      }
      const defs = this.def && Array.isArray(this.def.events) ? this.def.events : [];
      this.eventRows = events.map((e, i) => {
        const tr = el('tr');
        tr.dataset.test = `scenario-event-${e.name}`;
        const name = el('td', '', e.name);
        const d = defs[i];
        name.title = d ? `${d.fault}${d.address ? ' on ' + d.address : ''}${d.duration_s ? ` for ${d.duration_s} s` : ''}`
                       : (e.fault ?? '');
        const b = el('button', 'small-button', 'Trigger');
        b.dataset.test = 'scenario-trigger';
        b.dataset.control = 'scenario';
        b.title = `Start ${e.name} now`;
        b.addEventListener('click', () => this.act({action: 'trigger', event: e.name}));
        const cell = el('td');
        cell.append(b);
        const state = el('td');
        const next = el('td');
        tr.append(name, state, next, cell);
        table.append(tr);
        return {state, next};
      });
    }
    const now = this.status.time_s ?? 0;
    events.forEach((e, i) => {
      const row = this.eventRows[i];
      const text = e.active ? 'active' : 'idle';
      if (row.state.textContent !== text) row.state.textContent = text;
      row.state.className = e.active ? 'active' : 'dim';
      const next = typeof e.next_start_s === 'number'
        ? `${seconds(e.next_start_s)} (in ${seconds(e.next_start_s - now)})` : 'never';
      if (row.next.textContent !== next) row.next.textContent = next;
    });
  }

  markControls() {
    const off = !this.app.control();
    for (const c of $('scenario-panel').querySelectorAll('#scenario-actions button, #scenario-actions input, [data-control=scenario]')) {
      c.disabled = off;
      if (off) c.title = 'Read only: finsd was started without --http-control';
    }
  }

  async act(body) {
    try {
      const r = await this.app.control_({cmd: 'scenario', plc: this.plc, ...body});
      if (body.action === 'advance' && r && typeof r.ticks === 'number') {
        this.app.toast(`advanced ${r.ticks} ticks`, 'ok');
      }
    } catch (e) {
      if (e && e.message && !(e instanceof ApiError)) this.app.toast(e.message);
    }
  }
}

// The memory grid: one area (or EM bank) of the selected CPU Unit, virtualised (only the
// rows on screen exist in the DOM) and live (the rows on screen, plus a margin, are one
// WebSocket subscription of raw words; moving far enough re-subscribes).
import {VIEWS, view, format, parseEdit} from './values.js';

const ROW_HEIGHT = 22;
const MARGIN_ROWS = 12;
const MAX_SUBSCRIBED_WORDS = 1000;
const FLASH_MS = 700;

// Rows start at round decimal addresses, as engineers count words; a double takes 4.
// A narrow grid (a phone) has half as many one-word cells a row, so values stay legible.
const NARROW_PX = 600;
function wordsPerRow(viewId, narrow = false) {
  if (viewId === 'bits') return narrow ? 2 : 5;
  if (view(viewId).words === 4) return 8;
  return narrow && view(viewId).words === 1 ? 5 : 10;
}

export class Grid {
  // app: {live, plc(), control(), write(body) -> Promise, toast(text), addTrend(tag)}
  constructor(root, app) {
    this.app = app;
    this.root = root;
    this.head = root.querySelector('#grid-head');
    this.scroller = root.querySelector('#grid-scroll');
    this.spacer = root.querySelector('#grid-spacer');
    this.rowsBox = root.querySelector('#grid-rows');
    this.message = document.getElementById('grid-message');
    this.area = {prefix: 'D', words: 32768, label: 'D'};
    this.viewId = 'uint16';
    this.words = new Map();      // absolute word -> value
    this.flash = new Map();      // absolute word -> time it changed
    this.selected = 0;           // absolute word of the selected value
    this.bit = 15;               // the selected bit in the bits view
    this.sub = null;             // {id, first, count}
    this.subCounter = 0;
    this.editing = null;
    this.frame = 0;
    this.tagTypes = false;       // "Tag types": a scenario tag's cells show its own type
    this.tagSource = null;       // {tagsAt(prefix, word) -> tags, value(tag) -> {text}}
    this.scroller.addEventListener('scroll', () => this.schedule());
    this.narrow = false;
    new ResizeObserver(() => this.resized()).observe(this.scroller);
    this.rowsBox.addEventListener('mousedown', (e) => this.onMouseDown(e));
    this.rowsBox.addEventListener('dblclick', (e) => this.onDoubleClick(e));
    root.addEventListener('keydown', (e) => this.onKey(e));
  }

  address(word, bit) {
    // Bit numbers with two digits, as format_address prints them (CIO0.05).
    return `${this.area.prefix}${word}${bit === undefined ? '' : '.' + String(bit).padStart(2, '0')}`;
  }

  // Shows `area` from `word`, keeping the view.
  show(area, word = 0) {
    const changed = area.prefix !== this.area.prefix;
    this.area = area;
    if (changed) {
      this.words.clear();
      this.flash.clear();
    }
    this.selected = Math.max(0, Math.min(word, area.words - 1));
    this.layout();
    this.scrollTo(this.selected, true);
    this.resubscribe(true);
  }

  setView(viewId) {
    this.viewId = view(viewId).id;
    const w = view(this.viewId).words;
    this.selected -= this.selected % w;
    this.layout();
    this.scrollTo(this.selected, true);
    this.schedule();
    this.root.dispatchEvent(new CustomEvent('viewchange', {bubbles: true}));
  }

  // After a CPU Unit change: everything known is someone else's memory.
  reset() {
    this.words.clear();
    this.flash.clear();
    this.resubscribe(true);
  }

  wpr() {
    return wordsPerRow(this.viewId, this.narrow);
  }

  // The grid's width crossed NARROW_PX: fewer cells a row, the selection kept in view.
  resized() {
    const narrow = this.scroller.clientWidth > 0 && this.scroller.clientWidth < NARROW_PX;
    if (narrow !== this.narrow) {
      this.narrow = narrow;
      if (this.rows) {
        this.layout();
        this.scrollTo(this.selected, true);
        this.resubscribe(true);
        return;
      }
    }
    this.schedule();
  }

  layout() {
    const wpr = this.wpr();
    const per = view(this.viewId).words;
    this.rows = Math.ceil(this.area.words / wpr);
    this.spacer.style.height = `${this.rows * ROW_HEIGHT}px`;
    this.root.dataset.view = this.viewId;
    const cells = ['<span class="addr">Address</span>'];
    for (let c = 0; c < wpr; c += per) cells.push(`<span class="cell">+${c}</span>`);
    this.head.innerHTML = cells.join('');
    this.head.style.setProperty('--cols', String(wpr / per));
    this.rowsBox.style.setProperty('--cols', String(wpr / per));
    this.rowsBox.textContent = '';
    this.rowEls = [];
  }

  scrollTo(word, center = false) {
    const row = Math.floor(word / this.wpr());
    const top = row * ROW_HEIGHT;
    const h = this.scroller.clientHeight;
    if (center) {
      this.scroller.scrollTop = Math.max(0, top - ROW_HEIGHT * 2);
    } else if (top < this.scroller.scrollTop) {
      this.scroller.scrollTop = top;
    } else if (top + ROW_HEIGHT > this.scroller.scrollTop + h) {
      this.scroller.scrollTop = top + ROW_HEIGHT - h;
    }
    this.schedule();
  }

  schedule() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.render();
      this.resubscribe(false);
    });
  }

  visibleRows() {
    const first = Math.floor(this.scroller.scrollTop / ROW_HEIGHT);
    const n = Math.ceil(this.scroller.clientHeight / ROW_HEIGHT) + 1;
    return [first, Math.min(this.rows, first + n)];
  }

  // Subscribes the rows on screen plus a margin when they leave the subscribed range.
  resubscribe(force) {
    if (!this.rows) return;  // not laid out yet: show() subscribes
    const wpr = this.wpr();
    const [r0, r1] = this.visibleRows();
    const need0 = r0 * wpr;
    const need1 = Math.min(this.area.words, r1 * wpr);
    const s = this.sub;
    if (!force && s && s.prefix === this.area.prefix && need0 >= s.first && need1 <= s.first + s.count) return;
    let first = Math.max(0, (r0 - MARGIN_ROWS) * wpr);
    let last = Math.min(this.area.words, (r1 + MARGIN_ROWS) * wpr);
    if (last - first > MAX_SUBSCRIBED_WORDS) last = first + MAX_SUBSCRIBED_WORDS;
    if (last <= first) return;
    if (s) this.app.live.unsubscribe(s.id);
    const id = `g${++this.subCounter}`;
    this.sub = {id, prefix: this.area.prefix, first, count: last - first};
    this.app.live.subscribe({op: 'subscribe', id, plc: this.app.plc(), address: this.address(first),
                             count: last - first, as: 'uint16'});
  }

  // A WebSocket message for a grid subscription. Returns false when it is not ours.
  onMessage(msg) {
    const s = this.sub;
    if (!s || msg.id !== s.id) return typeof msg.id === 'string' && msg.id.startsWith('g');
    if (msg.type === 'error') {
      this.message.textContent = `${this.address(s.first)}: ${msg.error}`;
      this.message.classList.add('bad');
      return true;
    }
    this.message.classList.remove('bad');
    this.message.textContent = '';
    const now = performance.now();
    if (msg.type === 'snapshot') {
      if (!this.shown) {
        this.shown = true;
        performance.mark('finsd-first-values');  // bench/web_page.py: interactive
      }
      const values = msg.values ?? [];
      for (let i = 0; i < s.count; i++) {
        const w = s.first + i;
        const v = values[i];
        if (v === undefined) this.words.delete(w);
        else {
          if (this.words.has(w) && this.words.get(w) !== v) this.flash.set(w, now);
          this.words.set(w, v);
        }
      }
    } else {
      for (const [offset, value] of msg.changes ?? []) {
        const w = s.first + offset;
        if (this.words.has(w) && this.words.get(w) !== value) this.flash.set(w, now);
        this.words.set(w, value);
      }
    }
    this.schedule();
    if (this.flash.size) setTimeout(() => this.schedule(), FLASH_MS + 20);
    return true;
  }

  cellWords(word) {
    const per = view(this.viewId).words;
    const out = new Array(per);
    for (let i = 0; i < per; i++) out[i] = this.words.get(word + i);
    return out;
  }

  render() {
    if (!this.rowEls) return;
    const wpr = this.wpr();
    const per = view(this.viewId).words;
    const [r0, r1] = this.visibleRows();
    const n = r1 - r0;
    while (this.rowEls.length < n) {
      const row = document.createElement('div');
      row.className = 'row';
      const addr = document.createElement('span');
      addr.className = 'addr';
      row.append(addr);
      for (let c = 0; c < wpr; c += per) {
        const cell = document.createElement('span');
        cell.className = 'cell';
        row.append(cell);
      }
      this.rowsBox.append(row);
      this.rowEls.push(row);
    }
    while (this.rowEls.length > n) this.rowEls.pop().remove();
    this.rowsBox.style.transform = `translateY(${r0 * ROW_HEIGHT}px)`;
    const now = performance.now();
    for (const [w, t] of this.flash) if (now - t > FLASH_MS) this.flash.delete(w);
    for (let i = 0; i < n; i++) {
      const row = this.rowEls[i];
      const base = (r0 + i) * wpr;
      row.firstChild.textContent = this.address(base);
      let cell = row.firstChild.nextSibling;
      for (let c = 0; c < wpr; c += per, cell = cell.nextSibling) {
        const word = base + c;
        this.paintCell(cell, word);
      }
    }
  }

  // The scenario tags whose words include one of the cell at `word`.
  tagged(word) {
    if (!this.tagSource) return [];
    const per = view(this.viewId).words;
    if (per === 1) return this.tagSource.tagsAt(this.area.prefix, word);
    const out = new Set();
    for (let i = 0; i < per; i++) for (const t of this.tagSource.tagsAt(this.area.prefix, word + i)) out.add(t);
    return [...out];
  }

  // The scenario's tags or their values changed.
  tagsChanged(valuesOnly) {
    if (!valuesOnly || this.tagTypes) this.schedule();
  }

  setTagTypes(on) {
    this.tagTypes = on;
    this.schedule();
  }

  paintCell(cell, word) {
    if (word >= this.area.words) {
      cell.className = 'cell void';
      cell.textContent = '';
      delete cell.dataset.word;
      return;
    }
    cell.dataset.word = String(word);
    if (this.editing && this.editing.word === word) return;
    const words = this.cellWords(word);
    const text = format(this.viewId, words);
    let cls = 'cell';
    if (word === this.selected) cls += ' selected';
    if (words.some((_, i) => this.flash.has(word + i))) cls += ' changed';
    if (text === '') cls += ' unknown';
    else if (this.viewId !== 'bits' && this.viewId !== 'ascii' && words.every((x) => x === 0)) cls += ' zero';
    cell.className = cls;
    if (this.viewId === 'bits') {
      if (cell.childElementCount !== 16) {
        cell.textContent = '';
        for (let b = 15; b >= 0; b--) {
          const bit = document.createElement('i');
          bit.dataset.bit = String(b);
          cell.append(bit);
        }
      }
      const w = words[0] ?? 0;
      let b = 15;
      for (const el of cell.children) {
        el.className = (text !== '' && (w >> b) & 1 ? 'on' : '') + (word === this.selected && b === this.bit ? ' sel' : '');
        b--;
      }
      cell.title = `${this.address(word)} = ${text === '' ? '?' : '0x' + (w.toString(16).toUpperCase().padStart(4, '0'))}`;
    } else {
      const tagged = this.tagged(word);
      let shown = text;
      if (tagged.length) {
        cell.classList.add('tagged');
        const first = tagged.find((t) => t.word === word && t.type !== 'bool');
        if (this.tagTypes) {
          if (first) {
            shown = this.tagSource.value(first).text;
            cell.classList.add('tag-start');
          } else if (tagged.some((t) => t.type !== 'bool' && t.word < word)) {
            shown = '';
            cell.classList.add('tag-cont');
          }
        }
      }
      if (cell.textContent !== shown) cell.textContent = shown;
      cell.title = tagged.length
        ? `${this.address(word)}\n` + tagged.map((t) => `tag ${t.address} (${t.type}) = ${this.tagSource.value(t).text}`).join('\n')
        : this.address(word);
    }
  }

  onMouseDown(e) {
    const cell = e.target.closest('.cell');
    if (!cell || cell.dataset.word === undefined) return;
    const word = Number(cell.dataset.word);
    this.select(word);
    if (this.viewId === 'bits' && e.target.dataset.bit !== undefined) {
      this.bit = Number(e.target.dataset.bit);
      if (e.detail === 1) this.toggleBit(word, this.bit);
      this.schedule();
    }
    this.root.focus({preventScroll: true});
    e.preventDefault();
  }

  onDoubleClick(e) {
    const cell = e.target.closest('.cell');
    if (!cell || cell.dataset.word === undefined || this.viewId === 'bits') return;
    this.beginEdit(Number(cell.dataset.word));
  }

  select(word) {
    const per = view(this.viewId).words;
    word = Math.max(0, Math.min(word, this.area.words - per));
    this.selected = word - (word % per);
    this.scrollTo(this.selected);
    this.root.dispatchEvent(new CustomEvent('selectionchange', {bubbles: true}));
  }

  selectedTag() {
    return {plc: this.app.plc(), address: this.address(this.selected), as: this.viewId === 'bits' ||
            this.viewId === 'ascii' || this.viewId === 'hex' ? 'uint16' : this.viewId};
  }

  onKey(e) {
    if (this.editing || e.ctrlKey || e.metaKey || e.altKey) return;
    const wpr = this.wpr();
    const per = view(this.viewId).words;
    const page = Math.max(1, Math.floor(this.scroller.clientHeight / ROW_HEIGHT) - 1) * wpr;
    const moves = {
      ArrowLeft: -per, ArrowRight: per, ArrowUp: -wpr, ArrowDown: wpr, PageUp: -page, PageDown: page,
    };
    if (this.viewId === 'bits' && (e.key === 'ArrowLeft' || e.key === 'ArrowRight')) {
      // Bits run 15 (left) to 0 (right) inside a word, then on to the next word.
      const right = e.key === 'ArrowRight';
      if (right && this.bit === 0) { this.bit = 15; this.select(this.selected + 1); }
      else if (!right && this.bit === 15) { this.bit = 0; this.select(this.selected - 1); }
      else { this.bit += right ? -1 : 1; this.schedule(); }
    } else if (e.key in moves) {
      this.select(this.selected + moves[e.key]);
    } else if (e.key === 'Home') {
      this.select(0);
    } else if (e.key === 'End') {
      this.select(this.area.words - 1);
    } else if (e.key === 'Enter' || e.key === 'F2') {
      if (this.viewId !== 'bits') this.beginEdit(this.selected);
    } else if (e.key === ' ' && this.viewId === 'bits') {
      this.toggleBit(this.selected, this.bit);
    } else if (e.key === 't') {
      this.app.addTrend(this.selectedTag());
    } else if (/^[-+0-9.a-fA-F]$/.test(e.key) && this.viewId !== 'bits' && !(this.viewId !== 'hex' && /[a-fA-F]/.test(e.key))) {
      this.beginEdit(this.selected, e.key);
    } else {
      return;
    }
    e.preventDefault();
  }

  beginEdit(word, initial) {
    if (!this.app.control()) {
      this.app.toast('Read only: finsd was started without --http-control');
      return;
    }
    this.select(word);
    const cell = this.rowsBox.querySelector(`.cell[data-word="${word}"]`);
    if (!cell) return;
    const input = document.createElement('input');
    input.className = 'edit';
    input.spellcheck = false;
    input.value = initial ?? format(this.viewId, this.cellWords(word));
    this.editing = {word, input};
    cell.textContent = '';
    cell.className = 'cell selected editing';
    cell.append(input);
    input.focus();
    if (initial === undefined) input.select();
    const done = (commit) => {
      if (!this.editing || this.editing.input !== input) return;
      this.editing = null;
      if (commit) this.commit(word, input.value);
      this.root.focus({preventScroll: true});
      this.render();
    };
    input.addEventListener('keydown', (e) => {
      if (e.key === 'Enter') { e.preventDefault(); done(true); }
      else if (e.key === 'Escape') { e.preventDefault(); done(false); }
      else if (e.key === 'Tab') { e.preventDefault(); done(true); this.select(word + view(this.viewId).words); }
      e.stopPropagation();
    });
    input.addEventListener('blur', () => done(false));
  }

  async commit(word, text) {
    const body = parseEdit(this.viewId, this.address(word), text);
    if (body.error) {
      this.app.toast(body.error);
      return;
    }
    await this.app.write(body);
  }

  async toggleBit(word, bit) {
    if (!this.app.control()) {
      this.app.toast('Read only: finsd was started without --http-control');
      return;
    }
    const w = this.words.get(word);
    if (w === undefined) return;
    await this.app.write({address: this.address(word), values: [w ^ (1 << bit)], as: 'uint16'});
  }
}

export {VIEWS};

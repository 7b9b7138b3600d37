// finsd's page: wires the API (api.js) to the grid, the trend and the panels.
// Nothing here is fetched from elsewhere (CSP default-src 'self').
import {getJson, postJson, Live, ApiError, token, setToken, isTokenRefusal} from './api.js';
import {Grid} from './grid.js';
import {Trend} from './trend.js';
import {VIEWS, view} from './values.js';
import * as panels from './panels.js';
import {ScenarioPanel} from './scenario.js';

const $ = (id) => document.getElementById(id);

const state = {
  plcs: [],
  plc: null,          // the selected entry of /api/plcs
  control: null,      // null: not known yet (the first 403 says "off")
  tokenRequired: false,  // POSTs need --http-token-file's token (/api/plcs token_required)
  status: null,
  statusLive: false,  // the WebSocket's status topic has answered: stop polling
};

function plcKey(p) {
  return p ? p.name || `${p.net}.${p.node}` : undefined;
}

let toastTimer = 0;
function toast(text, kind = 'bad') {
  const t = $('toast');
  t.textContent = text;
  t.className = `toast ${kind}`;
  t.hidden = false;
  clearTimeout(toastTimer);
  toastTimer = setTimeout(() => { t.hidden = true; }, 4000);
}

const READ_ONLY = 'Read only: finsd was started without --http-control';

// Every control of the page that changes the PLC: disabled, with the reason as its title,
// on a read-only finsd (panels.js does the same for the switches it renders).
function markControls() {
  const off = state.control === false;
  const controls = [...$('mode-buttons').querySelectorAll('button'),
                    ...$('fal-form').querySelectorAll('input, select, button'),
                    ...$('cpu-errors').querySelectorAll('button')];
  for (const c of controls) {
    c.disabled = off;
    if (off) c.title = READ_ONLY;
    else if (c.title === READ_ONLY) c.removeAttribute('title');
  }
  $('grid').setAttribute('aria-readonly', String(off));
  scenario.markControls();
}

function setControl(on) {
  state.control = on;
  const b = $('control-badge');
  b.textContent = on === false ? 'read only' : on ? 'control' : '—';
  b.className = `badge ${on === false ? 'muted' : on ? 'ok' : 'unknown'}`;
  document.body.classList.toggle('read-only', on === false);
  markControls();
  if (state.status) panels.renderSwitches(state.status, app);
}

// ---- the token (finsd --http-token-file) ---------------------------------------------------

// Asks for the token in the page's dialog; resolves to it, or '' when cancelled.
function askToken(refused) {
  const dialog = $('token-dialog');
  const input = $('token-input');
  $('token-refused').hidden = !refused;
  input.value = '';
  return new Promise((resolve) => {
    const done = () => {
      dialog.removeEventListener('close', done);
      resolve(dialog.returnValue === 'ok' ? input.value.trim() : '');
    };
    dialog.addEventListener('close', done);
    dialog.returnValue = '';
    dialog.showModal();
    input.focus();
  });
}

let asking = null;  // one dialog for the POSTs that need it at once
async function ensureToken(refused) {
  if (!asking) asking = askToken(refused).finally(() => { asking = null; });
  const t = await asking;
  setToken(t);
  return t;
}

// A POST with the token when finsd needs one: asked for first when none is kept, asked
// again (and the request sent again) when finsd says the token is wrong.
async function post(path, body) {
  let refused = false;
  for (let attempt = 0; attempt < 3; attempt++) {
    if (state.tokenRequired && !token() && !(await ensureToken(refused))) {
      throw new ApiError(0, 'No token given: nothing was sent (finsd needs its --http-token-file token)');
    }
    try {
      return await postJson(path, body, {plc: plcKey(state.plc)});
    } catch (e) {
      if (!isTokenRefusal(e)) throw e;
      state.tokenRequired = true;  // a finsd restarted with a token since /api/plcs
      refused = !!token();
      setToken('');
    }
  }
  throw new ApiError(403, 'finsd refused the token');
}

async function call(promise) {
  try {
    const r = await promise;
    if (state.control === null) setControl(true);
    return r;
  } catch (e) {
    if (e instanceof ApiError && e.status === 403 && !isTokenRefusal(e)) setControl(false);
    toast(e.message);
    throw e;
  }
}

async function write(body) {
  try {
    await call(post('/api/write', body));
  } catch {
    // shown by call()
  }
}

async function control(cmd) {
  const r = await call(post('/api/control', cmd));
  if (r && r.error) throw new Error(r.error);
  refreshStatus();
  return r;
}

const app = {
  live: null,
  plc: () => plcKey(state.plc),
  control: () => state.control !== false,
  write,
  control_: control,
  toast,
  addTrend: (tag) => trend.add(tag),
};

let wasOffline = false;
app.live = new Live(onMessage, (s) => {
  $('link').dataset.state = s;
  document.body.dataset.link = s;  // stale values are dimmed while offline
  $('link-text').textContent = s;
  // finsd may have restarted with other options (--http-control, a token, other CPU
  // Units): what /api/plcs says is read again after every reconnect.
  if (s === 'offline') wasOffline = true;
  else if (s === 'live' && wasOffline) {
    wasOffline = false;
    loadPlcs().then(() => {
      const p = state.plcs.find((x) => plcKey(x) === plcKey(state.plc));
      if (p) selectPlc(p);
    });
  }
});

const grid = new Grid($('grid'), app);
const trend = new Trend($('trend-canvas'), $('trend-tags'), app);
const scenario = new ScenarioPanel(app, (text) => locate(text), (valuesOnly) => {
  $('tag-types').hidden = !scenario.tags.length;
  grid.tagsChanged(valuesOnly);
});
grid.tagSource = scenario;
window.finsd = {state, grid, trend, scenario, live: app.live};  // for the console and the tests

function onMessage(msg) {
  if (grid.onMessage(msg)) return;
  if (scenario.onMessage(msg)) return;
  if (trend.onMessage(msg)) return;
  if (msg.type === 'error') {
    if (msg.id !== 'st') toast(msg.error);
    return;
  }
  if (msg.id === 'st' && msg.value && typeof msg.value === 'object') {
    state.statusLive = true;
    showStatus(msg.value);
  }
}

// ---- areas and views ---------------------------------------------------------------

// The CPU Unit's memory areas as /api/plcs gives them ("areas": [{"prefix","words"}],
// from the model's profile). A finsd without them: the CS/CJ areas at their largest
// sizes (the server answers a word past a smaller model's end with its error).
function areasOf(p) {
  if (p && Array.isArray(p.areas) && p.areas.length) {
    return p.areas.map((a) => ({prefix: a.prefix, words: a.words, label: a.prefix}));
  }
  const list = [['CIO', 6144], ['W', 512], ['H', 1536], ['A', 1472], ['T', 4096], ['C', 4096],
                ['D', 32768]].map(([prefix, words]) => ({prefix, words, label: prefix}));
  const banks = p && Number.isInteger(p.em_banks) ? p.em_banks : 0;
  for (let b = 0; b < banks; b++) {
    const n = b.toString(16).toUpperCase();
    list.push({prefix: `E${n}_`, words: 32768, label: `E${n}`});
  }
  return list;
}

function areaButton(a, text) {
  const b = document.createElement('button');
  b.textContent = text;
  b.dataset.prefix = a.prefix;
  b.dataset.test = `area-${a.prefix}`;
  b.title = `${a.prefix}0 - ${a.prefix}${a.words - 1}`;
  b.addEventListener('click', () => go(`${a.prefix}0`));
  return b;
}

function renderAreas() {
  const ul = $('area-list');
  ul.textContent = '';
  const banks = [];
  for (const a of areasOf(state.plc)) {
    if (/^E[0-9A-F]+_$/.test(a.prefix)) {
      banks.push(a);
      continue;
    }
    const li = document.createElement('li');
    const b = areaButton(a, a.label);
    const size = document.createElement('span');
    size.className = 'dim';
    size.textContent = a.words >= 1024 ? `${Math.round(a.words / 1024)}K` : String(a.words);
    b.append(size);
    li.append(b);
    ul.append(li);
  }
  const box = $('bank-list');
  box.textContent = '';
  $('banks').hidden = !banks.length;
  for (const a of banks) box.append(areaButton(a, a.prefix.slice(1, -1)));
  markArea();
}

function markArea() {
  for (const b of document.querySelectorAll('#area-list button, #bank-list button')) {
    b.classList.toggle('current', b.dataset.prefix === grid.area.prefix);
  }
}

// "D100", "e3_20", "cio10", "10" -> {area, word}; null when no area of this CPU Unit.
function locate(text) {
  const t = text.trim().toUpperCase().replace(/^DM/, 'D');
  const areas = areasOf(state.plc).slice().sort((a, b) => b.prefix.length - a.prefix.length);
  const bare = /^[0-9]+$/.test(t) ? 'CIO' + t : t;
  for (const a of areas) {
    if (!bare.startsWith(a.prefix.toUpperCase())) continue;
    const rest = bare.slice(a.prefix.length);
    const m = /^([0-9]+)(\.[0-9]+)?$/.exec(rest);
    if (!m) continue;
    const word = Number(m[1]);
    if (word >= a.words) return {error: `${a.prefix}${word} is past the end of ${a.label} (${a.prefix}${a.words - 1})`};
    return {area: a, word};
  }
  return {error: `no area of this CPU Unit is called ${text.trim()}`};
}

function go(text) {
  const r = locate(text);
  if (r.error) {
    toast(r.error);
    return false;
  }
  grid.show(r.area, r.word);
  if (document.activeElement !== $('goto')) $('goto').value = grid.address(grid.selected);
  markArea();
  saveHash();
  return true;
}

function renderViews() {
  const box = $('views');
  box.textContent = '';
  for (const v of VIEWS) {
    const b = document.createElement('button');
    b.textContent = v.label;
    b.dataset.view = v.id;
    b.title = `View as ${v.label} ([ and ] step through the views)`;
    b.setAttribute('role', 'radio');
    b.addEventListener('click', () => { grid.setView(v.id); markView(); saveHash(); });
    box.append(b);
  }
  markView();
}

function markView() {
  for (const b of $('views').querySelectorAll('button')) {
    b.setAttribute('aria-checked', String(b.dataset.view === grid.viewId));
  }
}

// ---- CPU Units -----------------------------------------------------------------------

function selectPlc(p, address) {
  const changed = plcKey(p) !== plcKey(state.plc);
  state.plc = p;
  $('unit-title').textContent = p ? (p.name || p.model || 'CPU Unit') : '—';
  $('unit-address').textContent = p ? `node ${p.net}.${p.node}.${p.unit ?? 0}${p.model && p.name ? ' · ' + p.model : ''}` : '';
  document.title = p && p.name ? `${p.name} · finsd` : 'finsd';
  panels.renderPlant(state.plcs, p, (q) => selectPlc(q));
  panels.renderRouting(p);
  renderAreas();
  if (changed) {
    state.status = null;
    state.statusLive = false;
    grid.reset();
    app.live.subscribe({op: 'subscribe', id: 'st', topic: 'status', plc: plcKey(p)});
    refreshStatus();
  }
  if (address) go(address);
  else saveHash();
}

function saveHash() {
  const q = new URLSearchParams();
  if (state.plcs.length > 1 && state.plc) q.set('plc', plcKey(state.plc));
  q.set('addr', grid.address(grid.selected));
  q.set('as', grid.viewId);
  const h = '#' + q.toString();
  if (location.hash !== h) history.replaceState(null, '', h);
}

function readHash() {
  const q = new URLSearchParams(location.hash.slice(1));
  return {plc: q.get('plc'), addr: q.get('addr'), as: q.get('as')};
}

// ---- status --------------------------------------------------------------------------

function showStatus(s) {
  state.status = s;
  if (typeof s.control === 'boolean') setControl(s.control);
  else if (typeof s.http_control === 'boolean') setControl(s.http_control);
  panels.renderCpu(s, state.plc);
  panels.renderSwitches(s, app);
  markControls();
  panels.renderConnections(s);
  panels.renderLogs(s);
  scenario.update(plcKey(state.plc), s.scenario);
  const mode = String(s.mode ?? '').toLowerCase();
  const badge = $('mode-badge');
  badge.textContent = mode ? mode.toUpperCase() : '—';
  badge.className = `badge mode-${mode}`;
  for (const b of $('mode-buttons').querySelectorAll('button')) {
    b.setAttribute('aria-checked', String(b.dataset.mode === mode));
  }
}

let statusInFlight = false;
async function refreshStatus() {
  if (statusInFlight) return;
  statusInFlight = true;
  try {
    const j = await getJson('/api/status', {plc: plcKey(state.plc)});
    showStatus(j);
  } catch (e) {
    $('cpu-model').textContent = e.message;
  } finally {
    statusInFlight = false;
  }
}

// Until the WebSocket's status topic delivers, poll (an older or busy finsd).
setInterval(() => {
  if (!document.hidden && !state.statusLive) refreshStatus();
}, 2000);

// ---- wiring ------------------------------------------------------------------------

function wire() {
  window.addEventListener('finsd-control', (e) => control(e.detail).catch(() => {}));
  $('goto-form').addEventListener('submit', (e) => {
    e.preventDefault();
    if (go($('goto').value)) {
      $('goto').blur();
      $('grid').focus({preventScroll: true});
    }
  });
  $('goto').addEventListener('keydown', (e) => {
    if (e.key === 'Escape') $('grid').focus({preventScroll: true});
  });
  $('grid').addEventListener('selectionchange', () => {
    if (document.activeElement !== $('goto')) $('goto').value = grid.address(grid.selected);
    saveHash();
  });
  for (const b of $('mode-buttons').querySelectorAll('button')) {
    b.addEventListener('click', () => control({cmd: 'mode', mode: b.dataset.mode}).catch(() => {}));
  }
  $('fal-form').addEventListener('submit', (e) => {
    e.preventDefault();
    control({cmd: $('fal-kind').value, number: Number($('fal-number').value), message: $('fal-message').value})
      .then(() => { $('fal-message').value = ''; })
      .catch(() => {});
  });
  $('clear-errors').addEventListener('click', () => control({cmd: 'clear_errors'}).catch(() => {}));
  for (const tab of $('lower-tabs').querySelectorAll('[role=tab]')) {
    tab.addEventListener('click', () => {
      for (const t of $('lower-tabs').querySelectorAll('[role=tab]')) t.setAttribute('aria-selected', String(t === tab));
      for (const body of document.querySelectorAll('.tab-body')) body.hidden = body.dataset.body !== tab.dataset.tab;
      $('lower').dataset.tab = tab.dataset.tab;  // an empty trend folds (app.css)
      if (tab.dataset.tab === 'trend') trend.draw();
    });
  }
  document.addEventListener('visibilitychange', () => app.live.pause(document.hidden));
  $('help-button').addEventListener('click', () => $('help').showModal());
  $('tag-types').addEventListener('click', () => {
    const on = $('tag-types').getAttribute('aria-pressed') !== 'true';
    $('tag-types').setAttribute('aria-pressed', String(on));
    grid.setTagTypes(on);
  });
  $('token-cancel').addEventListener('click', () => $('token-dialog').close('cancel'));
  $('token-form').addEventListener('submit', (e) => {
    // method=dialog closes the dialog with the button's value ("ok" or "cancel")
    if (e.submitter?.value === 'ok' && !$('token-input').value.trim()) e.preventDefault();
  });
  document.addEventListener('keydown', (e) => {
    const typing = e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement;
    if (typing || e.ctrlKey || e.metaKey || e.altKey || $('help').open || $('token-dialog').open) return;
    if (e.key === 'g' || e.key === '/') {
      e.preventDefault();
      $('goto').focus();
      $('goto').select();
    } else if (e.key === '?') {
      $('help').showModal();
    } else if ((e.key === '[' || e.key === ']') && !grid.editing) {
      const i = VIEWS.findIndex((x) => x.id === grid.viewId);
      const v = VIEWS[(i + (e.key === ']' ? 1 : VIEWS.length - 1)) % VIEWS.length];
      grid.setView(v.id);
      markView();
      saveHash();
      e.preventDefault();
    }
  });
  window.addEventListener('hashchange', () => {
    const h = readHash();
    if (h.as && h.as !== grid.viewId) { grid.setView(h.as); markView(); }
    if (h.plc && h.plc !== plcKey(state.plc)) {
      const p = state.plcs.find((x) => plcKey(x) === h.plc || `${x.net}.${x.node}` === h.plc);
      if (p) selectPlc(p, h.addr);
    } else if (h.addr && h.addr !== grid.address(grid.selected)) {
      go(h.addr);
    }
  });
}

// /api/plcs: the CPU Units, whether control is on and whether POSTs need the token.
async function loadPlcs() {
  try {
    const j = await getJson('/api/plcs');
    state.plcs = Array.isArray(j.plcs) ? j.plcs : [];
    state.tokenRequired = j.token_required === true;
    if (typeof j.control === 'boolean') setControl(j.control);
  } catch (e) {
    toast(`finsd did not list its CPU Units: ${e.message}`);
  }
}

async function main() {
  wire();
  renderViews();
  const h = readHash();
  if (h.as) grid.setView(h.as);
  markView();
  app.live.start();
  await loadPlcs();
  const wanted = h.plc && state.plcs.find((x) => plcKey(x) === h.plc || `${x.net}.${x.node}` === h.plc);
  selectPlc(wanted || state.plcs[0] || null, h.addr || 'D0');
  $('grid').focus({preventScroll: true});
  document.body.dataset.ready = 'true';
}

main();

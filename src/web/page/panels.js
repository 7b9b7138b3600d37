// The panels around the grid: CPU Unit, protections and faults, connections, logs,
// scenario, the plant's CPU Units and their routing tables. Each renders from the
// status object (GET /api/status, or the WebSocket's "status" topic) or /api/plcs.

const $ = (id) => document.getElementById(id);

function el(tag, className, text) {
  const e = document.createElement(tag);
  if (className) e.className = className;
  if (text !== undefined && text !== null) e.textContent = String(text);
  return e;
}

function fmtMs(v) {
  if (v === undefined || v === null) return '—';
  const n = Number(v);
  return Number.isFinite(n) ? `${n < 10 ? n.toFixed(2) : n.toFixed(1)} ms` : String(v);
}

// ---- CPU Unit -------------------------------------------------------------------------

// The CPU Unit clock: the page's own clock plus the offset finsd reports (it changes
// only when 07 02 sets the clock), so the clock ticks here with no message from finsd.
let clockOffset = null;
function two(n) {
  return String(n).padStart(2, '0');
}
function tickClock() {
  const el = $('cpu-clock');
  if (clockOffset === null) {
    el.textContent = '—';
    return;
  }
  const t = new Date(Date.now() + clockOffset * 1000);
  el.textContent = `${t.getUTCFullYear()}-${two(t.getUTCMonth() + 1)}-${two(t.getUTCDate())} ` +
                   `${two(t.getUTCHours())}:${two(t.getUTCMinutes())}:${two(t.getUTCSeconds())}`;
}
setInterval(() => { if (!document.hidden) tickClock(); }, 1000);

export function renderCpu(s, plc) {
  $('cpu-model').textContent = s.model ?? plc?.model ?? '—';
  const ct = s.cycle_time;
  if (ct && typeof ct === 'object') {
    $('cpu-cycle').textContent = ct.max_ms
      ? `${fmtMs(ct.base_ms)} · min ${Number(ct.min_ms).toFixed(1)} · max ${Number(ct.max_ms).toFixed(1)}`
      : `${fmtMs(ct.base_ms)}  (stopped)`;
  } else {
    $('cpu-cycle').textContent = '—';
  }
  clockOffset = typeof s.clock_offset_s === 'number' ? s.clock_offset_s : null;
  tickClock();
  const battery = $('cpu-battery');
  battery.textContent = s.battery_low ? 'low (battery error)' : 'normal';
  battery.className = s.battery_low ? 'warn' : '';
  const holder = s.access_right_holder;
  const access = $('cpu-access');
  access.textContent = holder ? `node ${holder}` : 'free';
  const code = s.error_code ?? '0000';
  const codeEl = $('cpu-error-code');
  codeEl.textContent = code;
  codeEl.className = code !== '0000' ? (s.fatal_errors && s.fatal_errors !== '0000' ? 'bad' : 'warn') : 'dim';
  const ul = $('cpu-errors');
  ul.textContent = '';
  for (const e of s.errors ?? []) {
    const li = el('li', e.fatal ? 'fatal' : 'nonfatal');
    li.append(el('span', 'code', e.code), el('span', 'name', e.name),
              el('span', 'dim', e.message || (e.fatal ? 'fatal' : 'non-fatal')));
    const x = el('button', 'icon-button small', '×');
    x.title = `Clear ${e.code}`;
    x.addEventListener('click', () => window.dispatchEvent(new CustomEvent('finsd-control',
      {detail: {cmd: 'clear_errors', code: e.code}})));
    li.append(x);
    ul.append(li);
  }
  const messages = s.messages ?? {};
  for (const [n, text] of Object.entries(messages)) {
    const li = el('li', 'message');
    li.append(el('span', 'code', `MSG ${n}`), el('span', 'name', text));
    ul.append(li);
  }
}

// ---- protections and faults ------------------------------------------------------------

// Switches that are control verbs of the status object: key in status -> request.
const SWITCHES = [
  {key: 'network_write_protection', label: 'Network write protection',
   hint: 'FINS writes from the network answer 2102 (W342 5-1-2 note 5)',
   cmd: (on) => ({cmd: 'network_write_protection', on})},
  {key: 'um_read_protection', label: 'UM read protection',
   hint: 'The commands W342 5-1-2 disables under it answer 2002',
   cmd: (on) => ({cmd: 'um_read_protection', on})},
  {key: 'battery_low', label: 'Battery error',
   hint: 'Non-fatal error 00F7: 06 01 reports it, the ERR/ALM flag is set',
   cmd: (on) => ({cmd: 'battery_error', on})},
  {key: 'memory_card', label: 'Memory card inserted', kind: 'state',
   hint: 'File memory disk 8000 (22 xx)',
   value: (s) => Number(s.memory_card_kbytes ?? 0) > 0,
   cmd: (on) => ({cmd: 'card', inserted: on})},
];

function switchRow(label, hint, on, onChange, test, kind = 'fault') {
  const li = el('li', kind);
  const lab = el('label', 'switch');
  const input = el('input');
  input.type = 'checkbox';
  input.checked = !!on;
  input.setAttribute('role', 'switch');
  if (test) input.dataset.test = test;
  input.addEventListener('change', () => onChange(input.checked, input));
  const text = el('span', 'switch-text');
  text.append(el('span', '', label), el('span', 'hint', hint));
  lab.append(input, el('span', 'track'), text);
  li.append(lab);
  return li;
}

export function renderSwitches(s, app) {
  const ul = $('switches');
  const focused = document.activeElement?.dataset?.test;
  ul.textContent = '';
  const flip = (request) => async (on, input) => {
    try {
      await app.control_(request(on));
    } catch {
      input.checked = !on;
    }
  };
  for (const sw of SWITCHES) {
    if (!(sw.key in s) && !sw.value) continue;
    const on = sw.value ? sw.value(s) : s[sw.key];
    const li = switchRow(sw.label, sw.hint, on, flip(sw.cmd), `switch-${sw.key}`, sw.kind);
    if (!app.control()) {
      const input = li.querySelector('input');
      input.disabled = true;
      input.title = 'Read only: finsd was started without --http-control';
    }
    ul.append(li);
  }
  // What cannot be switched at run time: shown, not offered.
  const p = s.protections && typeof s.protections === 'object' ? s.protections : {};
  if (Array.isArray(p.network_write_nodes) && p.network_write_nodes.length) {
    ul.append(el('li', 'note', `Nodes allowed to write: ${p.network_write_nodes.join(', ')}`));
  }
  if (typeof p.dip_write === 'boolean') {
    const li = switchRow('DIP switch pin 1 (UM write protection)', 'Set at start-up (--dip-write-protection)',
                         p.dip_write, () => {}, 'switch-dip_write', 'state');
    li.querySelector('input').disabled = true;
    ul.append(li);
  }
  if (focused) ul.querySelector(`[data-test="${focused}"]`)?.focus();
}

// ---- tables ---------------------------------------------------------------------------

function cellText(v) {
  if (v === null || v === undefined) return '';
  if (typeof v === 'object') return JSON.stringify(v);
  return String(v);
}

// A table of objects; columns: `columns` ([key, title]) or every key of the rows.
function fillTable(table, rows, columns, empty) {
  table.textContent = '';
  const cols = columns ?? [...new Set(rows.flatMap((r) => Object.keys(r)))].map((k) => [k, k.replaceAll('_', ' ')]);
  const head = el('tr');
  for (const [, title] of cols) head.append(el('th', '', title));
  const thead = el('thead');
  thead.append(head);
  const tbody = el('tbody');
  for (const r of rows) {
    const tr = el('tr');
    for (const [k] of cols) tr.append(el('td', '', cellText(r[k])));
    tbody.append(tr);
  }
  if (!rows.length) {
    const tr = el('tr', 'empty');
    const td = el('td', 'dim', empty);
    td.colSpan = Math.max(1, cols.length);
    tr.append(td);
    tbody.append(tr);
  }
  table.append(thead, tbody);
}

export function renderConnections(s) {
  const tcp = Array.isArray(s.connections) ? s.connections : [];
  const udp = Array.isArray(s.udp_peers) ? s.udp_peers : [];
  // The node: the client node the FINS/TCP handshake gave, the SA1 of a UDP peer's frames.
  fillTable($('tcp-table'), tcp, [['address', 'address'], ['port', 'port'], ['node', 'node'], ['state', 'state']],
            'no FINS/TCP client connected');
  fillTable($('udp-table'), udp, [['address', 'address'], ['port', 'port'], ['node', 'node'], ['last_seen', 'last seen']],
            'no FINS/UDP datagram yet');
  $('conn-count').textContent = tcp.length + udp.length ? String(tcp.length + udp.length) : '';
}

export function renderLogs(s) {
  const access = Array.isArray(s.access_log) ? s.access_log : [];
  const errors = Array.isArray(s.error_log) ? s.error_log : [];
  fillTable($('access-table'), access.slice().reverse(), [['time', 'time'], ['source', 'source (net.node.unit)'], ['command', 'command']],
            'no write recorded (W342 5-3-27 write access log)');
  fillTable($('error-table'), errors.slice().reverse(), [['time', 'time'], ['code', 'error code'], ['detail', 'detail']],
            'the error log is empty');
  const na = s.write_access_log_records ?? access.length;
  const ne = s.error_log_records ?? errors.length;
  $('access-count').textContent = na ? String(na) : '';
  $('error-count').textContent = ne ? String(ne) : '';
}

// The Scenario panel is scenario.js.

// ---- the plant ------------------------------------------------------------------------

function relayTotal(relays) {
  if (!relays || typeof relays !== 'object') return 0;
  let n = 0;
  for (const v of Object.values(relays)) n += typeof v === 'number' ? v : 0;
  return n;
}

export function renderPlant(plcs, current, onSelect) {
  const section = $('plant');
  section.hidden = plcs.length < 2;
  $('routing-tab').hidden = !plcs.some((p) => (p.routes ?? []).length || relayTotal(p.relays));
  const box = $('plant-list');
  box.textContent = '';
  const byNet = new Map();
  for (const p of plcs) {
    if (!byNet.has(p.net)) byNet.set(p.net, []);
    byNet.get(p.net).push(p);
  }
  for (const net of [...byNet.keys()].sort((a, b) => a - b)) {
    box.append(el('div', 'net', `Network ${net}`));
    for (const p of byNet.get(net).sort((a, b) => a.node - b.node)) {
      // A link: a middle click opens that CPU Unit's view in a tab of its own.
      const b = el('a', 'unit');
      b.dataset.plc = p.name || `${p.net}.${p.node}`;
      b.href = `#plc=${encodeURIComponent(b.dataset.plc)}&addr=D0&as=uint16`;
      b.dataset.test = `unit-${b.dataset.plc}`;
      const relays = relayTotal(p.relays);
      const routes = (p.routes ?? []).length;
      b.append(el('span', 'unit-name', p.name || `node ${p.node}`), el('span', 'unit-addr', `${p.net}.${p.node}`),
               el('span', 'unit-model', p.model ?? ''),
               el('span', 'unit-meta', `${routes} route${routes === 1 ? '' : 's'} · ${relays.toLocaleString('en')} relayed`));
      b.setAttribute('aria-current', String(current === p));
      b.addEventListener('click', (e) => {
        if (e.button !== 0 || e.ctrlKey || e.metaKey || e.shiftKey) return;
        e.preventDefault();
        onSelect(p);
      });
      box.append(b);
    }
  }
}

export function renderRouting(p) {
  const box = $('routing-body');
  box.textContent = '';
  if (!p) return;
  const routes = Array.isArray(p.routes) ? p.routes : [];
  const split = el('div', 'split');
  const left = el('div');
  left.append(el('h3', '', `Routing tables of ${p.name || `${p.net}.${p.node}`}`));
  const t = el('table', 'table');
  fillTable(t, routes, routes.length ? null : [['network', 'network'], ['via', 'via']], 'no routing tables: local network only');
  left.append(t);
  const right = el('div');
  right.append(el('h3', '', 'Relays'));
  const relays = p.relays && typeof p.relays === 'object' ? p.relays : {};
  const rt = el('table', 'table');
  fillTable(rt, Object.entries(relays).map(([k, v]) => ({what: k, count: v})),
            [['what', 'end code / kind'], ['count', 'count']], 'nothing relayed');
  right.append(rt);
  split.append(left, right);
  box.append(split);
}

// The page is one client of finsd's HTTP API (docs/api/openapi.yaml): every button is a
// REST call, every live value comes over the WebSocket /ws.

export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

async function answer(response) {
  let body = null;
  try {
    body = await response.json();
  } catch {
    body = null;
  }
  if (!response.ok) {
    const message = body && typeof body.error === 'string' ? body.error : `HTTP ${response.status}`;
    throw new ApiError(response.status, message);
  }
  return body;
}

function query(params) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) if (v !== undefined && v !== null && v !== '') q.set(k, v);
  const s = q.toString();
  return s ? `?${s}` : '';
}

export async function getJson(path, params = {}) {
  return answer(await fetch(path + query(params), {headers: {Accept: 'application/json'}}));
}

// The bearer token of a finsd started with --http-token-file (docs/web.md "Remote
// set-up"): asked for by the page, kept in this tab's sessionStorage only, sent on
// every POST.
const TOKEN_KEY = 'finsd-token';

export function token() {
  try {
    return sessionStorage.getItem(TOKEN_KEY) || '';
  } catch {
    return '';
  }
}

export function setToken(value) {
  try {
    if (value) sessionStorage.setItem(TOKEN_KEY, value);
    else sessionStorage.removeItem(TOKEN_KEY);
  } catch {
    // storage off: the token lasts until the page is reloaded
  }
}

// finsd's 403 for a POST without the right token (api.cpp check_request) names the
// Authorization header; its other 403s (control off, Host, Origin) do not.
export function isTokenRefusal(e) {
  return e instanceof ApiError && e.status === 403 && /Authorization|Bearer|token/.test(e.message);
}

export async function postJson(path, body, params = {}) {
  const headers = {'Content-Type': 'application/json', Accept: 'application/json'};
  const t = token();
  if (t) headers.Authorization = `Bearer ${t}`;
  return answer(await fetch(path + query(params), {
    method: 'POST',
    headers,
    body: JSON.stringify(body),
  }));
}

// A WebSocket that reconnects (1 s, doubling to 10 s) and resumes: the server greets
// every connection with {"type":"hello","session"}; after a reconnect the page asks
// {"op":"resume","session","seq"} for the old session and gets what it missed
// ("resumed"), or "resume_failed" and then subscribes again (fresh snapshots).
// Subscriptions are kept by id; subscribing an id again replaces it on the server.
export class Live {
  constructor(onMessage, onState) {
    this.onMessage = onMessage;
    this.onState = onState;
    this.subs = new Map();
    this.session = null;   // the session whose messages we hold
    this.seq = 0;          // the last seq seen in it
    this.pending = [];     // subscribe/unsubscribe made while not connected
    this.paused = false;   // the tab is hidden
    this.ws = null;
    this.delay = 1000;
    this.timer = null;
  }

  start() {
    const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`;
    let ws;
    try {
      ws = new WebSocket(url);
    } catch {
      this.retry();
      return;
    }
    this.ws = ws;
    this.ready = false;
    this.onState('connecting');
    ws.onopen = () => {
      this.delay = 1000;
    };
    ws.onmessage = (event) => {
      let msg;
      try {
        msg = JSON.parse(event.data);
      } catch {
        return;
      }
      this.receive(msg);
    };
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      this.ready = false;
      this.onState('offline');
      this.retry();
    };
    ws.onerror = () => ws.close();
  }

  receive(msg) {
    switch (msg.type) {
      case 'hello':
        if (!this.fresh) performance.mark('finsd-hello');  // bench/web_page.py
        this.fresh = {session: msg.session, seq: msg.seq ?? 0};
        if (this.session) {
          this.raw({op: 'resume', session: this.session, seq: this.seq});
        } else {
          this.begin();
        }
        return;
      case 'resumed':
        this.ready = true;
        this.onState('live');
        for (const op of this.pending) this.raw(op);
        this.pending = [];
        return;
      case 'resume_failed':
        this.begin();  // this connection's own session, with every subscription again
        return;
      default:
        break;
    }
    if (typeof msg.seq === 'number') {
      if (msg.seq <= this.seq) return;  // replayed twice
      this.seq = msg.seq;
    }
    this.onMessage(msg);
  }

  begin() {
    this.session = this.fresh.session;
    this.seq = this.fresh.seq;
    this.pending = [];
    this.ready = true;
    this.onState('live');
    if (!this.paused) for (const sub of this.subs.values()) this.raw(sub);
  }

  retry() {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this.start(), this.delay);
    this.delay = Math.min(this.delay * 2, 10000);
  }

  raw(obj) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(obj));
  }

  send(obj) {
    if (this.ready) this.raw(obj);
    else this.pending.push(obj);
  }

  // A hidden tab asks for nothing (an idle page costs finsd nothing); shown again, it
  // subscribes again and gets fresh snapshots.
  pause(paused) {
    if (paused === this.paused) return;
    this.paused = paused;
    for (const sub of this.subs.values()) this.send(paused ? {op: 'unsubscribe', id: sub.id} : sub);
  }

  subscribe(sub) {
    const old = this.subs.get(sub.id);
    if (old && JSON.stringify(old) === JSON.stringify(sub)) return;
    this.subs.set(sub.id, sub);
    if (!this.paused) this.send(sub);
  }

  unsubscribe(id) {
    if (!this.subs.delete(id)) return;
    if (!this.paused) this.send({op: 'unsubscribe', id});
  }
}

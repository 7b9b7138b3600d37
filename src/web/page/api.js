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

export async function postJson(path, body, params = {}) {
  return answer(await fetch(path + query(params), {
    method: 'POST',
    headers: {'Content-Type': 'application/json', Accept: 'application/json'},
    body: JSON.stringify(body),
  }));
}

// A WebSocket that reconnects (1 s, doubling to 10 s), resumes from the last sequence
// number it saw, and re-sends its subscriptions so the server answers with snapshots for
// anything the resume could not replay. Subscriptions are kept by id; subscribing an
// id again replaces it.
export class Live {
  constructor(onMessage, onState) {
    this.onMessage = onMessage;
    this.onState = onState;
    this.subs = new Map();
    this.seq = null;
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
    this.onState('connecting');
    ws.onopen = () => {
      this.delay = 1000;
      this.onState('live');
      if (this.seq !== null) this.send({op: 'resume', seq: this.seq});
      for (const sub of this.subs.values()) this.send(sub);
    };
    ws.onmessage = (event) => {
      let msg;
      try {
        msg = JSON.parse(event.data);
      } catch {
        return;
      }
      if (typeof msg.seq === 'number') {
        if (this.seq !== null && msg.seq <= this.seq) return;  // replayed twice
        this.seq = msg.seq;
      }
      this.onMessage(msg);
    };
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      this.onState('offline');
      this.retry();
    };
    ws.onerror = () => ws.close();
  }

  retry() {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this.start(), this.delay);
    this.delay = Math.min(this.delay * 2, 10000);
  }

  send(obj) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(obj));
  }

  subscribe(sub) {
    const old = this.subs.get(sub.id);
    if (old && JSON.stringify(old) === JSON.stringify(sub)) return;
    this.subs.set(sub.id, sub);
    this.send(sub);
  }

  unsubscribe(id) {
    if (!this.subs.delete(id)) return;
    this.send({op: 'unsubscribe', id});
  }
}

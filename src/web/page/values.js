// Typed views of PLC words. The grid always holds raw 16-bit words (what the WebSocket
// sends as "uint16"); a view decides how many words one value takes and how it prints.
// Omron CS/CJ store a 32/64-bit value with its lowest word at the lowest address
// (W340 "Data formats"); ASCII keeps the first character in the high byte, and a byte is
// the character of the same code point (Latin-1: B0 is "°"), as the server's `ascii` reads
// it (fins/values.hpp), so every byte shows as one character and an edit writes it back.

const buffer = new DataView(new ArrayBuffer(8));

// words: array of numbers 0-65535 (or undefined while unknown), lowest address first.
function join(words, n) {
  for (let i = 0; i < n; i++) buffer.setUint16((n - 1 - i) * 2, words[i] ?? 0);
}

function bcdText(w) {
  const digits = w.toString(16).padStart(1, '0');
  return /^[0-9]+$/.test(digits) ? String(Number(digits)) : null;
}

// 00 ends a string on the server; in a cell it shows as nothing.
function asciiChar(b) {
  return b === 0 ? '' : String.fromCharCode(b);
}

function trimFloat(x, digits) {
  if (!Number.isFinite(x)) return String(x);
  if (x !== 0 && (Math.abs(x) >= 1e9 || Math.abs(x) < 1e-6)) return x.toExponential(digits - 1);
  return String(Number(x.toPrecision(digits)));
}

// Each view: words per value, the text of a value (null: not valid in this view, e.g.
// a word that is not BCD), the number it stands for (for the trend) and how the API
// names it ("as").
export const VIEWS = [
  {id: 'uint16', label: 'uint16', words: 1, key: '1'},
  {id: 'int16', label: 'int16', words: 1, key: '2'},
  {id: 'uint32', label: 'uint32', words: 2, key: '3'},
  {id: 'int32', label: 'int32', words: 2, key: '4'},
  {id: 'float', label: 'float', words: 2, key: '5'},
  {id: 'double', label: 'double', words: 4, key: '6'},
  {id: 'bcd', label: 'BCD', words: 1, key: '7'},
  {id: 'hex', label: 'hex', words: 1, key: '8'},
  {id: 'bits', label: 'bits', words: 1, key: '9'},
  {id: 'ascii', label: 'ASCII', words: 1, key: '0'},
];

export function view(id) {
  return VIEWS.find((v) => v.id === id) ?? VIEWS[0];
}

// The number a value stands for, or null when a word is unknown or not valid.
export function toNumber(viewId, words) {
  const v = view(viewId);
  for (let i = 0; i < v.words; i++) if (words[i] === undefined) return null;
  const w = words[0];
  switch (viewId) {
    case 'int16': return (w << 16) >> 16;
    case 'uint32': join(words, 2); return buffer.getUint32(0);
    case 'int32': join(words, 2); return buffer.getInt32(0);
    case 'float': join(words, 2); return buffer.getFloat32(0);
    case 'double': join(words, 4); return buffer.getFloat64(0);
    case 'bcd': { const t = bcdText(w); return t === null ? null : Number(t); }
    default: return w;
  }
}

// The text of one value.
export function format(viewId, words) {
  const v = view(viewId);
  for (let i = 0; i < v.words; i++) if (words[i] === undefined) return '';
  const w = words[0];
  switch (viewId) {
    case 'hex': return w.toString(16).toUpperCase().padStart(4, '0');
    case 'bcd': return bcdText(w) ?? '—';
    case 'bits': return w.toString(2).padStart(16, '0');
    case 'ascii': return asciiChar(w >> 8) + asciiChar(w & 0xff);
    case 'float': return trimFloat(toNumber('float', words), 7);
    case 'double': return trimFloat(toNumber('double', words), 15);
    default: return String(toNumber(viewId, words));
  }
}

// What the user typed -> {address, values, as} for POST /api/write, or {error}.
// Numbers go to the server in the view's own format, so the server (libfins, the same
// code as the fins CLI) checks the range; hex and ASCII are turned into words here.
export function parseEdit(viewId, address, text) {
  const t = text.trim();
  if (t === '') return {error: 'empty value'};
  switch (viewId) {
    case 'hex': {
      if (!/^(0x)?[0-9a-f]{1,4}$/i.test(t)) return {error: 'hex: 1-4 hex digits'};
      return {address, values: [parseInt(t.replace(/^0x/i, ''), 16)], as: 'uint16'};
    }
    case 'ascii': {
      // One byte a character: U+0001-U+00FF, as the server refuses what a byte cannot hold.
      const chars = [...t];
      if (chars.length > 2) return {error: 'ASCII: 1-2 characters'};
      const high = chars.find((c) => c.codePointAt(0) > 0xff);
      if (high !== undefined) {
        const code = high.codePointAt(0).toString(16).toUpperCase().padStart(4, '0');
        return {error: `ASCII: U+${code} is above U+00FF (a byte holds one Latin-1 character)`};
      }
      const s = t.padEnd(2, ' ');
      return {address, values: [(s.charCodeAt(0) << 8) | s.charCodeAt(1)], as: 'uint16'};
    }
    case 'bits': {
      if (!/^[01]{1,16}$/.test(t)) return {error: 'bits: up to 16 of 0 and 1'};
      return {address, values: [parseInt(t, 2)], as: 'uint16'};
    }
    case 'float': case 'double': {
      const x = Number(t);
      if (t === '' || Number.isNaN(x)) return {error: `${viewId}: not a number`};
      return {address, values: [x], as: viewId};
    }
    default: {
      if (!/^[-+]?[0-9]+$/.test(t)) return {error: `${viewId}: not an integer`};
      return {address, values: [Number(t)], as: viewId};
    }
  }
}

// The Node.js peer of bench/bridge_peers.sh (issue 27): what a user builds instead of
// fins-bridge with the npm packages omron-fins (FINS over UDP) and mqtt (MQTT.js). One
// FinsClient per PLC; every --interval-ms each PLC's --tags words from D0 are read in one
// MEMORY AREA READ and published, all of them, as fins-bridge's `always` mode does:
// `{prefix}/p{i}/g` `{"ts":ms,"values":{"t0":v,...}}` (ts: when the answer arrived).
//
// The cycles follow fins-bridge's rule (src/bridge/poll/poll_schedule.hpp), so that the two
// overrun counts mean the same: cycle k of PLC i is due at start + phase_i + k x interval
// whatever the earlier ones cost; a timer that fires after the next grid point skips the
// points it missed, and a cycle due while the PLC's previous read is still in flight is
// skipped; both count as overruns. Counters go out every --stats-s on
// `{prefix}/$peer/node/stats` with fins-bridge's names (values, overruns, timeouts ...),
// overruns split into `late` and `busy`; the totals are printed on SIGTERM.
//
//   node fins_peer.js --plcs 1000 --fins-port 9650 --net 127.0.60 --mqtt-port 1883
'use strict';

const fins = require('omron-fins');
const mqtt = require('mqtt');
const { performance } = require('perf_hooks');

function options(argv) {
    const o = {
        plcs: 1000,
        'fins-port': 9600,
        net: '127.0.60',
        'mqtt-port': 1883,
        prefix: 'node',
        'interval-ms': 100,
        tags: 100,
        'stats-s': 2,
        'timeout-ms': 1000,
    };
    for (let i = 2; i < argv.length; i += 2) {
        const key = argv[i].replace(/^--/, '');
        if (!(key in o) || i + 1 >= argv.length) {
            console.error(`fins_peer.js: unknown option or missing value: ${argv[i]}`);
            process.exit(2);
        }
        o[key] = typeof o[key] === 'number' ? Number(argv[i + 1]) : argv[i + 1];
    }
    return o;
}

const o = options(process.argv);
const [a, b] = o.net.split('.').slice(0, 2);
const third = Number(o.net.split('.')[2]);
// PLC i: 127.0.(third + i / 250).(1 + i % 250), FINS node = the last octet (as the plant).
const ipOf = (i) => `${a}.${b}.${third + Math.floor(i / 250)}.${1 + (i % 250)}`;
const nodeOf = (i) => 1 + (i % 250);

// overruns = late (grid points the timer fired too late for) + busy (a cycle due while the
// previous read was in flight).
const stats = { values: 0, frames: 0, overruns: 0, late: 0, busy: 0, timeouts: 0, errors: 0, published: 0 };
const broker = mqtt.connect(`mqtt://127.0.0.1:${o['mqtt-port']}`, {
    clientId: `fins-peer-node-${process.pid}`,
    clean: true,
});
broker.on('error', (e) => console.error(`fins_peer.js: mqtt: ${e.message}`));

const names = Array.from({ length: o.tags }, (_, k) => `t${k}`);
const interval = o['interval-ms'];
const golden = (Math.sqrt(5) - 1) / 2;

function startPlc(i, start) {
    const client = fins.FinsClient(o['fins-port'], ipOf(i), {
        protocol: 'udp',
        timeout: o['timeout-ms'],
        DNA: 0,
        DA1: nodeOf(i),
        DA2: 0,
        SNA: 0,
        SA1: 254,
        SA2: 0,
    });
    client.on('error', (e) => {
        ++stats.errors;
        if (stats.errors <= 5) console.error(`fins_peer.js: plc ${i}: ${e.message || e}`);
    });
    const topic = `${o.prefix}/p${i}/g`;
    const plc = { busy: false, next: start + (((i * golden) % 1) * interval) };
    const done = (err, msg) => {
        plc.busy = false;
        if (err) {
            if (msg && msg.timeout) ++stats.timeouts;
            else ++stats.errors;
            return;
        }
        const ts = Date.now();
        ++stats.frames;
        const words = msg.response && msg.response.values;
        if (!words || msg.response.endCode !== '0000') {
            ++stats.errors;
            return;
        }
        const values = {};
        for (let k = 0; k < o.tags; ++k) values[names[k]] = words[k];
        stats.values += o.tags;
        broker.publish(topic, JSON.stringify({ ts, values }), { qos: 0 });
        ++stats.published;
    };
    const tick = () => {
        const now = performance.now();
        plc.next += interval;
        if (plc.next <= now) {
            const missed = Math.floor((now - plc.next) / interval) + 1;
            plc.next += missed * interval;
            stats.overruns += missed;
            stats.late += missed;
        }
        setTimeout(tick, plc.next - performance.now());
        if (plc.busy) {
            ++stats.overruns;
            ++stats.busy;
            return;
        }
        plc.busy = true;
        client.read('D0', o.tags, done);
    };
    setTimeout(tick, plc.next - performance.now());
}

broker.once('connect', () => {
    const start = performance.now() + 100;
    for (let i = 0; i < o.plcs; ++i) startPlc(i, start);
    setInterval(() => {
        broker.publish(`${o.prefix}/$peer/node/stats`, JSON.stringify({ ts: Date.now(), ...stats }));
    }, o['stats-s'] * 1000);
    console.error(`fins_peer.js: polling ${o.plcs} PLCs x ${o.tags} words every ${interval} ms`);
});

const stop = () => {
    console.error(`fins_peer.js: totals ${JSON.stringify(stats)}`);
    broker.end(true, () => process.exit(0));
    setTimeout(() => process.exit(0), 2000).unref();
};
process.on('SIGTERM', stop);
process.on('SIGINT', stop);

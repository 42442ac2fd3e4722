// SPDX-License-Identifier: Apache-2.0
// Live mode: the end caps' telemetry and heartbeats as server-sent events. The
// robot is drawn in its description's pose (telemetry carries tensions and rest
// lengths, not positions) with each cable coloured by its live tension. On a lost
// stream the page says "disconnected" and keeps trying until the server is back.
import { getJSON, setStatus } from './api.js';
import { Plot } from './plots.js';
import { cableHue } from './colors.js';
import { live, stats } from './inspect.js';

const WINDOW_S = 30;
const MAX_LATENCIES = 20000;
// Live frames are drawn at most this often: in software WebGL beside a real-time
// HIL every frame drawn is CPU the page's event handling waits for (drawn at the
// display's rate, the page took seconds to handle each sample).
const MIN_FRAME_MS = 100;

async function clockOffsetMs() {
  // Host clock minus performance.now(), from the quickest of a few round trips.
  let best = null;
  for (let i = 0; i < 5; i++) {
    const t0 = performance.now();
    const c = await getJSON('/api/clock');
    const t1 = performance.now();
    if (best === null || t1 - t0 < best.rtt) best = { rtt: t1 - t0, offset: c.host_ms - (t0 + t1) / 2 };
  }
  return best.offset;
}

export class LiveView {
  constructor(scene, robot) {
    this.scene = scene;
    this.robot = robot;
    this.tension = new Array(robot.cables.length).fill(0);
    this.history = { t: [], tension: [], rest: [] };
    this.rest = new Array(robot.cables.length).fill(null);
    this.offsetMs = null;
    document.getElementById('live-panel').hidden = false;
    document.getElementById('plot-distance').hidden = true;
    document.getElementById('plot-energy').hidden = true;
    const refs = [{ y: robot.cutoff_tension_n, colour: '#ff9800' }, { y: robot.hard_limit_tension_n, colour: '#ff1744' }];
    this.plots = {
      tension: new Plot(document.getElementById('plot-tension'), `cable tension (N), last ${WINDOW_S} s`, { refLines: refs, yMin: 0 }),
      rest: new Plot(document.getElementById('plot-rest'), 'commanded rest length (m)',
        { yMin: robot.min_rest_length_m - 0.02, yMax: robot.max_rest_length_m + 0.02 }),
    };
    this.scene.update(null, this.tension);
    this.connect();
    setInterval(() => this.sampleHistory(), 200);
    requestAnimationFrame((t) => this.tick(t));
  }

  connect() {
    setStatus('connecting');
    const es = new EventSource('/api/live/events');
    this.source = es;
    es.onopen = async () => {
      live.connected = true;
      live.connects++;
      setStatus('connected');
      try {
        this.offsetMs = await clockOffsetMs();
      } catch (e) {
        this.offsetMs = null;
      }
    };
    es.onerror = () => {
      live.connected = false;
      setStatus('disconnected');
      if (es.readyState === EventSource.CLOSED) setTimeout(() => this.connect(), 1000);
    };
    es.addEventListener('status', (e) => this.onStatus(JSON.parse(e.data)));
    // A frame: each end cap's newest sample since the last one (live_bridge.hpp).
    es.addEventListener('telemetry', (e) => JSON.parse(e.data).forEach((s) => this.onTelemetry(s)));
  }

  onTelemetry(s) {
    const arrivedMs = performance.now();
    live.samples++;
    if (this.offsetMs !== null) {
      const keep = (list, ms) => {
        list.push([arrivedMs, ms]);
        if (list.length > MAX_LATENCIES) list.splice(0, MAX_LATENCIES / 2);
      };
      if (s.sample_host_ms > 0) keep(live.latenciesMs, arrivedMs + this.offsetMs - s.sample_host_ms);
      keep(live.viewLatenciesMs, arrivedMs + this.offsetMs - s.received_host_ms);
    }
    s.cables.forEach((c, k) => {
      this.tension[c] = s.tension_n[k];
      this.rest[c] = s.commanded_m[k];
    });
    this.dirty = true;
  }

  onStatus(st) {
    live.statusEvents++;
    live.endcapsSeen = st.endcaps.filter((e) => e.seen).length;
    const rows = st.endcaps.map((e) => {
      if (!e.seen) return `<tr class="stale"><td>${e.e}</td><td colspan="5">no heartbeat</td></tr>`;
      const cls = e.state === 'faulted' ? 'faulted' : e.heartbeat_age_s > 1 ? 'stale' : '';
      return `<tr class="${cls}"><td>${e.e}</td><td>${e.state}</td><td>${e.fault}</td>` +
        `<td>${e.heartbeat_age_s.toFixed(2)} s</td><td>${e.policy || '-'}</td><td>${e.telemetry}</td></tr>`;
    });
    document.querySelector('#endcaps tbody').innerHTML = rows.join('');
    const l = window.tensegrityView.live().latencyRecent;
    const v = window.tensegrityView.live().viewLatencyRecent;
    document.getElementById('latency').textContent = l.count
      ? `sample to page, last 5 s: median ${l.p50.toFixed(1)} ms, 95 % ${l.p95.toFixed(1)} ms ` +
        `(${l.count} samples); of which the view: median ${v.p50.toFixed(1)} ms`
      : 'waiting for telemetry (end caps with a synchronized clock)';
  }

  sampleHistory() {
    const h = this.history;
    const t = performance.now() / 1000;
    h.t.push(t);
    h.tension.push(...this.tension);
    h.rest.push(...this.rest);
    const n = this.tension.length;
    while (h.t.length > 0 && h.t[0] < t - WINDOW_S) {
      h.t.shift();
      h.tension.splice(0, n);
      h.rest.splice(0, n);
    }
    const per = (values) => Array.from({ length: n }, (_, i) => ({ values, stride: n, offset: i, colour: cableHue(i, n) }));
    this.plots.tension.set(h.t, per(h.tension));
    this.plots.rest.set(h.t, per(h.rest));
  }

  tick(nowMs) {
    if (this.dirty && !(nowMs - this.lastDrawMs < MIN_FRAME_MS)) {
      this.lastDrawMs = nowMs;
      this.scene.update(null, this.tension);
      this.scene.render();
      this.dirty = false;
      stats.framesDrawn++;
      if (stats.openMs === null) stats.openMs = performance.now();
    }
    requestAnimationFrame((t) => this.tick(t));
  }
}

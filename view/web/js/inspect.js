// SPDX-License-Identifier: Apache-2.0
// window.tensegrityView: a read-only look into the page for tests and curious
// users (the browser test reads it; nothing in it changes the page or the robot).
export const stats = {
  openMs: null, // navigation start to the first frame drawn with data
  fps: 0, // frames drawn per second while playing, last full second
  framesDrawn: 0,
};

export const live = {
  connected: false,
  connects: 0,
  samples: 0,
  statusEvents: 0,
  latenciesMs: [], // sample (end cap's host time) to its arrival in the page
  viewLatenciesMs: [], // the view's own part: its DDS receive to the page
  endcapsSeen: 0,
};

export const evolve = { generations: 0, state: null, replayVersion: 0 };

// The player on screen (replay, or the evolution's best team once loaded).
let currentPlayer = null;
export function setPlayer(p) { currentPlayer = p; }

export function install(mode, sceneRef) {
  const playerRef = () => currentPlayer;
  const percentile = (values, p) => {
    if (values.length === 0) return null;
    const s = [...values].sort((a, b) => a - b);
    return s[Math.min(s.length - 1, Math.floor((p / 100) * s.length))];
  };
  window.tensegrityView = Object.freeze({
    mode,
    get ready() { return !!sceneRef(); },
    counts: () => (sceneRef() ? sceneRef().counts() : null),
    sampleCanvas: () => (sceneRef() ? sceneRef().samplePixels() : null),
    robotCentre: () => (sceneRef() ? sceneRef().centre().toArray() : null),
    time: () => (playerRef() ? playerRef().time : null),
    frame: () => (playerRef() ? playerRef().frame : null),
    playing: () => (playerRef() ? playerRef().playing : false),
    stats: () => ({ ...stats }),
    live: () => {
      // Entries are [arrival ms, latency ms]; `recent`: the last 5 s only (a page
      // busy building its scene at first holds the first samples back).
      const summary = (entries, recent) => {
        const since = performance.now() - 5000;
        let v;
        if (recent) {
          // Entries are in arrival order: walk back from the newest only.
          v = [];
          for (let i = entries.length - 1; i >= 0 && entries[i][0] >= since; i--) v.push(entries[i][1]);
        } else {
          v = entries.map((e) => e[1]);
        }
        return { count: v.length, p50: percentile(v, 50), p95: percentile(v, 95), max: v.length ? Math.max(...v) : null };
      };
      return {
        ...live,
        latenciesMs: undefined,
        viewLatenciesMs: undefined,
        latency: summary(live.latenciesMs, false),
        viewLatency: summary(live.viewLatenciesMs, false),
        latencyRecent: summary(live.latenciesMs, true),
        viewLatencyRecent: summary(live.viewLatenciesMs, true),
      };
    },
    evolve: () => ({ ...evolve }),
  });
}

// SPDX-License-Identifier: Apache-2.0
// Learning mode: the evolution's curve (best and mean team score per generation,
// infeasible share), polled from the server, and the replay of the best team so
// far, which the server simulates whenever a better team appears.
import { getJSON, setStatus, showError } from './api.js';
import { Plot } from './plots.js';
import { Player, makeReplayPlots } from './player.js';
import { evolve, setPlayer } from './inspect.js';

const POLL_MS = 1500;

export class EvolveView {
  constructor(scene, robot) {
    this.scene = scene;
    this.robot = robot;
    this.player = null;
    document.getElementById('evolve-panel').hidden = false;
    this.curve = new Plot(document.getElementById('plot-curve'), 'team score per generation (m); infeasible share x10 m',
      { xUnit: 'gen', yMin: 0 });
    document.getElementById('load-best').onclick = () => this.loadBest();
    this.poll();
  }

  async poll() {
    try {
      const c = await getJSON('/api/evolve/curve');
      setStatus('connected');
      this.show(c);
      if (c.replay_version > evolve.replayVersion && (this.player === null || !this.player.playing)) await this.loadBest();
    } catch (e) {
      setStatus('disconnected');
    }
    setTimeout(() => this.poll(), POLL_MS);
  }

  show(c) {
    evolve.state = c.state;
    const el = document.getElementById('evolve-summary');
    if (!c.curve) {
      el.textContent = `${c.state}: ${c.message}`;
      return;
    }
    evolve.generations = c.curve.generation.length;
    el.textContent = `${c.state} (${c.method}): generation ${c.generation}, ${c.episodes} of ${c.budget} episodes; ` +
      `best ${c.best_score_m.toFixed(2)} m (generation ${c.best_generation})` + (c.message ? ` - ${c.message}` : '');
    const g = c.curve.generation;
    const infeasible = c.curve.infeasible_rate.map((r) => r * 10);
    this.curve.set(g, [
      { values: c.curve.best_so_far_m, colour: '#4fc3f7', width: 1.5, label: 'best so far' },
      { values: c.curve.best_score_m, colour: '#81c784', label: 'generation best' },
      { values: c.curve.mean_score_m, colour: '#ffb74d', label: 'generation mean' },
      { values: infeasible, colour: '#e57373', label: 'infeasible share' },
    ]);
  }

  async loadBest() {
    const data = await getJSON('/api/replay');
    if (data === null) return;  // still being simulated
    const c = await getJSON('/api/evolve/curve');
    evolve.replayVersion = c.replay_version;
    document.getElementById('title').textContent = data.source;
    try {
      if (this.player === null) this.player = new Player(this.scene, makeReplayPlots(this.robot), data);
      else this.player.load(data);
      setPlayer(this.player);
    } catch (e) {
      showError(`replay: ${e.message}`);
    }
  }
}

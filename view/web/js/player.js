// SPDX-License-Identifier: Apache-2.0
// Plays replay frames: play/pause, speed, a time slider, and the plots' cursor
// following the time shown.
import { Plot } from './plots.js';
import { cableHue } from './colors.js';
import { stats } from './inspect.js';

function lowerFrame(times, t) {
  let lo = 0;
  let hi = times.length - 1;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (times[mid] <= t) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

export function makeReplayPlots(robot) {
  const refs = [
    { y: robot.cutoff_tension_n, colour: '#ff9800' },
    { y: robot.hard_limit_tension_n, colour: '#ff1744' },
  ];
  return {
    distance: new Plot(document.getElementById('plot-distance'), 'distance travelled (m)'),
    tension: new Plot(document.getElementById('plot-tension'), 'cable tension (N), cut-off and hard limit dashed',
      { refLines: refs, yMin: 0 }),
    rest: new Plot(document.getElementById('plot-rest'), 'cable rest length (m)',
      { yMin: robot.min_rest_length_m - 0.02, yMax: robot.max_rest_length_m + 0.02 }),
    energy: new Plot(document.getElementById('plot-energy'), 'energy (J)'),
  };
}

export class Player {
  constructor(scene, plots, data) {
    this.scene = scene;
    this.plots = plots;
    this.playing = false;
    this.speed = 1;
    this.frame = 0;
    this.fpsWindow = { start: performance.now(), frames: 0 };
    this.slider = document.getElementById('slider');
    this.clock = document.getElementById('clock');
    this.button = document.getElementById('play');
    document.getElementById('controls').hidden = false;
    this.button.onclick = () => this.toggle();
    document.getElementById('speed').onchange = (e) => { this.speed = Number(e.target.value); };
    this.slider.oninput = () => this.seek(this.data.time_s[Number(this.slider.value)]);
    this.load(data);
    requestAnimationFrame((now) => this.tick(now));
  }

  load(data) {
    this.data = data;
    this.time = data.time_s[0];
    this.slider.max = String(data.frames - 1);
    this.scene.setPath(data.centre_m);
    const t = data.time_s;
    const cables = data.cables;
    const perCable = (values) => Array.from({ length: cables }, (_, i) =>
      ({ values, stride: cables, offset: i, colour: cableHue(i, cables) }));
    this.plots.distance.set(t, [{ values: data.distance_m, colour: '#4fc3f7', width: 1.5 }]);
    this.plots.tension.set(t, perCable(data.tension_n));
    this.plots.rest.set(t, perCable(data.rest_length_m));
    if (data.energy_j) {
      this.plots.energy.set(t, [
        { values: data.energy_j, stride: 3, offset: 0, colour: '#ffca28', label: 'kinetic' },
        { values: data.energy_j, stride: 3, offset: 1, colour: '#66bb6a', label: 'gravitational' },
        { values: data.energy_j, stride: 3, offset: 2, colour: '#ab47bc', label: 'elastic' },
      ]);
    } else {
      this.plots.energy.title = 'energy: not in this record';
      this.plots.energy.set([], []);
    }
    this.show(0);
  }

  toggle() {
    if (!this.playing && this.frame >= this.data.frames - 1) this.time = this.data.time_s[0];
    this.playing = !this.playing;
    this.button.textContent = this.playing ? 'pause' : 'play';
    this.last = null;
    this.fpsWindow = { start: performance.now(), frames: 0 };
  }

  seek(t) {
    this.time = t;
    this.show(lowerFrame(this.data.time_s, t));
  }

  show(frame) {
    const d = this.data;
    this.frame = frame;
    const n = d.nodes * 3;
    this.scene.update(d.node_m.slice(frame * n, frame * n + n), d.tension_n.slice(frame * d.cables, (frame + 1) * d.cables));
    this.scene.showPathUpTo(frame);
    this.slider.value = String(frame);
    this.clock.textContent = `${d.time_s[frame].toFixed(2)} s  ${d.distance_m[frame].toFixed(2)} m`;
    for (const p of Object.values(this.plots)) p.cursor(d.time_s[frame]);
    this.dirty = true;
  }

  tick(now) {
    if (this.playing) {
      if (this.last !== null) this.time += ((now - this.last) / 1000) * this.speed;
      const end = this.data.time_s[this.data.frames - 1];
      if (this.time >= end) {
        this.time = end;
        this.toggle();
      }
      this.show(lowerFrame(this.data.time_s, this.time));
      this.last = now;
    }
    if (this.dirty) {
      this.scene.render();
      this.dirty = false;
      stats.framesDrawn++;
      if (stats.openMs === null) stats.openMs = performance.now();
      if (this.playing) this.countFrame(now);
    }
    requestAnimationFrame((t) => this.tick(t));
  }

  countFrame(now) {
    this.fpsWindow.frames++;
    const elapsed = now - this.fpsWindow.start;
    if (elapsed >= 1000) {
      stats.fps = (this.fpsWindow.frames * 1000) / elapsed;
      this.fpsWindow = { start: now, frames: 0 };
    }
  }
}

// SPDX-License-Identifier: Apache-2.0
// Entry point: asks the server which mode it serves, builds the robot's scene and
// starts that mode (replay, live or evolve).
import { getJSON, setStatus, showError } from './api.js';
import { RobotScene } from './scene.js';
import { Player, makeReplayPlots } from './player.js';
import { LiveView } from './live.js';
import { EvolveView } from './evolve.js';
import { install, setPlayer } from './inspect.js';

let scene = null;

async function robotWhenReady() {
  for (;;) {
    const robot = await getJSON('/api/robot');
    if (robot !== null) return robot;
    await new Promise((r) => setTimeout(r, 500));
  }
}

async function main() {
  const mode = await getJSON('/api/mode');
  install(mode.mode, () => scene);
  document.getElementById('title').textContent = mode.title;
  const robot = await robotWhenReady();
  document.getElementById('cutoff').textContent = `(${robot.cutoff_tension_n} N)`;
  document.getElementById('hard').textContent = `(${robot.hard_limit_tension_n} N)`;
  const canvas = document.getElementById('scene');
  if (mode.mode === 'replay') {
    const data = await getJSON('/api/replay');
    scene = new RobotScene(canvas, robot);
    setPlayer(new Player(scene, makeReplayPlots(robot), data));
    setStatus('connected');
  } else if (mode.mode === 'live') {
    scene = new RobotScene(canvas, robot);
    new LiveView(scene, robot);
  } else {
    scene = new RobotScene(canvas, robot);
    new EvolveView(scene, robot);
  }
}

main().catch((e) => {
  setStatus('disconnected');
  showError(`tensegrity view: ${e.message}`);
});

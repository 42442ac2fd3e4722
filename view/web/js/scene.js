// SPDX-License-Identifier: Apache-2.0
// SUPERball in three.js: one sphere per end cap, one cylinder per strut and per
// cable (cables coloured by tension), the ground with a 1 m grid, the path the
// robot's centre travelled, and a camera that follows the centre while the user
// may still orbit and zoom around it. The simulator's z is up.
import * as THREE from '/three/build/three.module.js';
import { OrbitControls } from '/three/examples/jsm/controls/OrbitControls.js';
import { tensionColour } from './colors.js';

const Y_AXIS = new THREE.Vector3(0, 1, 0);
const ENDCAP_RADIUS_M = 0.06;
const CABLE_RADIUS_M = 0.008;
const MAX_PATH_POINTS = 20000;

function rod(radius, material) {
  const mesh = new THREE.Mesh(new THREE.CylinderBufferGeometry(radius, radius, 1, 8, 1), material);
  mesh.matrixAutoUpdate = true;
  return mesh;
}

// Places a unit cylinder (along y) between a and b.
function placeRod(mesh, a, b, tmp) {
  tmp.subVectors(b, a);
  const length = tmp.length();
  mesh.position.addVectors(a, b).multiplyScalar(0.5);
  if (length > 1e-9) mesh.quaternion.setFromUnitVectors(Y_AXIS, tmp.divideScalar(length));
  mesh.scale.set(1, length, 1);
}

export class RobotScene {
  constructor(canvas, robot) {
    this.robot = robot;
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    this.renderer.setPixelRatio(1);
    this.renderer.setClearColor(0x1b1e23);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.05, 500);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(2.8, -3.4, 2.0);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.target.set(0, 0, 0.8);
    this.controls.update();
    this.followed = new THREE.Vector3(0, 0, 0.8);
    this.tmp = new THREE.Vector3();
    this.points = robot.nodes_m.map((p) => new THREE.Vector3(p[0], p[1], p[2]));
    this.buildLightsAndGround();
    this.buildRobot();
    this.buildPath();
    this.resize();
    window.addEventListener('resize', () => this.resize());
  }

  buildLightsAndGround() {
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    const sun = new THREE.DirectionalLight(0xffffff, 0.7);
    sun.position.set(3, -5, 10);
    this.scene.add(sun);
    const ground = new THREE.Mesh(new THREE.PlaneBufferGeometry(400, 400),
      new THREE.MeshLambertMaterial({ color: 0x2b3038 }));
    this.scene.add(ground);
    const grid = new THREE.GridHelper(200, 200, 0x7a8699, 0x566070);
    grid.rotation.x = Math.PI / 2;
    grid.position.z = 0.002;
    this.scene.add(grid);
  }

  buildRobot() {
    const capMaterial = new THREE.MeshLambertMaterial({ color: 0xd0d4dc });
    const capGeometry = new THREE.SphereBufferGeometry(ENDCAP_RADIUS_M, 12, 8);
    this.endcaps = this.points.map((_, i) => {
      const m = new THREE.Mesh(capGeometry, capMaterial);
      m.userData = { kind: 'endcap', index: i };
      this.scene.add(m);
      return m;
    });
    const strutMaterial = new THREE.MeshLambertMaterial({ color: 0x8d6e63 });
    this.struts = this.robot.struts.map((s, i) => {
      const m = rod(Math.max(this.robot.strut_radius_m, 0.015), strutMaterial);
      m.userData = { kind: 'strut', index: i, nodes: s };
      this.scene.add(m);
      return m;
    });
    this.cables = this.robot.cables.map((c, i) => {
      const m = rod(CABLE_RADIUS_M, new THREE.MeshBasicMaterial({ color: 0x8a8f98 }));
      m.userData = { kind: 'cable', index: i, nodes: c, tension_n: 0 };
      this.scene.add(m);
      return m;
    });
  }

  buildPath() {
    const geometry = new THREE.BufferGeometry();
    this.pathPositions = new Float32Array(MAX_PATH_POINTS * 3);
    geometry.setAttribute('position', new THREE.BufferAttribute(this.pathPositions, 3));
    geometry.setDrawRange(0, 0);
    this.path = new THREE.Line(geometry, new THREE.LineBasicMaterial({ color: 0x4fc3f7 }));
    this.path.frustumCulled = false;
    this.scene.add(this.path);
  }

  // The path: centres as [x,y,z,...] (every point), drawn up to `count`.
  setPath(centres) {
    const n = Math.min(centres.length / 3, MAX_PATH_POINTS);
    const step = Math.max(1, Math.ceil(centres.length / 3 / MAX_PATH_POINTS));
    for (let k = 0; k < n; k++) {
      this.pathPositions[k * 3] = centres[k * step * 3];
      this.pathPositions[k * 3 + 1] = centres[k * step * 3 + 1];
      this.pathPositions[k * 3 + 2] = 0.01;
    }
    this.pathStep = step;
    this.path.geometry.attributes.position.needsUpdate = true;
  }

  showPathUpTo(frame) {
    this.path.geometry.setDrawRange(0, Math.floor(frame / (this.pathStep || 1)) + 1);
  }

  // nodes: flat [x,y,z] per end cap (or null to keep the pose); tensions per cable.
  update(nodes, tensions) {
    if (nodes) {
      for (let i = 0; i < this.points.length; i++) this.points[i].set(nodes[i * 3], nodes[i * 3 + 1], nodes[i * 3 + 2]);
    }
    this.points.forEach((p, i) => this.endcaps[i].position.copy(p));
    this.struts.forEach((m) => placeRod(m, this.points[m.userData.nodes[0]], this.points[m.userData.nodes[1]], this.tmp));
    const cutoff = this.robot.cutoff_tension_n;
    const hard = this.robot.hard_limit_tension_n;
    this.cables.forEach((m, i) => {
      placeRod(m, this.points[m.userData.nodes[0]], this.points[m.userData.nodes[1]], this.tmp);
      if (tensions && tensions[i] !== undefined && tensions[i] !== null) {
        m.userData.tension_n = tensions[i];
        const c = tensionColour(tensions[i], cutoff, hard);
        m.material.color.setRGB(c[0], c[1], c[2]);
      }
    });
    this.follow();
  }

  centre() {
    const c = new THREE.Vector3();
    this.endcaps.forEach((m) => c.add(m.position));
    return c.divideScalar(this.endcaps.length);
  }

  // Moves camera and orbit target with the robot's horizontal motion.
  follow() {
    const c = this.centre();
    const dx = c.x - this.followed.x;
    const dy = c.y - this.followed.y;
    this.followed.set(c.x, c.y, this.followed.z);
    this.camera.position.x += dx;
    this.camera.position.y += dy;
    this.controls.target.x += dx;
    this.controls.target.y += dy;
    this.controls.update();
  }

  resize() {
    const w = this.canvas.clientWidth || 640;
    const h = this.canvas.clientHeight || 480;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }

  // Renders and reads the pixels back at once (the drawing buffer is not kept
  // between frames): how many differ from the background, how many colours.
  samplePixels() {
    this.render();
    const gl = this.renderer.getContext();
    const w = gl.drawingBufferWidth;
    const h = gl.drawingBufferHeight;
    const px = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let nonBackground = 0;
    const colours = new Set();
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - 0x1b) + Math.abs(px[i + 1] - 0x1e) + Math.abs(px[i + 2] - 0x23) > 6) nonBackground++;
      if (colours.size < 4096) colours.add((px[i] << 16) | (px[i + 1] << 8) | px[i + 2]);
    }
    return { width: w, height: h, nonBackground, distinctColours: colours.size };
  }

  counts() {
    let endcaps = 0;
    let cables = 0;
    let struts = 0;
    this.scene.traverse((o) => {
      if (o.userData.kind === 'endcap') endcaps++;
      if (o.userData.kind === 'cable') cables++;
      if (o.userData.kind === 'strut') struts++;
    });
    return { endcaps, cables, struts };
  }
}

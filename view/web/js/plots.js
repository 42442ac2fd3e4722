// SPDX-License-Identifier: Apache-2.0
// Small time plots on a 2D canvas. The curves are drawn once into an off-screen
// canvas; a frame only copies it and draws the cursor, so plots cost nearly
// nothing while the replay plays.
const MARGIN = { left: 46, right: 8, top: 16, bottom: 18 };

export class Plot {
  constructor(canvas, title, options = {}) {
    this.canvas = canvas;
    this.title = title;
    this.options = options;
    this.series = [];
    this.x = [];
    this.background = document.createElement('canvas');
    this.cursorX = null;
  }

  // x: times; series: [{values, stride, offset, colour, width}], value k at values[k*stride+offset].
  set(x, series) {
    this.x = x;
    this.series = series;
    this.redraw();
  }

  range() {
    let lo = Infinity;
    let hi = -Infinity;
    for (const s of this.series) {
      const stride = s.stride || 1;
      for (let k = 0; k < this.x.length; k++) {
        const v = s.values[k * stride + (s.offset || 0)];
        if (v === null || v === undefined) continue;
        if (v < lo) lo = v;
        if (v > hi) hi = v;
      }
    }
    for (const r of this.options.refLines || []) hi = Math.max(hi, r.y * 1.05);
    if (this.options.yMin !== undefined) lo = this.options.yMin;
    if (this.options.yMax !== undefined) hi = this.options.yMax;
    if (!isFinite(lo) || !isFinite(hi)) return [0, 1];
    if (hi - lo < 1e-9) return [lo - 1, hi + 1];
    return [lo, hi];
  }

  redraw() {
    const w = this.canvas.clientWidth || 300;
    const h = this.canvas.clientHeight || 150;
    this.canvas.width = w;
    this.canvas.height = h;
    this.background.width = w;
    this.background.height = h;
    const g = this.background.getContext('2d');
    g.fillStyle = '#11141a';
    g.fillRect(0, 0, w, h);
    g.fillStyle = '#aab';
    g.font = '11px sans-serif';
    g.fillText(this.title, MARGIN.left, 11);
    const n = this.x.length;
    if (n < 2) {
      this.blit();
      return;
    }
    const [lo, hi] = this.range();
    const x0 = this.x[0];
    const x1 = this.x[n - 1] > x0 ? this.x[n - 1] : x0 + 1;
    const pw = w - MARGIN.left - MARGIN.right;
    const ph = h - MARGIN.top - MARGIN.bottom;
    this.map = { x0, x1, pw, ph, lo, hi };
    const px = (t) => MARGIN.left + ((t - x0) / (x1 - x0)) * pw;
    const py = (v) => MARGIN.top + ph - ((v - lo) / (hi - lo)) * ph;
    g.strokeStyle = '#444';
    g.strokeRect(MARGIN.left, MARGIN.top, pw, ph);
    g.fillStyle = '#889';
    g.fillText(hi.toPrecision(3), 2, MARGIN.top + 8);
    g.fillText(lo.toPrecision(3), 2, MARGIN.top + ph);
    g.fillText(`${x0.toFixed(0)}`, MARGIN.left, h - 4);
    g.fillText(`${x1.toFixed(1)} ${this.options.xUnit || 's'}`, w - MARGIN.right - 50, h - 4);
    for (const r of this.options.refLines || []) {
      g.strokeStyle = r.colour;
      g.setLineDash([4, 3]);
      g.beginPath();
      g.moveTo(MARGIN.left, py(r.y));
      g.lineTo(MARGIN.left + pw, py(r.y));
      g.stroke();
      g.setLineDash([]);
    }
    const step = Math.max(1, Math.floor(n / (2 * pw)));
    for (const s of this.series) {
      const stride = s.stride || 1;
      g.strokeStyle = s.colour;
      g.lineWidth = s.width || 1;
      g.beginPath();
      let started = false;
      for (let k = 0; k < n; k += step) {
        const v = s.values[k * stride + (s.offset || 0)];
        if (v === null || v === undefined) continue;
        if (!started) g.moveTo(px(this.x[k]), py(v));
        else g.lineTo(px(this.x[k]), py(v));
        started = true;
      }
      g.stroke();
    }
    g.lineWidth = 1;
    let lx = MARGIN.left + 4;
    for (const s of this.series.filter((q) => q.label)) {
      g.fillStyle = s.colour;
      g.fillText(s.label, lx, MARGIN.top + 10);
      lx += g.measureText(s.label).width + 10;
    }
    this.blit();
  }

  blit() {
    const g = this.canvas.getContext('2d');
    g.drawImage(this.background, 0, 0);
    if (this.cursorX === null || !this.map) return;
    const { x0, x1, pw, ph } = this.map;
    const x = MARGIN.left + ((this.cursorX - x0) / (x1 - x0)) * pw;
    g.strokeStyle = '#fff';
    g.beginPath();
    g.moveTo(x, MARGIN.top);
    g.lineTo(x, MARGIN.top + ph);
    g.stroke();
  }

  cursor(t) {
    if (t === this.cursorX) return;
    this.cursorX = t;
    this.blit();
  }
}

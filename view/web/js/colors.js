// SPDX-License-Identifier: Apache-2.0
// Cable colour from its tension against the robot's cut-off and hard limit, the
// same four bands as the legend.
const SLACK = [0.54, 0.56, 0.6];
const LOW = [0.25, 0.75, 0.37];
const NEAR = [1.0, 0.6, 0.0];
const OVER = [1.0, 0.09, 0.27];

function mix(a, b, f) {
  return [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f];
}

export function tensionColour(tensionN, cutoffN, hardN) {
  if (!(tensionN > 1)) return SLACK;
  if (tensionN < cutoffN) return mix(LOW, [0.85, 0.85, 0.2], tensionN / cutoffN);
  if (tensionN < hardN) return mix(NEAR, OVER, (tensionN - cutoffN) / (hardN - cutoffN));
  return OVER;
}

// One distinct hue per cable, for the per-cable plots.
export function cableHue(index, count) {
  return `hsl(${Math.round((360 * index) / count)}, 70%, 60%)`;
}

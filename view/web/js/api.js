// SPDX-License-Identifier: Apache-2.0
// GET JSON from the view's server; 503 means "not ready yet" (retried by callers).
export async function getJSON(path) {
  const res = await fetch(path, { cache: 'no-store' });
  if (res.status === 503) return null;
  if (!res.ok) throw new Error(`${path}: HTTP ${res.status}`);
  return res.json();
}

export function showError(message) {
  const el = document.getElementById('error');
  el.textContent = message;
  el.hidden = false;
}

export function setStatus(text) {
  const el = document.getElementById('status');
  el.textContent = text;
  el.className = `status ${text}`;
}

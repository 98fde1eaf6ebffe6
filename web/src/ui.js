// The page's controls and read-outs: DOM only, no protocol.
const $ = (id) => document.getElementById(id);

export function elements() {
  return {
    dataset: $('dataset'), token: $('token'), tokenLabel: $('token-label'),
    slider: $('iso-slider'), number: $('iso-number'), rangeMin: $('range-min'), rangeMax: $('range-max'),
    lod: $('lod'), cache: $('cache'), snapshot: $('snapshot'),
    message: $('message'), stage: $('stage'), canvas: $('view'),
    state: $('state'), bytes: $('c-bytes'), groups: $('c-groups'), named: $('c-named'),
    triangles: $('c-triangles'), first: $('c-first'), frame: $('c-frame'), view: $('c-view'),
  };
}

export function formatNumber(v) {
  return Number(v).toLocaleString('en-US');
}

export function formatBytes(v) {
  if (v < 1024) return `${v} B`;
  if (v < 1024 * 1024) return `${(v / 1024).toFixed(1)} KiB`;
  return `${(v / 1024 / 1024).toFixed(2)} MiB`;
}

export function formatMs(v) {
  return v === null || v === undefined ? '-' : `${v.toFixed(0)} ms`;
}

// A value for display: short, but enough digits to tell values apart.
export function formatValue(v) {
  return String(Number(Number(v).toPrecision(6)));
}

// One line; `kind` 'error' (red) or 'info'.
export function showMessage(ui, text, kind = 'error') {
  ui.message.textContent = text;
  ui.message.className = text ? kind : '';
  ui.message.title = text;
}

export function showCounters(ui, api) {
  const s = api.stats;
  ui.state.textContent = api.state;
  ui.bytes.textContent = formatBytes(s.bytes);
  ui.groups.textContent = formatNumber(s.groups);
  ui.named.textContent = formatNumber(s.named);
  ui.triangles.textContent = formatNumber(s.triangles);
  ui.first.textContent = formatMs(s.first_group_ms);
  ui.frame.textContent = formatMs(s.frame_ms);
  const v = api.view;
  ui.view.textContent = `yaw ${v.yaw.toFixed(1)} pitch ${v.pitch.toFixed(1)} zoom ${v.zoom.toFixed(2)} ` +
    `iso ${formatValue(v.iso)} ${v.width}x${v.height}`;
}

export function setDatasets(ui, names, selected) {
  const sel = ui.dataset;
  sel.textContent = '';
  const first = document.createElement('option');
  first.value = '';
  first.textContent = '(pick a volume)';
  sel.appendChild(first);
  const all = selected && !names.includes(selected) ? [...names, selected] : names;
  for (const n of all) {
    const o = document.createElement('option');
    o.value = n;
    o.textContent = n;
    sel.appendChild(o);
  }
  sel.value = selected || '';
}

export function setRange(ui, min, max, iso) {
  for (const el of [ui.slider, ui.number]) {
    el.min = String(min);
    el.max = String(max);
    el.disabled = false;
  }
  ui.rangeMin.textContent = formatValue(min);
  ui.rangeMax.textContent = formatValue(max);
  ui.slider.value = String(iso);
  ui.number.value = formatValue(iso);
}

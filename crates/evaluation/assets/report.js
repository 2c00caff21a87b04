// The interactive comparison page (report.html): decodes the embedded float16 images, tone-maps
// them with the chosen exposure, draws a split view with zoom and pixel inspection, false-colour
// error maps, a grid of every image, a metrics table and the error-versus-time plot. It writes
// its own state into #status (images decoded, canvases non-blank, errors caught) for the
// browser test.
'use strict';

const STATUS = { errors: [], images: 0, decoded: 0, viewerNonblank: false, plotNonblank: null, thumbs: 0 };
function writeStatus(state) {
  const el = document.getElementById('status');
  el.dataset.state = STATUS.errors.length ? 'error' : state;
  el.textContent = JSON.stringify(STATUS);
  if (STATUS.errors.length) {
    const shown = document.getElementById('page-error');
    shown.hidden = false;
    shown.textContent = 'This page failed to draw (it needs a browser with DecompressionStream: ' +
      'Chromium 80, Firefox 113, Safari 16.4 or later): ' + STATUS.errors.join('; ');
  }
}
window.addEventListener('error', (e) => { STATUS.errors.push(String(e.message || e)); writeStatus('error'); });
window.addEventListener('unhandledrejection', (e) => {
  STATUS.errors.push('unhandled rejection: ' + String((e.reason && e.reason.message) || e.reason));
  writeStatus('error');
});

const DATA = JSON.parse(document.getElementById('data').textContent);
const $ = (id) => document.getElementById(id);

// ---- decoding -------------------------------------------------------------------------------
function base64Bytes(s) {
  const bin = atob(s);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}
async function inflate(s) {
  const stream = new Blob([base64Bytes(s)]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}
// Every float16 bit pattern as a float32.
const F16 = (() => {
  const t = new Float32Array(65536);
  for (let h = 0; h < 65536; h++) {
    const sign = h & 0x8000 ? -1 : 1, e = (h >> 10) & 31, m = h & 1023;
    t[h] = e === 0 ? sign * m * 2 ** -24 : e === 31 ? (m ? NaN : sign * Infinity) : sign * (1 + m / 1024) * 2 ** (e - 15);
  }
  return t;
})();
async function decodeHdr(s, n) {
  const bytes = await inflate(s);
  if (bytes.length !== n * 6) throw new Error('image data has ' + bytes.length + ' bytes, expected ' + n * 6);
  const out = new Float32Array(n * 3);
  for (let i = 0; i < n * 3; i++) out[i] = F16[bytes[2 * i] | (bytes[2 * i + 1] << 8)];
  return out;
}
const MAGMA = base64Bytes(DATA.colormap);

// ---- tone mapping and error maps ------------------------------------------------------------
const SRGB_STEPS = 16384;
const SRGB = (() => {
  const t = new Uint8ClampedArray(SRGB_STEPS + 1);
  for (let i = 0; i <= SRGB_STEPS; i++) {
    const c = i / SRGB_STEPS;
    t[i] = Math.round(255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055));
  }
  return t;
})();
function srgb8(v) {
  return v > 0 ? (v >= 1 ? 255 : SRGB[Math.round(v * SRGB_STEPS)]) : 0;
}
const state = { scene: 0, a: 1, b: 0, mode: 'image', ev: 0, errmax: 1, split: 0.5, view: null, drag: null, hover: null };

function relErr(hdr, ref, i) {
  let e = 0;
  for (let c = 0; c < 3; c++) e += Math.abs(hdr[3 * i + c] - ref[3 * i + c]) / (Math.abs(ref[3 * i + c]) + 0.01);
  return e / 3;
}
// Draws one image into its own offscreen canvas for the current mode, exposure and error scale.
function render(scene, img) {
  const key = state.mode + '|' + state.ev + '|' + state.errmax;
  if (img.key === key) return img.canvas;
  const n = scene.width * scene.height, ref = scene.images[0].hdr, hdr = img.hdr;
  const px = new ImageData(scene.width, scene.height), d = px.data;
  const gain = 2 ** state.ev;
  for (let i = 0; i < n; i++) {
    const r = hdr[3 * i], g = hdr[3 * i + 1], b = hdr[3 * i + 2];
    if (!Number.isFinite(r + g + b)) { d.set([255, 0, 255, 255], 4 * i); continue; }
    if (state.mode === 'image') {
      d[4 * i] = srgb8(r * gain); d[4 * i + 1] = srgb8(g * gain); d[4 * i + 2] = srgb8(b * gain);
    } else {
      let t = 0;
      if (state.mode === 'relerr') t = relErr(hdr, ref, i) / state.errmax;
      else if (img.flipMap) t = img.flipMap[i] / 255;
      const k = 3 * Math.max(0, Math.min(255, Math.round(t * 255)));
      d[4 * i] = MAGMA[k]; d[4 * i + 1] = MAGMA[k + 1]; d[4 * i + 2] = MAGMA[k + 2];
    }
    d[4 * i + 3] = 255;
  }
  if (!img.canvas) {
    img.canvas = document.createElement('canvas');
    img.canvas.width = scene.width; img.canvas.height = scene.height;
  }
  img.canvas.getContext('2d').putImageData(px, 0, 0);
  img.key = key;
  return img.canvas;
}

// ---- the split viewer -----------------------------------------------------------------------
const view = $('view'), vctx = view.getContext('2d');
function scene() { return DATA.scenes[state.scene]; }
function fit() {
  const s = scene();
  const w = Math.max(320, Math.min($('stage').clientWidth || 800, 1060));
  const h = Math.round(Math.min(w * s.height / s.width, window.innerHeight * 0.7 || 600));
  view.width = w; view.height = Math.max(200, h);
  const k = Math.min(view.width / s.width, view.height / s.height);
  // Whole pixels on screen when the image is enlarged.
  const scale = k >= 1 ? Math.floor(k) : k;
  state.view = { scale, ox: (view.width - s.width * scale) / 2, oy: (view.height - s.height * scale) / 2 };
}
function label(img) {
  return img.budget == null ? img.label : img.label + ' @ ' + img.budget + ' s';
}
function draw() {
  const s = scene(), v = state.view, sx = state.split * view.width;
  vctx.fillStyle = '#333'; vctx.fillRect(0, 0, view.width, view.height);
  vctx.imageSmoothingEnabled = false;
  [[state.a, 0, sx], [state.b, sx, view.width]].forEach(([idx, x0, x1]) => {
    vctx.save();
    vctx.beginPath(); vctx.rect(x0, 0, x1 - x0, view.height); vctx.clip();
    vctx.drawImage(render(s, s.images[idx]), v.ox, v.oy, s.width * v.scale, s.height * v.scale);
    vctx.restore();
  });
  if (state.hover && v.scale >= 4) {
    const [x, y] = state.hover;
    vctx.strokeStyle = '#0ff'; vctx.lineWidth = 1;
    vctx.strokeRect(v.ox + x * v.scale + 0.5, v.oy + y * v.scale + 0.5, v.scale - 1, v.scale - 1);
  }
  vctx.fillStyle = '#fff'; vctx.fillRect(Math.round(sx) - 1, 0, 2, view.height);
  vctx.beginPath(); vctx.arc(sx, view.height / 2, 7, 0, 2 * Math.PI); vctx.fill();
  vctx.font = '13px system-ui, sans-serif';
  const tag = (text, x, align) => {
    vctx.textAlign = align;
    const w = vctx.measureText(text).width + 10;
    vctx.fillStyle = 'rgba(0,0,0,0.6)'; vctx.fillRect(align === 'left' ? x : x - w, 6, w, 20);
    vctx.fillStyle = '#fff'; vctx.fillText(text, align === 'left' ? x + 5 : x - 5, 21);
  };
  tag('A: ' + label(s.images[state.a]), 6, 'left');
  tag('B: ' + label(s.images[state.b]), view.width - 6, 'right');
  drawColorbar();
}
function drawColorbar() {
  const bar = $('colorbar'), c = bar.getContext('2d'), show = state.mode !== 'image';
  $('colorbar-row').style.visibility = show ? 'visible' : 'hidden';
  $('errmax-label').style.visibility = state.mode === 'relerr' ? 'visible' : 'hidden';
  for (let x = 0; x < 256; x++) {
    c.fillStyle = 'rgb(' + MAGMA[3 * x] + ',' + MAGMA[3 * x + 1] + ',' + MAGMA[3 * x + 2] + ')';
    c.fillRect(x, 0, 1, bar.height);
  }
  $('colorbar-hi').textContent = state.mode === 'relerr' ? String(state.errmax) : '1';
}
function fmt(v) {
  if (v == null) return '–';
  return Number.isFinite(v) ? (Math.abs(v) >= 1e-3 && Math.abs(v) < 1e4 ? v.toPrecision(4) : v.toExponential(3)) : String(v);
}
function pixelAt(ev) {
  const r = view.getBoundingClientRect(), v = state.view, s = scene();
  const cx = (ev.clientX - r.left) * view.width / r.width, cy = (ev.clientY - r.top) * view.height / r.height;
  const x = Math.floor((cx - v.ox) / v.scale), y = Math.floor((cy - v.oy) / v.scale);
  return { cx, cy, inside: x >= 0 && y >= 0 && x < s.width && y < s.height, x, y };
}
function inspect(p) {
  const s = scene(), el = $('inspector');
  if (!p || !p.inside) { el.textContent = 'Hover over the image to read a pixel\'s values.'; return; }
  const i = p.y * s.width + p.x, ref = s.images[0].hdr;
  const row = (name, img) => {
    const h = img.hdr, rgb = [0, 1, 2].map((c) => fmt(h[3 * i + c]).padStart(10)).join(' ');
    let extra = '';
    if (img !== s.images[0]) {
      extra = '   rel. error ' + fmt(relErr(h, ref, i));
      if (img.flipMap) extra += '   FLIP ' + (img.flipMap[i] / 255).toFixed(3);
    }
    return name.padEnd(30) + rgb + extra;
  };
  const lines = ['pixel (' + p.x + ', ' + p.y + ')' + ' '.repeat(14) + '         R          G          B'];
  lines.push(row('A ' + label(s.images[state.a]), s.images[state.a]));
  lines.push(row('B ' + label(s.images[state.b]), s.images[state.b]));
  if (state.a !== 0 && state.b !== 0) lines.push(row(label(s.images[0]), s.images[0]));
  el.textContent = lines.join('\n');
}
view.addEventListener('wheel', (ev) => {
  ev.preventDefault();
  const p = pixelAt(ev), v = state.view;
  const k = Math.min(64, Math.max(0.1, v.scale * 1.25 ** (-Math.sign(ev.deltaY)))) / v.scale;
  v.ox = p.cx - (p.cx - v.ox) * k; v.oy = p.cy - (p.cy - v.oy) * k; v.scale *= k;
  draw();
}, { passive: false });
view.addEventListener('mousedown', (ev) => {
  const p = pixelAt(ev);
  state.drag = Math.abs(p.cx - state.split * view.width) < 10
    ? { split: true } : { x: p.cx, y: p.cy, ox: state.view.ox, oy: state.view.oy };
});
window.addEventListener('mouseup', () => { state.drag = null; });
view.addEventListener('mousemove', (ev) => {
  const p = pixelAt(ev), d = state.drag;
  if (d && d.split) {
    state.split = Math.max(0, Math.min(1, p.cx / view.width)); $('split').value = state.split;
  } else if (d) {
    state.view.ox = d.ox + p.cx - d.x; state.view.oy = d.oy + p.cy - d.y;
  }
  state.hover = p.inside ? [p.x, p.y] : null;
  inspect(p); draw();
});
view.addEventListener('mouseleave', () => { state.hover = null; inspect(null); draw(); });
view.addEventListener('dblclick', () => { fit(); draw(); });
window.addEventListener('resize', () => { if (state.view) { fit(); draw(); } });

// ---- controls, grid and table ---------------------------------------------------------------
function select(which, idx) {
  state[which] = idx;
  $('sel-' + which).value = idx;
  refreshMarks(); draw();
}
function refreshMarks() {
  document.querySelectorAll('#grid canvas').forEach((c) => {
    const i = Number(c.dataset.index);
    c.classList.toggle('sel-a', i === state.a); c.classList.toggle('sel-b', i === state.b);
  });
}
function drawThumbs() {
  const s = scene();
  document.querySelectorAll('#grid canvas').forEach((c) => {
    const ctx = c.getContext('2d');
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(render(s, s.images[Number(c.dataset.index)]), 0, 0, c.width, c.height);
  });
}
function thumb(s, idx) {
  const c = document.createElement('canvas'), k = Math.min(1, 160 / Math.max(s.width, s.height)) * Math.max(1, Math.floor(96 / Math.max(s.width, s.height)));
  c.width = Math.max(1, Math.round(s.width * k)); c.height = Math.max(1, Math.round(s.height * k));
  c.dataset.index = idx; c.title = label(s.images[idx]) + ' (click: A, shift-click: B)';
  c.addEventListener('click', (ev) => select(ev.shiftKey ? 'b' : 'a', idx));
  c.addEventListener('contextmenu', (ev) => { ev.preventDefault(); select('b', idx); });
  STATUS.thumbs++;
  return c;
}
function buildScene() {
  const s = scene();
  $('scene-note').textContent = s.note;
  document.querySelectorAll('nav button').forEach((b, i) => b.classList.toggle('active', i === state.scene));
  for (const which of ['a', 'b']) {
    const sel = $('sel-' + which);
    sel.innerHTML = '';
    s.images.forEach((img, i) => sel.add(new Option(label(img), i)));
  }
  // Default: the last render of the first configuration (its largest budget) against the reference.
  const first = s.images.length > 1 ? s.images[1].label : null;
  let a = 0;
  s.images.forEach((img, i) => { if (i > 0 && img.label === first) a = i; });
  state.a = a; state.b = 0;
  $('sel-a').value = state.a; $('sel-b').value = state.b;
  // Grid: the reference, then one row per configuration, one column per budget.
  const grid = $('grid'), table = document.createElement('table');
  grid.innerHTML = '';
  const budgets = [...new Set(s.images.slice(1).map((i) => i.budget))];
  const head = table.insertRow();
  head.insertCell().textContent = '';
  budgets.forEach((b) => { const th = document.createElement('th'); th.style.textAlign = 'center'; th.textContent = b == null ? '' : b + ' s'; head.appendChild(th); });
  const refRow = table.insertRow(), th = document.createElement('th');
  th.textContent = s.images[0].label; refRow.appendChild(th);
  refRow.insertCell().appendChild(thumb(s, 0));
  const labels = [...new Set(s.images.slice(1).map((i) => i.label))];
  for (const l of labels) {
    const row = table.insertRow(), h = document.createElement('th');
    h.textContent = l; row.appendChild(h);
    for (const b of budgets) {
      const cell = row.insertCell(), idx = s.images.findIndex((i, k) => k > 0 && i.label === l && i.budget === b);
      if (idx < 0) continue;
      cell.appendChild(thumb(s, idx));
      cell.appendChild(document.createTextNode('relMSE ' + fmt(s.images[idx].relmse)));
    }
  }
  grid.appendChild(table);
  // Metrics of every image shown.
  const m = $('metrics');
  m.innerHTML = '';
  const hr = m.insertRow();
  ['image', 'budget (s)', 'time (s)', 'passes', 'relMSE', 'MAPE', 'FLIP', 'mean ratio'].forEach((t) => {
    const h = document.createElement('th'); h.textContent = t; hr.appendChild(h);
  });
  s.images.forEach((img, i) => {
    if (i === 0) return;
    const r = m.insertRow();
    r.className = 'clickable'; r.title = 'show as A';
    r.addEventListener('click', () => select('a', i));
    [img.label, img.budget == null ? '–' : img.budget, img.seconds == null ? '–' : img.seconds.toFixed(2),
      img.passes == null ? '–' : img.passes, fmt(img.relmse), fmt(img.mape), fmt(img.flip), fmt(img.mean_ratio)]
      .forEach((t) => { r.insertCell().textContent = t; });
  });
  $('plot-panel').style.display = s.plot ? '' : 'none';
  fit(); refreshMarks(); drawThumbs(); draw(); drawPlot();
}
$('sel-a').addEventListener('change', (e) => select('a', Number(e.target.value)));
$('sel-b').addEventListener('change', (e) => select('b', Number(e.target.value)));
$('swap').addEventListener('click', () => { const a = state.a; select('a', state.b); select('b', a); });
$('mode').addEventListener('change', (e) => { state.mode = e.target.value; drawThumbs(); draw(); });
$('exposure').addEventListener('input', (e) => {
  state.ev = Number(e.target.value);
  $('exposure-value').textContent = (state.ev >= 0 ? '+' : '') + state.ev.toFixed(1) + ' EV';
  drawThumbs(); draw();
});
$('errmax').addEventListener('input', (e) => {
  state.errmax = Number((10 ** Number(e.target.value)).toPrecision(2));
  $('errmax-value').textContent = String(state.errmax);
  drawThumbs(); draw();
});
$('split').addEventListener('input', (e) => { state.split = Number(e.target.value); draw(); });
$('fit').addEventListener('click', () => { fit(); draw(); });
$('one').addEventListener('click', () => {
  const s = scene();
  state.view = { scale: 1, ox: (view.width - s.width) / 2, oy: (view.height - s.height) / 2 };
  draw();
});
$('plot-metric').addEventListener('change', drawPlot);

// ---- the plot -------------------------------------------------------------------------------
const COLORS = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2', '#17becf'];
const plotHits = [];
function decades(values) {
  const v = values.filter((x) => Number.isFinite(x) && x > 0);
  if (!v.length) return [0.1, 10];
  const lo = 10 ** Math.floor(Math.log10(Math.min(...v))), hi = 10 ** Math.ceil(Math.log10(Math.max(...v)));
  return [lo, Math.max(hi, lo * 10)];
}
function drawPlot() {
  const s = scene(), p = s.plot, c = $('plot'), ctx = c.getContext('2d');
  plotHits.length = 0;
  if (!p) return;
  const metric = $('plot-metric').value;
  // Columns: medians [t, relMSE, min, max, MAPE, FLIP, budget]; points [t, relMSE, MAPE, FLIP].
  const mc = { relmse: 1, mape: 4, flip: 5 }[metric], pc = { relmse: 1, mape: 2, flip: 3 }[metric];
  const ys = p.series.flatMap((q) => q.points.map((x) => x[pc]));
  if (metric === 'relmse' && p.noise) ys.push(p.noise);
  const [x0, x1] = decades(p.series.flatMap((q) => q.points.map((x) => x[0])));
  const [y0, y1] = decades(ys);
  const L = 80, R = c.width - 20, T = 20, B = c.height - 50;
  const X = (t) => L + (Math.log10(t) - Math.log10(x0)) / (Math.log10(x1) - Math.log10(x0)) * (R - L);
  const Y = (e) => B - (Math.log10(e) - Math.log10(y0)) / (Math.log10(y1) - Math.log10(y0)) * (B - T);
  const ok = (v) => Number.isFinite(v) && v > 0;
  ctx.fillStyle = '#fff'; ctx.fillRect(0, 0, c.width, c.height);
  ctx.font = '12px system-ui, sans-serif'; ctx.strokeStyle = '#ddd'; ctx.fillStyle = '#333'; ctx.lineWidth = 1;
  for (let d = x0; d <= x1 * 1.0001; d *= 10) {
    ctx.beginPath(); ctx.moveTo(X(d), T); ctx.lineTo(X(d), B); ctx.stroke();
    ctx.textAlign = 'center'; ctx.fillText(String(Number(d.toPrecision(3))), X(d), B + 16);
  }
  for (let d = y0; d <= y1 * 1.0001; d *= 10) {
    ctx.beginPath(); ctx.moveTo(L, Y(d)); ctx.lineTo(R, Y(d)); ctx.stroke();
    ctx.textAlign = 'right'; ctx.fillText(d.toExponential(0), L - 6, Y(d) + 4);
  }
  ctx.strokeStyle = '#333'; ctx.strokeRect(L, T, R - L, B - T);
  ctx.textAlign = 'center'; ctx.fillText('render time (s)', (L + R) / 2, c.height - 12);
  ctx.save(); ctx.translate(18, (T + B) / 2); ctx.rotate(-Math.PI / 2);
  ctx.fillText($('plot-metric').selectedOptions[0].textContent, 0, 0); ctx.restore();
  const legend = [];
  p.series.forEach((q, i) => {
    const col = COLORS[i % COLORS.length];
    ctx.strokeStyle = col; ctx.fillStyle = col; ctx.lineWidth = 2;
    ctx.beginPath();
    q.medians.filter((m) => ok(m[0]) && ok(m[mc])).forEach((m, k) => (k ? ctx.lineTo : ctx.moveTo).call(ctx, X(m[0]), Y(m[mc])));
    ctx.stroke();
    ctx.lineWidth = 1;
    if (metric === 'relmse') {
      q.medians.filter((m) => ok(m[0]) && ok(m[2]) && ok(m[3])).forEach((m) => {
        ctx.beginPath(); ctx.moveTo(X(m[0]), Y(m[2])); ctx.lineTo(X(m[0]), Y(m[3])); ctx.stroke();
      });
    }
    ctx.globalAlpha = 0.6;
    q.points.filter((x) => ok(x[0]) && ok(x[pc])).forEach((x) => { ctx.beginPath(); ctx.arc(X(x[0]), Y(x[pc]), 2.5, 0, 2 * Math.PI); ctx.fill(); });
    ctx.globalAlpha = 1;
    q.medians.filter((m) => ok(m[0]) && ok(m[mc])).forEach((m) => {
      plotHits.push({ x: X(m[0]), y: Y(m[mc]), label: q.label, budget: m[6] });
    });
    legend.push([q.label, col, 2]);
  });
  if (metric === 'relmse' && ok(p.noise)) {
    ctx.strokeStyle = '#888'; ctx.beginPath(); ctx.moveTo(L, Y(p.noise)); ctx.lineTo(R, Y(p.noise)); ctx.stroke();
    legend.push(['reference\'s own relMSE (est.)', '#888', 1]);
  }
  const lh = 18, lw = 230, ly = B - 8 - legend.length * lh;
  ctx.fillStyle = 'rgba(255,255,255,0.85)'; ctx.fillRect(L + 8, ly, lw, legend.length * lh + 4);
  ctx.strokeStyle = '#333'; ctx.lineWidth = 1; ctx.strokeRect(L + 8, ly, lw, legend.length * lh + 4);
  legend.forEach(([text, col, w], k) => {
    const y = ly + 12 + k * lh;
    ctx.strokeStyle = col; ctx.lineWidth = w; ctx.beginPath(); ctx.moveTo(L + 16, y); ctx.lineTo(L + 40, y); ctx.stroke();
    ctx.fillStyle = '#222'; ctx.textAlign = 'left'; ctx.fillText(text, L + 46, y + 4);
  });
}
$('plot').addEventListener('click', (ev) => {
  const c = $('plot'), r = c.getBoundingClientRect();
  const x = (ev.clientX - r.left) * c.width / r.width, y = (ev.clientY - r.top) * c.height / r.height;
  let best = null, bd = 100;
  for (const h of plotHits) { const d = (h.x - x) ** 2 + (h.y - y) ** 2; if (d < bd) { bd = d; best = h; } }
  if (!best) return;
  const idx = scene().images.findIndex((i, k) => k > 0 && i.label === best.label && i.budget === best.budget);
  if (idx > 0) select('a', idx);
});

// ---- a view given in the address: #scene=1&a=3&b=0&mode=relerr&ev=1.5&split=0.3&zoom=4&px=40,60
function applyHash() {
  const h = new URLSearchParams(location.hash.slice(1)), s = () => scene();
  const num = (k) => (h.has(k) && Number.isFinite(Number(h.get(k))) ? Number(h.get(k)) : null);
  if (num('scene') != null && DATA.scenes[num('scene')]) { state.scene = num('scene'); buildScene(); }
  for (const k of ['a', 'b']) if (num(k) != null && s().images[num(k)]) select(k, num(k));
  if (['image', 'relerr', 'flip'].includes(h.get('mode'))) { state.mode = h.get('mode'); $('mode').value = state.mode; }
  if (num('ev') != null) { $('exposure').value = num('ev'); $('exposure').dispatchEvent(new Event('input')); }
  if (num('split') != null) { state.split = Math.max(0, Math.min(1, num('split'))); $('split').value = state.split; }
  const px = (h.get('px') || '').split(',').map(Number);
  if (num('zoom') != null) {
    const v = state.view, k = num('zoom') / v.scale;
    const [cx, cy] = px.length === 2 ? [v.ox + (px[0] + 0.5) * v.scale, v.oy + (px[1] + 0.5) * v.scale] : [view.width / 2, view.height / 2];
    v.scale *= k; v.ox = view.width / 2 - (cx - v.ox) * k; v.oy = view.height / 2 - (cy - v.oy) * k;
  }
  drawThumbs(); draw();
  if (px.length === 2 && px.every(Number.isInteger)) {
    state.hover = px; draw();
    inspect({ inside: px[0] >= 0 && px[1] >= 0 && px[0] < s().width && px[1] < s().height, x: px[0], y: px[1] });
    state.pinned = true;
  }
}

// ---- start ----------------------------------------------------------------------------------
function nonblank(canvas) {
  const d = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
  for (let i = 4; i < d.length; i += 4) {
    if (d[i] !== d[0] || d[i + 1] !== d[1] || d[i + 2] !== d[2]) return true;
  }
  return false;
}
async function start() {
  STATUS.images = DATA.scenes.reduce((n, s) => n + s.images.length, 0);
  writeStatus('loading');
  for (const s of DATA.scenes) {
    await Promise.all(s.images.map(async (img) => {
      img.hdr = await decodeHdr(img.hdr_f16, s.width * s.height);
      img.flipMap = img.flip_u8 ? await inflate(img.flip_u8) : null;
      STATUS.decoded++;
    }));
  }
  const nav = $('scenes');
  if (DATA.scenes.length > 1) {
    DATA.scenes.forEach((s, i) => {
      const b = document.createElement('button');
      b.textContent = s.name;
      b.addEventListener('click', () => { state.scene = i; buildScene(); });
      nav.appendChild(b);
    });
  }
  buildScene();
  applyHash();
  // The pixel inspector on the first pixel: a header line, A, B (the reference).
  inspect({ inside: true, x: 0, y: 0 });
  STATUS.inspectorLines = $('inspector').textContent.split('\n').length;
  if (state.pinned) applyHash(); else inspect(null);
  STATUS.viewerNonblank = nonblank(view);
  STATUS.mode = state.mode;
  STATUS.scale = state.view.scale;
  STATUS.plotNonblank = scene().plot ? nonblank($('plot')) : null;
  writeStatus('ready');
}
start().catch((e) => { STATUS.errors.push('start: ' + String((e && e.stack) || e)); writeStatus('error'); });

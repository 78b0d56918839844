// attsync view: the page's own code (no third-party code, no network).
// Reads the run's data from <script id="data">, draws the bodies with a
// small Canvas 2D renderer (perspective projection, painter's order), the
// error curves, and a timeline. `#t=12.5&paused&speed=2` picks the start;
// after each drawing <html data-rendered="t"> says the time drawn.
(function () {
  'use strict';

  const D = JSON.parse(document.getElementById('data').textContent);
  if (D.format !== 1) throw new Error('view data format ' + D.format + ' (this page reads 1)');
  const F = D.frames;
  const T = F.t;
  const NF = T.length;
  const NB = D.bodies.length;
  const QS = 10000; // frames.rs QUAT_SCALE
  const ES = 100; // frames.rs ERR_SCALE
  const T0 = NF ? T[0] : 0;
  const T1 = NF ? T[NF - 1] : 0;
  const $ = (id) => document.getElementById(id);

  const state = { t: T0, playing: true, speed: 1, yaw: -0.9, pitch: 0.62, zoom: 1, dirty: true, last: null };

  // ---- colours: errors.svg's palette (results/palette.rs) -------------
  const PAL = D.palette;
  /** Agent k's colour (0-based), shaded: light 58 is the palette's own,
   *  less is darker (towards black), more is lighter (towards white). */
  function agentColor(k, light, alpha) {
    const hex = PAL.colours[k % PAL.colours.length];
    const c = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
    const f = light / 58;
    const m = c.map((x) => Math.round(f <= 1 ? x * f : x + ((255 - x) * (light - 58)) / 42));
    return 'rgba(' + m.join(',') + ',' + (alpha === undefined ? 1 : alpha) + ')';
  }
  /** Agent k's dash pattern ([] solid), in px at a device pixel ratio of 1. */
  function agentDash(k) {
    const d = PAL.dashes[Math.floor(k / PAL.colours.length) % PAL.dashes.length];
    return d[0] ? d : [];
  }
  const AXIS = ['#ff5c5c', '#5cd65c', '#5c9dff'];

  // ---- vectors and quaternions ---------------------------------------
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => Math.sqrt(dot(a, a));
  const unit = (a) => mul(a, 1 / (norm(a) || 1));

  /** Rotates v by unit quaternion q = [w, x, y, z] (body → world). */
  function rotate(q, v) {
    const u = [q[1], q[2], q[3]];
    const t = mul(cross(u, v), 2);
    return add(add(v, mul(t, q[0])), cross(u, t));
  }

  /** Index k of the last frame at or before t (0 if none). */
  function frameAt(t) {
    let lo = 0;
    let hi = NF - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (T[mid] <= t) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  /** The attitude in `arr` (4 numbers per frame) at time t, or null. */
  function quatAt(arr, t) {
    if (!arr || !arr.length || !NF) return null;
    const k = frameAt(t);
    const a = arr.slice(4 * k, 4 * k + 4);
    if (a.some((x) => x === null)) return null;
    if (k + 1 >= NF || t <= T[k]) return unit4(a);
    const b = arr.slice(4 * k + 4, 4 * k + 8);
    if (b.some((x) => x === null)) return unit4(a);
    const f = (t - T[k]) / (T[k + 1] - T[k]);
    const s = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] < 0 ? -1 : 1;
    return unit4(a.map((x, i) => x * (1 - f) + s * b[i] * f));
  }
  function unit4(q) {
    const n = Math.hypot(q[0], q[1], q[2], q[3]) || QS;
    return q.map((x) => x / n);
  }

  // ---- camera ----------------------------------------------------------
  const centre = (function () {
    let lo = [Infinity, Infinity, 0];
    let hi = [-Infinity, -Infinity, 0];
    for (const b of D.bodies) {
      lo = [Math.min(lo[0], b.pos[0]), Math.min(lo[1], b.pos[1]), 0];
      hi = [Math.max(hi[0], b.pos[0]), Math.max(hi[1], b.pos[1]), 0];
    }
    return mul(add(lo, hi), 0.5);
  })();
  const radius = Math.max(1, ...D.bodies.map((b) => norm(sub(b.pos, centre)) + size(b)));
  function size(b) { return Math.max(...b.axes.map(norm)); }

  function camera(w, h) {
    // The sphere of every body fits the view with a margin: at a distance
    // d its half-width seen under the half-angle of 19° is d·sin 19°.
    const dist = (radius * 1.12) / Math.sin((19 * Math.PI) / 180) / state.zoom;
    const cp = Math.cos(state.pitch);
    const eye = add(centre, mul([cp * Math.cos(state.yaw), cp * Math.sin(state.yaw), Math.sin(state.pitch)], dist));
    const f = unit(sub(centre, eye));
    const r = unit(cross(f, [0, 0, 1]));
    const u = cross(r, f);
    const focal = (0.5 * Math.min(w, h)) / Math.tan((38 * Math.PI) / 360);
    return {
      eye,
      f,
      project(p) {
        const d = sub(p, eye);
        const z = Math.max(dot(d, f), 1e-3);
        return [w / 2 + (focal * dot(d, r)) / z, h / 2 - (focal * dot(d, u)) / z, z];
      },
    };
  }

  // ---- the scene -------------------------------------------------------
  const scene = $('scene');
  const ctx = scene.getContext('2d');
  const FACES = [[0, 1], [0, -1], [1, 1], [1, -1], [2, 1], [2, -1]];
  const LIGHT = unit([0.4, -0.5, 0.9]);

  /** The 8 corners of box `axes` at `pos` turned by q, and its 6 faces. */
  function boxOf(pos, axes, q) {
    const a = axes.map((v) => rotate(q, v));
    const corner = (s) => add(add(add(pos, mul(a[0], s[0])), mul(a[1], s[1])), mul(a[2], s[2]));
    const faces = FACES.map(([k, s]) => {
      const i = (k + 1) % 3;
      const j = (k + 2) % 3;
      const pts = [[1, 1], [-1, 1], [-1, -1], [1, -1]].map(([p, r]) => {
        const c = [0, 0, 0];
        c[k] = s; c[i] = p; c[j] = r;
        return corner(c);
      });
      return { pts, normal: mul(unit(a[k]), s) };
    });
    return { a, faces };
  }

  function drawScene() {
    const w = scene.width;
    const h = scene.height;
    const dpr = window.devicePixelRatio || 1;
    ctx.fillStyle = '#14171c';
    ctx.fillRect(0, 0, w, h);
    const cam = camera(w, h);
    drawRings(cam, dpr);
    drawEdges(cam, dpr);
    const polys = [];
    const overlays = [];
    D.bodies.forEach((b, k) => {
      const q = quatAt(F.q[k], state.t);
      if (!q) return;
      const box = boxOf(b.pos, b.axes, q);
      const base = k === 0 ? [0, 0, 86] : null;
      for (const face of box.faces) {
        const mid = mul(face.pts.reduce(add, [0, 0, 0]), 0.25);
        if (dot(face.normal, sub(mid, cam.eye)) >= 0) continue;
        const light = 0.35 + 0.65 * Math.max(0, dot(face.normal, LIGHT));
        const fill = base ? 'hsl(0,0%,' + Math.round(30 + 56 * light) + '%)' : agentColor(k - 1, Math.round(22 + 48 * light));
        polys.push({ z: cam.project(mid)[2], pts: face.pts.map(cam.project), fill });
      }
      overlays.push({ k, b, box });
    });
    polys.sort((p, q) => q.z - p.z);
    for (const p of polys) {
      ctx.beginPath();
      p.pts.forEach((s, i) => (i ? ctx.lineTo(s[0], s[1]) : ctx.moveTo(s[0], s[1])));
      ctx.closePath();
      ctx.fillStyle = p.fill;
      ctx.fill();
      ctx.strokeStyle = 'rgba(0,0,0,0.35)';
      ctx.lineWidth = dpr;
      ctx.stroke();
    }
    for (const o of overlays) drawOverlay(cam, o, dpr);
  }

  function drawRings(cam, dpr) {
    const depth = Math.max(0, ...D.bodies.map((b) => b.depth));
    ctx.strokeStyle = 'rgba(255,255,255,0.06)';
    ctx.lineWidth = dpr;
    for (let d = 1; d <= depth; d++) {
      ctx.beginPath();
      for (let i = 0; i <= 96; i++) {
        const a = (i / 96) * 2 * Math.PI;
        const s = cam.project(add(D.bodies[0].pos, [d * Math.cos(a), d * Math.sin(a), 0]));
        if (i) ctx.lineTo(s[0], s[1]); else ctx.moveTo(s[0], s[1]);
      }
      ctx.stroke();
    }
  }

  function drawEdges(cam, dpr) {
    const line = (a, b) => {
      const p = cam.project(a);
      const q = cam.project(b);
      ctx.beginPath();
      ctx.moveTo(p[0], p[1]);
      ctx.lineTo(q[0], q[1]);
      ctx.stroke();
    };
    ctx.lineWidth = 2 * dpr;
    ctx.strokeStyle = 'rgba(170,180,195,0.55)';
    ctx.setLineDash([]);
    for (const [i, j] of D.edges) line(D.bodies[i].pos, D.bodies[j].pos);
    ctx.strokeStyle = 'rgba(255,196,64,0.8)';
    ctx.setLineDash([6 * dpr, 5 * dpr]);
    D.bodies.forEach((b) => { if (b.leader_link) line(D.bodies[0].pos, b.pos); });
    ctx.setLineDash([]);
  }

  /** Axes, the observer's ghost, the leader-link ring and the label of one body. */
  function drawOverlay(cam, o, dpr) {
    const { k, b, box } = o;
    if ($('axes').checked) {
      box.a.forEach((v, i) => {
        const p = cam.project(b.pos);
        const q = cam.project(add(b.pos, mul(unit(v), size(b) * (k === 0 ? 2.2 : 1.5))));
        ctx.strokeStyle = AXIS[i];
        ctx.lineWidth = (k === 0 ? 3 : 1.5) * dpr;
        ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
      });
    }
    if (k > 0 && D.observer && $('ghosts').checked) {
      const qh = quatAt(F.q_hat[k - 1], state.t);
      if (qh) drawGhost(cam, boxOf(b.pos, b.axes.map((v) => mul(v, 1.12)), qh), k, dpr);
    }
    if (b.leader_link) {
      ctx.strokeStyle = 'rgba(255,196,64,0.9)';
      ctx.lineWidth = 2 * dpr;
      ctx.beginPath();
      for (let i = 0; i <= 48; i++) {
        const a = (i / 48) * 2 * Math.PI;
        const s = cam.project(add(b.pos, mul([Math.cos(a), Math.sin(a), 0], size(b) * 1.45)));
        if (i) ctx.lineTo(s[0], s[1]); else ctx.moveTo(s[0], s[1]);
      }
      ctx.stroke();
    }
    const s = cam.project(add(b.pos, [0, 0, size(b) * 1.7]));
    ctx.fillStyle = k === 0 ? '#ffffff' : agentColor(k - 1, 75);
    ctx.font = Math.round(12 * dpr) + 'px system-ui, sans-serif';
    ctx.textAlign = 'center';
    ctx.fillText(k === 0 ? 'leader' : String(b.id), s[0], s[1]);
  }

  function drawGhost(cam, box, k, dpr) {
    ctx.strokeStyle = agentColor(k - 1, 80, 0.85);
    ctx.lineWidth = 1.2 * dpr;
    ctx.setLineDash([4 * dpr, 3 * dpr]);
    for (const face of box.faces) {
      ctx.beginPath();
      face.pts.map(cam.project).forEach((s, i) => (i ? ctx.lineTo(s[0], s[1]) : ctx.moveTo(s[0], s[1])));
      ctx.closePath();
      ctx.stroke();
    }
    ctx.setLineDash([]);
  }

  // ---- error plots -----------------------------------------------------
  const plots = [
    { canvas: $('plot-att'), curves: [F.att, F.obs_att] },
    { canvas: $('plot-angvel'), curves: [F.angvel, F.obs_angvel] },
  ];

  /** Decades [lo, hi] (log10) spanning every value of `curves`. */
  function range(curves) {
    let lo = Infinity;
    let hi = -Infinity;
    for (const set of curves) for (const c of set) for (const v of c) {
      if (v === null) continue;
      lo = Math.min(lo, v / ES);
      hi = Math.max(hi, v / ES);
    }
    if (!isFinite(lo)) return [-16, 0];
    return [Math.floor(lo), Math.max(Math.ceil(hi), Math.floor(lo) + 1)];
  }

  function frame(p) {
    const w = p.canvas.width;
    const h = p.canvas.height;
    const dpr = window.devicePixelRatio || 1;
    return { w, h, dpr, l: 44 * dpr, r: w - 8 * dpr, t: 6 * dpr, b: h - 20 * dpr };
  }

  function renderPlot(p) {
    const img = document.createElement('canvas');
    img.width = p.canvas.width;
    img.height = p.canvas.height;
    const g = img.getContext('2d');
    const fr = frame(p);
    const [lo, hi] = range(p.curves);
    p.range = [lo, hi];
    const X = (t) => fr.l + ((t - T0) / (T1 - T0 || 1)) * (fr.r - fr.l);
    const Y = (v) => fr.b - ((v - lo) / (hi - lo)) * (fr.b - fr.t);
    g.fillStyle = '#101318';
    g.fillRect(0, 0, fr.w, fr.h);
    g.font = Math.round(10 * fr.dpr) + 'px system-ui, sans-serif';
    g.fillStyle = '#7d8793';
    g.strokeStyle = 'rgba(255,255,255,0.08)';
    g.lineWidth = fr.dpr;
    const step = Math.max(1, Math.ceil((hi - lo) / 8));
    g.textAlign = 'right';
    for (let d = lo; d <= hi; d += step) {
      g.beginPath(); g.moveTo(fr.l, Y(d)); g.lineTo(fr.r, Y(d)); g.stroke();
      g.fillText('1e' + d, fr.l - 4 * fr.dpr, Y(d) + 3 * fr.dpr);
    }
    g.textAlign = 'center';
    const tick = niceStep((T1 - T0) / 6);
    for (let t = Math.ceil(T0 / tick) * tick; t <= T1 + 1e-9; t += tick) {
      g.fillText(String(+t.toFixed(6)), X(t), fr.h - 6 * fr.dpr);
    }
    p.curves.forEach((set, observer) => set.forEach((c, k) => {
      // The body's curve in the agent's look; its observer's thinner, lighter.
      g.strokeStyle = agentColor(k, observer ? 80 : 58, observer ? 0.7 : 1);
      g.lineWidth = (observer ? 1 : 1.5) * fr.dpr;
      g.setLineDash(agentDash(k).map((x) => x * fr.dpr));
      g.beginPath();
      let pen = false;
      c.forEach((v, i) => {
        if (v === null) { pen = false; return; }
        if (pen) g.lineTo(X(T[i]), Y(v / ES)); else g.moveTo(X(T[i]), Y(v / ES));
        pen = true;
      });
      g.stroke();
    }));
    marks(g, fr, X);
    p.image = img;
    p.X = X;
  }

  /** The run's events as dashed vertical lines, labelled, on a plot. */
  function marks(g, fr, X) {
    g.setLineDash([3 * fr.dpr, 3 * fr.dpr]);
    g.strokeStyle = 'rgba(255,214,102,0.7)';
    g.fillStyle = 'rgba(255,214,102,0.9)';
    g.lineWidth = fr.dpr;
    g.textAlign = 'left';
    for (const e of D.run.events || []) {
      const x = X(e.t);
      g.beginPath(); g.moveTo(x, fr.t); g.lineTo(x, fr.b); g.stroke();
      g.fillText(e.label, x + 3 * fr.dpr, fr.t + 10 * fr.dpr);
    }
    g.setLineDash([]);
  }

  /** The run's events as tick marks of the time slider. */
  function eventTicks() {
    const events = D.run.events || [];
    if (!events.length) return;
    const list = document.createElement('datalist');
    list.id = 'events';
    for (const e of events) {
      const o = document.createElement('option');
      o.value = String(Math.round(((e.t - T0) / (T1 - T0 || 1)) * 10000));
      o.label = e.label;
      list.appendChild(o);
    }
    document.body.appendChild(list);
    $('scrub').setAttribute('list', 'events');
  }

  function niceStep(x) {
    const e = Math.pow(10, Math.floor(Math.log10(x || 1)));
    const m = x / e;
    return (m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10) * e;
  }

  function drawPlot(p) {
    const g = p.canvas.getContext('2d');
    const fr = frame(p);
    if (!p.image) renderPlot(p);
    g.drawImage(p.image, 0, 0);
    const x = p.X(state.t);
    g.strokeStyle = '#ffffff';
    g.lineWidth = fr.dpr;
    g.beginPath(); g.moveTo(x, fr.t); g.lineTo(x, fr.b); g.stroke();
  }

  // ---- page --------------------------------------------------------------
  function resize() {
    const dpr = window.devicePixelRatio || 1;
    for (const c of [scene, ...plots.map((p) => p.canvas)]) {
      c.width = Math.max(1, Math.round(c.clientWidth * dpr));
      c.height = Math.max(1, Math.round(c.clientHeight * dpr));
    }
    plots.forEach((p) => { p.image = null; });
    state.dirty = true;
  }

  function draw() {
    drawScene();
    plots.forEach(drawPlot);
    $('time').textContent = 't = ' + state.t.toFixed(2) + ' s / ' + T1.toFixed(2) + ' s';
    $('scrub').value = String(Math.round(((state.t - T0) / (T1 - T0 || 1)) * 10000));
    $('play').textContent = state.playing ? 'pause' : 'play';
    document.documentElement.setAttribute('data-rendered', state.t.toFixed(3));
    state.dirty = false;
  }

  function seek(t) {
    state.t = Math.min(T1, Math.max(T0, t));
    state.dirty = true;
  }

  function tick(now) {
    if (state.playing && state.last !== null) {
      seek(state.t + ((now - state.last) / 1000) * state.speed);
      if (state.t >= T1) state.playing = false;
    }
    state.last = now;
    if (state.dirty) draw();
    requestAnimationFrame(tick);
  }

  /** `#t=12.5&paused&speed=2`. */
  function readHash() {
    const args = new URLSearchParams(location.hash.replace(/^#/, ''));
    if (args.has('t')) seek(parseFloat(args.get('t')) || 0);
    if (args.has('speed')) {
      state.speed = parseFloat(args.get('speed')) || 1;
      $('speed').value = String(state.speed);
    }
    state.playing = !args.has('paused');
    state.dirty = true;
  }

  function controls() {
    $('play').addEventListener('click', () => {
      if (!state.playing && state.t >= T1) seek(T0);
      state.playing = !state.playing;
      state.dirty = true;
    });
    $('scrub').addEventListener('input', (e) => seek(T0 + (e.target.value / 10000) * (T1 - T0)));
    $('speed').addEventListener('change', (e) => { state.speed = parseFloat(e.target.value); });
    for (const id of ['ghosts', 'axes']) $(id).addEventListener('change', () => { state.dirty = true; });
    let drag = null;
    scene.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; scene.setPointerCapture(e.pointerId); });
    scene.addEventListener('pointerup', () => { drag = null; });
    scene.addEventListener('pointermove', (e) => {
      if (!drag) return;
      state.yaw -= (e.clientX - drag[0]) * 0.01;
      state.pitch = Math.min(1.55, Math.max(-0.2, state.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      state.dirty = true;
    });
    scene.addEventListener('wheel', (e) => {
      e.preventDefault();
      state.zoom = Math.min(8, Math.max(0.3, state.zoom * Math.exp(-e.deltaY * 0.001)));
      state.dirty = true;
    }, { passive: false });
    for (const p of plots) {
      const go = (e) => {
        const fr = frame(p);
        const x = (e.offsetX * fr.w) / p.canvas.clientWidth;
        seek(T0 + ((x - fr.l) / (fr.r - fr.l)) * (T1 - T0));
      };
      p.canvas.addEventListener('pointerdown', (e) => { go(e); p.canvas.setPointerCapture(e.pointerId); });
      p.canvas.addEventListener('pointermove', (e) => { if (e.buttons) go(e); });
    }
    window.addEventListener('keydown', (e) => {
      if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT') return;
      const dt = NF > 1 ? T[1] - T[0] : 0;
      if (e.key === ' ') { e.preventDefault(); $('play').click(); }
      if (e.key === 'ArrowRight') seek(state.t + dt);
      if (e.key === 'ArrowLeft') seek(state.t - dt);
    });
    window.addEventListener('resize', resize);
    window.addEventListener('hashchange', readHash);
  }

  function describe() {
    const r = D.run;
    const agents = NB - 1;
    const linked = D.bodies.filter((b) => b.leader_link).length;
    $('info').textContent = D.scheme + ' · ' + agents + ' agents (' + linked + ' read the leader, dashed gold) · ' +
      (T1 - T0).toFixed(2) + ' s in ' + NF + ' frames' + (r.realtime ? ' · real time ×' + r.realtime : ' · lockstep');
    if (!r.complete) {
      $('warning').hidden = false;
      $('warning').textContent = 'incomplete: ' + (r.incomplete_reason || 'stopped early');
    }
    // The legend folds away past a dozen agents (it would cover the bodies).
    const legend = $('legend-list');
    $('legend').open = agents <= 12;
    $('legend-count').textContent = agents + ' agents';
    D.bodies.forEach((b, k) => {
      if (k === 0) return;
      const row = document.createElement('div');
      const sw = document.createElement('i');
      const colour = agentColor(k - 1, 58);
      const [on, off] = agentDash(k - 1).length ? agentDash(k - 1) : [1, 0];
      sw.style.background = 'repeating-linear-gradient(90deg, ' + colour + ' 0 ' + on + 'px, transparent ' + on +
        'px ' + (on + off) + 'px)';
      row.append(sw, 'agent ' + b.id + (b.leader_link ? ' ◎' : ''));
      legend.append(row);
    });
    $('plot-note').textContent = D.observer
      ? 'thick: the body (Rᵢ, ωᵢ); thin, lighter: its observer (R̂ᵢ, ω̂ᵢ), drawn in 3D as a dashed ghost'
      : 'observerless scheme: no estimates';
    if (!D.observer) $('ghosts').parentElement.hidden = true;
  }

  describe();
  controls();
  eventTicks();
  readHash();
  resize();
  draw();
  requestAnimationFrame(tick);
})();

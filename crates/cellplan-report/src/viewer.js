// cellplan report viewer: plays a plan back in WebGL2 and moves a time cursor over the charts.
// Part of cellplan (MIT). No dependencies; the page embeds the data as JSON in
// <script id="cellplan-data">. URL hash options: t=<s> (time), view=3d (viewer fills the
// window), az=<deg>, el=<deg> (camera), play=1.
'use strict';
(function () {
  const D = JSON.parse(document.getElementById('cellplan-data').textContent);
  const bytes = (s) => Uint8Array.from(atob(s), (c) => c.charCodeAt(0));
  const f32 = (s) => new Float32Array(bytes(s).buffer);
  const u32 = (s) => new Uint32Array(bytes(s).buffer);
  const hash = new Map(
    location.hash.replace(/^#/, '').split('&').filter(Boolean).map((kv) => {
      const [k, v] = kv.split('=');
      const decode = (x) => {
        try {
          return decodeURIComponent(x);
        } catch (e) {
          return x;
        }
      };
      return [decode(k), decode(v || '')];
    })
  );
  if (hash.get('view') === '3d') document.body.classList.add('only-3d');

  // ---- 4×4 matrices, column-major ----------------------------------------------------------
  const mat = {
    mul(a, b) {
      const o = new Float32Array(16);
      for (let c = 0; c < 4; c++)
        for (let r = 0; r < 4; r++) {
          let s = 0;
          for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
          o[c * 4 + r] = s;
        }
      return o;
    },
    // [x, y, z, qx, qy, qz, qw]
    pose(p) {
      const [x, y, z, qx, qy, qz, qw] = p;
      const m = new Float32Array(16);
      m[0] = 1 - 2 * (qy * qy + qz * qz);
      m[1] = 2 * (qx * qy + qz * qw);
      m[2] = 2 * (qx * qz - qy * qw);
      m[4] = 2 * (qx * qy - qz * qw);
      m[5] = 1 - 2 * (qx * qx + qz * qz);
      m[6] = 2 * (qy * qz + qx * qw);
      m[8] = 2 * (qx * qz + qy * qw);
      m[9] = 2 * (qy * qz - qx * qw);
      m[10] = 1 - 2 * (qx * qx + qy * qy);
      m[12] = x;
      m[13] = y;
      m[14] = z;
      m[15] = 1;
      return m;
    },
    joint(axis, prismatic, v) {
      if (prismatic) return mat.pose([axis[0] * v, axis[1] * v, axis[2] * v, 0, 0, 0, 1]);
      const s = Math.sin(v / 2);
      return mat.pose([0, 0, 0, axis[0] * s, axis[1] * s, axis[2] * s, Math.cos(v / 2)]);
    },
    perspective(fovy, aspect, near, far) {
      const f = 1 / Math.tan(fovy / 2);
      const m = new Float32Array(16);
      m[0] = f / aspect;
      m[5] = f;
      m[10] = (far + near) / (near - far);
      m[11] = -1;
      m[14] = (2 * far * near) / (near - far);
      return m;
    },
    lookAt(eye, at, up) {
      const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
      const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
      const norm = (a) => {
        const l = Math.hypot(a[0], a[1], a[2]) || 1;
        return [a[0] / l, a[1] / l, a[2] / l];
      };
      const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
      const z = norm(sub(eye, at));
      const x = norm(cross(up, z));
      const y = cross(z, x);
      return new Float32Array([
        x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
        -dot(x, eye), -dot(y, eye), -dot(z, eye), 1,
      ]);
    },
  };

  // ---- the plan on the clock ---------------------------------------------------------------
  const robots = D.robots.map((r) => ({
    ...r,
    t: f32(r.t),
    q: f32(r.q),
    path: f32(r.path),
    before: r.before ? f32(r.before) : new Float32Array(0),
  }));
  const tEnd = D.t_end;
  function qAt(r, t) {
    const n = r.t.length;
    const dof = r.dof;
    let lo = 0;
    let hi = n;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (r.t[mid] <= t) lo = mid + 1;
      else hi = mid;
    }
    const k = lo;
    const q = new Array(dof);
    if (k === 0 || k === n) {
      const s = k === 0 ? 0 : n - 1;
      for (let j = 0; j < dof; j++) q[j] = r.q[s * dof + j];
      return q;
    }
    const a = k - 1;
    const f = r.t[k] > r.t[a] ? (t - r.t[a]) / (r.t[k] - r.t[a]) : 0;
    for (let j = 0; j < dof; j++) {
      const x = r.q[a * dof + j];
      q[j] = x + f * (r.q[k * dof + j] - x);
    }
    return q;
  }
  function linkMatrices(r, q) {
    let parent = mat.pose(r.base);
    return r.links.map((l) => {
      let m = mat.mul(parent, mat.pose(l.o));
      if (l.j >= 0) m = mat.mul(m, mat.joint(l.axis, l.prismatic, q[l.j]));
      parent = m;
      return m;
    });
  }
  function activity(ri, t) {
    const iv = D.robots[ri].intervals;
    for (const [s, e, what] of iv) if (t >= s && t < e) return what;
    return t >= (iv.length ? iv[iv.length - 1][1] : 0) ? 'done (home)' : 'idle';
  }

  // ---- WebGL -------------------------------------------------------------------------------
  const canvas = document.getElementById('view');
  const msg = document.getElementById('viewer-msg');
  const gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
  if (!gl) {
    msg.textContent = 'This browser has no WebGL2: the 3D view cannot be shown (the charts below still work).';
    document.body.dataset.viewer = 'no-webgl';
    setupClock(null);
    return;
  }
  function program(vs, fs) {
    const p = gl.createProgram();
    for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const sh = gl.createShader(type);
      gl.shaderSource(sh, src);
      gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      gl.attachShader(p, sh);
    }
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    const u = {};
    const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < n; i++) {
      const name = gl.getActiveUniform(p, i).name;
      u[name] = gl.getUniformLocation(p, name);
    }
    return { p, u };
  }
  const meshProg = program(
    `#version 300 es
layout(location = 0) in vec3 aPos; uniform mat4 uPV; uniform mat4 uM; out vec3 vW;
void main() { vec4 w = uM * vec4(aPos, 1.0); vW = w.xyz; gl_Position = uPV * w; }`,
    `#version 300 es
precision highp float; in vec3 vW; uniform vec3 uC; uniform vec3 uEye; out vec4 o;
void main() {
  vec3 n = normalize(cross(dFdx(vW), dFdy(vW)));
  vec3 l = normalize(uEye - vW);
  float d = abs(dot(n, l));
  o = vec4(uC * (0.38 + 0.42 * d + 0.22 * abs(n.z)), 1.0);
}`
  );
  const lineProg = program(
    `#version 300 es
in vec3 aPos; in vec3 aCol; uniform mat4 uPV; uniform float uSize; out vec3 vC;
void main() { vC = aCol; gl_Position = uPV * vec4(aPos, 1.0); gl_PointSize = uSize; }`,
    `#version 300 es
precision highp float; in vec3 vC; out vec4 o; void main() { o = vec4(vC, 1.0); }`
  );
  const geoms = D.geometries.map((g) => {
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const vb = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, vb);
    gl.bufferData(gl.ARRAY_BUFFER, f32(g.p), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    const ib = gl.createBuffer();
    const idx = u32(g.i);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    return { vao, count: idx.length };
  });
  // Line sets: {vao, count, mode}
  function lineSet(pos, col, mode) {
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const loc = [gl.getAttribLocation(lineProg.p, 'aPos'), gl.getAttribLocation(lineProg.p, 'aCol')];
    const bufs = [];
    for (const [k, data] of [[0, pos], [1, col]]) {
      const b = gl.createBuffer();
      bufs.push(b);
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.DYNAMIC_DRAW);
      gl.enableVertexAttribArray(loc[k]);
      gl.vertexAttribPointer(loc[k], 3, gl.FLOAT, false, 0, 0);
    }
    gl.bindVertexArray(null);
    return { vao, count: pos.length / 3, mode, bufs };
  }
  const polyline = (xyz, c, pos, col) => {
    for (let k = 0; k + 5 < xyz.length; k += 3) {
      pos.push(xyz[k], xyz[k + 1], xyz[k + 2], xyz[k + 3], xyz[k + 4], xyz[k + 5]);
      col.push(...c, ...c);
    }
  };
  const grey = [0.55, 0.55, 0.58];
  const red = [0.84, 0.15, 0.16];
  const taskColour = (t) => (t.r >= 0 ? D.robots[t.r].colour : red);
  const sets = {};
  {
    const pos = [];
    const col = [];
    for (const t of D.tasks) {
      const c = taskColour(t);
      pos.push(...t.p, t.p[0] + 0.15 * t.n[0], t.p[1] + 0.15 * t.n[1], t.p[2] + 0.15 * t.n[2]);
      col.push(...c, ...c);
    }
    sets.normals = lineSet(pos, col, gl.LINES);
    sets.mps = lineSet(D.tasks.flatMap((t) => t.p), D.tasks.flatMap(taskColour), gl.POINTS);
  }
  {
    const pos = [];
    const col = [];
    robots.forEach((r) => polyline(r.path, r.colour, pos, col));
    sets.paths = lineSet(pos, col, gl.LINES);
    const bpos = [];
    const bcol = [];
    robots.forEach((r) => polyline(r.before, r.colour.map((x) => 0.45 + 0.45 * x), bpos, bcol));
    sets.before = lineSet(bpos, bcol, gl.LINES);
  }
  {
    const pos = [];
    const col = [];
    const s = 0.12;
    for (const c of D.conflicts) {
      for (const p of c.p) {
        for (const [dx, dy, dz] of [[s, s, s], [s, -s, s], [-s, s, s], [-s, -s, s]]) {
          pos.push(p[0] - dx, p[1] - dy, p[2] - dz, p[0] + dx, p[1] + dy, p[2] + dz);
          col.push(...red, ...red);
        }
      }
      pos.push(...c.p[0], ...c.p[1]);
      col.push(...red, ...red);
    }
    sets.conflicts = lineSet(pos, col, gl.LINES);
  }
  {
    const a = 0.5;
    sets.axes = lineSet(
      [0, 0, 0, a, 0, 0, 0, 0, 0, 0, a, 0, 0, 0, 0, 0, 0, a],
      [1, 0, 0, 1, 0, 0, 0, 0.6, 0, 0, 0.6, 0, 0, 0, 1, 0, 0, 1],
      gl.LINES
    );
  }
  const tcpSet = lineSet(new Array(robots.length * 3).fill(0), robots.flatMap((r) => r.colour), gl.POINTS);

  // ---- camera ------------------------------------------------------------------------------
  const box = D.bounds; // [min, max]
  const centre = [0, 1, 2].map((i) => (box[0][i] + box[1][i]) / 2);
  const radius = Math.max(0.5, Math.hypot(box[1][0] - box[0][0], box[1][1] - box[0][1], box[1][2] - box[0][2]) / 2);
  const cam = {
    az: hash.has('az') ? (+hash.get('az') * Math.PI) / 180 : D.camera_azimuth,
    el: hash.has('el') ? (+hash.get('el') * Math.PI) / 180 : 0.5,
    dist: 1.8 * radius,
    target: centre.slice(),
  };
  function eye() {
    const c = Math.cos(cam.el);
    return [
      cam.target[0] + cam.dist * c * Math.cos(cam.az),
      cam.target[1] + cam.dist * c * Math.sin(cam.az),
      cam.target[2] + cam.dist * Math.sin(cam.el),
    ];
  }
  const home = { ...cam, target: cam.target.slice() };
  document.getElementById('reset-view').addEventListener('click', () => {
    Object.assign(cam, home, { target: home.target.slice() });
    requestDraw();
  });
  const show = { paths: true, before: false, conflicts: true, normals: true };
  let now = 0;
  let frames = 0;

  function draw() {
    const w = Math.max(1, Math.round(canvas.clientWidth * devicePixelRatio));
    const h = Math.max(1, Math.round(canvas.clientHeight * devicePixelRatio));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
    }
    gl.viewport(0, 0, w, h);
    gl.clearColor(0.97, 0.97, 0.98, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const e = eye();
    const pv = mat.mul(
      mat.perspective(0.8, w / h, cam.dist / 200, cam.dist * 20),
      mat.lookAt(e, cam.target, [0, 0, 1])
    );
    gl.useProgram(meshProg.p);
    gl.uniformMatrix4fv(meshProg.u.uPV, false, pv);
    gl.uniform3fv(meshProg.u.uEye, e);
    const drawPart = (g, m, c) => {
      gl.uniformMatrix4fv(meshProg.u.uM, false, m);
      gl.uniform3fv(meshProg.u.uC, c);
      gl.bindVertexArray(geoms[g].vao);
      gl.drawElements(gl.TRIANGLES, geoms[g].count, gl.UNSIGNED_INT, 0);
    };
    for (const s of D.statics) drawPart(s.g, mat.pose(s.pose), s.colour);
    const tcp = [];
    robots.forEach((r) => {
      const q = qAt(r, now);
      const links = linkMatrices(r, q);
      const body = r.colour.map((x) => 0.25 + 0.75 * x);
      links.forEach((m, i) => {
        for (const part of r.links[i].parts) drawPart(part.g, mat.mul(m, mat.pose(part.pose)), body);
      });
      const t = mat.mul(links.length ? links[links.length - 1] : mat.pose(r.base), mat.pose(r.tcp));
      tcp.push(t[12], t[13], t[14]);
    });
    gl.useProgram(lineProg.p);
    gl.uniformMatrix4fv(lineProg.u.uPV, false, pv);
    const lines = (set, size) => {
      gl.uniform1f(lineProg.u.uSize, size || 1);
      gl.bindVertexArray(set.vao);
      gl.drawArrays(set.mode, 0, set.count);
    };
    lines(sets.axes);
    if (show.normals) {
      lines(sets.normals);
      lines(sets.mps, 5 * devicePixelRatio);
    }
    if (show.paths) lines(sets.paths);
    if (show.before) lines(sets.before);
    if (show.conflicts) lines(sets.conflicts);
    gl.bindBuffer(gl.ARRAY_BUFFER, tcpSet.bufs[0]);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, new Float32Array(tcp));
    lines(tcpSet, 9 * devicePixelRatio);
    gl.bindVertexArray(null);
    frames++;
    document.body.dataset.viewer = 'ok';
    document.body.dataset.frames = String(frames);
    document.body.dataset.time = now.toFixed(3);
  }

  // ---- interaction -------------------------------------------------------------------------
  let drag = null;
  canvas.addEventListener('pointerdown', (ev) => {
    drag = { x: ev.clientX, y: ev.clientY, pan: ev.shiftKey || ev.button === 2 };
    canvas.setPointerCapture(ev.pointerId);
  });
  canvas.addEventListener('pointermove', (ev) => {
    if (!drag) return;
    const dx = ev.clientX - drag.x;
    const dy = ev.clientY - drag.y;
    drag.x = ev.clientX;
    drag.y = ev.clientY;
    if (drag.pan) {
      const s = cam.dist / canvas.clientHeight;
      const right = [-Math.sin(cam.az), Math.cos(cam.az), 0];
      cam.target[0] -= right[0] * dx * s;
      cam.target[1] -= right[1] * dx * s;
      cam.target[2] += dy * s;
    } else {
      cam.az -= dx * 0.008;
      cam.el = Math.max(-1.5, Math.min(1.5, cam.el + dy * 0.008));
    }
    requestDraw();
  });
  canvas.addEventListener('pointerup', () => (drag = null));
  canvas.addEventListener('contextmenu', (ev) => ev.preventDefault());
  canvas.addEventListener(
    'wheel',
    (ev) => {
      ev.preventDefault();
      cam.dist *= Math.exp(ev.deltaY * 0.001);
      requestDraw();
    },
    { passive: false }
  );
  for (const key of Object.keys(show)) {
    const box = document.getElementById('show-' + key);
    if (!box) continue;
    box.checked = show[key];
    box.addEventListener('change', () => {
      show[key] = box.checked;
      requestDraw();
    });
  }
  let pending = false;
  function requestDraw() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      draw();
    });
  }
  window.addEventListener('resize', requestDraw);
  setupClock((t) => {
    now = t;
    requestDraw();
  });
  now = clampT(+hash.get('t') || 0);
  draw();

  function clampT(t) {
    return Math.max(0, Math.min(tEnd, isFinite(t) ? t : 0));
  }

  // ---- the clock: slider, play/pause, chart cursors, status --------------------------------
  function setupClock(onTime) {
    const slider = document.getElementById('time');
    const clock = document.getElementById('clock');
    const play = document.getElementById('play');
    const speed = document.getElementById('speed');
    const status = document.getElementById('status');
    const charts = Array.from(document.querySelectorAll('svg.clock'));
    slider.max = String(tEnd);
    let t = clampT(+hash.get('t') || 0);
    let playing = false;
    let last = 0;
    function set(v) {
      t = clampT(v);
      slider.value = String(t);
      clock.textContent = t.toFixed(2) + ' s';
      for (const c of charts) {
        const [t0, t1, x0, x1] = ['t0', 't1', 'x0', 'x1'].map((k) => +c.dataset[k]);
        const x = x0 + ((t - t0) / (t1 - t0 || 1)) * (x1 - x0);
        const line = c.querySelector('line.cursor');
        line.setAttribute('x1', x);
        line.setAttribute('x2', x);
      }
      status.textContent = D.robots.map((r, i) => r.name + ': ' + activity(i, t)).join('   ·   ');
      if (onTime) onTime(t);
    }
    slider.addEventListener('input', () => set(+slider.value));
    function tick(ms) {
      if (!playing) return;
      const dt = last ? (ms - last) / 1000 : 0;
      last = ms;
      let next = t + dt * +speed.value;
      if (next > tEnd) next = 0;
      set(next);
      requestAnimationFrame(tick);
    }
    play.addEventListener('click', () => {
      playing = !playing;
      play.textContent = playing ? '❚❚ pause' : '▶ play';
      last = 0;
      if (playing) requestAnimationFrame(tick);
    });
    for (const c of charts) {
      c.addEventListener('click', (ev) => {
        const pt = new DOMPoint(ev.clientX, ev.clientY).matrixTransform(c.getScreenCTM().inverse());
        const [t0, t1, x0, x1] = ['t0', 't1', 'x0', 'x1'].map((k) => +c.dataset[k]);
        set(t0 + ((pt.x - x0) / (x1 - x0)) * (t1 - t0));
      });
    }
    document.addEventListener('keydown', (ev) => {
      if (ev.code !== 'Space' || /^(INPUT|SELECT|BUTTON|TEXTAREA)$/.test(ev.target.tagName)) return;
      ev.preventDefault();
      play.click();
    });
    set(t);
    if (hash.get('play') === '1') play.click();
  }
})();

// The report page: reads the embedded data and draws the replay, the
// fitness curves, the architecture and the genome layout. No network.
'use strict';
(function () {
  const errors = [];
  function showError(msg) {
    errors.push(msg);
    const box = document.getElementById('errors');
    if (box) {
      box.hidden = false;
      box.textContent = 'This report met an error; some parts may be missing:\n' + errors.join('\n');
    }
    document.body.dataset.errors = String(errors.length);
  }
  window.addEventListener('error', (e) => showError(String(e.message || e)));

  const D = JSON.parse(document.getElementById('data').textContent);
  // A team's other robots' columns (robots.json), beside their episode.
  D.episodes.forEach((e, i) => { e._team = (D.robots || [])[i] || null; e._board = (D.boards || [])[i] || null; });
  // An episode without a single action (a flat battery) has nothing to show.
  D.episodes = D.episodes.filter((e) => e.actions.x.length > 0);
  const $ = (id) => document.getElementById(id);
  const PALETTE = ['#1f77b4', '#e8741c', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#17becf', '#7f7f7f', '#bcbd22'];
  const SVGNS = 'http://www.w3.org/2000/svg';
  const color = (i) => PALETTE[i % PALETTE.length];

  function el(tag, attrs, ...kids) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v === null || v === undefined || v === false) continue;
      if (k === 'text') e.textContent = v;
      else if (k === 'cls') e.className = v;
      else e.setAttribute(k, v === true ? '' : v);
    }
    for (const k of kids) if (k !== null && k !== undefined) e.append(k);
    return e;
  }
  function sv(tag, attrs, ...kids) {
    const e = document.createElementNS(SVGNS, tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v === null || v === undefined) continue;
      if (k === 'text') e.textContent = v;
      else e.setAttribute(k, String(v));
    }
    for (const k of kids) if (k) e.append(k);
    return e;
  }
  const fmt = (v, d) => (v === null || v === undefined || !isFinite(v)) ? '–' : Number(v).toFixed(d);
  const signed = (v, d) => (v > 0 ? '+' : '') + fmt(v, d);

  function tabs(box, labels, onSelect) {
    box.textContent = '';
    const buttons = labels.map((label, i) => {
      const b = el('button', { role: 'tab', 'aria-selected': 'false', text: label });
      b.addEventListener('click', () => onSelect(i));
      box.append(b);
      return b;
    });
    return (i) => buttons.forEach((b, k) => b.setAttribute('aria-selected', k === i ? 'true' : 'false'));
  }

  // ------------------------------------------------------------------ header
  const kinds = { run: 'run', experiment: 'experiment over ' + D.seeds.length + ' seeds', sweep: 'sweep over ' + D.seeds.length + ' seeds', stage: 'stage', replay: 'replay' };
  $('title').textContent = D.title;
  $('subtitle').textContent = kinds[D.kind] + ' · ' + D.source + ' · stages: ' + D.stages.map((s) => s.name).join(' → ');
  $('footer').textContent = 'Made by ' + D.generator + ' from ' + D.source + '. Self-contained: this file needs no network.';
  document.querySelectorAll('nav a').forEach((a) => a.addEventListener('click', (e) => {
    e.preventDefault();
    const s = $('sec-' + a.dataset.section);
    if (s) s.scrollIntoView({ behavior: 'smooth' });
  }));

  // ------------------------------------------------------------------ replay
  const R = { ep: null, base: null, robot: 0, epIndex: 0, a: 0, playing: false, speed: 10, acc: 0, last: 0, hashTimer: 0, timer: 0 };

  // The colours of a team's robots 1, 2, ... (robot 0 is drawn by its winning module).
  const TEAM = ['#606e82', '#a6783c', '#46826e', '#965a82', '#6e6e3c', '#3c6ea0', '#a05050', '#645aa0'];
  // The colours of a team's roles, as the trajectory picture draws them.
  const ROLES = ['#286ec8', '#dc8200', '#289646', '#8c46aa', '#0096a0', '#966432'];
  // Robot `j`'s colour: its role's in a team of roles, else its own.
  function robotColour(ep, j) {
    const team = ep._team;
    const role = team && (j === 0 ? team.role : (team.robots[j - 1] || {}).role);
    if (role) {
      const names = [];
      for (const r of [team.role].concat(team.robots.map((x) => x.role))) if (r && !names.includes(r)) names.push(r);
      return ROLES[names.indexOf(role) % ROLES.length];
    }
    return TEAM[(j + TEAM.length - 1) % TEAM.length];
  }

  // The robots of a team's episode that the page can follow (1 for one robot).
  const followable = (ep) => 1 + (ep._team ? ep._team.robots.length : 0);

  // Episode `ep` as robot `k` lived it: its columns, modules and starts in
  // place of robot 0's, the others (robot 0 among them) drawn around it.
  function robotView(ep, k) {
    if (!k || !ep._team) return ep;
    ep._views = ep._views || {};
    if (ep._views[k]) return ep._views[k];
    const c0 = ep.actions, team = ep._team, mine = team.robots[k - 1];
    const total = 1 + (c0.others || []).length;
    const pose = (j) => j === 0 ? { x: c0.x, y: c0.y, theta: c0.theta } : c0.others[j - 1];
    const nums = [];
    for (let j = 0; j < total; j++) if (j !== k) nums.push(j);
    const actions = Object.assign({}, mine.actions, { objects: c0.objects, others: nums.map(pose) });
    const start = (w, j) => j === 0 ? w.start : (w.others || [])[j - 1];
    const worlds = ep.worlds.map((w) => Object.assign({}, w, {
      start: start(w, k) || w.start,
      others: (w.others || []).length >= k ? nums.map((j) => start(w, j)).filter((p) => p) : [],
    }));
    const v = Object.assign({}, ep, { actions, worlds, modules: mine.modules, _: null, _views: null, _nums: nums, _robot: k, _role: mine.role || null });
    ep._views[k] = v;
    return v;
  }

  // The range-and-bearing board at action `a` of `ep` (as robot `ep._robot`
  // lived it): the robots' numbers and where they are, and the pairs that
  // perceive and hear each other in what the board read at `a`: within
  // its range (gap between the bodies) and, with occlusion, no inner wall
  // or cylinder across, on where the robots were after the previous action
  // (their starts at a world's first action), as the board was measured.
  // Every pair up to 300 robots; beyond, only the followed robot's.
  // `null` without a board.
  function hearing(ep, a) {
    const b = ep._board, wi = ep._.world[a], w = ep.worlds[wi];
    if (!b || !b.worlds[wi] || !(b.worlds[wi].range > 0)) return null;
    const c = ep.actions, others = c.others || [], starts = w.others || [];
    const first = a === w.from, k = a - 1;
    const me = ep._robot || 0;
    const robots = [{ num: me, x: first ? w.start[0] : c.x[k], y: first ? w.start[1] : c.y[k], at: [c.x[a], c.y[a]] }];
    for (let j = 0; j < others.length && j < starts.length; j++) {
      const o = others[j];
      robots.push({ num: ep._nums ? ep._nums[j] : j + 1, x: first ? starts[j][0] : o.x[k], y: first ? starts[j][1] : o.y[k], at: [o.x[a], o.y[a]] });
    }
    const reach = 2 * w.body_radius + b.worlds[wi].range;
    const hidden = (p, q) => b.worlds[wi].occlusion && (
      (w.walls || []).some(([u, v]) => crosses(p, q, u, v)) ||
      (w.cylinders || []).some(([cx, cy, r]) => segDist2([cx, cy], p, q) < r * r));
    const pairs = [];
    const all = robots.length <= 300;
    for (let i = 0; i < robots.length; i++) {
      for (let j = i + 1; j < robots.length; j++) {
        if (!all && i !== 0) break;
        const p = robots[i], q = robots[j];
        const dx = q.x - p.x, dy = q.y - p.y;
        if (dx * dx + dy * dy > reach * reach || hidden([p.x, p.y], [q.x, q.y])) continue;
        pairs.push([i, j]);
      }
    }
    const heard = pairs.filter(([i]) => i === 0).map(([, j]) => robots[j].num).sort((x, y) => x - y);
    return { robots, pairs, heard };
  }
  const cross = (o, p, q) => (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0]);
  // Whether segments p-q and u-v cross (as the simulator's shading test).
  function crosses(p, q, u, v) {
    const d1 = cross(u, v, p), d2 = cross(u, v, q), d3 = cross(p, q, u), d4 = cross(p, q, v);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
  }
  // The squared distance from point `c` to segment p-q.
  function segDist2(c, p, q) {
    const dx = q[0] - p[0], dy = q[1] - p[1], l2 = dx * dx + dy * dy;
    const t = l2 > 0 ? Math.max(0, Math.min(1, ((c[0] - p[0]) * dx + (c[1] - p[1]) * dy) / l2)) : 0;
    const ex = p[0] + t * dx - c[0], ey = p[1] + t * dy - c[1];
    return ex * ex + ey * ey;
  }

  function prepare(ep) {
    const c = ep.actions;
    const n = c.x.length;
    const world = new Array(n);
    const objs = new Array(n);
    let change = 0;
    ep.worlds.forEach((w, wi) => {
      const end = wi + 1 < ep.worlds.length ? ep.worlds[wi + 1].from : n;
      let cur = w.objects.map((o) => o.slice());
      while (change < c.objects.length && c.objects[change][0] < w.from) change++;
      for (let a = w.from; a < end && a < n; a++) {
        while (change < c.objects.length && c.objects[change][0] === a) {
          const [, i, x, y, r, s] = c.objects[change];
          cur[i] = [x, y, r, s];
          change++;
        }
        world[a] = wi;
        objs[a] = cur.map((o) => o.slice());
      }
    });
    // A module's performance indicator means something once it has had a signal.
    const perfSeen = ep.modules.map((_, m) => {
      const seen = new Array(n);
      let s = false;
      for (let a = 0; a < n; a++) { s = s || c.reinforcement[m][a] !== 0; seen[a] = s; }
      return seen;
    });
    const learners = ep.modules.map((_, m) => m).filter((m) => c.reinforcement[m].some((v) => v !== 0));
    // A test stage's lives: [life, lives] of each world among the consecutive worlds of its stage.
    const life = ep.worlds.map((w, wi) => {
      let first = wi, last = wi;
      while (first > 0 && ep.worlds[first - 1].stage === w.stage) first--;
      while (last + 1 < ep.worlds.length && ep.worlds[last + 1].stage === w.stage) last++;
      return [wi - first + 1, last - first + 1];
    });
    ep._ = { n, world, objs, perfSeen, learners, life };
  }

  function worldBox(ep) {
    let w = 0, h = 0;
    for (const x of ep.worlds) { w = Math.max(w, x.arena[0]); h = Math.max(h, x.arena[1]); }
    return [w, h];
  }

  function drawArena() {
    const ep = R.ep, cv = $('arena');
    const [aw, ah] = worldBox(ep);
    const pad = 16, top = 22, maxW = 480, maxH = 580;
    const s = Math.min((maxW - 2 * pad) / aw, (maxH - pad - top) / ah);
    const W = Math.round(aw * s + 2 * pad), H = Math.round(ah * s + pad + top);
    const dpr = window.devicePixelRatio || 1;
    if (cv.width !== Math.round(W * dpr) || cv.height !== Math.round(H * dpr)) {
      cv.width = Math.round(W * dpr); cv.height = Math.round(H * dpr);
      cv.style.width = W + 'px';
    }
    const g = cv.getContext('2d');
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, W, H);
    const X = (x) => pad + x * s, Y = (y) => H - pad - y * s;
    const a = R.a, c = ep.actions, wi = ep._.world[a], w = ep.worlds[wi];
    // Floor and walls.
    g.fillStyle = '#fbfaf6'; g.fillRect(X(0), Y(w.arena[1]), w.arena[0] * s, w.arena[1] * s);
    g.strokeStyle = '#38414d'; g.lineWidth = 3; g.strokeRect(X(0), Y(w.arena[1]), w.arena[0] * s, w.arena[1] * s);
    // Floor zones at their grey level (a charger outlined), inner walls, cylinders.
    for (const z of w.zones || []) {
      const v = Math.round(155 + 100 * z.grey);
      const zx = X(Math.min(z.from[0], z.to[0])), zy = Y(Math.max(z.from[1], z.to[1]));
      const zw = Math.abs(z.to[0] - z.from[0]) * s, zh = Math.abs(z.to[1] - z.from[1]) * s;
      g.fillStyle = 'rgb(' + v + ',' + v + ',' + v + ')'; g.fillRect(zx, zy, zw, zh);
      if (z.charger) { g.strokeStyle = '#e8741c'; g.lineWidth = 2; g.strokeRect(zx, zy, zw, zh); }
    }
    g.strokeStyle = '#38414d'; g.lineWidth = 3; g.lineCap = 'round';
    for (const [p, q] of w.walls || []) {
      g.beginPath(); g.moveTo(X(p[0]), Y(p[1])); g.lineTo(X(q[0]), Y(q[1])); g.stroke();
    }
    g.fillStyle = '#5a5a5a';
    for (const [cx, cy, r] of w.cylinders || []) {
      g.beginPath(); g.arc(X(cx), Y(cy), Math.max(r * s, 2), 0, 2 * Math.PI); g.fill();
    }
    // Lamps and charger.
    for (const [lx, ly] of (w.lamp ? [w.lamp] : []).concat(w.lamps || [])) {
      const grd = g.createRadialGradient(X(lx), Y(ly), 0, X(lx), Y(ly), 90 * s);
      grd.addColorStop(0, 'rgba(255, 210, 40, 0.55)'); grd.addColorStop(1, 'rgba(255, 210, 40, 0)');
      g.fillStyle = grd; g.beginPath(); g.arc(X(lx), Y(ly), 90 * s, 0, 2 * Math.PI); g.fill();
      g.fillStyle = '#f2b705'; g.beginPath(); g.arc(X(lx), Y(ly), 5, 0, 2 * Math.PI); g.fill();
    }
    if (w.bar) {
      g.strokeStyle = '#e8741c'; g.lineWidth = 6; g.lineCap = 'butt';
      g.beginPath(); g.moveTo(X(w.bar[0][0]), Y(w.bar[0][1])); g.lineTo(X(w.bar[1][0]), Y(w.bar[1][1])); g.stroke();
    }
    // Trail since the start of this world, coloured by the winning module.
    g.lineWidth = 2; g.lineCap = 'round';
    let px = w.start[0], py = w.start[1];
    for (let k = w.from; k <= a; k++) {
      // Older parts of a long trail fade.
      g.strokeStyle = color(c.winner[k]); g.globalAlpha = 0.15 + 0.5 * Math.max(0, 1 - (a - k) / 400);
      g.beginPath(); g.moveTo(X(px), Y(py)); g.lineTo(X(c.x[k]), Y(c.y[k])); g.stroke();
      px = c.x[k]; py = c.y[k];
    }
    g.globalAlpha = 1;
    g.fillStyle = '#38414d'; g.beginPath(); g.arc(X(w.start[0]), Y(w.start[1]), 3, 0, 2 * Math.PI); g.fill();
    // Objects on the floor and in the gripper.
    for (const [ox, oy, r, st] of ep._.objs[a]) {
      if (st === 2) continue;
      g.beginPath(); g.arc(X(ox), Y(oy), Math.max(r * s, 2), 0, 2 * Math.PI);
      g.fillStyle = st === 1 ? '#1e8a4c' : '#8fb996'; g.fill();
      g.strokeStyle = '#2d5a36'; g.lineWidth = 1; g.stroke();
    }
    // Who hears whom: a line between the robots that perceive each other
    // on the board read at this action, the followed robot's darker.
    const hear = hearing(ep, a);
    if (hear) {
      g.lineWidth = 1;
      for (const [i, j] of hear.pairs) {
        const p = hear.robots[i].at, q = hear.robots[j].at;
        g.strokeStyle = i === 0 ? 'rgba(42, 98, 201, 0.75)' : 'rgba(42, 98, 201, 0.22)';
        g.beginPath(); g.moveTo(X(p[0]), Y(p[1])); g.lineTo(X(q[0]), Y(q[1])); g.stroke();
      }
      document.body.dataset.hears = String(hear.pairs.length);
      document.body.dataset.heard = hear.heard.join(' ');
    } else {
      delete document.body.dataset.hears;
      delete document.body.dataset.heard;
    }
    // A team's other robots: each one's trail in this world, its body and heading, its number.
    const others = w.others || [];
    for (let j = 0; j < others.length && j < (c.others || []).length; j++) {
      const num = ep._nums ? ep._nums[j] : j + 1;
      const o = c.others[j], col = robotColour(R.base, num), r = w.body_radius;
      g.strokeStyle = col; g.lineWidth = 1.5; g.globalAlpha = 0.5;
      g.beginPath(); g.moveTo(X(others[j][0]), Y(others[j][1]));
      for (let k = w.from; k <= a; k++) g.lineTo(X(o.x[k]), Y(o.y[k]));
      g.stroke(); g.globalAlpha = 1;
      const ox = o.x[a], oy = o.y[a], ot = o.theta[a];
      g.beginPath(); g.arc(X(ox), Y(oy), r * s, 0, 2 * Math.PI);
      g.fillStyle = col; g.globalAlpha = 0.25; g.fill(); g.globalAlpha = 1;
      g.strokeStyle = col; g.lineWidth = 2; g.stroke();
      g.beginPath(); g.moveTo(X(ox), Y(oy)); g.lineTo(X(ox + r * Math.cos(ot)), Y(oy + r * Math.sin(ot))); g.stroke();
      g.fillStyle = '#38414d'; g.font = '10px sans-serif'; g.textAlign = 'center';
      g.fillText(String(num), X(ox), Y(oy) + 3.5); g.textAlign = 'start';
    }
    // The robot.
    const x = c.x[a], y = c.y[a], th = c.theta[a], br = w.body_radius;
    const ir = c.ir[a];
    for (let i = 0; i < ep.sensor_bearings.length; i++) {
      const b = th + ep.sensor_bearings[i] * Math.PI / 180;
      const v = Math.max(0, Math.min(1, ir[i]));
      const x0 = x + br * Math.cos(b), y0 = y + br * Math.sin(b);
      const x1 = x + (br + ep.sensor_range) * Math.cos(b), y1 = y + (br + ep.sensor_range) * Math.sin(b);
      g.strokeStyle = 'rgba(210, 40, 40, ' + (0.12 + 0.88 * v).toFixed(3) + ')';
      g.lineWidth = 1 + 3 * v;
      g.beginPath(); g.moveTo(X(x0), Y(y0)); g.lineTo(X(x1), Y(y1)); g.stroke();
    }
    if (ep.gripper) {
      const down = c.arm_down[a] === 1, closed = c.claw_closed[a] === 1;
      const reach = down ? 14 : 6, gap = closed ? 3 : 8;
      g.strokeStyle = down ? '#38414d' : '#9aa5b1'; g.lineWidth = 3;
      for (const side of [-1, 1]) {
        const ox = -Math.sin(th) * gap * side, oy = Math.cos(th) * gap * side;
        g.beginPath();
        g.moveTo(X(x + br * Math.cos(th) + ox), Y(y + br * Math.sin(th) + oy));
        g.lineTo(X(x + (br + reach) * Math.cos(th) + ox), Y(y + (br + reach) * Math.sin(th) + oy));
        g.stroke();
      }
      if (c.barrier[a] === 1) {
        g.fillStyle = '#d62728'; g.beginPath();
        g.arc(X(x + (br + reach * 0.6) * Math.cos(th)), Y(y + (br + reach * 0.6) * Math.sin(th)), 2.5, 0, 2 * Math.PI); g.fill();
      }
    }
    g.beginPath(); g.arc(X(x), Y(y), br * s, 0, 2 * Math.PI);
    g.fillStyle = color(c.winner[a]); g.globalAlpha = 0.3; g.fill(); g.globalAlpha = 1;
    g.lineWidth = c.collided[a] ? 3 : 2; g.strokeStyle = c.collided[a] ? '#d62728' : '#38414d'; g.stroke();
    if (c.recharged[a]) { g.strokeStyle = '#1e8a4c'; g.lineWidth = 3; g.beginPath(); g.arc(X(x), Y(y), br * s + 5, 0, 2 * Math.PI); g.stroke(); }
    g.strokeStyle = '#38414d'; g.lineWidth = 2;
    g.beginPath(); g.moveTo(X(x), Y(y)); g.lineTo(X(x + br * Math.cos(th)), Y(y + br * Math.sin(th))); g.stroke();
    // The stage whose world this is.
    g.fillStyle = '#5f6b7a'; g.font = '12px sans-serif';
    const team = others.length ? ' · ' + (others.length + 1) + ' robots, following robot ' + (ep._robot || 0) : '';
    g.fillText('world of ' + w.stage + ' · ' + Math.round(w.arena[0]) + ' × ' + Math.round(w.arena[1]) + ' mm' + team + ' · action ' + a, pad, 14);
  }

  // Timeline geometry: one band per module, then battery, reinforcement and performance.
  function timelineLayout(ep) {
    const rows = [];
    let y = ep.worlds.length > 1 ? 16 : 6;
    const add = (kind, h, extra) => { rows.push(Object.assign({ kind, y, h }, extra || {})); y += h + 4; };
    add('winner', 14);
    ep.modules.forEach((name, m) => add('module', 22, { m, name }));
    add('battery', 30);
    if (ep._.learners.length) { add('reinf', 24); add('perf', 54); }
    add('events', 14);
    return { rows, height: y + 14, left: 110, right: 22 };
  }

  function drawTimelineStatic() {
    const ep = R.ep, cv = $('timeline'), L = timelineLayout(ep);
    const cssW = Math.max(600, cv.parentElement.clientWidth - 2);
    const dpr = window.devicePixelRatio || 1;
    cv.width = Math.round(cssW * dpr); cv.height = Math.round(L.height * dpr);
    cv.style.height = L.height + 'px';
    const off = document.createElement('canvas');
    off.width = cv.width; off.height = cv.height;
    const g = off.getContext('2d');
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    const n = ep._.n, c = ep.actions;
    const x0 = L.left, x1 = cssW - L.right, dx = (x1 - x0) / Math.max(n, 1);
    const X = (a) => x0 + a * dx;
    g.fillStyle = '#fff'; g.fillRect(0, 0, cssW, L.height);
    g.font = '12px sans-serif'; g.textBaseline = 'middle';
    for (const r of L.rows) {
      g.fillStyle = '#5f6b7a';
      const label = { winner: 'winner', battery: 'battery', reinf: 'reinforcement', perf: 'performance', events: 'events' }[r.kind] || r.name;
      if (r.kind === 'module') { g.fillStyle = color(r.m); g.fillRect(4, r.y + r.h / 2 - 5, 10, 10); g.fillStyle = '#1d232b'; g.fillText(label, 18, r.y + r.h / 2); }
      else g.fillText(label, 4, r.y + r.h / 2);
      g.fillStyle = '#f4f6f8'; g.fillRect(x0, r.y, x1 - x0, r.h);
      if (r.kind === 'winner') {
        for (let a = 0; a < n; a++) { g.fillStyle = color(c.winner[a]); g.fillRect(X(a), r.y, dx + 0.5, r.h); }
      } else if (r.kind === 'module') {
        const act = c.activation[r.m];
        g.fillStyle = color(r.m);
        for (let a = 0; a < n; a++) {
          const v = Math.max(0, Math.min(1, act[a]));
          g.globalAlpha = c.winner[a] === r.m ? 0.95 : 0.35;
          g.fillRect(X(a), r.y + r.h * (1 - v), dx + 0.5, r.h * v);
        }
        g.globalAlpha = 1;
      } else if (r.kind === 'battery') {
        for (let a = 0; a < n; a++) if (c.holding[a]) { g.fillStyle = 'rgba(30, 138, 76, 0.18)'; g.fillRect(X(a), r.y, dx + 0.5, r.h); }
        g.strokeStyle = '#1e8a4c'; g.lineWidth = 1.5; g.beginPath();
        for (let a = 0; a < n; a++) { const yy = r.y + r.h * (1 - c.battery[a]); if (a) g.lineTo(X(a + 0.5), yy); else g.moveTo(X(a + 0.5), yy); }
        g.stroke();
      } else if (r.kind === 'reinf') {
        const mid = r.y + r.h / 2;
        g.strokeStyle = '#c9d0d8'; g.beginPath(); g.moveTo(x0, mid); g.lineTo(x1, mid); g.stroke();
        for (const m of ep._.learners) {
          g.fillStyle = color(m);
          for (let a = 0; a < n; a++) {
            const v = c.reinforcement[m][a];
            if (v > 0) g.fillRect(X(a), r.y + 1, Math.max(dx, 1.5), r.h / 2 - 1);
            else if (v < 0) g.fillRect(X(a), mid, Math.max(dx, 1.5), r.h / 2 - 1);
          }
        }
      } else if (r.kind === 'perf') {
        const mid = r.y + r.h / 2;
        g.strokeStyle = '#c9d0d8'; g.beginPath(); g.moveTo(x0, mid); g.lineTo(x1, mid); g.stroke();
        for (const m of ep._.learners) {
          g.strokeStyle = color(m); g.lineWidth = 1.5; g.beginPath();
          let on = false;
          for (let a = 0; a < n; a++) {
            if (!ep._.perfSeen[m][a]) continue;
            const yy = mid - (r.h / 2 - 2) * Math.max(-1, Math.min(1, c.performance[m][a]));
            if (on) g.lineTo(X(a + 0.5), yy); else { g.moveTo(X(a + 0.5), yy); on = true; }
          }
          g.stroke();
        }
      } else if (r.kind === 'events') {
        let grips = 0, rel = 0;
        for (let a = 0; a < n; a++) {
          const mid = r.y + r.h / 2;
          if (c.grips[a] > grips) { g.fillStyle = '#1e8a4c'; g.beginPath(); g.moveTo(X(a), mid + 5); g.lineTo(X(a) + 4, mid - 5); g.lineTo(X(a) - 4, mid - 5); g.fill(); }
          if (c.releases[a] > rel) { g.fillStyle = '#9467bd'; g.beginPath(); g.moveTo(X(a), mid - 5); g.lineTo(X(a) + 4, mid + 5); g.lineTo(X(a) - 4, mid + 5); g.fill(); }
          if (c.recharged[a]) { g.fillStyle = '#e8741c'; g.fillRect(X(a) - 2, r.y + 2, 4, r.h - 4); }
          if (c.collided[a]) { g.fillStyle = '#d62728'; g.fillRect(X(a), mid - 1, Math.max(dx, 1), 2); }
          grips = c.grips[a]; rel = c.releases[a];
        }
      }
    }
    // World changes (a test stage) and action ticks.
    g.strokeStyle = '#38414d'; g.setLineDash([4, 3]); g.fillStyle = '#38414d'; g.textBaseline = 'top';
    // A test stage's lives in one world: light lines, the change labelled.
    ep.worlds.forEach((w, wi) => {
      if (wi === 0) return;
      const change = w.stage !== ep.worlds[wi - 1].stage;
      g.strokeStyle = change ? '#38414d' : '#b8bec7'; g.setLineDash(change ? [4, 3] : [1, 3]);
      g.beginPath(); g.moveTo(X(w.from), 2); g.lineTo(X(w.from), L.height - 14); g.stroke();
      if (change) g.fillText('world of ' + w.stage + ' →', X(w.from) + 4, 4);
    });
    g.setLineDash([]);
    g.fillStyle = '#5f6b7a'; g.textBaseline = 'alphabetic';
    const step = niceStep(n / 8);
    for (let a = 0; a <= n; a += step) g.fillText(String(a), X(a) - 6, L.height - 2);
    R.tl = { off, L, X, dx, x0, x1, cssW, dpr };
  }

  function niceStep(raw) {
    const p = Math.pow(10, Math.floor(Math.log10(Math.max(raw, 1))));
    for (const k of [1, 2, 5, 10]) if (k * p >= raw) return k * p;
    return 10 * p;
  }

  function drawTimeline() {
    const cv = $('timeline'), t = R.tl;
    const g = cv.getContext('2d');
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.drawImage(t.off, 0, 0);
    g.setTransform(t.dpr, 0, 0, t.dpr, 0, 0);
    const xa = t.X(R.a);
    g.fillStyle = 'rgba(42, 98, 201, 0.18)'; g.fillRect(xa, 0, Math.max(t.dx, 2), t.L.height);
    g.strokeStyle = '#2a62c9'; g.lineWidth = 1.5; g.beginPath(); g.moveTo(xa + t.dx / 2, 0); g.lineTo(xa + t.dx / 2, t.L.height); g.stroke();
  }

  function readout() {
    const ep = R.ep, c = ep.actions, a = R.a, w = ep.worlds[ep._.world[a]];
    $('r-action').textContent = String(a);
    $('r-total').textContent = String(ep._.n - 1);
    const [life, lives] = ep._.life[ep._.world[a]];
    $('r-world').textContent = w.stage + (lives > 1 ? ' (life ' + life + ' of ' + lives + ')' : ep.worlds.length > 1 ? ' (part ' + (ep._.world[a] + 1) + ' of ' + ep.worlds.length + ')' : '') +
      ' · seed ' + ep.seed + ', learning ' + (ep.learning ? 'on' : 'off');
    const win = c.winner[a];
    // A team's robot 0 whose battery is empty stands still while the others go on.
    const stopped = (c.others || []).length > 0 && c.battery[a] <= 0;
    const robot = ep._robot || 0;
    $('r-winner').textContent = stopped ? 'none: robot ' + robot + ' stopped, its battery empty' : ep.modules[win] || '–';
    const team = R.base && R.base._team;
    const role = robot === 0 ? team && team.role : ep._role;
    $('r-robot').textContent = team ? robot + ' of ' + followable(R.base) + (role ? ', role ' + role : '') : '0';
    $('r-robot').hidden = $('r-robot-dt').hidden = !team;
    $('r-winner-chip').style.background = color(win);
    $('r-x').textContent = fmt(c.x[a], 2);
    $('r-y').textContent = fmt(c.y[a], 2);
    $('r-theta').textContent = fmt(c.theta[a] * 180 / Math.PI, 1) + '°';
    $('r-battery').textContent = fmt(c.battery[a], 3);
    $('r-battery-bar').style.width = (100 * Math.max(0, Math.min(1, c.battery[a]))).toFixed(1) + '%';
    $('r-wheels').textContent = fmt(c.wheels[a][0], 2) + ', ' + fmt(c.wheels[a][1], 2);
    $('r-gripper').textContent = ep.gripper
      ? 'arm ' + (c.arm_down[a] ? 'down' : 'up') + ', claw ' + (c.claw_closed[a] ? 'closed' : 'open') + ', barrier ' + (c.barrier[a] ? 'on' : 'off') + (c.holding[a] ? ', holding an object' : '')
      : 'none';
    const objs = ep._.objs[a];
    const floor = objs.filter((o) => o[3] === 0).length, out = objs.filter((o) => o[3] === 2).length;
    $('r-objects').textContent = objs.length ? floor + ' on the floor' + (objs.some((o) => o[3] === 1) ? ', 1 held' : '') + (out ? ', ' + out + ' thrown out' : '') + (objs.length ? ' (' + fmt(objs[0][2] * 2, 0) + ' mm)' : '') : 'none';
    const ev = [];
    ev.push(c.grips[a] + ' grips', c.releases[a] + ' released outside');
    if (c.recharged[a]) ev.push('recharged');
    if (c.collided[a]) ev.push('collision');
    $('r-events').textContent = ev.join(', ');
    boardReadout(ep, a);
    const body = $('r-modules').tBodies[0];
    body.textContent = '';
    ep.modules.forEach((name, m) => {
      const r = c.reinforcement[m][a];
      const tr = el('tr', { cls: m === win && !stopped ? 'win' : '' },
        el('td', {}, el('span', { cls: 'chip', style: 'background:' + color(m) }), name),
        el('td', { cls: 'num', text: stopped ? '' : fmt(c.activation[m][a], 3) }),
        el('td', { cls: 'num', text: r === 0 ? '' : signed(r, 0) }),
        el('td', { cls: 'num', text: ep._.perfSeen[m][a] ? fmt(c.performance[m][a], 2) : '' }));
      body.append(tr);
    });
    $('scrub').value = String(a);
    $('b-play').innerHTML = R.playing
      ? '<svg viewBox="0 0 16 16" width="14" height="14"><path d="M3 2h4v12H3zM9 2h4v12H9z"/></svg> pause'
      : '<svg viewBox="0 0 16 16" width="14" height="14"><path d="M3 2v12l11-6z"/></svg> play';
    $('b-play').setAttribute('aria-label', R.playing ? 'pause' : 'play');
    document.body.dataset.action = String(a);
    document.body.dataset.stage = ep.stage;
    document.body.dataset.robot = String(robot);
  }

  // The readout's board: what the followed robot's range-and-bearing
  // sensors read at this action and what it broadcast, one row per
  // sensor and actuator, and the robots it perceives (as drawn).
  function boardReadout(ep, a) {
    const b = ep._board, box = $('r-board'), body = box.tBodies[0];
    const vals = b && (b.robots[ep._robot || 0] || [])[a];
    box.hidden = !b;
    body.textContent = '';
    if (!b) return;
    const rows = [];
    b.names.forEach((n, i) => {
      const name = n.slice(0, n.lastIndexOf('['));
      if (!rows.length || rows[rows.length - 1][0] !== name) rows.push([name, []]);
      rows[rows.length - 1][1].push(vals && vals.length ? fmt(vals[i], 2) : '–');
    });
    for (const [name, v] of rows) body.append(el('tr', {}, el('td', { text: name }), el('td', { cls: 'num', text: v.join(' ') })));
    const hear = hearing(ep, a);
    const heard = hear ? (hear.heard.length ? 'robots ' + hear.heard.join(', ') : 'none') : '–';
    body.append(el('tr', {}, el('td', { text: 'in range' }), el('td', { cls: 'num', text: heard })));
  }

  function render() {
    if (!R.ep) return;
    drawArena();
    drawTimeline();
    readout();
  }

  function writeHash() {
    if (!R.ep) return;
    // A team's episode says which robot is followed.
    const h = '#stage=' + encodeURIComponent(R.ep.stage) + '&action=' + R.a + (R.base._team ? '&robot=' + R.robot : '');
    if (location.hash === h) return;
    try { history.replaceState(null, '', h); } catch (e) { /* some browsers refuse on file: URLs */ }
  }

  function seek(a, keepHash) {
    if (!R.ep) return;
    R.a = Math.max(0, Math.min(R.ep._.n - 1, Math.round(a)));
    render();
    if (!keepHash) writeHash();
  }

  let selectEpisodeTab = () => {};
  function selectEpisode(i, action, robot) {
    const base = D.episodes[i];
    if (!base) return;
    const n = followable(base);
    // The robot asked for, else the one followed before if this team has
    // it, else the one a replay follows (`replay --robot`).
    let k = robot !== undefined ? robot : R.base && R.robot < n ? R.robot : base._team ? base._team.follow || 0 : 0;
    if (!(k >= 0 && k < n)) k = 0;
    const ep = robotView(base, k);
    R.epIndex = i; R.ep = ep; R.base = base; R.robot = k;
    if (!ep._) prepare(ep);
    selectEpisodeTab(i);
    robotChoice(base, k);
    $('scrub').max = String(Math.max(ep._.n - 1, 0));
    drawTimelineStatic();
    seek(action === undefined ? 0 : action, true);
  }

  function play(on) {
    R.playing = on && R.ep !== null;
    if (R.playing && R.a >= R.ep._.n - 1) R.a = 0;
    R.acc = 0; R.last = performance.now();
    readout();
    clearTimeout(R.timer);
    if (R.playing) R.timer = setTimeout(tick, frameDelay());
    else writeHash();
  }

  // Timers rather than animation frames: they also run in a headless browser.
  const frameDelay = () => Math.max(16, 1000 / R.speed);

  function tick() {
    if (!R.playing) return;
    const now = performance.now();
    R.acc += (now - R.last) / 1000 * R.speed;
    R.last = now;
    if (R.acc >= 1) {
      const step = Math.floor(R.acc);
      R.acc -= step;
      if (R.a + step >= R.ep._.n - 1) { seek(R.ep._.n - 1); play(false); return; }
      seek(R.a + step, true);
      if (now - R.hashTimer > 300) { writeHash(); R.hashTimer = now; }
    }
    R.timer = setTimeout(tick, frameDelay());
  }

  // The robot selector: one entry per robot of a team's episode (with its
  // role), hidden for one robot.
  function robotChoice(base, k) {
    const box = $('robot-box'), sel = $('robot'), team = base._team;
    box.hidden = !team;
    if (!team) return;
    sel.textContent = '';
    for (let j = 0; j < followable(base); j++) {
      const role = j === 0 ? team.role : team.robots[j - 1].role;
      sel.append(el('option', { value: String(j), text: 'robot ' + j + (role ? ' (' + role + ')' : '') }));
    }
    sel.value = String(k);
  }

  function followRobot(k) {
    if (!R.base || !(k >= 0 && k < followable(R.base))) return;
    selectEpisode(R.epIndex, R.a, k);
    writeHash();
  }

  function parseHash() {
    const out = {};
    for (const part of location.hash.replace(/^#/, '').split('&')) {
      const k = part.indexOf('=');
      if (k > 0) out[decodeURIComponent(part.slice(0, k))] = decodeURIComponent(part.slice(k + 1));
    }
    return out;
  }

  function applyHash() {
    const h = parseHash();
    if (h.stage === undefined && h.action === undefined && h.robot === undefined) return false;
    let i = R.epIndex;
    if (h.stage !== undefined) {
      const k = D.episodes.findIndex((e) => e.stage === h.stage);
      if (k >= 0) i = k;
    }
    const a = h.action !== undefined && /^\d+$/.test(h.action) ? parseInt(h.action, 10) : 0;
    const n = followable(D.episodes[i]);
    let k;
    $('robot-note').textContent = '';
    if (h.robot !== undefined) {
      if (/^\d+$/.test(h.robot) && parseInt(h.robot, 10) < n) k = parseInt(h.robot, 10);
      else $('robot-note').textContent = 'no robot ' + h.robot + ' in this episode (' + (n > 1 ? 'robots 0 to ' + (n - 1) : 'one robot, robot 0') + ')';
    }
    if (i !== R.epIndex || !R.ep || (k !== undefined && k !== R.robot)) selectEpisode(i, a, k); else seek(a, true);
    return true;
  }

  function setSpeed(v) {
    R.speed = v;
    const sel = $('speed');
    if (![...sel.options].some((o) => Number(o.value) === v)) sel.append(el('option', { value: String(v), text: v + '/s' }));
    sel.value = String(v);
  }

  function initReplay() {
    if (!D.episodes.length) {
      $('replay-body').hidden = true; $('no-episode').hidden = false;
      return;
    }
    $('ep-note').textContent = 'The episodes of ' + D.episodes_note + '. ' +
      'Trail and timeline in the colour of the module that drove each action; red rays: proximity readings; green: objects (dark: held).' +
      (D.episodes.some((e) => e._board) ? ' Blue lines: robots within range of each other\u2019s range-and-bearing board at that action (dark: the followed robot\u2019s).' : '');
    selectEpisodeTab = tabs($('ep-tabs'), D.episodes.map((e) => e.stage + (e.worlds.length > 1 ? ' (before / after the change)' : '')), (i) => { play(false); selectEpisode(i, 0); writeHash(); });
    $('b-first').addEventListener('click', () => seek(0));
    $('b-last').addEventListener('click', () => seek(R.ep._.n - 1));
    $('b-prev').addEventListener('click', (e) => seek(R.a - (e.shiftKey ? 10 : 1)));
    $('b-next').addEventListener('click', (e) => seek(R.a + (e.shiftKey ? 10 : 1)));
    $('b-play').addEventListener('click', () => play(!R.playing));
    $('scrub').addEventListener('input', () => seek(Number($('scrub').value)));
    $('speed').addEventListener('change', () => { setSpeed(Number($('speed').value)); $('speed').blur(); });
    $('robot').addEventListener('change', () => { followRobot(Number($('robot').value)); $('robot').blur(); });
    // After a mouse click the keys drive the replay again, not the button.
    document.querySelectorAll('#controls button, #ep-tabs button').forEach((b) => b.addEventListener('click', (e) => { if (e.detail > 0) b.blur(); }));
    const tl = $('timeline');
    let dragging = false;
    const fromMouse = (e) => {
      const r = tl.getBoundingClientRect(), t = R.tl;
      const x = (e.clientX - r.left) * (t.cssW / r.width);
      seek((x - t.x0) / t.dx - 0.5);
    };
    tl.addEventListener('mousedown', (e) => { dragging = true; play(false); fromMouse(e); });
    window.addEventListener('mousemove', (e) => { if (dragging) fromMouse(e); });
    window.addEventListener('mouseup', () => { dragging = false; });
    document.addEventListener('keydown', (e) => {
      const t = e.target;
      if (t && (t.tagName === 'INPUT' && t.type !== 'range' || t.tagName === 'SELECT' || t.tagName === 'TEXTAREA')) return;
      if (e.ctrlKey || e.metaKey || e.altKey) return;
      // A focused button (reached with Tab) takes Space and Enter itself.
      if (t && t.tagName === 'BUTTON' && (e.key === ' ' || e.key === 'Enter')) return;
      const big = e.shiftKey ? 10 : 1;
      const speeds = [1, 2, 5, 10, 20, 50, 100, 200];
      switch (e.key) {
        case ' ': case 'k': play(!R.playing); break;
        case 'ArrowLeft': play(false); seek(R.a - big); break;
        case 'ArrowRight': play(false); seek(R.a + big); break;
        case 'Home': seek(0); break;
        case 'End': seek(R.ep._.n - 1); break;
        case '+': case '=': setSpeed(speeds.find((s) => s > R.speed) || R.speed); break;
        case '-': case '_': setSpeed([...speeds].reverse().find((s) => s < R.speed) || R.speed); break;
        case '[': play(false); selectEpisode((R.epIndex + D.episodes.length - 1) % D.episodes.length, 0); writeHash(); break;
        case ']': play(false); selectEpisode((R.epIndex + 1) % D.episodes.length, 0); writeHash(); break;
        default: return;
      }
      e.preventDefault();
    });
    window.addEventListener('hashchange', applyHash);
    let resizeTimer = 0;
    window.addEventListener('resize', () => { clearTimeout(resizeTimer); resizeTimer = setTimeout(() => { if (R.ep) { drawTimelineStatic(); render(); } }, 100); });
    // The last episode by default: a run's final stage shows the whole architecture.
    if (!applyHash()) selectEpisode(D.episodes.length - 1, 0);
  }

  // ------------------------------------------------------------------ fitness
  function initFitness() {
    const F = D.fitness;
    if (!F.length) {
      $('fit-note').textContent = 'No evolved stage in this directory.';
    } else {
      $('fit-note').textContent = D.kind === 'experiment' || D.kind === 'sweep'
        ? 'Median over ' + D.seeds.length + ' seeds (' + D.seeds.join(', ') + ') of the best and of the mean fitness per generation; the band is the range of the best over seeds.'
        : 'Best and mean fitness per generation; generations continue across stages (the paper\'s figure 9).';
      $('fit-chart').append(fitnessChart(F));
    }
    results();
  }

  function fitnessChart(F) {
    const W = 1000, H = 340, l = 56, r = 16, t = 26, b = 40;
    let g0 = Infinity, g1 = -Infinity, y1 = 0, y0 = 0;
    for (const s of F) {
      for (const g of s.generation) { g0 = Math.min(g0, g); g1 = Math.max(g1, g); }
      for (const v of s.best.concat(s.mean, s.best_max, s.best_min)) if (isFinite(v)) { y1 = Math.max(y1, v); y0 = Math.min(y0, v); }
    }
    if (g1 <= g0) g1 = g0 + 1;
    const ys = niceStepF((y1 - y0) / 5);
    y1 = Math.ceil(y1 / ys) * ys || 1; y0 = Math.floor(y0 / ys) * ys;
    const X = (g) => l + (g - g0) / (g1 - g0) * (W - l - r), Y = (v) => H - b - (v - y0) / (y1 - y0) * (H - t - b);
    const svg = sv('svg', { viewBox: '0 0 ' + W + ' ' + H, role: 'img', 'aria-label': 'fitness per generation' });
    for (let v = y0; v <= y1 + 1e-9; v += ys) {
      svg.append(sv('line', { x1: l, x2: W - r, y1: Y(v), y2: Y(v), stroke: '#e3e7ec' }));
      svg.append(sv('text', { x: l - 6, y: Y(v) + 4, 'text-anchor': 'end', text: fmt(v, ys < 0.1 ? 2 : 1) }));
    }
    const gs = niceStep((g1 - g0) / 10);
    for (let g = Math.ceil(g0 / gs) * gs; g <= g1; g += gs) svg.append(sv('text', { x: X(g), y: H - b + 16, 'text-anchor': 'middle', text: String(g) }));
    svg.append(sv('text', { x: (l + W - r) / 2, y: H - 6, 'text-anchor': 'middle', text: 'generation' }));
    svg.append(sv('text', { x: 14, y: (t + H - b) / 2, 'text-anchor': 'middle', transform: 'rotate(-90 14 ' + (t + H - b) / 2 + ')', text: 'fitness' }));
    const path = (xs, vs) => xs.map((g, i) => (i ? 'L' : 'M') + X(g).toFixed(1) + ' ' + Y(vs[i]).toFixed(1)).join(' ');
    for (const s of F) {
      if (!s.generation.length) continue;
      const gx = X(s.generation[0]);
      svg.append(sv('line', { x1: gx, x2: gx, y1: t - 8, y2: H - b, stroke: '#9aa5b1', 'stroke-dasharray': '4 3' }));
      svg.append(sv('text', { x: gx + 4, y: t - 10, text: s.stage }));
      if (s.best_min.length) {
        const up = s.generation.map((g, i) => X(g).toFixed(1) + ' ' + Y(s.best_max[i]).toFixed(1));
        const down = s.generation.map((g, i) => X(g).toFixed(1) + ' ' + Y(s.best_min[i]).toFixed(1)).reverse();
        svg.append(sv('path', { d: 'M' + up.join(' L') + ' L' + down.join(' L') + ' Z', fill: 'rgba(42, 98, 201, 0.15)', stroke: 'none' }));
      }
      svg.append(sv('path', { d: path(s.generation, s.mean), fill: 'none', stroke: '#e8741c', 'stroke-width': 2 }));
      svg.append(sv('path', { d: path(s.generation, s.best), fill: 'none', stroke: '#2a62c9', 'stroke-width': 2.5 }));
    }
    const ex = D.kind === 'experiment' || D.kind === 'sweep';
    const legend = [[ex ? 'median best' : 'best', '#2a62c9'], [ex ? 'median mean' : 'mean', '#e8741c']];
    if (ex) legend.push(['range of the best', 'rgba(42, 98, 201, 0.3)']);
    legend.forEach(([name, col], i) => {
      svg.append(sv('rect', { x: l + 10 + i * 170, y: t + 4, width: 18, height: 5, fill: col }));
      svg.append(sv('text', { x: l + 34 + i * 170, y: t + 10, text: name }));
    });
    // Hover: the values of the generation under the mouse.
    const guide = sv('line', { y1: t, y2: H - b, stroke: '#38414d', 'stroke-width': 1, visibility: 'hidden' });
    const tip = sv('text', { x: 0, y: t + 28, visibility: 'hidden' });
    svg.append(guide, tip);
    svg.addEventListener('mousemove', (e) => {
      const box = svg.getBoundingClientRect();
      const gx = (e.clientX - box.left) / box.width * W;
      const g = Math.round(g0 + (gx - l) / (W - l - r) * (g1 - g0));
      for (const s of F) {
        const i = s.generation.indexOf(g);
        if (i < 0) continue;
        guide.setAttribute('x1', X(g)); guide.setAttribute('x2', X(g)); guide.setAttribute('visibility', 'visible');
        tip.setAttribute('x', Math.min(X(g) + 6, W - 330)); tip.setAttribute('visibility', 'visible');
        tip.textContent = s.stage + ' gen ' + g + ': best ' + fmt(s.best[i], 3) + ', mean ' + fmt(s.mean[i], 3) +
          (s.best_min.length ? ' (best ' + fmt(s.best_min[i], 3) + '..' + fmt(s.best_max[i], 3) + ', ' + s.seeds[i] + ' seeds)' : '');
        return;
      }
    });
    svg.addEventListener('mouseleave', () => { guide.setAttribute('visibility', 'hidden'); tip.setAttribute('visibility', 'hidden'); });
    return svg;
  }

  function niceStepF(raw) {
    if (!(raw > 0)) return 0.1;
    const p = Math.pow(10, Math.floor(Math.log10(raw)));
    for (const k of [1, 2, 2.5, 5, 10]) if (k * p >= raw) return k * p;
    return 10 * p;
  }

  function results() {
    const tb = $('results');
    const head = el('tr', {}, ...['stage', 'how', 'result'].map((h) => el('th', { text: h })));
    tb.append(head);
    for (const st of D.stages) {
      const s = D.fitness.find((f) => f.stage === st.name);
      let text = '';
      if (s && s.best.length) {
        const k = s.best.length - 1;
        text = D.kind === 'experiment' || D.kind === 'sweep'
          ? 'median over seeds: final best ' + fmt(s.best[k], 3) + ', final mean ' + fmt(s.mean[k], 3) + ', final best ranges ' + fmt(s.best_min[k], 3) + '..' + fmt(s.best_max[k], 3)
          : 'final best ' + fmt(s.best[k], 3) + ', mean ' + fmt(s.mean[k], 3) + ', highest best ' + fmt(Math.max(...s.best), 3);
      } else if (st.results) {
        const r = st.results, b = r.before || {}, a = r.after || {};
        text = 'fitness ' + fmt(b.fitness, 3) + ' → ' + fmt(a.fitness, 3) + ', grips ' + b.grips + ' → ' + a.grips +
          ', released outside ' + b.releases_outside + ' → ' + a.releases_outside + ', recharges ' + b.recharges + ' → ' + a.recharges +
          ' (before → after the change' + (r.lives > 1 ? '; ' + r.lives + ' lives in each world: fitness the mean per life, events the totals' : '') + ')' + (D.shown_seed !== null && D.shown_seed !== undefined ? ', run seed ' + D.shown_seed : '');
      }
      if (st.crowded) text = (text ? text + '. ' : '') + 'Warning: ' + st.crowded + '.';
      tb.append(el('tr', {}, el('td', { text: st.name }), el('td', { text: st.run }), el('td', { text: text || '–' })));
    }
  }

  // ------------------------------------------------------------------ architecture
  let selectArchTab = () => {};
  function initArchitecture() {
    if (!D.stages.length) return;
    selectArchTab = tabs($('arch-tabs'), D.stages.map((s) => s.name), showStage);
    showStage(D.stages.length - 1);
  }

  function showStage(i) {
    selectArchTab(i);
    const st = D.stages[i], box = $('arch-body');
    box.textContent = '';
    box.append(el('p', {}, el('b', { text: st.name }), st.parent ? ' extends ' + st.parent + '. ' : '. ', st.run + '.'));
    box.append(el('p', { cls: 'muted', text: 'World: ' + st.world + '. Fitness: ' + (st.fitness || 'none') + '. Sensors: ' + st.sensors.join(', ') + '.' }));
    box.append(el('div', { text: st.parent ? 'Added by this stage:' : 'This stage has:' }), el('ul', { cls: 'added' }, ...st.added.map((a) => el('li', { text: a }))));
    const wrap = el('div', { cls: 'arch' });
    wrap.append(graph(st), matrix(st));
    box.append(wrap);
    box.append(el('p', { cls: 'muted small', text: 'Links: blue excitatory, red inhibitory, width by weight' + (st.genome ? ' (decoded from ' + st.genome + ')' : ' (no genome found: evolved weights unknown)') + '; dashed: frozen by an earlier stage; thick outline: module new in this stage. Hover a module to see its links.' }));
    const cards = el('div', { cls: 'cards' });
    st.modules.forEach((m, k) => {
      cards.append(el('div', { cls: 'card' + (m.new ? ' new' : '') },
        el('h4', {}, el('span', { cls: 'chip', style: 'background:' + color(k) }), m.name, el('span', { cls: 'badge' + (m.new ? '' : ' old'), text: m.new ? 'new' : 'from ' + m.stage })),
        el('p', {}, el('span', { cls: 'muted', text: 'senses ' }), m.sensors.join(', ') || 'nothing'),
        el('p', {}, el('span', { cls: 'muted', text: 'behavior ' }), m.behavior),
        m.learning ? el('p', {}, el('span', { cls: 'muted', text: 'learns ' }), m.learning) : null,
        m.reinforce ? el('p', { cls: 'muted', text: 'has a reinforcement program' }) : null));
    });
    box.append(cards);
  }

  function graph(st) {
    const n = st.modules.length, W = 560, H = 460, cx = W / 2, cy = H / 2, rad = Math.min(W, H) / 2 - 70;
    const svg = sv('svg', { viewBox: '0 0 ' + W + ' ' + H, role: 'img', 'aria-label': 'module graph of ' + st.name });
    const defs = sv('defs');
    for (const [id, col] of [['pos', '#2563eb'], ['neg', '#d23c3c'], ['nil', '#9aa5b1']]) {
      defs.append(sv('marker', { id: 'arrow-' + id, viewBox: '0 0 10 10', refX: 9, refY: 5, markerWidth: 9, markerHeight: 9, markerUnits: 'userSpaceOnUse', orient: 'auto-start-reverse' },
        sv('path', { d: 'M0 0 L10 5 L0 10 z', fill: col })));
    }
    svg.append(defs);
    const pos = st.modules.map((_, k) => {
      const a = -Math.PI / 2 + 2 * Math.PI * k / Math.max(n, 1);
      return [cx + rad * Math.cos(a), cy + rad * Math.sin(a)];
    });
    const wmax = Math.max(1e-6, ...st.links.map((l) => Math.abs(l.weight || 0)));
    const nodeW = 104, nodeH = 40;
    const edges = [];
    for (const l of st.links) {
      const [x1, y1] = pos[l.from], [x2, y2] = pos[l.to];
      const dx = x2 - x1, dy = y2 - y1, d = Math.hypot(dx, dy) || 1;
      // Bend to the right of the direction, so a -> b and b -> a do not overlap.
      const nx = -dy / d, ny = dx / d, bend = 26;
      const mx = (x1 + x2) / 2 + nx * bend, my = (y1 + y2) / 2 + ny * bend;
      const clip = (x, y, tx, ty) => {
        const vx = tx - x, vy = ty - y;
        const k = Math.min((nodeW / 2 + 3) / Math.abs(vx || 1e-9), (nodeH / 2 + 3) / Math.abs(vy || 1e-9));
        return [x + vx * k, y + vy * k];
      };
      const [sx, sy] = clip(x1, y1, mx, my), [ex, ey] = clip(x2, y2, mx, my);
      const w = l.weight;
      const kind = w === null || w === undefined ? 'nil' : w >= 0 ? 'pos' : 'neg';
      const stroke = { pos: '#2563eb', neg: '#d23c3c', nil: '#9aa5b1' }[kind];
      const width = w === null || w === undefined ? 1 : 0.6 + 3.4 * Math.abs(w) / wmax;
      const p = sv('path', {
        d: 'M' + sx.toFixed(1) + ' ' + sy.toFixed(1) + ' Q' + mx.toFixed(1) + ' ' + my.toFixed(1) + ' ' + ex.toFixed(1) + ' ' + ey.toFixed(1),
        fill: 'none', stroke, 'stroke-width': width.toFixed(2), 'marker-end': 'url(#arrow-' + kind + ')',
        'stroke-dasharray': l.frozen ? '5 3' : null, opacity: l.frozen ? 0.55 : 0.9,
      }, sv('title', { text: st.modules[l.from].name + ' → ' + st.modules[l.to].name + ': ' + (w === null || w === undefined ? l.kind : 'w = ' + fmt(w, 3)) + (l.gene !== null && l.gene !== undefined ? ' (gene ' + l.gene + (l.frozen ? ', frozen' : ', evolvable') + ')' : ' (' + l.kind + ')') }));
      p.dataset.from = l.from; p.dataset.to = l.to;
      edges.push(p);
      svg.append(p);
    }
    st.modules.forEach((m, k) => {
      const [x, y] = pos[k];
      const gnode = sv('g', { transform: 'translate(' + (x - nodeW / 2).toFixed(1) + ' ' + (y - nodeH / 2).toFixed(1) + ')', style: 'cursor: default' },
        sv('rect', { width: nodeW, height: nodeH, rx: 8, fill: '#fff', stroke: m.new ? '#2a62c9' : color(k), 'stroke-width': m.new ? 3.5 : 1.8 }),
        sv('rect', { x: 6, y: 8, width: 9, height: 9, rx: 2, fill: color(k) }),
        sv('text', { x: 20, y: 17, 'font-weight': 600, text: m.name }),
        sv('text', { x: 8, y: 33, fill: '#5f6b7a', 'font-size': 11, text: (m.behavior.startsWith('neural') ? 'neural' : 'script') + (m.learning ? ' · learns' : '') }),
        sv('title', { text: m.name + '\nsenses ' + m.sensors.join(', ') + '\n' + m.behavior + (m.learning ? '\nlearns ' + m.learning : '') }));
      gnode.addEventListener('mouseenter', () => edges.forEach((e) => { e.style.opacity = (e.dataset.from == k || e.dataset.to == k) ? '1' : '0.08'; }));
      gnode.addEventListener('mouseleave', () => edges.forEach((e) => { e.style.opacity = ''; }));
      svg.append(gnode);
    });
    return svg;
  }

  function matrix(st) {
    const t = el('table', { cls: 'grid matrix' });
    t.append(el('caption', { cls: 'muted small', text: 'link weights, from (row) to (column)' }));
    t.append(el('tr', {}, el('th', { text: 'from \\ to' }), ...st.modules.map((m) => el('th', { text: m.name }))));
    const wmax = Math.max(1e-6, ...st.links.map((l) => Math.abs(l.weight || 0)));
    st.modules.forEach((m, i) => {
      const tr = el('tr', {}, el('th', { text: m.name }));
      st.modules.forEach((_, j) => {
        const l = st.links.find((x) => x.from === i && x.to === j);
        if (!l) { tr.append(el('td', { cls: 'muted', text: '·' })); return; }
        const w = l.weight;
        const alpha = w === null || w === undefined ? 0 : 0.12 + 0.6 * Math.abs(w) / wmax;
        const bg = w === null || w === undefined ? '' : (w >= 0 ? 'rgba(37, 99, 235, ' : 'rgba(210, 60, 60, ') + alpha.toFixed(2) + ')';
        tr.append(el('td', { style: 'background:' + bg, title: l.kind + (l.frozen ? ', frozen' : '') + (l.new ? ', new in this stage' : ''), text: w === null || w === undefined ? l.kind : fmt(w, 2) }));
      });
      t.append(tr);
    });
    return t;
  }

  // ------------------------------------------------------------------ genome
  let genStage = 0;
  let selectGenTab = () => {};
  function initGenome() {
    if (!D.stages.length) return;
    selectGenTab = tabs($('gen-tabs'), D.stages.map((s) => s.name), showGenes);
    $('gen-search').addEventListener('input', filterGenes);
    showGenes(D.stages.length - 1);
  }

  function showGenes(i) {
    genStage = i;
    selectGenTab(i);
    const st = D.stages[i], genes = st.genes;
    const bits = genes.reduce((s, g) => s + g.bits, 0);
    const frozen = genes.filter((g) => g.frozen);
    const fbits = frozen.reduce((s, g) => s + g.bits, 0);
    $('gen-summary').textContent = st.name + ': ' + genes.length + ' genes, ' + bits + ' bits; frozen ' + frozen.length + ' genes (' + fbits + ' bits), evolvable ' + (genes.length - frozen.length) + ' (' + (bits - fbits) + ' bits)' +
      (st.genome ? '; values decoded from ' + st.genome : '; no genome found, so no values') + '. The strip shows the bit string, one block per gene, coloured by the stage that added it (faded: frozen); click a block to find its gene.' +
      (st.frozen_from ? ' ' + st.frozen_from : '');
    const strip = $('gen-strip');
    strip.textContent = '';
    const stageIndex = (name) => D.stages.findIndex((s) => s.name === name);
    for (const g of genes) {
      const b = el('span', { cls: g.frozen ? 'frozen' : '', title: '#' + g.index + ' ' + g.module + ': ' + g.role + (g.value !== null && g.value !== undefined ? ' = ' + fmt(g.value, 3) : ''), style: 'flex:' + g.bits + ' 0 0;background:' + PALETTE[(stageIndex(g.stage) + 4) % PALETTE.length] });
      b.addEventListener('click', () => { $('gen-search').value = '#' + g.index; filterGenes(); });
      strip.append(b);
    }
    const t = $('gen-table');
    t.textContent = '';
    t.append(el('thead', {}, el('tr', {}, ...['#', 'offset', 'bits', 'stage', 'module', 'role', 'range', 'state', 'code', 'value'].map((h) => el('th', { text: h })))));
    const body = el('tbody');
    for (const g of genes) {
      const tr = el('tr', { cls: g.frozen ? 'frozen' : '' },
        el('td', { cls: 'num', text: String(g.index) }), el('td', { cls: 'num', text: String(g.offset) }), el('td', { cls: 'num', text: String(g.bits) }),
        el('td', { text: g.stage }), el('td', { text: g.module }), el('td', { text: g.role }),
        el('td', { text: fmt(g.lo, 2) + '..' + fmt(g.hi, 2) }), el('td', { text: g.frozen ? 'frozen' : 'evolvable' }),
        el('td', { cls: 'code', text: g.code || '' }),
        el('td', { cls: 'num', text: fmt(g.value, 3) + (g.parent_value === null || g.parent_value === undefined ? '' : ' (parent best: ' + fmt(g.parent_value, 3) + ')'), title: g.parent_value === null || g.parent_value === undefined ? null : "differs from the parent stage's best.genome" }));
      tr.dataset.search = ('#' + g.index + ' ' + g.stage + ' ' + g.module + ' ' + g.role + ' ' + (g.frozen ? 'frozen' : 'evolvable')).toLowerCase();
      body.append(tr);
    }
    t.append(body);
    filterGenes();
  }

  function filterGenes() {
    const q = $('gen-search').value.trim().toLowerCase();
    const words = q.split(/\s+/).filter(Boolean);
    const rows = $('gen-table').tBodies[0] ? [...$('gen-table').tBodies[0].rows] : [];
    let shown = 0;
    for (const tr of rows) {
      const s = tr.dataset.search;
      const ok = words.every((w) => w.startsWith('#') ? s.split(' ')[0] === w : s.includes(w));
      tr.hidden = !ok;
      if (ok) shown++;
    }
    $('gen-count').textContent = shown + ' of ' + rows.length + ' genes shown';
  }

  // ------------------------------------------------------------------ sweep
  // Every point of the sweep this experiment belongs to: its settings and,
  // per evolved stage, the chosen best over the seeds (summary.json).
  function initSweep() {
    const S = D.sweep;
    if (!S || !S.points || !S.points.length) return;
    $('sec-sweep').hidden = false;
    $('nav-sweep').hidden = false;
    const targets = (S.sets || []).map((x) => x.target);
    const evolved = (S.points[0].stages || []).filter((x) => x.kind === 'evolve').map((x) => x.stage);
    const spreadText = (v) => v ? fmt(v.median, 3) + ' (' + fmt(v.min, 3) + '..' + fmt(v.max, 3) + ')' : '–';
    $('sweep-note').textContent = S.points.length + ' points over ' + S.seeds.length + ' seeds; chosen best of each evolved stage, median (min..max) over seeds.' +
      (D.sweep_point ? ' This page shows the point ' + D.sweep_point + ' (highlighted).' : '');
    const t = $('sweep-table');
    t.append(el('tr', {}, ...['point', ...targets, ...evolved.map((e) => e + ' chosen best')].map((h) => el('th', { text: h }))));
    S.points.forEach((p, i) => {
      const cells = [el('td', { cls: 'num', text: String(i + 1) })];
      for (const k of targets) cells.push(el('td', { text: (p.settings || {})[k] || '–' }));
      for (const e of evolved) {
        const st = (p.stages || []).find((x) => x.stage === e);
        cells.push(el('td', { cls: 'num', text: spreadText(st && st.chosen_best) }));
      }
      const tr = el('tr', {}, ...cells);
      if (p.name === D.sweep_point) tr.className = 'shown';
      t.append(tr);
    });
  }

  // ------------------------------------------------------------------ statistics
  // The tables are in the page (summary.json's tests); link them when there.
  function initStats() {
    if (document.getElementById('sec-stats')) $('nav-stats').hidden = false;
  }

  // ------------------------------------------------------------------ start
  for (const [name, f] of [['sweep', initSweep], ['stats', initStats], ['replay', initReplay], ['fitness', initFitness], ['architecture', initArchitecture], ['genome', initGenome]]) {
    try { f(); } catch (e) { showError(name + ': ' + (e && e.stack ? e.stack : e)); }
  }
  document.body.dataset.ready = '1';
})();

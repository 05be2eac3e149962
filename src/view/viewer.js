// mprog viewer: decodes the page's data block (see src/view/data.rs) and plays it on a 2-D
// canvas through a small perspective camera (orbit, zoom, pan), with a floor grid, stick
// figures, shadows, root trails, overlays, contacts, the prompt timeline and per-statement
// error charts.
// Self-contained: no network, no libraries.
(function () {
  "use strict";

  var J = 22, NEAR = 0.05, FOV = 40 * Math.PI / 180;
  // Colour families as in the GIF renders: [right side (dark), left side (light), centre].
  var FAMILIES = [
    ["#1446aa", "#6eaafa", "#2d6ed2"],
    ["#aa1e1e", "#fa8773", "#d7463c"],
    ["#14732d", "#78d27d", "#37a050"],
    ["#692896", "#c396eb", "#965ac8"],
    ["#af5f00", "#fabe5a", "#dc8c1e"]
  ];
  var OVERLAY = "#d20096", CONTACT = "#ff8200";
  // Prompt spans, cycled along a timeline (as in the GIF and PNG renders).
  var SPAN_COLORS = ["#4285f4", "#34a853", "#f57c00", "#ab47bc", "#0096aa", "#d32f2f"];

  function $(id) { return document.getElementById(id); }

  function fail(message) {
    var box = document.createElement("div");
    box.id = "error";
    box.textContent = "mprog viewer: " + message;
    document.body.insertBefore(box, document.body.firstChild);
  }

  var D;
  try {
    D = JSON.parse($("mprog-data").textContent);
  } catch (e) {
    fail("cannot read the embedded motion data (" + e + ")");
    return;
  }
  if (D.format !== "mprog-view" || D.version !== 1) {
    fail("unknown data block " + D.format + " v" + D.version);
    return;
  }

  // ---- data ----------------------------------------------------------------------------
  var N = D.frames, fps = D.fps;
  var people = [];
  for (var i = 0; i < D.people.length; i++) {
    var p = D.people[i];
    if (p.mm.length !== p.frames * J * 3) {
      fail(p.name + ": " + p.mm.length + " numbers for " + p.frames + " frames");
      return;
    }
    var pos = new Float32Array(p.mm.length), acc = new Float64Array(J * 3);
    for (var f = 0; f < p.frames; f++) {
      for (var k = 0; k < J * 3; k++) {
        acc[k] += p.mm[f * J * 3 + k];
        pos[f * J * 3 + k] = acc[k] / 1000;
      }
    }
    people.push({ name: p.name, n: p.frames, pos: pos, col: FAMILIES[i % FAMILIES.length] });
  }
  function joint(person, f, j) {
    var o = (Math.min(f, person.n - 1) * J + j) * 3, a = person.pos;
    return [a[o], a[o + 1], a[o + 2]];
  }
  var bones = []; // [parent, child, side index 0 right / 1 left / 2 centre]
  D.chains.forEach(function (chain, c) {
    var side = { right: 0, left: 1, centre: 2 }[D.chain_sides[c]];
    for (var b = 1; b < chain.length; b++) bones.push([chain[b - 1], chain[b], side]);
  });

  // ---- vector helpers ----------------------------------------------------------------------
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
  function mul(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { var l = Math.sqrt(dot(a, a)) || 1; return mul(a, 1 / l); }
  function lerp(a, b, t) { return add(a, mul(sub(b, a), t)); }
  function clamp(v, lo, hi) { return Math.max(lo, Math.min(hi, v)); }

  // ---- scene extent ------------------------------------------------------------------------
  var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  function grow(q) { for (var k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], q[k]); hi[k] = Math.max(hi[k], q[k]); } }
  people.forEach(function (pp) { for (var f = 0; f < pp.n; f++) for (var j = 0; j < J; j++) grow(joint(pp, f, j)); });
  var bodyLo = lo.slice(), bodyHi = hi.slice();
  D.overlays.forEach(function (o) {
    if (o.kind === "point") grow(o.at);
    else if (o.kind === "segment") { grow(o.from); grow(o.to); }
    else if (o.kind === "vertical_plane") grow(o.point);
    else if (o.kind === "box") { grow(o.min); grow(o.max); }
  });
  var floorLo = [Math.floor(Math.min(lo[0], 0) - 1), Math.floor(Math.min(lo[2], 0) - 1)];
  var floorHi = [Math.ceil(Math.max(hi[0], 0) + 1), Math.ceil(Math.max(hi[2], 0) + 1)];
  var planeTop = Math.max(2.0, hi[1] + 0.3), planeBottom = Math.min(0, lo[1]);
  D.overlays.forEach(function (o) { if (o.kind === "horizontal_plane") planeTop = Math.max(planeTop, o.height); });

  // ---- camera ------------------------------------------------------------------------------
  var cam = {};
  function resetCamera() {
    var root0 = joint(people[0], 0, 0), root1 = joint(people[0], people[0].n - 1, 0);
    var t = [root1[0] - root0[0], 0, root1[2] - root0[2]], off;
    if (Math.hypot(t[0], t[2]) > 0.5) {
      t = norm(t); // travel: look from its right side, a little ahead, so it moves rightwards
      var right = cross(t, [0, 1, 0]);
      off = add(mul(right, 0.9), mul(t, 0.3));
    } else { // in place: look from the front-right of the first frame's facing
      var across = sub(joint(people[0], 0, 1), joint(people[0], 0, 2));
      var fwd = norm([-across[2], 0, across[0]]);
      off = add(mul(fwd, 0.8), mul(cross(fwd, [0, 1, 0]), 0.6));
    }
    cam.yaw = Math.atan2(off[0], off[2]);
    cam.pitch = 18 * Math.PI / 180;
    cam.target = [(lo[0] + hi[0]) / 2, clamp((lo[1] + hi[1]) / 2, 0.6, 1.2), (lo[2] + hi[2]) / 2];
    fitDistance();
  }
  // Moves the camera along its line of sight until the scene's bounding box fills most of
  // the canvas (a few passes, since perspective makes the fit depend on the distance).
  function fitDistance() {
    var ys = [Math.min(lo[1], 0), Math.max(hi[1], 1.0)], corners = [];
    for (var k = 0; k < 8; k++) corners.push([k & 1 ? hi[0] : lo[0], ys[k & 2 ? 1 : 0], k & 4 ? hi[2] : lo[2]]);
    cam.dist = 5;
    for (var it = 0; it < 10; it++) {
      setupView();
      var need = 0;
      corners.forEach(function (c) {
        var q = toCam(c);
        if (q[2] < NEAR) { need = Math.max(need, 2); return; }
        need = Math.max(need, Math.abs(q[0] / q[2] * view.focal) / (0.44 * W), Math.abs(q[1] / q[2] * view.focal) / (0.40 * H));
      });
      cam.dist = clamp(cam.dist * clamp(need, 0.5, 2), 2.5, 500);
    }
  }

  var canvas = $("view"), ctx = canvas.getContext("2d"), W = 0, H = 0;
  var view = {};
  function setupView() {
    var cp = Math.cos(cam.pitch);
    view.eye = add(cam.target, mul([cp * Math.sin(cam.yaw), Math.sin(cam.pitch), cp * Math.cos(cam.yaw)], cam.dist));
    view.f = norm(sub(cam.target, view.eye));
    view.r = norm(cross(view.f, [0, 1, 0]));
    view.u = cross(view.r, view.f);
    view.focal = 0.5 * H / Math.tan(FOV / 2);
  }
  function toCam(q) { var d = sub(q, view.eye); return [dot(d, view.r), dot(d, view.u), dot(d, view.f)]; }
  function proj(c) { return [W / 2 + c[0] / c[2] * view.focal, H / 2 - c[1] / c[2] * view.focal]; }
  // World segment → screen [a, b, depth] or null when behind the camera.
  function seg(a, b) {
    var ca = toCam(a), cb = toCam(b);
    if (ca[2] < NEAR && cb[2] < NEAR) return null;
    if (ca[2] < NEAR) ca = lerp(ca, cb, (NEAR - ca[2]) / (cb[2] - ca[2]));
    else if (cb[2] < NEAR) cb = lerp(cb, ca, (NEAR - cb[2]) / (ca[2] - cb[2]));
    return [proj(ca), proj(cb), (ca[2] + cb[2]) / 2];
  }
  // World polygon → screen points, clipped to the near plane.
  function poly(points) {
    var cs = points.map(toCam), out = [];
    for (var k = 0; k < cs.length; k++) {
      var a = cs[k], b = cs[(k + 1) % cs.length], ina = a[2] >= NEAR, inb = b[2] >= NEAR;
      if (ina) out.push(a);
      if (ina !== inb) out.push(lerp(a, b, (NEAR - a[2]) / (b[2] - a[2])));
    }
    return out.map(proj);
  }
  function pointPx(q) { var c = toCam(q); return c[2] < NEAR ? null : { p: proj(c), z: c[2] }; }

  // ---- drawing -----------------------------------------------------------------------------
  function line(s, color, width, dash) {
    if (!s) return;
    ctx.strokeStyle = color; ctx.lineWidth = width; ctx.setLineDash(dash || []);
    ctx.beginPath(); ctx.moveTo(s[0][0], s[0][1]); ctx.lineTo(s[1][0], s[1][1]); ctx.stroke();
    ctx.setLineDash([]);
  }
  function fillPoly(pts, fill, stroke) {
    if (pts.length < 3) return;
    ctx.beginPath(); ctx.moveTo(pts[0][0], pts[0][1]);
    for (var k = 1; k < pts.length; k++) ctx.lineTo(pts[k][0], pts[k][1]);
    ctx.closePath();
    if (fill) { ctx.fillStyle = fill; ctx.fill(); }
    if (stroke) { ctx.strokeStyle = stroke; ctx.lineWidth = 1.2; ctx.stroke(); }
  }
  function dotAt(p, r, color) { ctx.fillStyle = color; ctx.beginPath(); ctx.arc(p[0], p[1], r, 0, 2 * Math.PI); ctx.fill(); }
  function text(p, s, color, align) {
    ctx.font = "12px system-ui, sans-serif"; ctx.textAlign = align || "left"; ctx.textBaseline = "middle";
    ctx.lineWidth = 3; ctx.strokeStyle = "rgba(255,255,255,0.85)"; ctx.strokeText(s, p[0], p[1]);
    ctx.fillStyle = color; ctx.fillText(s, p[0], p[1]);
  }
  function px(metres, z) { return clamp(metres * view.focal / z, 1.2, 14); }

  function drawFloor() {
    var x0 = floorLo[0], z0 = floorLo[1], x1 = floorHi[0], z1 = floorHi[1];
    fillPoly(poly([[x0, 0, z0], [x1, 0, z0], [x1, 0, z1], [x0, 0, z1]]), "#f2f2ee", "#a0a09b");
    for (var x = x0 + 1; x < x1; x++) line(seg([x, 0, z0], [x, 0, z1]), "#cdcdc8", 1);
    for (var z = z0 + 1; z < z1; z++) line(seg([x0, 0, z], [x1, 0, z]), "#cdcdc8", 1);
    line(seg([0, 0, 0], [1, 0, 0]), "#d23c3c", 2);
    line(seg([0, 0, 0], [0, 0, 1]), "#2d64d2", 2);
    var ax = pointPx([1.12, 0, 0]), az = pointPx([0, 0, 1.12]);
    if (ax) text(ax.p, "+X", "#d23c3c", "center");
    if (az) text(az.p, "+Z", "#2d64d2", "center");
  }

  function drawPlanes() {
    D.overlays.forEach(function (o) {
      if (o.kind === "horizontal_plane") {
        var h = o.height;
        fillPoly(poly([[floorLo[0], h, floorLo[1]], [floorHi[0], h, floorLo[1]], [floorHi[0], h, floorHi[1]], [floorLo[0], h, floorHi[1]]]),
          "rgba(210,0,150,0.07)", "rgba(210,0,150,0.55)");
      } else if (o.kind === "vertical_plane") {
        var along = [-o.normal[2], o.normal[0]], l = Math.hypot(along[0], along[1]);
        var ends = clipLine([o.point[0], o.point[2]], [along[0] / l, along[1] / l]);
        if (!ends) return;
        var a = ends[0], b = ends[1];
        fillPoly(poly([[a[0], planeBottom, a[1]], [b[0], planeBottom, b[1]], [b[0], planeTop, b[1]], [a[0], planeTop, a[1]]]),
          "rgba(210,0,150,0.10)", "rgba(210,0,150,0.6)");
      }
    });
  }
  // The part of the line base + s·dir (floor coordinates x, z) inside the floor rectangle.
  function clipLine(base, dir) {
    var t0 = -Infinity, t1 = Infinity;
    for (var k = 0; k < 2; k++) {
      if (Math.abs(dir[k]) < 1e-9) {
        if (base[k] < floorLo[k] || base[k] > floorHi[k]) return null;
      } else {
        var a = (floorLo[k] - base[k]) / dir[k], b = (floorHi[k] - base[k]) / dir[k];
        t0 = Math.max(t0, Math.min(a, b)); t1 = Math.min(t1, Math.max(a, b));
      }
    }
    if (t0 > t1) return null;
    return [[base[0] + dir[0] * t0, base[1] + dir[1] * t0], [base[0] + dir[0] * t1, base[1] + dir[1] * t1]];
  }

  function drawShadowsAndTrails(f) {
    people.forEach(function (pp) {
      var flat = function (q) { return [q[0], 0, q[2]]; };
      bones.forEach(function (b) {
        line(seg(flat(joint(pp, f, b[0])), flat(joint(pp, f, b[1]))), "rgba(120,120,115,0.35)", 3);
      });
      var prev = flat(joint(pp, 0, 0));
      for (var t = 1; t < pp.n; t++) {
        var cur = flat(joint(pp, t, 0));
        line(seg(prev, cur), t <= f ? pp.col[2] : "rgba(130,130,130,0.45)", t <= f ? 2.2 : 1.2);
        prev = cur;
      }
      var start = pointPx(flat(joint(pp, 0, 0)));
      if (start) { ctx.strokeStyle = pp.col[2]; ctx.lineWidth = 1.5; ctx.beginPath(); ctx.arc(start.p[0], start.p[1], 4, 0, 2 * Math.PI); ctx.stroke(); }
    });
  }

  // Everything with depth goes into one list drawn far to near.
  function drawDepthSorted(f) {
    var items = [];
    people.forEach(function (pp) {
      bones.forEach(function (b) {
        var s = seg(joint(pp, f, b[0]), joint(pp, f, b[1]));
        if (s) items.push({ z: s[2], draw: function () { line(s, pp.col[b[2]], px(0.035, s[2])); } });
      });
      for (var j = 0; j < J; j++) {
        var q = pointPx(joint(pp, f, j));
        if (!q) continue;
        (function (q, j) {
          if (j === 15) {
            items.push({ z: q.z, draw: function () { dotAt(q.p, px(0.09, q.z), pp.col[2]); } });
          } else {
            items.push({ z: q.z - 0.01, draw: function () { dotAt(q.p, px(0.022, q.z), pp.col[2]); } });
          }
        })(q, j);
      }
    });
    D.overlays.forEach(function (o) {
      var lines = [];
      if (o.kind === "segment") lines.push([o.from, o.to]);
      if (o.kind === "box") {
        var c = function (k) { return [k & 1 ? o.max[0] : o.min[0], k & 2 ? o.max[1] : o.min[1], k & 4 ? o.max[2] : o.min[2]]; };
        for (var k = 0; k < 8; k++) [1, 2, 4].forEach(function (bit) { if (!(k & bit)) lines.push([c(k), c(k | bit)]); });
      }
      lines.forEach(function (l) {
        var s = seg(l[0], l[1]);
        if (s) items.push({ z: s[2], draw: function () { line(s, OVERLAY, 2); } });
      });
      if (o.kind === "point") {
        var q = pointPx(o.at), foot = seg(o.at, [o.at[0], 0, o.at[2]]);
        if (q) items.push({ z: q.z, draw: function () {
          line(foot, "rgba(210,0,150,0.6)", 1, [4, 4]);
          dotAt(q.p, 5, OVERLAY);
          if (o.label) text([q.p[0] + 9, q.p[1]], o.label, OVERLAY);
        } });
      }
    });
    D.contacts.forEach(function (c) {
      var on = f >= c.frames[0] && f <= c.frames[1];
      var a = joint(people[c.a[0]], f, c.a[1]), b = joint(people[c.b[0]], f, c.b[1]), s = seg(a, b);
      if (!s) return;
      items.push({ z: s[2] - 0.05, draw: function () {
        if (on) {
          line(s, "rgba(255,130,0,0.3)", 9);
          line(s, CONTACT, 3);
          dotAt(s[0], 5, CONTACT); dotAt(s[1], 5, CONTACT);
          if (c.label) text([(s[0][0] + s[1][0]) / 2 + 8, (s[0][1] + s[1][1]) / 2 - 10], c.label, "#b45a00");
        } else {
          line(s, "rgba(110,110,110,0.7)", 1.2, [5, 5]);
        }
      } });
    });
    items.sort(function (a, b) { return b.z - a.z; });
    items.forEach(function (it) { it.draw(); });
    if (people.length > 1) people.forEach(function (pp) {
      var q = pointPx(add(joint(pp, f, 15), [0, 0.28, 0]));
      if (q) text(q.p, pp.name, pp.col[0], "center");
    });
  }

  function drawScene() {
    var f = cur();
    ctx.clearRect(0, 0, W, H);
    ctx.fillStyle = "#ffffff"; ctx.fillRect(0, 0, W, H);
    setupView();
    drawFloor();
    drawPlanes();
    drawShadowsAndTrails(f);
    drawDepthSorted(f);
  }

  // ---- prompt timeline ----------------------------------------------------------------------
  // One row per person with spans; shown when some person has more than one prompt.
  var tlRows = [];
  (D.timeline || []).forEach(function (spans, p) {
    if (spans.length && people[p]) tlRows.push({ name: people[p].name, spans: spans });
  });
  if (!tlRows.some(function (r) { return r.spans.length > 1; })) tlRows = [];
  // x of a frame boundary b (between frames b - 1 and b) on a chart or bar w pixels wide.
  function edgeX(b, w) { return clamp(6 + (N > 1 ? (b - 0.5) / (N - 1) : 0.5) * (w - 12), 6, w - 6); }
  function activeText(row, f) {
    var on = row.spans.filter(function (s) { return f >= s.from && f < s.to; });
    return on.length ? on.map(function (s) { return "\u201c" + s.prompt + "\u201d"; }).join(" \u2192 ") : "\u2013";
  }
  function promptAt(f) {
    if (tlRows.length === 1) return activeText(tlRows[0], f);
    return tlRows.map(function (r) { return r.name + ": " + activeText(r, f); }).join(" \u00b7 ");
  }
  var TL_ROW = 22, tlCanvas = null;
  if (tlRows.length) {
    var tlBox = $("timeline"), tlHead = document.createElement("div");
    tlHead.className = "head";
    tlHead.textContent = "prompts over time" + (tlRows.length > 1 ? " (one row per person)" : "");
    tlCanvas = document.createElement("canvas");
    tlCanvas.style.height = (tlRows.length * TL_ROW + 4) + "px";
    tlBox.appendChild(tlHead); tlBox.appendChild(tlCanvas);
    seekOnDrag(tlCanvas, function (x) {
      return Math.round(clamp((x - 6) / Math.max(1, tlCanvas.clientWidth - 12), 0, 1) * (N - 1));
    });
  }
  function drawTimeline(f) {
    if (!tlCanvas) return;
    var cv = tlCanvas, w = cv.clientWidth, h = cv.clientHeight, dpr = window.devicePixelRatio || 1;
    if (cv.width !== Math.round(w * dpr) || cv.height !== Math.round(h * dpr)) { cv.width = Math.round(w * dpr); cv.height = Math.round(h * dpr); }
    var g = cv.getContext("2d");
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, w, h);
    g.font = "12px system-ui, sans-serif"; g.textBaseline = "middle"; g.textAlign = "left";
    tlRows.forEach(function (row, r) {
      var y0 = 2 + r * TL_ROW, rh = TL_ROW - 3;
      row.spans.forEach(function (s, i) {
        var on = f >= s.from && f < s.to, c = SPAN_COLORS[i % SPAN_COLORS.length];
        var a = edgeX(s.from, w), b = edgeX(s.to, w);
        // Where it blends with the span before, each fills half the row.
        var prev = row.spans[i - 1], blend = prev && prev.to > s.from ? edgeX(Math.min(prev.to, s.to), w) - a : 0;
        g.globalAlpha = 1; g.fillStyle = "#fff"; g.fillRect(a, y0, blend, rh);
        g.globalAlpha = on ? 0.55 : 0.25; g.fillStyle = c; g.fillRect(a, y0, Math.max(1, b - a), rh);
        if (blend > 0) {
          var pOn = f >= prev.from && f < prev.to;
          g.globalAlpha = 1; g.fillStyle = "#fff"; g.fillRect(a, y0, blend, rh / 2);
          g.globalAlpha = pOn ? 0.55 : 0.25; g.fillStyle = SPAN_COLORS[(i - 1) % SPAN_COLORS.length];
          g.fillRect(a, y0, blend, rh / 2);
        }
        g.globalAlpha = 1; g.fillStyle = c; g.fillRect(a, y0, 1, rh);
      });
      row.spans.forEach(function (s, i) {
        var prev = row.spans[i - 1], next = row.spans[i + 1];
        var from = prev ? Math.max(s.from, prev.to) : s.from, to = next ? Math.min(s.to, next.from) : s.to;
        var a = edgeX(from, w) + 4, room = edgeX(Math.max(to, from), w) - 3 - a;
        var label = (i === 0 && tlRows.length > 1 ? row.name + ": " : "") + s.prompt;
        if (room < 14) return;
        while (label.length > 1 && g.measureText(label).width > room) label = label.slice(0, -2) + "\u2026";
        g.fillStyle = "#1a1a1a"; g.fillText(label, a, y0 + rh / 2);
      });
    });
    var x = edgeX(f + 0.5, w);
    g.strokeStyle = "#c0262d"; g.lineWidth = 2;
    g.beginPath(); g.moveTo(x, 0); g.lineTo(x, h); g.stroke();
  }
  // The spans shaded behind an error chart w × h: the first person with several prompts.
  function shadeSpans(g, w, h) {
    var row = tlRows.filter(function (r) { return r.spans.length > 1; })[0];
    if (!row) return;
    row.spans.forEach(function (s, i) {
      var a = edgeX(s.from, w), b = edgeX(s.to, w);
      g.globalAlpha = 0.08; g.fillStyle = SPAN_COLORS[i % SPAN_COLORS.length]; g.fillRect(a, 0, b - a, h);
      g.globalAlpha = 0.6; g.fillRect(a, 0, 1, h);
    });
    g.globalAlpha = 1;
  }

  // ---- statement error charts ----------------------------------------------------------------
  var charts = D.statement_errors.map(function (s) {
    var box = document.createElement("div"), head = document.createElement("div");
    box.className = "chart"; head.className = "head";
    var name = document.createElement("span"), val = document.createElement("span");
    name.textContent = s.label + (s.line != null && s.label.indexOf("line " + s.line) < 0 ? "  (line " + s.line + ")" : "");
    val.className = "val mono";
    head.appendChild(name); head.appendChild(val);
    var cv = document.createElement("canvas");
    box.appendChild(head); box.appendChild(cv);
    $("charts").appendChild(box);
    var vmin = 0, vmax = s.tolerance != null ? s.tolerance : 0;
    s.values.forEach(function (v) { if (v != null) { vmin = Math.min(vmin, v); vmax = Math.max(vmax, v); } });
    if (vmax - vmin < 1e-12) vmax = vmin + 1;
    var chart = { s: s, cv: cv, val: val, vmin: vmin, vmax: vmax * 1.08 };
    seekOnDrag(cv, function (x) {
      var w = cv.clientWidth;
      return Math.round(clamp((x - 6) / Math.max(1, w - 12), 0, 1) * (N - 1));
    });
    return chart;
  });

  function fmt(v) {
    if (v == null) return "–";
    var a = Math.abs(v);
    return a !== 0 && (a < 0.001 || a >= 10000) ? v.toExponential(2) : v.toPrecision(3);
  }

  function drawChart(c, f) {
    var cv = c.cv, w = cv.clientWidth, h = cv.clientHeight, dpr = window.devicePixelRatio || 1;
    if (cv.width !== Math.round(w * dpr) || cv.height !== Math.round(h * dpr)) { cv.width = Math.round(w * dpr); cv.height = Math.round(h * dpr); }
    var g = cv.getContext("2d");
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, w, h);
    shadeSpans(g, w, h);
    var X = function (t) { return 6 + (N > 1 ? t / (N - 1) : 0.5) * (w - 12); };
    var Y = function (v) { return h - 5 - (v - c.vmin) / (c.vmax - c.vmin) * (h - 10); };
    if (c.vmin < 0) { g.strokeStyle = "#ddd"; g.lineWidth = 1; g.beginPath(); g.moveTo(0, Y(0)); g.lineTo(w, Y(0)); g.stroke(); }
    if (c.s.tolerance != null) {
      g.strokeStyle = "#999"; g.setLineDash([4, 3]); g.lineWidth = 1;
      g.beginPath(); g.moveTo(0, Y(c.s.tolerance)); g.lineTo(w, Y(c.s.tolerance)); g.stroke(); g.setLineDash([]);
    }
    g.strokeStyle = "#2d6ed2"; g.lineWidth = 1.5; g.beginPath();
    var open = false;
    c.s.values.forEach(function (v, t) {
      if (v == null) { open = false; return; }
      if (open) g.lineTo(X(t), Y(v)); else { g.moveTo(X(t), Y(v)); open = true; }
    });
    g.stroke();
    g.strokeStyle = "#c0262d"; g.lineWidth = 1.5;
    g.beginPath(); g.moveTo(X(f), 0); g.lineTo(X(f), h); g.stroke();
    var v = c.s.values[f];
    if (v != null) { g.fillStyle = "#c0262d"; g.beginPath(); g.arc(X(f), Y(v), 3, 0, 2 * Math.PI); g.fill(); }
    g.fillStyle = "#888"; g.font = "10px system-ui, sans-serif"; g.textBaseline = "top"; g.textAlign = "left";
    g.fillText(fmt(c.vmax / 1.08) + (c.s.unit ? " " + c.s.unit : ""), 8, 2);
    var over = v != null && c.s.tolerance != null && v > c.s.tolerance;
    c.val.className = "val mono" + (over ? " bad" : "");
    c.val.textContent = "frame " + f + ": " + fmt(v) + (c.s.unit ? " " + c.s.unit : "") +
      (c.s.tolerance != null ? "  (tolerance " + fmt(c.s.tolerance) + ")" : "");
  }

  // ---- legend ------------------------------------------------------------------------------
  var contactTags = [];
  (function legend() {
    var lg = $("legend");
    people.forEach(function (pp) {
      var item = document.createElement("span");
      [0, 1].forEach(function (k) {
        var sw = document.createElement("span");
        sw.className = "sw"; sw.style.background = pp.col[k]; sw.title = k ? "left side" : "right side";
        item.appendChild(sw);
      });
      item.appendChild(document.createTextNode(pp.name + " (dark: right, light: left)"));
      lg.appendChild(item);
    });
    if (D.overlays.length) {
      var o = document.createElement("span");
      o.innerHTML = '<span class="sw" style="background:' + OVERLAY + '"></span>';
      o.appendChild(document.createTextNode(D.overlays.length + " program shape" + (D.overlays.length > 1 ? "s" : "")));
      lg.appendChild(o);
    }
    D.contacts.forEach(function (c) {
      var t = document.createElement("span");
      t.textContent = "contact " + (c.label || people[c.a[0]].name + " " + D.joint_names[c.a[1]] + " – " + people[c.b[0]].name + " " + D.joint_names[c.b[1]]) +
        " [" + c.frames[0] + "–" + c.frames[1] + "]";
      lg.appendChild(t);
      contactTags.push({ el: t, c: c });
    });
  })();

  // ---- playback and controls ------------------------------------------------------------------
  var frame = 0, playing = true, speed = 1, last = null, dirty = true;
  var SPEEDS = [0.25, 0.5, 1, 2, 4];
  function cur() { return clamp(Math.floor(frame), 0, N - 1); }
  function seek(f) { frame = clamp(f, 0, N - 1); dirty = true; }
  function setPlaying(on) { playing = on; last = null; $("play").innerHTML = on ? "&#10074;&#10074;" : "&#9654;"; dirty = true; }
  function setSpeed(s) { speed = s; $("speed").value = String(s); }

  var slider = $("slider");
  slider.max = String(N - 1);
  slider.addEventListener("input", function () { setPlaying(false); seek(+slider.value); });
  $("play").addEventListener("click", function () { setPlaying(!playing); this.blur(); });
  $("reset").addEventListener("click", function () { resetCamera(); dirty = true; this.blur(); });
  $("speed").addEventListener("change", function () { speed = +this.value; this.blur(); });

  document.addEventListener("keydown", function (e) {
    if (e.target && e.target.tagName === "SELECT") return;
    var step = e.shiftKey ? 10 : 1, handled = true;
    switch (e.key) {
      case " ": setPlaying(!playing); break;
      case "ArrowRight": setPlaying(false); seek(cur() + step); break;
      case "ArrowLeft": setPlaying(false); seek(cur() - step); break;
      case "ArrowUp": setSpeed(SPEEDS[Math.min(SPEEDS.length - 1, SPEEDS.indexOf(speed) + 1)] || 1); break;
      case "ArrowDown": setSpeed(SPEEDS[Math.max(0, SPEEDS.indexOf(speed) - 1)] || 1); break;
      case "Home": setPlaying(false); seek(0); break;
      case "End": setPlaying(false); seek(N - 1); break;
      case "r": case "R": resetCamera(); dirty = true; break;
      default: handled = false;
    }
    if (handled) e.preventDefault();
  });

  function seekOnDrag(el, toFrame) {
    var down = false;
    el.addEventListener("pointerdown", function (e) { down = true; el.setPointerCapture(e.pointerId); setPlaying(false); seek(toFrame(e.offsetX)); });
    el.addEventListener("pointermove", function (e) { if (down) seek(toFrame(e.offsetX)); });
    el.addEventListener("pointerup", function () { down = false; });
  }

  // Orbit (drag), pan (shift-drag), zoom (wheel).
  var drag = null;
  canvas.addEventListener("pointerdown", function (e) {
    drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
    canvas.setPointerCapture(e.pointerId); canvas.classList.add("dragging"); canvas.focus();
  });
  canvas.addEventListener("pointermove", function (e) {
    if (!drag) return;
    var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      var s = cam.dist / view.focal, fh = norm([view.f[0], 0, view.f[2]]);
      cam.target = add(cam.target, add(mul(view.r, -dx * s), mul(fh, dy * s)));
    } else {
      cam.yaw -= dx * 0.008;
      cam.pitch = clamp(cam.pitch + dy * 0.008, -0.1, 1.5);
    }
    dirty = true;
  });
  function endDrag() { drag = null; canvas.classList.remove("dragging"); }
  canvas.addEventListener("pointerup", endDrag);
  canvas.addEventListener("pointercancel", endDrag);
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    cam.dist = clamp(cam.dist * Math.exp(e.deltaY * 0.001), 0.5, 500);
    dirty = true;
  }, { passive: false });
  canvas.style.touchAction = "none";

  function resize() {
    var dpr = window.devicePixelRatio || 1;
    W = canvas.clientWidth; H = canvas.clientHeight;
    canvas.width = Math.round(W * dpr); canvas.height = Math.round(H * dpr);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    dirty = true;
  }
  window.addEventListener("resize", resize);

  function render() {
    var f = cur();
    drawScene();
    slider.value = String(f);
    $("counter").textContent = "frame " + f + " / " + (N - 1) + " · " + (f / fps).toFixed(2) + " s / " +
      ((N - 1) / fps).toFixed(2) + " s · " + fps + " fps";
    var active = D.contacts.filter(function (c) { return f >= c.frames[0] && f <= c.frames[1]; }).length;
    $("hud").textContent = active ? active + " contact" + (active > 1 ? "s" : "") + " active" : "";
    contactTags.forEach(function (t) { t.el.className = f >= t.c.frames[0] && f <= t.c.frames[1] ? "active" : ""; });
    if (tlRows.length) { var pt = promptAt(f); $("prompt").textContent = pt; $("prompt").title = pt; }
    drawTimeline(f);
    charts.forEach(function (c) { drawChart(c, f); });
    document.body.setAttribute("data-frame", String(f));
  }

  function tick(now) {
    if (playing && N > 1) {
      if (last !== null) {
        var before = cur();
        frame = (frame + (now - last) / 1000 * fps * speed) % N;
        if (cur() !== before) dirty = true;
      }
      last = now;
    }
    if (dirty) { dirty = false; render(); }
    requestAnimationFrame(tick);
  }

  // Start state from the URL hash: #frame=40&play=1&speed=0.5&yaw=30&pitch=20&zoom=1.5
  function applyHash() {
    var h = {};
    location.hash.replace(/^#/, "").split("&").forEach(function (kv) {
      var i = kv.indexOf("=");
      if (i > 0) h[decodeURIComponent(kv.slice(0, i))] = decodeURIComponent(kv.slice(i + 1));
    });
    resetCamera();
    if (h.yaw !== undefined && isFinite(+h.yaw)) cam.yaw = +h.yaw * Math.PI / 180;
    if (h.pitch !== undefined && isFinite(+h.pitch)) cam.pitch = clamp(+h.pitch * Math.PI / 180, -0.1, 1.5);
    if (h.zoom !== undefined && +h.zoom > 0) cam.dist /= +h.zoom;
    if (h.speed !== undefined && +h.speed > 0) setSpeed(+h.speed);
    if (h.frame !== undefined && isFinite(+h.frame)) { seek(Math.round(+h.frame)); setPlaying(h.play === "1"); }
    else setPlaying(h.play !== "0");
    dirty = true;
  }
  window.addEventListener("hashchange", applyHash);

  resize();
  applyHash();
  render(); // draw once now, so a screenshot taken right after load shows the scene
  dirty = false;
  requestAnimationFrame(tick);
})();

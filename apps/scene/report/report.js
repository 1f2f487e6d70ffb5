// report.html's script (apps/scene/report/, embedded by cmake/embed_report.cmake): draws the
// diagrams, the chain's shapes and the tables from the page's data, which report.cpp writes into
// the page. The drawing functions follow the gnuplot diagrams' rules: a marker per special-point
// type (special_marks.h), labels placed apart on rings of candidate positions with a leader line
// when away (label_layout.h), jump arrows at least a minimum length on screen.
(function () {
  'use strict';
  var errors = [];
  function fail(message) {
    errors.push(String(message));
    var box = document.getElementById('errors');
    box.textContent = 'Errors while drawing this page:\n' + errors.join('\n');
    box.hidden = false;
    document.body.setAttribute('data-status', 'error');
  }
  window.addEventListener('error', function (e) { fail(e.message + ' (line ' + e.lineno + ')'); });

  var NS = 'http://www.w3.org/2000/svg';
  var PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#e377c2', '#17becf'];
  function ok(v) { return typeof v === 'number' && isFinite(v); }
  function svg(tag, attrs, parent) {
    var e = document.createElementNS(NS, tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function html(tag, attrs, parent, text) {
    var e = document.createElement(tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    if (parent) parent.appendChild(e);
    return e;
  }
  function fmt(v, digits) {
    if (!ok(v)) return '–';
    var a = Math.abs(v);
    if (a !== 0 && (a < 1e-3 || a >= 1e5)) return v.toExponential(2);
    return String(+v.toPrecision(digits || 5));
  }
  function ticks(lo, hi, count) {
    var raw = (hi - lo) / count, step = Math.pow(10, Math.floor(Math.log(raw) / Math.LN10)), r = raw / step;
    step *= r >= 7.5 ? 10 : r >= 3.5 ? 5 : r >= 1.5 ? 2 : 1;
    var out = [];
    for (var t = Math.ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) out.push(Math.abs(t) < 1e-9 * step ? 0 : t);
    return out;
  }
  function range(values) {
    var lo = Infinity, hi = -Infinity;
    values.forEach(function (v) { if (ok(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); } });
    if (lo > hi) return null;
    if (hi - lo <= 1e-12 * Math.max(1, Math.abs(lo))) { var d = Math.max(Math.abs(lo) * 0.1, 1e-3); lo -= d; hi += d; }
    var pad = 0.04 * (hi - lo);
    return [lo - pad, hi + pad];
  }

  // A marker shaped as gnuplot's point type `point` (7 circle, 5 square, 9 / 11 triangle up /
  // down, 13 diamond, 15 pentagon, 3 star), radius r, centred at (x, y).
  function marker(parent, point, x, y, r, fill, attrs) {
    var e, a = {fill: fill, stroke: '#000', 'stroke-width': 0.8};
    for (var k in attrs) a[k] = attrs[k];
    function polygon(corners, turn, scale) {
      var p = [];
      for (var i = 0; i < corners; ++i) {
        var t = turn + 2 * Math.PI * i / corners;
        p.push((x + scale * r * Math.cos(t)).toFixed(1) + ',' + (y - scale * r * Math.sin(t)).toFixed(1));
      }
      a.points = p.join(' ');
      return svg('polygon', a, parent);
    }
    if (point === 5) { a.x = x - 0.9 * r; a.y = y - 0.9 * r; a.width = a.height = 1.8 * r; e = svg('rect', a, parent); }
    else if (point === 9) e = polygon(3, Math.PI / 2, 1.3);
    else if (point === 11) e = polygon(3, -Math.PI / 2, 1.3);
    else if (point === 13) e = polygon(4, Math.PI / 2, 1.25);
    else if (point === 15) e = polygon(5, Math.PI / 2, 1.15);
    else if (point === 3) {
      var d = '';
      for (var i = 0; i < 4; ++i) {
        var t = Math.PI * i / 4, cx = 1.2 * r * Math.cos(t), cy = 1.2 * r * Math.sin(t);
        d += 'M' + (x - cx).toFixed(1) + ' ' + (y - cy).toFixed(1) + 'L' + (x + cx).toFixed(1) + ' ' + (y + cy).toFixed(1);
      }
      a.d = d; a.stroke = fill === '#000000' ? '#000' : fill; a['stroke-width'] = 1.6;
      e = svg('path', a, parent);
    } else { a.cx = x; a.cy = y; a.r = r; e = svg('circle', a, parent); }
    return e;
  }

  // Pixels covered by curves, with a summed-area table: the covered pixels under a box in one lookup.
  function Occupancy(w, h) {
    var grid = new Uint8Array(w * h), sum = null;
    this.segment = function (x0, y0, x1, y1) {
      if (!ok(x0) || !ok(y0) || !ok(x1) || !ok(y1)) return;
      var steps = Math.min(4000, Math.ceil(Math.hypot(x1 - x0, y1 - y0)) + 1);
      for (var k = 0; k <= steps; ++k) {
        var x = x0 + (x1 - x0) * k / steps, y = y0 + (y1 - y0) * k / steps;
        if (x >= 0 && y >= 0 && x < w && y < h) grid[Math.floor(y) * w + Math.floor(x)] = 1;
      }
    };
    this.fill = function (b) {
      for (var y = Math.max(0, Math.floor(b.y0)); y < Math.min(h, b.y1); ++y)
        for (var x = Math.max(0, Math.floor(b.x0)); x < Math.min(w, b.x1); ++x) grid[y * w + x] = 1;
    };
    this.finish = function () {
      sum = new Int32Array((w + 1) * (h + 1));
      for (var y = 0; y < h; ++y)
        for (var x = 0; x < w; ++x)
          sum[(y + 1) * (w + 1) + x + 1] = grid[y * w + x] + sum[(y + 1) * (w + 1) + x] + sum[y * (w + 1) + x + 1] - sum[y * (w + 1) + x];
    };
    this.count = function (b) {
      function c(v, hi) { return Math.max(0, Math.min(hi, Math.floor(v))); }
      var x0 = c(b.x0, w), x1 = c(b.x1, w), y0 = c(b.y0, h), y1 = c(b.y1, h);
      return sum[y1 * (w + 1) + x1] - sum[y1 * (w + 1) + x0] - sum[y0 * (w + 1) + x1] + sum[y0 * (w + 1) + x0];
    };
  }
  function overlaps(a, b) { return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1; }

  // The gnuplot diagrams' label placement (plot_internal.h, placeLabels), in screen pixels
  // (y down): candidate positions on rings of growing radius around the point, in 16 directions
  // (the diagonals first), the cheapest taken, greedily by priority, then from left to right; a
  // label that overlaps another label or leaves the plot area is not drawn (its marker and the
  // key still show the point).
  var LABEL_RINGS = [2, 18, 36, 58, 84, 116, 156], SUMMARY_RINGS = LABEL_RINGS.concat([200, 250, 310, 380, 460, 560]);
  var LABEL_H = 13, MARKER_HALF = 7, DIRECTIONS = [2, 6, 14, 10, 0, 8, 4, 12, 1, 3, 5, 7, 9, 11, 13, 15];
  function placeLabels(labels, area, occupied, rings) {
    var markers = labels.map(function (l) {
      return {x0: l.px - MARKER_HALF, y0: l.py - MARKER_HALF, x1: l.px + MARKER_HALF, y1: l.py + MARKER_HALF};
    });
    var order = labels.map(function (l, i) { return i; });
    order.sort(function (a, b) { return labels[a].priority - labels[b].priority || labels[a].px - labels[b].px || a - b; });
    var placed = [];
    order.forEach(function (i) {
      var l = labels[i], w = l.width + 4, h = LABEL_H, best = Infinity, rank = 0;
      rings.forEach(function (r) {
        for (var k = 0; k < 16; ++k, ++rank) {
          var a = DIRECTIONS[k] * Math.PI / 8;
          var cx = l.px + Math.cos(a) * (MARKER_HALF + r + w / 2), cy = l.py - Math.sin(a) * (MARKER_HALF + r + h / 2);
          var b = {x0: cx - w / 2, y0: cy - h / 2, x1: cx + w / 2, y1: cy + h / 2};
          var cost = r + 0.5 * rank / 16;
          if (b.x0 < area.x0 || b.x1 > area.x1 || b.y0 < area.y0 || b.y1 > area.y1) cost += 1e7;
          for (var p = 0; p < placed.length; ++p) if (overlaps(b, placed[p])) cost += 1e6;
          for (var m = 0; m < markers.length; ++m) if (overlaps(b, markers[m])) cost += 1e5;
          cost += 3 * occupied.count(b);
          if (cost < best) { best = cost; l.box = b; l.leader = r > 2; }
        }
      });
      l.shown = best < 1e6;
      if (l.shown) placed.push(l.box);
    });
  }

  // A jump from p to q (pixels) drawn at least `min` pixels long: a straight arrow when it is,
  // else a hop (a quadratic arc from p to q bulging to the side with fewer curves) whose length
  // is about `min`, so that a jump of a few pixels is still seen to leave and land.
  function jumpPath(p, q, min, occupied) {
    var dx = q[0] - p[0], dy = q[1] - p[1], len = Math.hypot(dx, dy);
    if (len >= min) return {d: 'M' + p[0].toFixed(1) + ' ' + p[1].toFixed(1) + 'L' + q[0].toFixed(1) + ' ' + q[1].toFixed(1),
                            points: [p, q]};
    var nx = len > 1e-9 ? -dy / len : 0, ny = len > 1e-9 ? dx / len : -1;
    var bulge = Math.sqrt(Math.max(0, min * min - len * len)) / 2;  // the arc's apex this far off the chord
    var mx = (p[0] + q[0]) / 2, my = (p[1] + q[1]) / 2;
    function side(s) {
      var x = mx + s * nx * bulge, y = my + s * ny * bulge;
      return occupied.count({x0: x - 6, y0: y - 6, x1: x + 6, y1: y + 6});
    }
    var s = side(-1) < side(1) ? -1 : 1, c = [mx + 2 * s * nx * bulge, my + 2 * s * ny * bulge], pts = [];
    for (var k = 0; k <= 12; ++k) {
      var t = k / 12;
      pts.push([(1 - t) * (1 - t) * p[0] + 2 * t * (1 - t) * c[0] + t * t * q[0], (1 - t) * (1 - t) * p[1] + 2 * t * (1 - t) * c[1] + t * t * q[1]]);
    }
    return {d: 'M' + p[0].toFixed(1) + ' ' + p[1].toFixed(1) + 'Q' + c[0].toFixed(1) + ' ' + c[1].toFixed(1) + ' ' +
               q[0].toFixed(1) + ' ' + q[1].toFixed(1), points: pts};
  }

  // Markers of one group closer than `radius` pixels to one already kept are not drawn.
  function thinned(points, radius) {
    var grid = {}, kept = [];
    points.forEach(function (p, i) {
      var cx = Math.floor(p[0] / radius), cy = Math.floor(p[1] / radius), near = false;
      for (var dx = -1; dx <= 1 && !near; ++dx)
        for (var dy = -1; dy <= 1 && !near; ++dy)
          (grid[(cx + dx) + ',' + (cy + dy)] || []).forEach(function (k) {
            near = near || Math.hypot(points[k][0] - p[0], points[k][1] - p[1]) < radius;
          });
      if (near) return;
      (grid[cx + ',' + cy] = grid[cx + ',' + cy] || []).push(i);
      kept.push(i);
    });
    return kept;
  }

  // A chart: o.lines [{x, y, color, dash, width, cls}]; o.marks [{x, y, color, point, r, title,
  // act, cls, type, thin}] (a mark with `thin` is left out within o.thinPx of a kept one of the
  // same `thin` group; full-size marks of different types shrink to stay apart); o.labels [{x, y,
  // text, priority, group, color}] (merged per group within o.mergePx by o.merge, placed apart);
  // o.arrows [{x0, y0, x1, y1, title}] drawn at least o.arrowMin pixels long; o.pick [{x, y, act}]
  // (hover/click targets); o.legend [{color, dash, label}] inside the plot, or o.key [{kind
  // 'line'/'mark'/'arrow', color, dash, point, label, type}] in the right margin; o.equal: one
  // scale on both axes.
  function chart(parent, o) {
    var keyWidth = 0;
    (o.key || []).forEach(function (g) { keyWidth = Math.max(keyWidth, 44 + 6.5 * g.label.length); });
    keyWidth = Math.min(keyWidth, 260);
    var W = (o.width || 640) + keyWidth, H = o.height || 400, L = 66, R = 14 + keyWidth, T = 26, B = 44;
    var root = svg('svg', {viewBox: '0 0 ' + W + ' ' + H, 'class': o.cls || 'chart'}, parent);
    if (keyWidth) root.style.width = W + 'px';  // the key widens the chart, not shrinks the plot
    if (o.id) root.setAttribute('id', o.id);
    svg('text', {x: (L + W - R) / 2, y: 16, 'text-anchor': 'middle', 'class': 'title'}, root).textContent = o.title || '';
    var xs = [], ys = [];
    o.lines.forEach(function (l) {
      for (var i = 0; i < l.x.length; ++i) if (ok(l.x[i]) && ok(l.y[i])) { xs.push(l.x[i]); ys.push(l.y[i]); }
    });
    (o.marks || []).forEach(function (m) { if (ok(m.x) && ok(m.y)) { xs.push(m.x); ys.push(m.y); } });
    (o.arrows || []).forEach(function (a) { xs.push(a.x0, a.x1); ys.push(a.y0, a.y1); });
    var rx = range(xs), ry = range(ys);
    if (!rx || !ry) {
      svg('text', {x: W / 2, y: H / 2, 'text-anchor': 'middle'}, root).textContent = 'nothing to draw';
      return root;
    }
    var pw = W - L - R, ph = H - T - B;
    if (o.equal) {  // one unit is as long on both axes: widen the narrower range
      var ux = (rx[1] - rx[0]) / pw, uy = (ry[1] - ry[0]) / ph, u = Math.max(ux, uy);
      var cx = (rx[0] + rx[1]) / 2, cy = (ry[0] + ry[1]) / 2;
      rx = [cx - u * pw / 2, cx + u * pw / 2];
      ry = [cy - u * ph / 2, cy + u * ph / 2];
    }
    function sx(v) { return L + (v - rx[0]) / (rx[1] - rx[0]) * pw; }
    function sy(v) { return T + ph - (v - ry[0]) / (ry[1] - ry[0]) * ph; }
    ticks(rx[0], rx[1], 7).forEach(function (t) {
      svg('line', {x1: sx(t), x2: sx(t), y1: T, y2: T + ph, 'class': 'grid'}, root);
      svg('text', {x: sx(t), y: T + ph + 14, 'text-anchor': 'middle'}, root).textContent = fmt(t, 4);
    });
    ticks(ry[0], ry[1], 6).forEach(function (t) {
      svg('line', {x1: L, x2: L + pw, y1: sy(t), y2: sy(t), 'class': 'grid'}, root);
      svg('text', {x: L - 4, y: sy(t) + 4, 'text-anchor': 'end'}, root).textContent = fmt(t, 4);
    });
    svg('rect', {x: L, y: T, width: pw, height: ph, 'class': 'axis'}, root);
    svg('text', {x: L + pw / 2, y: H - 8, 'text-anchor': 'middle', 'class': 'xlabel'}, root).textContent = o.xlabel || '';
    svg('text', {x: 14, y: T + ph / 2, 'text-anchor': 'middle', 'class': 'ylabel',
                 transform: 'rotate(-90 14 ' + (T + ph / 2) + ')'}, root).textContent = o.ylabel || '';
    var clip = 'clip' + Math.random().toString(36).slice(2);
    svg('rect', {x: L, y: T, width: pw, height: ph}, svg('clipPath', {id: clip}, root));
    var body = svg('g', {'clip-path': 'url(#' + clip + ')'}, root);
    var occupied = new Occupancy(Math.ceil(W), Math.ceil(H));
    o.lines.forEach(function (l) {
      var d = '', pen = false, px = null;
      for (var i = 0; i < l.x.length; ++i) {
        if (!ok(l.x[i]) || !ok(l.y[i])) { pen = false; continue; }
        var q = [sx(l.x[i]), sy(l.y[i])];
        d += (pen ? 'L' : 'M') + q[0].toFixed(1) + ' ' + q[1].toFixed(1);
        if (pen && l.color !== 'none') occupied.segment(px[0], px[1], q[0], q[1]);
        pen = true;
        px = q;
      }
      if (d) svg('path', {d: d, fill: 'none', stroke: l.color, 'stroke-width': l.width || 1.8,
                          'stroke-dasharray': l.dash || 'none', 'stroke-opacity': l.opacity || 1, 'class': l.cls || 'line'}, body);
    });
    occupied.finish();  // the curves: the hops of short jumps bulge away from them
    var arrowHead = null;
    (o.arrows || []).forEach(function (a) {
      if (!arrowHead) {
        arrowHead = 'head' + Math.random().toString(36).slice(2);
        svg('path', {d: 'M0,0 L10,4 L0,8 z', fill: '#ff7f0e'},
            svg('marker', {id: arrowHead, viewBox: '0 0 10 8', refX: 9, refY: 4, markerWidth: 9, markerHeight: 7,
                           orient: 'auto', markerUnits: 'userSpaceOnUse'}, svg('defs', {}, root)));
      }
      var j = jumpPath([sx(a.x0), sy(a.y0)], [sx(a.x1), sy(a.y1)], o.arrowMin || 0, occupied);
      var e = svg('path', {d: j.d, fill: 'none', stroke: '#ff7f0e', 'stroke-width': 1.8, 'class': 'jump',
                           'marker-end': 'url(#' + arrowHead + ')'}, body);
      if (a.title) svg('title', {}, e).textContent = a.title;
      for (var k = 0; k + 1 < j.points.length; ++k)
        occupied.segment(j.points[k][0], j.points[k][1], j.points[k + 1][0], j.points[k + 1][1]);
    });
    // the marks: thinned per group, then full-size ones of different types kept apart by size
    var marks = (o.marks || []).filter(function (m) { return ok(m.x) && ok(m.y); });
    marks.forEach(function (m) { m.px = sx(m.x); m.py = sy(m.y); m.drawn = true; });
    var groups = {};
    marks.forEach(function (m) { if (m.thin) (groups[m.thin] = groups[m.thin] || []).push(m); });
    Object.keys(groups).forEach(function (g) {
      var list = groups[g];
      list.forEach(function (m) { m.drawn = false; });
      thinned(list.map(function (m) { return [m.px, m.py]; }), o.thinPx || 4).forEach(function (k) { list[k].drawn = true; });
    });
    var full = marks.filter(function (m) { return !m.thin; });
    full.forEach(function (m) {
      var r = m.r || 4.5;
      full.forEach(function (n) {
        if (n !== m && n.type !== m.type) r = Math.min(r, Math.max(2.5, 0.5 * Math.hypot(n.px - m.px, n.py - m.py)));
      });
      m.radius = r;
    });
    marks.forEach(function (m) {
      if (!m.drawn) return;
      var r = m.radius || m.r || 4.5;
      if (m.thin) occupied.fill({x0: m.px - 2, y0: m.py - 2, x1: m.px + 2, y1: m.py + 2});
      var c = marker(body, m.point, m.px, m.py, r, m.color, {'class': m.cls || 'mark', 'data-type': m.type || ''});
      if (m.title) svg('title', {}, c).textContent = m.title;
      if (m.act) { c.style.cursor = 'pointer'; c.addEventListener('click', m.act); }
    });
    occupied.finish();
    // labels: one per group's points within o.mergePx, placed apart, leader lines under the text
    var labels = [];
    (o.labels || []).forEach(function (l) {
      if (!ok(l.x) || !ok(l.y)) return;
      var px = sx(l.x), py = sy(l.y), k = 0;
      while (k < labels.length && (labels[k].group !== l.group || Math.hypot(labels[k].px - px, labels[k].py - py) > (o.mergePx || 3))) ++k;
      if (k === labels.length) labels.push({px: px, py: py, group: l.group, priority: l.priority || 0, parts: [], color: l.color});
      labels[k].priority = Math.min(labels[k].priority, l.priority || 0);
      if (labels[k].parts.indexOf(l.text) < 0) labels[k].parts.push(l.text);
    });
    var layer = svg('g', {'class': 'labels'}, root);
    labels.forEach(function (l) {
      l.text = o.merge ? o.merge(l.parts) : l.parts.join(', ');
      l.node = svg('text', {'class': 'sp-label', 'text-anchor': 'middle'}, layer);
      l.node.textContent = l.text;
      l.width = l.node.getComputedTextLength() || 6.5 * l.text.length;
    });
    placeLabels(labels, {x0: L, y0: T, x1: L + pw, y1: T + ph}, occupied, o.summary ? SUMMARY_RINGS : LABEL_RINGS);
    labels.forEach(function (l) {
      if (!l.shown) { layer.removeChild(l.node); return; }
      var b = l.box, cx = (b.x0 + b.x1) / 2;
      l.node.setAttribute('x', cx.toFixed(1));
      l.node.setAttribute('y', (b.y1 - 3.5).toFixed(1));
      if (l.color) l.node.style.fill = l.color;
      if (l.leader) {
        var ex = Math.min(Math.max(l.px, b.x0), b.x1), ey = Math.min(Math.max(l.py, b.y0), b.y1);
        layer.insertBefore(svg('line', {x1: l.px.toFixed(1), y1: l.py.toFixed(1), x2: ex.toFixed(1), y2: ey.toFixed(1),
                                        stroke: '#777', 'stroke-width': 0.8, 'class': 'leader'}), layer.firstChild);
      }
    });
    root.setAttribute('data-labels', labels.filter(function (l) { return l.shown; }).length);
    root.setAttribute('data-labels-left-out', labels.filter(function (l) { return !l.shown; }).length);
    (o.legend || []).forEach(function (g, k) {
      var y = T + 12 + 15 * k;
      svg('line', {x1: L + pw - 150, x2: L + pw - 124, y1: y, y2: y, stroke: g.color, 'stroke-width': 2,
                   'stroke-dasharray': g.dash || 'none'}, root);
      svg('text', {x: L + pw - 120, y: y + 4}, root).textContent = g.label;
    });
    if (o.key && o.key.length) {
      var key = svg('g', {'class': 'key'}, root), kx = L + pw + 12;
      svg('rect', {x: kx - 4, y: T, width: keyWidth - 6, height: 10 + 16 * o.key.length, fill: '#fff', stroke: '#ccc'}, key);
      o.key.forEach(function (g, k) {
        var y = T + 13 + 16 * k, e = svg('g', {'class': 'key-entry', 'data-kind': g.kind, 'data-type': g.type || ''}, key);
        if (g.kind === 'mark') marker(e, g.point, kx + 13, y, 4.5, g.color, {});
        else {
          var line = svg('line', {x1: kx, x2: kx + 26, y1: y, y2: y, stroke: g.color, 'stroke-width': 2,
                                  'stroke-dasharray': g.dash || 'none'}, e);
          if (g.kind === 'arrow') svg('path', {d: 'M' + (kx + 20) + ',' + (y - 4) + ' L' + (kx + 28) + ',' + y + ' L' + (kx + 20) + ',' + (y + 4) + ' z',
                                               fill: g.color}, e);
          if (g.kind === 'arrow') line.setAttribute('x2', kx + 21);
        }
        svg('text', {x: kx + 34, y: y + 4}, e).textContent = g.label;
      });
    }
    if (o.pick && o.pick.length) {
      var cursor = svg('circle', {r: 5, fill: 'none', stroke: '#000', 'stroke-width': 1.5, visibility: 'hidden'}, root);
      var nearest = function (ev) {
        var m = root.getScreenCTM();
        if (!m) return null;
        var pt = root.createSVGPoint();
        pt.x = ev.clientX; pt.y = ev.clientY;
        pt = pt.matrixTransform(m.inverse());
        var best = null, bestD = 20 * 20;
        o.pick.forEach(function (p) {
          if (!ok(p.x) || !ok(p.y)) return;
          var dx = sx(p.x) - pt.x, dy = sy(p.y) - pt.y, d2 = dx * dx + dy * dy;
          if (d2 < bestD) { bestD = d2; best = p; }
        });
        return best;
      };
      var show = function (ev) {
        var p = nearest(ev);
        if (!p) return;
        cursor.setAttribute('cx', sx(p.x)); cursor.setAttribute('cy', sy(p.y));
        cursor.setAttribute('visibility', 'visible');
        p.act();
      };
      root.addEventListener('mousemove', show);
      root.addEventListener('click', show);
    }
    return root;
  }

  var D = JSON.parse(document.getElementById('buckle-data').textContent);
  function label(column) { return (D.labels && D.labels[column]) || column; }  // with the scene's unit
  var STYLE = {}, TYPE_COLOR = {};  // per special-point type: its marker, key entry and colour (special_marks.h)
  D.marks.styles.forEach(function (st) { STYLE[st.type] = st; TYPE_COLOR[st.type] = st.color; });
  function styleOf(type) { return STYLE[type] || {type: type, point: 7, key: type, color: '#555555'}; }
  // one label for points drawn at one place: a summary writes branch points' modes as ranges
  // ("BP 3, 4", "BP 24-27"), the other texts after them (special_marks.h, mergedLabel)
  function mergedLabel(parts, summary) {
    var modes = [], rest = [], text = '';
    parts.forEach(function (p) {
      if (summary && /^BP [0-9]+$/.test(p)) modes.push(+p.slice(3)); else rest.push(p);
    });
    modes.sort(function (a, b) { return a - b; });
    for (var i = 0; i < modes.length;) {
      var j = i;
      while (j + 1 < modes.length && modes[j + 1] === modes[j] + 1) ++j;
      text += (i ? ', ' : 'BP ') + modes[i];
      if (j === i + 1) text += ', ' + modes[j];
      if (j > i + 1) text += '-' + modes[j];
      i = j + 1;
    }
    rest.forEach(function (p) { text += (text ? ', ' : '') + p; });
    return text;
  }

  // ---- the chain's shape ----------------------------------------------------------------------
  var shapeBox = {};  // per case: a fixed frame (every shape of the case fits), so hovering does not rescale
  function caseFrame(c) {
    if (shapeBox[c.index]) return shapeBox[c.index];
    var xs = [0], ys = [0];
    function add(s) { if (s) for (var i = 0; i < s.length; i += 2) { xs.push(s[i]); ys.push(s[i + 1]); } }
    c.shapes.forEach(add);
    c.specials.forEach(function (s) { add(s.joints); add(s.jump_joints); });
    add(c.unloaded);
    return (shapeBox[c.index] = {xs: xs, ys: ys});
  }
  function drawShapes(target, c, shapes, info, frame) {
    while (target.firstChild) target.removeChild(target.firstChild);
    var lines = [], marks = [];
    shapes.forEach(function (s) {
      var x = [], y = [];
      for (var i = 0; i < s.joints.length; i += 2) { x.push(s.joints[i]); y.push(s.joints[i + 1]); }
      lines.push({x: x, y: y, color: s.color, dash: s.dash, width: 2.5});
      // a dot per joint while they are apart (up to 30 segments), else the base and the end only
      for (var k = 0; k < x.length; ++k)
        if (x.length <= 32 || k === 0 || k === x.length - 1)
          marks.push({x: x[k], y: y[k], color: k === 0 || k === x.length - 1 ? '#000' : s.color, r: 3});
    });
    frame = frame || caseFrame(c);
    // invisible frame line, so every shape of the case is drawn at the same scale; bounds by a
    // loop (Math.min.apply over a long chain's 10^5 coordinates overflows the call stack)
    function bounds(v) {
      var lo = Infinity, hi = -Infinity;
      for (var i = 0; i < v.length; ++i) { if (v[i] < lo) lo = v[i]; if (v[i] > hi) hi = v[i]; }
      return [lo, hi];
    }
    lines.push({x: bounds(frame.xs), y: bounds(frame.ys), color: 'none', width: 0});
    var g = chart(target, {lines: lines, marks: marks, equal: true, width: 560, height: 400, cls: 'shape',
                           xlabel: 'x' + D.unit_suffix.length, ylabel: 'y' + D.unit_suffix.length, title: info.title,
                           legend: info.legend});
    while (g.firstChild) target.appendChild(g.firstChild);
    target.removeChild(g);
    if (target.id === 'shape') document.getElementById('shape-info').textContent = info.text || '';
  }
  function nearestShape(c, i) {  // the point itself, or the nearest on its branch that carries a shape
    for (var d = 0; d < c.shapes.length; ++d) {
      var a = i - d, b = i + d;
      if (a >= 0 && c.shapes[a] && c.branch[a] === c.branch[i]) return a;
      if (b < c.shapes.length && c.shapes[b] && c.branch[b] === c.branch[i]) return b;
    }
    return -1;
  }
  function showPoint(c, i) {
    var j = nearestShape(c, i);
    if (j < 0) return;
    drawShapes(document.getElementById('shape'), c, [{joints: c.shapes[j], color: c.stable[j] ? '#1f77b4' : '#d62728'}], {
      title: (D.cases.length > 1 ? c.label + ': ' : '') + 'branch ' + c.branch[j] + ', point ' + c.point[j],
      text: c.parameter + ' = ' + fmt(c.columns.parameter[j], 6) + ', ' + (c.stable[j] ? 'stable' : 'unstable') +
            (j !== i ? ' (nearest point with a stored shape)' : '')});
  }
  function showSpecial(c, s) {
    var shapes = [{joints: s.joints, color: TYPE_COLOR[s.type] || '#000'}], legend = [];
    if (s.jump_joints) {
      shapes.push({joints: s.jump_joints, color: '#2ca02c', dash: '6 4'});
      legend = [{color: TYPE_COLOR[s.type] || '#000', label: s.type}, {color: '#2ca02c', dash: '6 4', label: 'after the jump'}];
    }
    drawShapes(document.getElementById('shape'), c, shapes, {
      title: s.type + ' (' + s.field + ') on branch ' + s.branch, legend: legend,
      text: c.parameter + ' = ' + fmt(s.parameter, 8) + ', shape ' + s.shape + ', stability ' + s.before + ' → ' + s.after +
            (s.jump ? '; jump: ' + s.jump : '')});
  }

  // ---- branch diagrams --------------------------------------------------------------------------
  // Summary for large diagrams as the gnuplot ones (docs/outputs.md, Plots of long chains): above
  // D.marks.summary_above markers only the primary branch's branch points and then, up to
  // D.marks.summary_extra, the jumps and first folds are labelled at full size; the others are
  // small markers thinned within D.marks.thin_px, and the key counts each type.
  var JUMP_MIN_PX = 36;  // a jump's arrow is drawn at least this long (a hop where the jump is shorter)
  function branchChart(parent, spec, id) {
    var lines = [], marks = [], pick = [], key = [], labels = [], arrows = [];
    var multi = D.cases.length > 1 || spec.y.length > 1;
    var chosen = D.cases.filter(function (c) { return !spec.cases || spec.cases.indexOf(c.index) >= 0; });
    var markers = 0;
    chosen.forEach(function (c) { markers += c.specials.length * spec.y.length; });
    var summary = spec.labels === 'summary' || (spec.labels !== 'all' && markers > D.marks.summary_above);
    var counts = {}, types = [], labelled = 0;
    chosen.forEach(function (c) {
      // the points labelled: all, or in a summary the primary branch points, then by importance
      var extra = 0, ranked = c.specials.map(function (s, i) { return i; });
      ranked.sort(function (a, b) { return c.specials[a].rank - c.specials[b].rank || a - b; });
      var isLabelled = c.specials.map(function () { return !summary; });
      if (summary)
        ranked.forEach(function (i) {
          var r = c.specials[i].rank;
          if (r === 0 || (r < 3 && extra++ < D.marks.summary_extra)) isLabelled[i] = true;
        });
      spec.y.forEach(function (ycol, k) {
        var X = c.columns[spec.x], Y = c.columns[ycol];
        if (!X || !Y) return;
        var base = multi ? PALETTE[(c.index * spec.y.length + k) % PALETTE.length] : null;
        var stableColor = base || '#1f77b4', unstableColor = base || '#d62728', run = null;
        for (var i = 0; i < X.length; ++i) {
          var same = i > 0 && c.branch[i] === c.branch[i - 1];
          if (run && same && c.stable[i] === c.stable[i - 1]) { run.x.push(X[i]); run.y.push(Y[i]); }
          else {
            if (run && same) { run.x.push(X[i]); run.y.push(Y[i]); }  // the stability changes here: keep the line joined
            run = {x: [X[i]], y: [Y[i]], color: c.stable[i] ? stableColor : unstableColor, dash: c.stable[i] ? '' : '6 4',
                   cls: c.stable[i] ? 'branch stable' : 'branch unstable'};
            lines.push(run);
          }
          pick.push({x: X[i], y: Y[i], act: showPoint.bind(null, c, i)});
        }
        if (multi) key.push({kind: 'line', color: stableColor, label: (D.cases.length > 1 ? c.label + ' ' : '') + ycol});
        c.specials.forEach(function (s, n) {
          if (!s.values || !ok(s.values[spec.x]) || !ok(s.values[ycol])) return;
          var st = styleOf(s.type), x = s.values[spec.x], y = s.values[ycol];
          if (!counts[s.type]) { counts[s.type] = 0; types.push(s.type); }
          ++counts[s.type];
          var full = isLabelled[n];
          marks.push({x: x, y: y, point: st.point, type: s.type, r: full ? 4.5 : 2.2, cls: 'special',
                      color: summary || !multi ? st.color : PALETTE[(c.index * spec.y.length + k) % PALETTE.length],
                      thin: full ? null : c.index + ' ' + s.type,
                      title: s.type + ' ' + s.field + ' at ' + c.parameter + ' = ' + fmt(s.parameter, 6),
                      act: s.joints ? showSpecial.bind(null, c, s) : null});
          if (full) {
            labels.push({x: x, y: y, text: summary ? s.label_summary : s.label, group: c.index + '/' + k, priority: summary ? s.rank : 0,
                         color: multi ? PALETTE[(c.index * spec.y.length + k) % PALETTE.length] : null});
            ++labelled;
          }
          if (s.landing && ok(s.landing[spec.x]) && ok(s.landing[ycol]))
            arrows.push({x0: x, y0: y, x1: s.landing[spec.x], y1: s.landing[ycol], title: 'jump: ' + (s.jump || '')});
        });
      });
    });
    if (!multi) key = [{kind: 'line', color: '#1f77b4', label: 'stable'}, {kind: 'line', color: '#d62728', dash: '6 4', label: 'unstable'}];
    else key.push({kind: 'line', color: '#000', label: 'stable'}, {kind: 'line', color: '#000', dash: '6 4', label: 'unstable'});
    if (arrows.length) key.push({kind: 'arrow', color: '#ff7f0e', label: 'jump'});
    D.marks.styles.map(function (st) { return st.type; }).concat(types).forEach(function (t, i, all) {
      if (!counts[t] || all.indexOf(t) !== i) return;
      var st = styleOf(t);
      key.push({kind: 'mark', type: t, point: st.point, color: summary || !multi ? st.color : '#000',
                label: st.key + (summary ? ' (' + counts[t] + ')' : '')});
    });
    // hundreds of overlapping branches stay apart as in the gnuplot diagrams (plot_branches.cpp,
    // branchLook): full width up to a dozen branches, then thinner and translucent, unstable fainter
    var branches = {};
    chosen.forEach(function (c) { c.branch.forEach(function (b) { branches[c.index + ' ' + b] = 1; }); });
    var count = Object.keys(branches).length;
    if (count > 12) {
      var alpha = Math.min(0x50, 0x10 + Math.floor(count / 4)), width = Math.max(0.8, 2 * Math.sqrt(12 / count));
      lines.forEach(function (l) {
        l.width = width;
        l.opacity = 1 - (l.dash ? Math.min(0xA0, alpha + 0x50) : alpha) / 255;
      });
    }
    var root = chart(parent, {id: id, lines: lines, marks: marks, pick: pick, key: key, labels: labels, arrows: arrows,
                              arrowMin: JUMP_MIN_PX, summary: summary, thinPx: D.marks.thin_px,
                              mergePx: summary ? D.marks.summary_merge_px : D.marks.merge_px,
                              merge: function (parts) { return mergedLabel(parts, summary); },
                              title: spec.title, xlabel: label(spec.x), ylabel: spec.y.map(label).join(', ')});
    root.setAttribute('data-summary', summary ? 'yes' : 'no');
    root.setAttribute('data-labelled-points', labelled);
    if (summary) html('p', {'class': 'note'}, parent, 'Summary of ' + markers + ' special-point markers: labelled are the branch ' +
                      'points of the primary branch (BP k: the branch leaving it has mode k), the jumps and the first fold of ' +
                      'each branch (up to ' + D.marks.summary_extra + '); the others are small markers, counted per type in the key.');
    return root;
  }

  // ---- the page -----------------------------------------------------------------------------
  document.getElementById('title').textContent = 'buckle report: ' + D.scene;
  document.getElementById('description').textContent = D.description;
  document.getElementById('abridged').textContent = D.abridged || '';
  document.title = 'buckle: ' + D.scene;
  var s = D.summary;
  document.getElementById('status-line').textContent =
      (s.complete ? 'Complete.' : 'Not complete.') + (s.interrupted ? ' Stopped early: ' + s.interruption + '.' : '') +
      ' Computed: ' + s.computed.join('; ') + '.';

  if (D.main) branchChart(document.getElementById('diagram-box'), D.main, 'diagram');
  else html('p', {id: 'diagram'}, document.getElementById('diagram-box'), 'No branches were traced (the scene asks for no continuation).');

  // special points table
  var box = document.getElementById('special-points-box');
  var rows = [];
  D.cases.forEach(function (c) { c.specials.forEach(function (sp) { rows.push([c, sp]); }); });
  if (!rows.length) html('p', {id: 'special-points'}, box, 'No special points.');
  else {
    // a long chain's thousands of rows scroll inside their box, under a header that stays
    var table = html('table', {id: 'special-points'}, html('div', {'class': 'scroll'}, box));
    var head = html('tr', {}, html('thead', {}, table));
    // a load that is the path parameter is its column (not twice)
    var heads = ['case', 'type', 'field', 'branch', label('parameter'), label('Fx'), label('Fy'), label('Me'), 'shape', 'stability',
                 '|Δλ|' + (D.unit_suffix.parameter || ''), '‖F‖ residual', 'refined', 'jump'];
    var same = D.cases.every(function (c) { return c.parameter === D.cases[0].parameter; });
    var skip = same ? ['Fx', 'Fy', 'Me'].indexOf(D.cases[0].parameter) + 5 : -1;
    if (skip < 5) skip = -1;
    heads.forEach(function (h, k) { if (k !== skip) html('th', {}, head, h); });
    var tbody = html('tbody', {}, table);
    rows.forEach(function (r) {
      var c = r[0], sp = r[1], tr = html('tr', {'class': 'sp'}, tbody);
      [c.label || String(c.index), sp.type, sp.field, String(sp.branch), fmt(sp.parameter, 8), fmt(sp.Fx, 6), fmt(sp.Fy, 6),
       fmt(sp.Me, 6), sp.shape, sp.before + ' → ' + sp.after, fmt(sp.accuracy, 2), fmt(sp.residual, 2),
       sp.refined ? 'yes' : 'no', sp.jump || ''].forEach(function (v, k) {
        if (k !== skip) html('td', {'class': k === 13 ? 't wrap' : [0, 1, 2, 8, 9].indexOf(k) >= 0 ? 't' : ''}, tr, v);
      });
      if (sp.note) tr.title = sp.note;
      if (sp.joints) tr.addEventListener('click', function () {
        Array.prototype.forEach.call(tbody.children, function (x) { x.classList.remove('on'); });
        tr.classList.add('on');
        showSpecial(c, sp);
      });
    });
  }
  if (D.critical && D.critical.length) {
    var cb = document.getElementById('critical-box');
    html('h2', {}, cb, 'Critical loads (linear buckling of the start configuration)');
    var ct = html('table', {id: 'critical-loads'}, cb);
    var ch = html('tr', {}, ct);
    ['case', 'critical ' + label(D.critical_column || 'parameter'), 'shape', 'shortening' + D.unit_suffix.length].forEach(function (h) { html('th', {}, ch, h); });
    D.critical.forEach(function (m) {
      var tr = html('tr', {}, ct);
      [m.case_label || String(m['case']), fmt(m.load_factor, 8), m.shape, fmt(m.shortening, 5)].forEach(function (v, k) {
        html('td', {'class': k === 0 || k === 2 ? 't' : ''}, tr, v);
      });
    });
  }

  // every point the page holds, paged: a long chain's tens of thousands of rows stay one page of
  // PAGE_ROWS at a time
  var PAGE_ROWS = 50, pbox = document.getElementById('points-box'), prow = [], pcols = [];
  D.cases.forEach(function (c) {
    for (var i = 0; i < c.branch.length; ++i) prow.push([c, i]);
    Object.keys(c.columns).forEach(function (k) {
      if (pcols.indexOf(k) < 0 && !(k === 'parameter' && c.columns[c.parameter])) pcols.push(k);
    });
  });
  pcols.sort(function (a, b) { return (a !== 'parameter') - (b !== 'parameter') || (a < b ? -1 : a > b ? 1 : 0); });
  if (!prow.length) html('p', {id: 'points-table'}, pbox, 'No traced points.');
  else {
    var held = D.abridged ? ' (the page holds every k-th point of a branch, see above; branches.csv has all)' : '';
    var pager = html('div', {'class': 'pager'}, pbox), pinfo = html('span', {id: 'points-range'});
    var ptable = html('table', {id: 'points-table', 'data-rows': prow.length}, html('div', {'class': 'scroll'}, pbox));
    var phead = html('tr', {}, html('thead', {}, ptable));
    (D.cases.length > 1 ? ['case'] : []).concat(['branch', 'point', 'stability']).concat(pcols.map(label))
        .forEach(function (h) { html('th', {}, phead, h); });
    var pbody = html('tbody', {}, ptable), first = 0;
    var showRows = function (from) {
      first = Math.max(0, Math.min(from, Math.floor((prow.length - 1) / PAGE_ROWS) * PAGE_ROWS));
      while (pbody.firstChild) pbody.removeChild(pbody.firstChild);
      prow.slice(first, first + PAGE_ROWS).forEach(function (r) {
        var c = r[0], i = r[1], tr = html('tr', {'class': 'pt'}, pbody);
        (D.cases.length > 1 ? [c.label] : []).concat([String(c.branch[i]), String(c.point[i]), c.stable[i] ? 'stable' : 'unstable'])
            .concat(pcols.map(function (k) { return c.columns[k] ? fmt(c.columns[k][i], 6) : ''; }))
            .forEach(function (v, k) { html('td', {}, tr, v); });
        tr.addEventListener('click', function () { showPoint(c, i); });
      });
      pinfo.textContent = ' rows ' + (first + 1) + '–' + Math.min(prow.length, first + PAGE_ROWS) + ' of ' + prow.length + held + ' ';
    };
    [['«', function () { return 0; }], ['‹', function () { return first - PAGE_ROWS; }]].forEach(function (b) {
      html('button', {type: 'button'}, pager, b[0]).addEventListener('click', function () { showRows(b[1]()); });
    });
    pager.appendChild(pinfo);
    [['›', function () { return first + PAGE_ROWS; }], ['»', function () { return prow.length; }]].forEach(function (b) {
      html('button', {type: 'button'}, pager, b[0]).addEventListener('click', function () { showRows(b[1]()); });
    });
    showRows(0);
  }

  // the scene's views
  var views = document.getElementById('views');
  D.plots.forEach(function (p, n) {
    var panel = html('div', {'class': 'panel view', id: 'view-' + p.name}, views);
    var chosen = D.cases.filter(function (c) { return !p.cases || p.cases.indexOf(c.index) >= 0; });
    if (p.type === 'bifurcation' || p.type === 'stiffness') { branchChart(panel, p, null); return; }
    if (['shapes', 'energy_curves', 'torque_angle', 'sudden_load'].indexOf(p.type) < 0) {
      // the views the page does not draw itself (critical_curves, equilibrium_shapes, workspace,
      // input_map): gnuplot's image beside the page (p.name is letters, digits, '_' and '-')
      html('p', {'class': 'note'}, panel, (p.title || p.name) + ' (plots/' + p.name + '.png, drawn by gnuplot):');
      html('img', {src: 'plots/' + p.name + '.png', alt: 'plots/' + p.name + '.png (not drawn: see summary.json plots)',
                   style: 'max-width: 100%'}, panel);
      return;
    }
    var lines = [], marks = [], legend = [];
    if (p.type === 'shapes') {
      var frameXs = [0], frameYs = [0], shapes = [];
      chosen.forEach(function (c) {
        p.at.forEach(function (at, k) {
          var best = -1, bestD = Infinity;
          for (var i = 0; i < c.shapes.length; ++i) {
            var d = Math.abs(c.columns.parameter[i] - at);
            if (c.stable[i] && c.shapes[i] && d < bestD) { bestD = d; best = i; }
          }
          if (best < 0) return;
          var color = PALETTE[(k + c.index * p.at.length) % PALETTE.length];
          shapes.push({joints: c.shapes[best], color: color});
          legend.push({color: color, label: (chosen.length > 1 ? c.label + ' ' : '') + c.parameter + ' = ' +
                                            fmt(c.columns.parameter[best], 4)});
          for (var j = 0; j < c.shapes[best].length; j += 2) { frameXs.push(c.shapes[best][j]); frameYs.push(c.shapes[best][j + 1]); }
        });
      });
      if (!shapes.length) { html('p', {}, panel, (p.title || 'shapes') + ': no stable point was traced'); return; }
      var target = svg('svg', {viewBox: '0 0 560 400', 'class': 'shape'}, panel);
      drawShapes(target, chosen[0], shapes, {title: p.title || 'Chain shapes (stable points nearest to the levels asked for)',
                                             legend: legend}, {xs: frameXs, ys: frameYs});
      return;
    }
    var xlabel = '', ylabel = '';
    chosen.forEach(function (c) {
      var tag = chosen.length > 1 ? c.label + ' ' : '';
      if (p.type === 'energy_curves' && c.landscape) {
        ['positive', 'negative'].forEach(function (b, k) {
          var color = PALETTE[(2 * c.index + k) % PALETTE.length];
          lines.push({x: c.landscape[b].q1, y: c.landscape[b].E, color: color});
          legend.push({color: color, label: tag + 'E, q3 ' + (k ? '≤' : '≥') + ' 0'});
          if (c.landscape.torque) {
            lines.push({x: c.landscape[b].q1, y: c.landscape[b].Me, color: color, dash: '3 3'});
            legend.push({color: color, dash: '3 3', label: tag + 'Me, q3 ' + (k ? '≤' : '≥') + ' 0'});
          }
        });
        c.landscape.equilibria.forEach(function (e) {
          marks.push({x: e.q1, y: e.E, color: e.stable ? '#2ca02c' : '#d62728', title: (e.stable ? 'stable ' : 'unstable ') + e.shape});
        });
        xlabel = 'q1 (rad)'; ylabel = 'E' + D.unit_suffix.moment + (c.landscape.torque ? ', Me' + D.unit_suffix.moment : '');
      } else if (p.type === 'torque_angle' && c.torque) {
        lines.push({x: c.torque.q, y: c.torque.M, color: PALETTE[(2 * c.index) % PALETTE.length]});
        lines.push({x: c.torque.q, y: c.torque.Kq, color: PALETTE[(2 * c.index + 1) % PALETTE.length], dash: '6 4'});
        legend.push({color: PALETTE[(2 * c.index) % PALETTE.length], label: tag + 'M'});
        legend.push({color: PALETTE[(2 * c.index + 1) % PALETTE.length], dash: '6 4', label: tag + 'K_q'});
        c.torque.zeros.forEach(function (z) { marks.push({x: z.q, y: 0, color: z.stable ? '#2ca02c' : '#d62728'}); });
        xlabel = 'q (rad)'; ylabel = 'M' + D.unit_suffix.moment + ', K_q' + D.unit_suffix.rotational_stiffness;
      } else if (p.type === 'sudden_load' && c.sudden) {
        [['potential', '#1f77b4', ''], ['kinetic', '#d62728', '6 4'], ['dissipated', '#2ca02c', '3 3']].forEach(function (q) {
          lines.push({x: c.sudden.t, y: c.sudden[q[0]], color: q[1], dash: q[2]});
          legend.push({color: q[1], dash: q[2], label: tag + q[0]});
        });
        xlabel = 't (model time)'; ylabel = 'energy' + D.unit_suffix.moment;
      }
    });
    chart(panel, {lines: lines, marks: marks, legend: legend.slice(0, 8), title: p.title || p.name, xlabel: xlabel, ylabel: ylabel});
    if (p.type === 'sudden_load') {  // where the chain comes to rest, beside the quasi-static answer
      chosen.forEach(function (c) {
        if (!c.sudden || !c.sudden.rest) return;
        var shapes = [{joints: c.sudden.rest, color: '#d62728'}], legend = [{color: '#d62728', label: 'sudden: at rest'}];
        if (c.sudden['static']) {
          shapes.push({joints: c.sudden['static'], color: '#1f77b4', dash: '6 4'});
          legend.push({color: '#1f77b4', dash: '6 4', label: 'quasi-static'});
        }
        var xs = [0], ys = [0];
        shapes.forEach(function (sh) { for (var j = 0; j < sh.joints.length; j += 2) { xs.push(sh.joints[j]); ys.push(sh.joints[j + 1]); } });
        drawShapes(svg('svg', {viewBox: '0 0 560 400', 'class': 'shape'}, panel), c, shapes,
                   {title: (chosen.length > 1 ? c.label + ': ' : '') + 'shapes after the sudden load', legend: legend, text: c.sudden.message},
                   {xs: xs, ys: ys});
      });
    }
  });

  // run facts
  var rb = document.getElementById('run-box'), facts = html('table', {id: 'run-facts'}, rb);
  [['complete', String(s.complete)], ['interrupted', s.interrupted ? s.interruption : 'no'],
   ['max corrector residual', fmt(s.accuracy.max_corrector_residual, 3)],
   ['max |Δλ| of located points', fmt(s.accuracy.max_special_point_parameter_error, 3)],
   ['computation time (s)', D.time_text, 'total-time']].forEach(function (f) {
    var tr = html('tr', {}, facts);
    html('th', {}, tr, f[0]);
    html('td', f[2] ? {'class': 't', id: f[2]} : {'class': 't'}, tr, f[1]);
  });
  html('p', {'class': 'note'}, rb, 'The computation time is summary.json\'s timings_seconds.total, the time the run\'s last ' +
       'line gives as "computed in"; writing the plots and this page comes after it.');
  (s.warnings || []).slice(0, 20).forEach(function (w) { html('p', {'class': 'note warning'}, rb, 'warning: ' + w); });
  (s.problems || []).slice(0, 20).forEach(function (p) { html('p', {'class': 'note'}, rb, p); });

  // first view: the first stable point of the main diagram's first case, else the unloaded chain
  if (D.cases.length) {
    var c0 = D.cases[0];
    if (c0.shapes.length) showPoint(c0, 0);
    else drawShapes(document.getElementById('shape'), c0, [{joints: c0.unloaded, color: '#1f77b4'}], {title: 'unloaded chain'});
  }
  if (!errors.length) document.body.setAttribute('data-status', 'ok');
})();

// The drawing functions of report.html's script (report.cpp puts them between the page's data and
// the script that lays the page out): SVG charts with ticks, a key in the right margin, markers
// shaped per special-point type as the gnuplot diagrams draw them (special_marks.h), labels
// placed apart by the rules of the gnuplot diagrams' placement (plot_internal.h, placeLabels:
// rings of candidate positions around the point, the cheapest free one, a leader line when away)
// and jump arrows drawn at least a minimum length on screen.
#include "scene/report_page.h"

namespace buckle::scene {

const char* const kReportChartScript = R"PAGE(  var NS = 'http://www.w3.org/2000/svg';
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

)PAGE";

}  // namespace buckle::scene

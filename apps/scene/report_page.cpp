// The page of report.html around its data (report.cpp writes the data between the two): the
// HTML, the styles and the script that draws the diagrams, shapes and the table in the browser.
#include "scene/report_page.h"

namespace buckle::scene {

const char* const kReportHead = R"PAGE(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="generator" content="buckle run">
<title>buckle report</title>
<style>
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em auto; max-width: 1360px; padding: 0 1em; color: #222; }
h1 { font-size: 1.4em; margin: 0 0 .2em; } h2 { font-size: 1.15em; margin: 1.4em 0 .4em; }
.desc { color: #555; max-width: 70em; }
.row { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; }
.panel { border: 1px solid #ddd; border-radius: 4px; padding: .4em; background: #fff; }
svg.chart { width: 640px; max-width: 100%; height: auto; display: block; }
svg.shape { width: 560px; max-width: 100%; height: auto; display: block; }
svg text { font-size: 11px; fill: #333; } svg .title { font-size: 13px; font-weight: 600; }
svg .grid { stroke: #eee; } svg .axis { stroke: #555; fill: none; }
table { border-collapse: collapse; font-size: 13px; }
th, td { border: 1px solid #ddd; padding: 2px 6px; text-align: right; white-space: nowrap; }
th { background: #f4f4f4; text-align: center; } td.t { text-align: left; }
tr.sp { cursor: pointer; } tr.sp:hover, tr.sp.on { background: #fff4cc; }
#shape-info { min-height: 2.8em; font-size: 13px; max-width: 560px; }
#errors { color: #b00; background: #fee; padding: .5em; white-space: pre-wrap; }
.note { color: #666; font-size: 12px; }
</style>
</head>
<body data-status="loading">
<h1 id="title">buckle report</h1>
<p class="desc" id="description"></p>
<p id="status-line"></p>
<p class="desc" id="abridged"></p>
<pre id="errors" hidden></pre>
<div class="row">
  <div class="panel"><div id="diagram-box"></div>
    <p class="note">Solid: stable, dashed: unstable. Hover or click a point of a branch, or a row of the table, to see the chain there.</p></div>
  <div class="panel"><svg id="shape" class="shape" viewBox="0 0 560 400"></svg><div id="shape-info"></div></div>
</div>
<h2>Special points</h2>
<div id="special-points-box"></div>
<div id="critical-box"></div>
<h2>Views asked for by the scene</h2>
<div class="row" id="views"></div>
<h2>Run</h2>
<div id="run-box"></div>
<script type="application/json" id="buckle-data">)PAGE";

const char* const kReportTail = R"PAGE(</script>
<script>
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
  var TYPE_COLOR = {BP: '#d62728', LP: '#ff7f0e', BD: '#7f7f7f', KMIN: '#9467bd', CT: '#8c564b', RL: '#17becf'};
  function ok(v) { return typeof v === 'number' && isFinite(v); }
  function label(column) { return (D.labels && D.labels[column]) || column; }  // with the scene's unit
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

  // A chart: o.lines [{x, y, color, dash, width}], o.marks [{x, y, color, title, act}], o.pick
  // [{x, y, act}] (hover/click targets), o.legend [{color, dash, label}], o.equal (same scale on both axes).
  function chart(parent, o) {
    var W = o.width || 640, H = o.height || 400, L = 66, R = 14, T = 26, B = 44;
    var root = svg('svg', {viewBox: '0 0 ' + W + ' ' + H, 'class': o.cls || 'chart'}, parent);
    if (o.id) root.setAttribute('id', o.id);
    svg('text', {x: W / 2, y: 16, 'text-anchor': 'middle', 'class': 'title'}, root).textContent = o.title || '';
    var xs = [], ys = [];
    o.lines.forEach(function (l) {
      for (var i = 0; i < l.x.length; ++i) if (ok(l.x[i]) && ok(l.y[i])) { xs.push(l.x[i]); ys.push(l.y[i]); }
    });
    (o.marks || []).forEach(function (m) { if (ok(m.x) && ok(m.y)) { xs.push(m.x); ys.push(m.y); } });
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
    svg('text', {x: L + pw / 2, y: H - 8, 'text-anchor': 'middle'}, root).textContent = o.xlabel || '';
    svg('text', {x: 14, y: T + ph / 2, 'text-anchor': 'middle', transform: 'rotate(-90 14 ' + (T + ph / 2) + ')'}, root)
        .textContent = o.ylabel || '';
    var clip = 'clip' + Math.random().toString(36).slice(2);
    svg('rect', {x: L, y: T, width: pw, height: ph}, svg('clipPath', {id: clip}, root));
    var body = svg('g', {'clip-path': 'url(#' + clip + ')'}, root);
    o.lines.forEach(function (l) {
      var d = '', pen = false;
      for (var i = 0; i < l.x.length; ++i) {
        if (!ok(l.x[i]) || !ok(l.y[i])) { pen = false; continue; }
        d += (pen ? 'L' : 'M') + sx(l.x[i]).toFixed(1) + ' ' + sy(l.y[i]).toFixed(1);
        pen = true;
      }
      if (d) svg('path', {d: d, fill: 'none', stroke: l.color, 'stroke-width': l.width || 1.8,
                          'stroke-dasharray': l.dash || 'none', 'class': l.cls || 'line'}, body);
    });
    (o.marks || []).forEach(function (m) {
      if (!ok(m.x) || !ok(m.y)) return;
      var c = svg('circle', {cx: sx(m.x), cy: sy(m.y), r: m.r || 4.5, fill: m.color, stroke: '#000',
                             'stroke-width': 0.8, 'class': m.cls || 'mark'}, body);
      if (m.title) svg('title', {}, c).textContent = m.title;
      if (m.act) { c.style.cursor = 'pointer'; c.addEventListener('click', m.act); }
    });
    (o.legend || []).forEach(function (g, k) {
      var y = T + 12 + 15 * k;
      svg('line', {x1: L + pw - 150, x2: L + pw - 124, y1: y, y2: y, stroke: g.color, 'stroke-width': 2,
                   'stroke-dasharray': g.dash || 'none'}, root);
      svg('text', {x: L + pw - 120, y: y + 4}, root).textContent = g.label;
    });
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
  function branchChart(parent, spec, id) {
    var lines = [], marks = [], pick = [], legend = [];
    var multi = D.cases.length > 1 || spec.y.length > 1;
    D.cases.forEach(function (c) {
      if (spec.cases && spec.cases.indexOf(c.index) < 0) return;
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
        if (multi) legend.push({color: stableColor, label: (D.cases.length > 1 ? c.label + ' ' : '') + ycol});
        // a long chain's thousands of special points: smaller markers, the branches stay visible
        var radius = c.specials.length > 60 ? 2.5 : 4.5;
        c.specials.forEach(function (s) {
          if (!s.values) return;
          marks.push({x: s.values[spec.x], y: s.values[ycol], color: TYPE_COLOR[s.type] || '#000', cls: 'special', r: radius,
                      title: s.type + ' ' + s.field + ' at ' + c.parameter + ' = ' + fmt(s.parameter, 6),
                      act: s.joints ? showSpecial.bind(null, c, s) : null});
        });
      });
    });
    if (!multi) legend = [{color: '#1f77b4', label: 'stable'}, {color: '#d62728', dash: '6 4', label: 'unstable'}];
    return chart(parent, {id: id, lines: lines, marks: marks, pick: pick, legend: legend, title: spec.title,
                          xlabel: label(spec.x), ylabel: spec.y.map(label).join(', ')});
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
    var table = html('table', {id: 'special-points'}, box);
    var head = html('tr', {}, html('thead', {}, table));
    ['case', 'type', 'field', 'branch', 'parameter', 'Fx', 'Fy', 'Me', 'shape', 'stability', '|Δλ|', '‖F‖', 'refined', 'jump']
        .forEach(function (h) { html('th', {}, head, h); });
    var tbody = html('tbody', {}, table);
    rows.forEach(function (r) {
      var c = r[0], sp = r[1], tr = html('tr', {'class': 'sp'}, tbody);
      [c.label || String(c.index), sp.type, sp.field, String(sp.branch), fmt(sp.parameter, 8), fmt(sp.Fx, 6), fmt(sp.Fy, 6),
       fmt(sp.Me, 6), sp.shape, sp.before + ' → ' + sp.after, fmt(sp.accuracy, 2), fmt(sp.residual, 2),
       sp.refined ? 'yes' : 'no', sp.jump || ''].forEach(function (v, k) {
        html('td', {'class': [0, 1, 2, 8, 9, 13].indexOf(k) >= 0 ? 't' : ''}, tr, v);
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
    ['case', 'load factor', 'shape', 'shortening'].forEach(function (h) { html('th', {}, ch, h); });
    D.critical.forEach(function (m) {
      var tr = html('tr', {}, ct);
      [m.case_label || String(m['case']), fmt(m.load_factor, 8), m.shape, fmt(m.shortening, 5)].forEach(function (v, k) {
        html('td', {'class': k === 0 || k === 2 ? 't' : ''}, tr, v);
      });
    });
  }

  // the scene's views
  var views = document.getElementById('views');
  D.plots.forEach(function (p, n) {
    var panel = html('div', {'class': 'panel view', id: 'view-' + p.name}, views);
    var chosen = D.cases.filter(function (c) { return !p.cases || p.cases.indexOf(c.index) >= 0; });
    if (p.type === 'bifurcation' || p.type === 'stiffness') { branchChart(panel, p, null); return; }
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
   ['total time (s)', fmt(s.timings_seconds.total, 4)]].forEach(function (f) {
    var tr = html('tr', {}, facts);
    html('th', {}, tr, f[0]);
    html('td', {'class': 't'}, tr, f[1]);
  });
  (s.problems || []).slice(0, 20).forEach(function (p) { html('p', {'class': 'note'}, rb, p); });

  // first view: the first stable point of the main diagram's first case, else the unloaded chain
  if (D.cases.length) {
    var c0 = D.cases[0];
    if (c0.shapes.length) showPoint(c0, 0);
    else drawShapes(document.getElementById('shape'), c0, [{joints: c0.unloaded, color: '#1f77b4'}], {title: 'unloaded chain'});
  }
  if (!errors.length) document.body.setAttribute('data-status', 'ok');
})();
</script>
</body>
</html>
)PAGE";

}  // namespace buckle::scene

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
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em auto; max-width: 1560px; padding: 0 1em; color: #222; }
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
.scroll { max-height: 32em; overflow: auto; max-width: 100%; display: inline-block; border: 1px solid #ddd; }
.scroll thead th { position: sticky; top: 0; } td.wrap { white-space: normal; min-width: 18em; text-align: left; }
.pager { margin: .3em 0; } .pager button { min-width: 2.2em; }
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
<h2>Traced points</h2>
<div id="points-box"></div>
<h2>Views asked for by the scene</h2>
<div class="row" id="views"></div>
<h2>Run</h2>
<div id="run-box"></div>
<script type="application/json" id="buckle-data">)PAGE";

const char* const kReportScriptStart = R"PAGE(</script>
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

)PAGE";

const char* const kReportTail = R"PAGE(  var D = JSON.parse(document.getElementById('buckle-data').textContent);
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

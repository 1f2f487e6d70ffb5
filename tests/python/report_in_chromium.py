#!/usr/bin/env python3
"""The default scene's report.html in a real browser (headless Chromium, Debian `chromium`).

Usage: report_in_chromium.py BUCKLE SCENE ARTEFACT_DIR [SEGMENTS]

With SEGMENTS the scene's chain gets that many segments (a long chain: the report of the default
scene at 50 segments carries 2479 special points and 51 099 traced points); the checks are the
same, but for the exact shape hovered and the jump of the first fold (most of its folds have none).

Runs `BUCKLE run SCENE`, opens the report from disk with the network features of Chromium off,
and checks through the DOM that the page's script ran to its end without errors
(body[data-status=ok], the error box empty), that the diagram has stable and unstable branches
and special-point markers, and that the special-point table has one row per special point of
special_points.json; Chromium's log must hold no console message. A copy of the page with a
script appended clicks a table row and moves the mouse onto a branch point of the diagram: the
shape panel must then describe that special point / branch point. Then a screenshot
(ARTEFACT_DIR/report.png, kept with report.html beside it) must show the diagram's colours.
The page's elements are checked against the files beside it: every chart's axes name a unit; the
diagram's key has one marker entry per special-point type (with the count of special_points.json
in a summary), a jump entry when a jump succeeded; the labelled special points (all of them, or
on a summary the primary branch's branch points, the jumps and the first folds) as the page
counts them, every label drawn inside the plot area without overlapping another (boxes measured
by the browser); one jump arrow per successful jump, each at least 36 px long; the traced points
table holds the rows of branches.csv (or, on a summary page, the count the page's note gives) and
stays inside the window; the computation time reads as summary.json's timings_seconds.total.
Exit 0 pass, 1 fail, 77 chromium is not installed (ctest SKIP_RETURN_CODE).
"""
import json
import pathlib
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib
from html import unescape

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-extensions", "--hide-scrollbars"]


# Appended to a copy of the page: a click on special-point row ROW, then a mouse move onto the
# first branch-point marker of the diagram; each writes what the shape panel says.
INTERACTION = """<script>
(function () {
  function said() {
    return document.querySelector('#shape .title').textContent + ' | ' + document.getElementById('shape-info').textContent;
  }
  function note(id, text) { var d = document.createElement('div'); d.id = id; d.textContent = text; document.body.appendChild(d); }
  document.querySelectorAll('#special-points tr.sp')[ROW].click();
  note('probe-click', said());
  var mark = document.querySelector('#diagram circle.special'), box = mark.getBoundingClientRect();
  document.getElementById('diagram').dispatchEvent(new MouseEvent('mousemove', {
    clientX: box.left + box.width / 2, clientY: box.top + box.height / 2, bubbles: true}));
  note('probe-hover', said());
})();
</script>
"""


# Appended to a copy of the page: the browser's boxes of the diagram's labels, jump arrows and
# tables, written as JSON into div#probe-layout.
LAYOUT = """<script>
(function () {
  var d = document.getElementById('diagram'), area = d.querySelector('rect.axis').getBBox(), boxes = [];
  d.querySelectorAll('text.sp-label').forEach(function (t) {
    var b = t.getBBox();
    boxes.push({text: t.textContent, x0: b.x, y0: b.y, x1: b.x + b.width, y1: b.y + b.height});
  });
  var out = {area: {x0: area.x, y0: area.y, x1: area.x + area.width, y1: area.y + area.height}, labels: boxes,
             jumps: Array.prototype.map.call(d.querySelectorAll('path.jump'), function (p) { return p.getTotalLength(); }),
             window: document.documentElement.clientWidth, right: {}};
  ['special-points', 'points-table'].forEach(function (id) {
    var t = document.getElementById(id);
    if (t) out.right[id] = Math.max(t.parentNode.getBoundingClientRect().right, 0);
  });
  var div = document.createElement('div');
  div.id = 'probe-layout';
  div.textContent = JSON.stringify(out);
  document.body.appendChild(div);
})();
</script>
"""


def rank_counts(specials, summary):
    """How many special points a summary labels: every branch point of a primary branch (no
    parent), then up to 24 of the jumps and the first fold of each branch (special_marks.h)."""
    labelled = 0
    for case in summary["cases"]:
        primary = {b["id"] for b in case["branches"] if b["parent"] < 0}
        mine = [p for p in specials if p["case_label"] == case["label"]]
        folded, ranks = set(), []
        for p in mine:
            if p["type"] == "BP" and p["branch"] in primary:
                ranks.append(0)
            elif p["type"] == "JUMP" or p.get("jump_to", {}).get("success"):
                ranks.append(1)
            elif p["type"] in ("LP", "LPF") and p["branch"] not in folded:
                folded.add(p["branch"])
                ranks.append(2)
            else:
                ranks.append(3)
        labelled += ranks.count(0) + min(24, ranks.count(1) + ranks.count(2))
    return labelled


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def png_pixels(path):
    """(width, height, rows of RGB tuples) of an 8-bit RGB/RGBA PNG (what Chromium writes)."""
    data = path.read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path} is not a PNG")
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            if depth != 8 or colour not in (2, 6):
                fail(f"unexpected PNG format (depth {depth}, colour type {colour})")
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw, stride, rows, previous = zlib.decompress(idat), width * channels, [], bytearray(width * channels)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, row = line[0], bytearray(line[1:])
        for i in range(stride):  # PNG filters (RFC 2083, 6.3)
            a = row[i - channels] if i >= channels else 0
            b = previous[i]
            c = previous[i - channels] if i >= channels else 0
            if kind == 1:
                row[i] = (row[i] + a) & 255
            elif kind == 2:
                row[i] = (row[i] + b) & 255
            elif kind == 3:
                row[i] = (row[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[i] = (row[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(row[x * channels:x * channels + 3]) for x in range(width)])
        previous = row
    return width, height, rows


def attribute(element, name):
    found = re.search(name + r'="([^"]*)"', element)
    return found.group(1) if found else None


def check_page(html, out, specials, browser, flags, tmp, report):
    """The key, labels, jump arrows, tables, units and time of the page against the files."""
    summary = json.loads((out / "summary.json").read_text())
    svg_open = re.search(r'<svg[^>]*id="diagram"[^>]*>', html).group(0)
    diagram = re.search(r'<svg[^>]*id="diagram".*?</svg>', html, re.S).group(0)
    # axes with units: every chart's axis labels end with a unit in parentheses
    for chart in re.findall(r'<svg[^>]*class="(?:chart|shape)"[^>]*>.*?</svg>', html, re.S):
        for axis in ("xlabel", "ylabel"):
            text = re.search(r'<text[^>]*class="' + axis + r'"[^>]*>([^<]*)</text>', chart)
            if text and text.group(1) and not re.search(r"\(.+\)$", text.group(1)):
                fail(f"the axis label {text.group(1)!r} has no unit")
    xlabel = re.search(r'class="xlabel"[^>]*>([^<]*)<', diagram)
    if not xlabel:
        fail("the diagram has no x axis label (text.xlabel)")
    xlabel = xlabel.group(1)
    unit = summary["units"]["force"]
    if unit not in xlabel:
        fail(f"the diagram's x label {xlabel!r} does not give the force unit {unit!r}")
    # the key: one marker entry per type drawn, a jump entry when a jump succeeded
    types = {}
    for p in specials:
        types[p["type"]] = types.get(p["type"], 0) + 1
    entries = re.findall(r'<g class="key-entry" data-kind="mark" data-type="([^"]*)">.*?<text[^>]*>([^<]*)</text>', diagram)
    if {t for t, _ in entries} != set(types):
        fail(f"the key's marker entries {[t for t, _ in entries]} are not the types {sorted(types)}")
    is_summary = attribute(svg_open, "data-summary") == "yes"
    if is_summary != (len(specials) > 60):
        fail(f"data-summary {is_summary} for {len(specials)} special points (the summary starts above 60)")
    if is_summary:
        for t, text in entries:
            if not text.endswith(f"({types[t]})"):
                fail(f"the key entry {text!r} does not count the {types[t]} {t} points of special_points.json")
    jumps = sum(1 for p in specials if p.get("jump_to", {}).get("success"))
    if ('data-kind="arrow"' in diagram) != (jumps > 0):
        fail(f"the key's jump entry does not match the {jumps} successful jumps")
    # labelled special points: all of them, or the summary's choice
    expected = rank_counts(specials, summary) if is_summary else len(specials)
    if attribute(svg_open, "data-labelled-points") is None:
        fail("the diagram does not say how many special points it labels (data-labelled-points)")
    labelled = int(attribute(svg_open, "data-labelled-points"))
    if labelled != expected:
        fail(f"{labelled} special points labelled, expected {expected}")
    shown, left_out = int(attribute(svg_open, "data-labels")), int(attribute(svg_open, "data-labels-left-out"))
    texts = re.findall(r'<text class="sp-label"[^>]*>([^<]*)</text>', diagram)
    if len(texts) != shown or shown == 0:
        fail(f"{len(texts)} label texts on the diagram, the page says {shown}")
    if not is_summary:
        if left_out:
            fail(f"{left_out} labels found no place on a diagram of {len(specials)} special points")
        parts = {part for t in texts for part in t.split(", ")}
        for p in specials:
            name = p["type"] + (" " + p["shape"] if p["type"] == "BP" and p["shape"] not in ("", "other") else "")
            if name not in parts:
                fail(f"no label {name!r} on the diagram (labels: {sorted(parts)})")
    # jump arrows: one per successful jump, and the table's time and rows
    arrows = diagram.count('class="jump"')
    if arrows != jumps:
        fail(f"{arrows} jump arrows on the diagram, {jumps} successful jumps in special_points.json")
    time = re.search(r'<td class="t" id="total-time">([^<]*)</td>', html)
    if not time or time.group(1) != "%.3g" % summary["timings_seconds"]["total"]:
        fail(f"the page's computation time {time and time.group(1)!r} is not summary.json's "
             f"{summary['timings_seconds']['total']}")
    # the run's warnings (summary.json), each in the run box
    shown_warnings = [unescape(w) for w in re.findall(r'<p class="note warning">warning: ([^<]*)</p>', html)]
    if shown_warnings != summary.get("warnings", [])[:20]:
        fail(f"the page's warnings {shown_warnings} are not summary.json's {summary.get('warnings', [])[:20]}")
    rows = re.search(r'<table id="points-table" data-rows="([0-9]+)"', html)
    if not rows:
        fail("no traced points table (table#points-table)")
    rows = int(rows.group(1))
    with open(out / "branches.csv") as f:
        csv_rows = sum(1 for _ in f) - 1
    abridged = re.search(r"it draws ([0-9]+) of the ([0-9]+) traced points", html)
    if abridged:
        if rows != int(abridged.group(1)) or int(abridged.group(2)) != csv_rows:
            fail(f"the points table has {rows} rows; the note says {abridged.group(0)!r}, branches.csv {csv_rows}")
    elif rows != csv_rows:
        fail(f"the points table has {rows} rows, branches.csv {csv_rows}")
    if f"of {rows}" not in re.search(r'<span id="points-range">([^<]*)</span>', html).group(1):
        fail("the points table's pager does not give the row count")
    # the browser's boxes: labels apart and inside the plot area, arrows long enough, tables inside the window
    probe = tmp / "layout.html"
    probe.write_text(report.read_text().replace("</body>", LAYOUT + "</body>"))
    dom = subprocess.run([browser, *flags, "--window-size=1300,1500", "--dump-dom", probe.as_uri()],
                         capture_output=True, text=True, timeout=180)
    found = re.search(r'<div id="probe-layout">(.*?)</div>', dom.stdout, re.S)
    if not found:
        fail("the layout probe did not run: " + dom.stderr[-2000:])
    layout = json.loads(found.group(1).replace("&quot;", '"').replace("&amp;", "&"))
    area, boxes = layout["area"], layout["labels"]
    for i, a in enumerate(boxes):
        if a["x0"] < area["x0"] - 0.5 or a["x1"] > area["x1"] + 0.5 or a["y0"] < area["y0"] - 0.5 or a["y1"] > area["y1"] + 0.5:
            fail(f"the label {a['text']!r} leaves the plot area: {a} outside {area}")
        for b in boxes[i + 1:]:
            if a["x0"] < b["x1"] - 0.5 and b["x0"] < a["x1"] - 0.5 and a["y0"] < b["y1"] - 0.5 and b["y0"] < a["y1"] - 0.5:
                fail(f"the labels {a['text']!r} and {b['text']!r} overlap: {a} {b}")
    if any(length < 35.5 for length in layout["jumps"]):
        fail(f"a jump arrow is shorter than 36 px: {layout['jumps']}")
    for table, right in layout["right"].items():
        if right > layout["window"] + 1:
            fail(f"table #{table} runs off the window's right edge ({right} > {layout['window']} px)")
    print(f"page: {len(entries)} marker types in the key, {labelled} special points labelled ({shown} labels, "
          f"{left_out} left out), {arrows} jump arrows {[round(j) for j in layout['jumps']]}, {rows} table rows, "
          f"time {time.group(1)} s")


def main():
    if len(sys.argv) not in (4, 5):
        fail(__doc__)
    buckle, scene, artefacts = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    segments = int(sys.argv[4]) if len(sys.argv) == 5 else None
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        print("SKIP: chromium is not installed (Debian package chromium)")
        return 77
    with tempfile.TemporaryDirectory(prefix="buckle-report-") as tmp:
        tmp = pathlib.Path(tmp)
        out = tmp / "out"
        if segments is not None:
            doc = json.loads(scene.read_text())
            doc["chain"]["segments"] = segments
            scene = tmp / "scene.json"
            scene.write_text(json.dumps(doc))
        run = subprocess.run([buckle, "run", str(scene), "--out", str(out), "--quiet"], capture_output=True,
                             text=True, timeout=300)
        if run.returncode != 0:
            fail(f"buckle run exited {run.returncode}: {run.stderr}")
        report = out / "report.html"
        specials = json.loads((out / "special_points.json").read_text())["special_points"]
        flags = FLAGS + [f"--user-data-dir={tmp / 'profile'}"]
        dom = subprocess.run([browser, *flags, "--enable-logging=stderr", "--v=0", "--dump-dom", report.as_uri()],
                             capture_output=True, text=True, timeout=180)
        if dom.returncode != 0:
            fail(f"chromium --dump-dom exited {dom.returncode}: {dom.stderr[-2000:]}")
        html, log = dom.stdout, dom.stderr
        console = [line for line in log.splitlines() if "CONSOLE" in line or "Uncaught" in line]
        if console:
            fail("console messages while rendering:\n" + "\n".join(console))
        if not re.search(r'<body[^>]*data-status="ok"', html):
            errors = re.search(r'<pre id="errors"[^>]*>(.*?)</pre>', html, re.S)
            fail("the page's script did not finish: " + (errors.group(1) if errors else html[:500]))
        if not re.search(r'<pre id="errors" hidden=""></pre>', html):
            fail("the error box is not empty")
        diagram = re.search(r'<svg[^>]*id="diagram".*?</svg>', html, re.S)
        if not diagram:
            fail("no diagram (svg#diagram) in the page")
        for cls in ("branch stable", "branch unstable"):
            if f'class="{cls}"' not in diagram.group(0):
                fail(f"the diagram has no {cls} branch")
        marks = diagram.group(0).count('class="special"')
        table = re.search(r'<table id="special-points">.*?</table>', html, re.S)
        if not table:
            fail("no special-point table (table#special-points)")
        rows = table.group(0).count('<tr class="sp"')
        if rows != len(specials) or rows == 0:
            fail(f"the table has {rows} rows, special_points.json {len(specials)} special points")
        if marks == 0:
            fail("no special point is marked on the diagram")
        check_page(html, out, specials, browser, flags, tmp, report)

        # interaction: click the first fold's row, then hover the diagram at the first branch point
        folds = [i for i, p in enumerate(specials) if p["type"] == "LP"]
        if not folds:
            fail("the default scene should have a fold")
        probe = tmp / "probe.html"
        probe.write_text(report.read_text().replace("</body>", INTERACTION.replace("ROW", str(folds[0])) + "</body>"))
        dom = subprocess.run([browser, *flags, "--enable-logging=stderr", "--v=0", "--dump-dom", probe.as_uri()],
                             capture_output=True, text=True, timeout=180)
        clicked = re.search(r'<div id="probe-click">(.*?)</div>', dom.stdout, re.S)
        hovered = re.search(r'<div id="probe-hover">(.*?)</div>', dom.stdout, re.S)
        if not clicked or not hovered:
            fail("the interaction probe did not run: " + dom.stderr[-2000:])
        if "LP" not in clicked.group(1) or (segments is None and "jump" not in clicked.group(1)):
            fail("clicking the fold's row did not show its shape and jump: " + clicked.group(1))
        # the nearest traced point: on the straight branch or the first point of the U branch
        if not hovered.group(1).startswith("branch ") or (segments is None and "Fx = -0.70" not in hovered.group(1)):
            fail("hovering the first branch point did not show the chain there: " + hovered.group(1))
        print(f"interaction: click -> {clicked.group(1)!r}; hover -> {hovered.group(1)!r}")

        artefacts.mkdir(parents=True, exist_ok=True)
        shutil.copy(report, artefacts / "report.html")
        png = artefacts / "report.png"
        png.unlink(missing_ok=True)
        shot = subprocess.run([browser, *flags, "--window-size=1400,1900", f"--screenshot={png}", report.as_uri()],
                              capture_output=True, text=True, timeout=180)
        if shot.returncode != 0 or not png.is_file():
            fail(f"chromium --screenshot exited {shot.returncode}: {shot.stderr[-2000:]}")
    width, height, pixels = png_pixels(png)

    def near(p, rgb):
        return all(abs(p[i] - rgb[i]) <= 40 for i in range(3))

    # the diagram is drawn in the page's stable blue (#1f77b4) and unstable red (#d62728)
    blue = sum(near(p, (0x1f, 0x77, 0xb4)) for row in pixels for p in row)
    red = sum(near(p, (0xd6, 0x27, 0x28)) for row in pixels for p in row)
    if blue < 200 or red < 200:
        fail(f"the screenshot shows too little of the diagram ({blue} blue, {red} red pixels of {width}×{height})")
    print(f"PASS: {rows} special points in the table, {marks} on the diagram; screenshot {png} "
          f"({width}×{height}, {blue} stable-blue and {red} unstable-red pixels)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

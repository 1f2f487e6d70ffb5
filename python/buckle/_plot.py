# The matplotlib figures of RunResult.plot*: bifurcation / force-deflection / stiffness diagrams
# and chain shapes, drawn from the result's arrays with the axis labels the compiled module gives
# (the column dictionary of the plots, in the scene's units). matplotlib is imported on first use.
import math
import re

import numpy as np

# Marker and colour per special-point type (docs/outputs.md lists the types)
MARKERS = {"BP": "o", "LP": "s", "LPF": "D", "BD": "^", "KMIN": "v", "JUMP": "*", "CT": "P", "RL": "X",
           "WC": "P", "WR": "X", "BC": "h", "SC": "p", "LS": "<", "IB": ">"}
COLOURS = {"BP": "tab:red", "LP": "tab:green", "LPF": "tab:olive", "BD": "black", "KMIN": "tab:purple",
           "JUMP": "tab:orange", "CT": "tab:brown", "RL": "tab:pink", "WC": "darkgreen", "WR": "navy",
           "BC": "tab:gray", "SC": "tab:cyan"}
# Above this many special points "auto" labels only the primary branch's branch points (as the
# command line's summary plots, docs/scenes.md `labels`)
AUTO_LABEL_LIMIT = 60


def pyplot():
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("buckle's plots need matplotlib (Debian: apt-get install python3-matplotlib; or pip "
                          "install matplotlib); without it the same data are in the result as NumPy arrays and "
                          "run_scene(..., out=DIR) draws the scene's plots into DIR/plots") from e
    return plt


def _on_branch(result, c, column, k):
    """Special point k of case c in `column` where it carries no value of its own (a stiffness away from
    a KMIN): interpolated along the segment between consecutive traced points of its branch nearest to
    it in (path parameter, q) — the parameter scaled by its range, so that the straight branch
    (q = 0) and a fold (the parameter at an extremum) are both located."""
    sp = result["cases"][c]["special_points"]
    branches = result["cases"][c]["branches"]
    on = np.flatnonzero(branches["branch"] == sp["branch"][k])
    if len(on) < 2:
        return np.nan
    span = np.ptp(branches["parameter"]) or 1.0
    z = np.column_stack([branches["parameter"][on] / span, branches["q"][on]])
    zs = np.concatenate([[sp["parameter"][k] / span], sp["q"][k]])
    v = result.column(column, c)[on]
    d = z[1:] - z[:-1]
    length2 = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("ij,ij->i", zs - z[:-1], d) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    distance = np.linalg.norm(z[:-1] + t[:, None] * d - zs, axis=1)
    i = int(np.argmin(distance))
    a, b = v[i], v[i + 1]
    if not np.isfinite(a) or not np.isfinite(b):  # one end without a value (a rigid direction)
        return b if np.isfinite(b) else a
    return a + t[i] * (b - a)


def special_values(result, c, column):
    """The case's special points in `column`: their own values, else interpolated on their branch."""
    sp = result["cases"][c]["special_points"]
    try:
        values = np.array(result.column(column, c, "special_points"), dtype=float)
    except KeyError:  # a column of the traced points only (min_eig)
        values = np.full(len(sp["type"]), np.nan)
    for k in np.flatnonzero(np.isnan(values)):
        values[k] = _on_branch(result, c, column, k)
    return values


def _landing(result, c, column, k):
    """Where the jump from special point k of case c lands, in `column` (None: not known there)."""
    sp = result["cases"][c]["special_points"]
    point = result["special_points"][int(sp["index"][k])]
    j = point.get("jump_to") or {}
    if not j.get("success") or not j.get("q"):
        return None
    if column == "parameter":
        return point["parameter"]
    if column in ("Fx", "Fy", "Me"):
        return j["loads"][column]
    if column in ("x", "y", "phi"):
        return j["position"][column]
    if column == "dx":  # x0 − x, x0 = dx + x at the fold
        return sp["dx"][k] + sp["x"][k] - j["position"]["x"]
    if column == "dy":  # y − y0, y0 = y − dy at the fold
        return j["position"]["y"] - (sp["y"][k] - sp["dy"][k])
    if column[:1] == "q" and column[1:].isdigit() and 1 <= int(column[1:]) <= len(j["q"]):
        return j["q"][int(column[1:]) - 1]
    return None


# The branches traced from equilibria the tree does not reach (equilibria "branches"), as the
# gnuplot diagrams draw them (plot_branches.cpp)
DISCONNECTED_COLOUR = "#c51b7d"


def _branch_collections(ax, xs, ys, branch, stable, stable_colour, unstable_colour, gid, disconnected=()):
    from matplotlib.collections import LineCollection

    ids = list(dict.fromkeys(branch.tolist()))  # branches in the order traced
    many = len(ids) > 12  # hundreds of overlapping branches stay apart thinner and translucent
    for b in ids:
        on_colour, off_colour = (DISCONNECTED_COLOUR, DISCONNECTED_COLOUR) if b in disconnected else (
            stable_colour, unstable_colour)
        on = np.flatnonzero(branch == b)
        pts = np.column_stack([xs[on], ys[on]])
        if len(on) == 1:
            pts = np.vstack([pts, pts])
        segments = np.stack([pts[:-1], pts[1:]], axis=1)
        st = stable[on]
        seg_stable = st[:-1] & st[1:] if len(on) > 1 else st[:1]
        ax.add_collection(LineCollection(
            segments, colors=[on_colour if s else off_colour for s in seg_stable],
            linestyles=["solid" if s else (0, (4, 3)) for s in seg_stable], linewidths=0.7 if many else 1.4,
            alpha=0.55 if many else 1.0, gid=f"{gid} branch {b}" + (" disconnected" if b in disconnected else "")))


def _place_labels(ax, points, texts):
    """Labels beside their points (display coordinates), each at the free one of eight offsets that
    overlaps the labels placed before and the markers least; returns the annotations."""
    fig = ax.figure
    scale = fig.dpi / 72.0
    size = 8
    offsets = [(5, 4), (5, -11), (-5, 4), (-5, -11), (8, -3), (-8, -3), (0, 9), (0, -16)]
    boxes = [(x - 4 * scale, y - 4 * scale, x + 4 * scale, y + 4 * scale) for x, y in points]
    placed = []
    for (x, y), text in zip(points, texts):
        w, h = 0.62 * size * len(text) * scale, 1.2 * size * scale
        best, best_overlap = None, math.inf
        for dx, dy in offsets:
            left = x + dx * scale - (w if dx < 0 else w / 2 if dx == 0 else 0)
            bottom = y + dy * scale
            box = (left, bottom, left + w, bottom + h)
            overlap = sum(max(0.0, min(box[2], o[2]) - max(box[0], o[0])) * max(0.0, min(box[3], o[3]) - max(box[1], o[1]))
                          for o in boxes)
            if overlap < best_overlap:
                best, best_overlap = (dx, dy, box), overlap
        dx, dy, box = best
        boxes.append(box)
        ha = "right" if dx < 0 else "center" if dx == 0 else "left"
        placed.append(ax.annotate(text, ax.transData.inverted().transform((x, y)), xytext=(dx, dy),
                                  textcoords="offset points", ha=ha, va="bottom", fontsize=size,
                                  gid="label " + text))
    return placed


def _merged_labels(ax, marks):
    """Display positions and texts of the labels of `marks` (case, x, y, text, mode): one case's points at
    one place share a label ("LP, JUMP"); a summary's branch points (text None, mode their mode
    number or None) within 40 pixels of the first of a run share one, as a range of modes ("BP 24-27")."""
    merged = {}
    runs = []  # summary branch points: [case, [display points], [modes]]
    for c, px, py, text, mode in sorted(marks, key=lambda m: (m[0], m[1])):
        if not (np.isfinite(px) and np.isfinite(py)):
            continue
        d = ax.transData.transform((px, py))
        if text is None:
            run = runs[-1] if runs else None
            if run and run[0] == c and abs(d[0] - run[1][0][0]) < 40 and abs(d[1] - run[1][0][1]) < 12:
                run[1].append(d)
                run[2].append(mode)
            else:
                runs.append([c, [d], [mode]])
            continue
        key = (c, round(d[0] / 3), round(d[1] / 3))
        if key in merged:
            if text not in merged[key][1]:
                merged[key][1].append(text)
        else:
            merged[key] = (d, [text])
    points = [v[0] for v in merged.values()]
    texts = [", ".join(v[1]) for v in merged.values()]
    for _, ds, modes in runs:
        known = sorted(m for m in modes if m is not None)
        span = "" if not known else f" {known[0]}" if known[0] == known[-1] else f" {known[0]}-{known[-1]}"
        points.append(ds[len(ds) // 2])
        texts.append("BP" + span)
    return points, texts


def _scale(ax, values):
    """Logarithmic axis for positive values, symmetric-logarithmic across sign changes."""
    finite = values[np.isfinite(values)]
    if len(finite) and (finite > 0).all():
        ax.set_yscale("log")
    elif len(finite):
        nonzero = np.abs(finite[finite != 0])
        linthresh = max(nonzero.min(), 1e-9 * nonzero.max()) if len(nonzero) else 1.0
        ax.set_yscale("symlog", linthresh=linthresh)


def diagram(result, x, ys, case, ax, labels, title, log):
    """The figure of plot_bifurcation / plot_force_deflection / plot_stiffness (their docstrings)."""
    plt = pyplot()
    from matplotlib.lines import Line2D

    ys = [ys] if isinstance(ys, str) else list(ys)
    if labels not in ("auto", "all", "none"):
        raise ValueError(f"labels must be 'auto', 'all' or 'none', got {labels!r}")
    cases = result._cases(case)
    for c in cases:  # a KeyError naming the columns there are, before anything is drawn
        for column in [x] + ys:
            result.column(column, c)
    if ax is None:
        fig, ax = plt.subplots(figsize=(7.5, 5.2), layout="constrained")
    fig = ax.figure
    series = [(c, y) for c in cases for y in ys]
    single = len(series) == 1
    handles = []
    all_y = []
    marks = []  # (case, type, x, y, text) of every special point drawn
    specials_drawn = {}
    any_disconnected = False
    for k, (c, y) in enumerate(series):
        colour = f"C{k % 10}"
        stable_colour, unstable_colour = ("tab:blue", "tab:red") if single else (colour, colour)
        b = result["cases"][c]["branches"]
        xs, yv = result.column(x, c), result.column(y, c)
        all_y.append(yv)
        gid = f"case {c}" + ("" if len(ys) == 1 else f" {y}")
        equilibria = result["cases"][c].get("equilibria") or {}
        disconnected = {d["id"] for d in equilibria.get("disconnected_branches", [])}
        any_disconnected = any_disconnected or bool(disconnected & set(b["branch"].tolist()))
        _branch_collections(ax, xs, yv, b["branch"], b["stable"], stable_colour, unstable_colour, gid, disconnected)
        if not single:
            name = result["cases"][c]["label"] or f"case {c}"
            handles.append(Line2D([], [], color=colour, label=name + ("" if len(ys) == 1 else f": {y}")))
        sp = result["cases"][c]["special_points"]
        if len(sp["type"]) == 0:
            continue
        sx, sy = special_values(result, c, x), special_values(result, c, y)
        types = np.array(sp["type"])
        primary = b["branch"][0] if len(b["branch"]) else None
        # a summary for large trees: small markers, labels only on the primary branch's branch points
        summary = labels == "auto" and len(types) > AUTO_LABEL_LIMIT
        for t in dict.fromkeys(sp["type"]):
            on = np.flatnonzero(types == t)
            specials_drawn[(t, k)] = ax.plot(sx[on], sy[on], ls="none", marker=MARKERS.get(t, "d"),
                                             ms=3.5 if summary else 6, color=COLOURS.get(t, "tab:olive"),
                                             mec="black", mew=0 if summary else 0.6, zorder=3,
                                             gid=f"special {t}" + ("" if single else f" {gid}"))[0]
        for i in range(len(types)):
            if labels == "all" or (labels == "auto" and not summary):
                text = types[i] + (f" {sp['shape'][i]}" if types[i] == "BP" and sp["shape"][i] else "")
                marks.append((c, sx[i], sy[i], text, None))
            elif summary and types[i] == "BP" and sp["branch"][i] == primary:
                mode = re.fullmatch(r"mode (\d+)", sp["shape"][i])
                marks.append((c, sx[i], sy[i], None, int(mode[1]) if mode else None))
                ax.plot([sx[i]], [sy[i]], ls="none", marker=MARKERS["BP"], ms=6, color=COLOURS["BP"], mec="black",
                        mew=0.6, zorder=4, gid="labelled BP")
            target = (_landing(result, c, x, i), _landing(result, c, y, i))
            if None not in target and np.isfinite(sx[i]) and np.isfinite(sy[i]):
                ax.annotate("", xy=target, xytext=(sx[i], sy[i]), gid="jump",
                            arrowprops=dict(arrowstyle="-|>", color="tab:orange", lw=1.3, shrinkA=3, shrinkB=3))
                all_y.append(np.array([target[1]]))
    ax.autoscale_view()
    if log:
        _scale(ax, np.concatenate(all_y) if all_y else np.array([]))
    ax.set_xlabel(result.label(x))
    ax.set_ylabel(", ".join(result.label(y) for y in ys))
    if title:
        ax.set_title(title)
    points, texts = _merged_labels(ax, marks)
    _place_labels(ax, points, texts)
    legend = [Line2D([], [], color="tab:blue" if single else "0.3", label="stable"),
              Line2D([], [], color="tab:red" if single else "0.3", ls=(0, (4, 3)), label="unstable")]
    if any_disconnected:
        legend.append(Line2D([], [], color=DISCONNECTED_COLOUR, label="disconnected branch"))
    counts = {}  # per type over the cases (each case's points once, however many y columns)
    for (t, k), line in specials_drawn.items():
        if series[k][1] == ys[0]:
            counts[t] = counts.get(t, 0) + len(line.get_xdata())
    legend += [Line2D([], [], ls="none", marker=MARKERS.get(t, "d"), color=COLOURS.get(t, "tab:olive"), mec="black",
                      label=f"{t} ({n})") for t, n in counts.items()]
    # "best" weighs every drawn point: for large trees a fixed corner
    many = sum(len(result["cases"][c]["branches"]["branch"]) for c in cases) > 5000
    ax.legend(handles=handles + legend, fontsize=8, loc="upper left" if many else "best")
    ax.grid(True, alpha=0.3)
    return fig


def _nearest_stable(result, c, value):
    """Index of the stable traced point of case c whose path parameter is nearest `value`, and whether
    it is near enough to stand for it: within the largest parameter step between consecutive points
    of a branch (else `value` is outside the traced stable range or in a gap of it)."""
    b = result["cases"][c]["branches"]
    stable = np.flatnonzero(b["stable"])
    if len(stable) == 0:
        return None, False
    i = stable[np.argmin(np.abs(b["parameter"][stable] - value))]
    same = b["branch"][1:] == b["branch"][:-1]
    steps = np.abs(np.diff(b["parameter"]))[same]
    return i, abs(b["parameter"][i] - value) <= (steps.max() if len(steps) else 0.0)


def shapes(result, at, case, title):
    """The figure of plot_shapes (its docstring)."""
    plt = pyplot()
    cases = result._cases(case)
    columns = min(len(at), 5)
    rows_per_case = math.ceil(len(at) / columns)
    fig, axes = plt.subplots(rows_per_case * len(cases), columns, figsize=(3.0 * columns, 2.8 * rows_per_case * len(cases)),
                             squeeze=False, layout="constrained")
    drawn = []
    for r, c in enumerate(cases):
        chain = result["cases"][c]["chain"]
        b = result["cases"][c]["branches"]
        for j, value in enumerate(at):
            ax = axes[r * rows_per_case + j // columns][j % columns]
            i, near = _nearest_stable(result, c, value)
            name = result.label("parameter").split(" (")[0]
            case_name = (result["cases"][c]["label"] or f"case {c}") + ": " if len(cases) > 1 else ""
            if not near:
                why = "no stable point traced" if i is None else \
                    f"no stable point traced near it\n(nearest {name} = {b['parameter'][i]:.4g})"
                ax.set_title(f"{case_name}{name} = {value:g}:\n{why}", fontsize=8)
                ax.set_xticks([])
                ax.set_yticks([])
                continue
            p = chain.joint_positions(b["q"][i])
            n = len(p) - 2
            ax.plot(p[:, 0], p[:, 1], "-", color="tab:blue", lw=1.6, marker="o" if n <= 30 else None, ms=3, gid="chain")
            ax.plot(p[:1, 0], p[:1, 1], "ks", ms=6, gid="base")
            drawn.append(p)
            got = b["parameter"][i]
            asked = "" if math.isclose(got, value, rel_tol=1e-9, abs_tol=1e-12) else f" (asked {value:g})"
            ax.set_title(f"{case_name}{name} = {got:.4g}{asked}", fontsize=9)
            ax.set_xlabel(result.label("x"))
            ax.set_ylabel(result.label("y"))
            ax.grid(True, alpha=0.3)
    # one scale for every panel, each chain to its true aspect ratio; the figure's height follows the
    # chains' extent so that they fill their panels
    if drawn:
        everything = np.vstack(drawn)
        lo, hi = everything.min(axis=0), everything.max(axis=0)
        pad = 0.06 * max(hi - lo) if max(hi - lo) > 0 else 1.0
        ratio = (hi[1] - lo[1] + 2 * pad) / (hi[0] - lo[0] + 2 * pad)
        fig.set_size_inches(3.0 * columns, len(axes) * (min(4.0, max(0.8, 2.4 * ratio)) + 1.0))
        for row in axes:
            for ax in row:
                if ax.lines:
                    ax.set_xlim(lo[0] - pad, hi[0] + pad)
                    ax.set_ylim(lo[1] - pad, hi[1] + pad)
                    ax.set_aspect("equal", adjustable="box")
    for j in range(len(at), rows_per_case * columns):  # the grid's unused panels
        for r in range(len(cases)):
            axes[r * rows_per_case + j // columns][j % columns].axis("off")
    if title:
        fig.suptitle(title)
    return fig

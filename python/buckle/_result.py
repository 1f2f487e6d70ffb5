# RunResult: what buckle.run_scene returns. It is the dict the compiled module builds (its keys:
# help(buckle.run_scene), docs/python.md) with methods on top: columns by name, pandas DataFrames
# and matplotlib plots. pandas and matplotlib are imported by the methods that need them, so the
# package imports without them.
import re

import numpy as np

from . import _plot


def _pandas(method):
    try:
        import pandas
    except ImportError as e:
        raise ImportError(
            f"RunResult.{method} needs pandas (Debian: apt-get install python3-pandas; or pip install pandas). "
            "The same data are in the result as NumPy arrays: result['cases'][k]['branches'], "
            "['special_points'], ['equilibria'].") from e
    return pandas


def _expand_q(table, data, width):
    """data[...] gets table's columns in order, q as q1 … q<width> (NaN beyond the case's n)."""
    for key, values in table.items():
        if key == "q":
            q = np.asarray(values)
            for i in range(width):
                data[f"q{i + 1}"] = q[:, i] if i < q.shape[1] else np.full(q.shape[0], np.nan)
        elif key != "disconnected_branches" and not np.isscalar(values):
            data[key] = values
    return data


class RunResult(dict):
    """The result of buckle.run_scene: a dict (keys in help(buckle.run_scene) and docs/python.md) whose
    tables are NumPy arrays, with methods on top:

    - column(name, case=0, table="branches"): one column as an array ("q2" is the second joint angle);
    - label(name): the axis label of a column in the scene's units ("Fx (N)"), as the plots write it;
    - units: the scene's unit system (summary.json `units`);
    - branches_frame(), special_points_frame(), equilibria_frame(): pandas DataFrames (pandas needed);
    - plot(what), plot_bifurcation(), plot_force_deflection(), plot_stiffness(), plot_shapes():
      matplotlib figures (matplotlib needed).
    """

    __slots__ = ()

    def __repr__(self):
        cases = self.get("cases", [])
        points = sum(len(c["branches"]["parameter"]) for c in cases)
        state = "complete" if self.get("complete") else "interrupted" if self.get("interrupted") else "incomplete"
        return (f"<RunResult {self['summary'].get('scene', '?')!r}: {len(cases)} case(s), {points} point(s), "
                f"{len(self.get('special_points', []))} special point(s), {state}>")

    @property
    def units(self):
        """The scene's units as summary.json writes them: `system` and, per dimension, the unit."""
        return self["summary"].get("units")

    @property
    def case_count(self):
        return len(self["cases"])

    def label(self, name):
        """Axis label of a column with the scene's unit ("Fx (N)", "q2 (rad)"); "parameter" gives the path
        parameter's label."""
        labels = self["labels"]
        if name not in labels:
            raise KeyError(f"no column {name!r}; the columns are {', '.join(labels)}")
        return labels[name]

    def column(self, name, case=0, table="branches"):
        """Column `name` of case `case`'s table ("branches", "special_points" or "equilibria") as a NumPy
        array; "q<i>" is the i-th joint angle (1-based, as in branches.csv)."""
        c = self._case(case)
        if table not in c:
            raise KeyError(f"case {case} has no {table!r} table (it has {', '.join(k for k in c if isinstance(c[k], dict))})")
        t = c[table]
        if name in t and name != "q":
            return np.asarray(t[name])
        m = re.fullmatch(r"q([1-9][0-9]*)", name)
        if m and int(m[1]) <= t["q"].shape[1]:
            return np.asarray(t["q"])[:, int(m[1]) - 1]
        columns = [k for k in t if k != "q"] + [f"q1 … q{t['q'].shape[1]}"]
        raise KeyError(f"no column {name!r} in case {case}'s {table}; the columns are {', '.join(columns)}")

    def _case(self, case):
        if not 0 <= case < len(self["cases"]):
            raise IndexError(f"case {case}: the run has {len(self['cases'])} case(s), 0 … {len(self['cases']) - 1}")
        return self["cases"][case]

    def _cases(self, case):
        """The case indices `case` names: None all, an int one, a list those."""
        if case is None:
            return list(range(len(self["cases"])))
        chosen = [int(c) for c in np.atleast_1d(case)]
        for c in chosen:
            self._case(c)
        return chosen

    def _frame(self, method, table, case, extra):
        pd = _pandas(method)
        cases = [c for c in self._cases(case) if table in self["cases"][c]]
        width = max([self["cases"][c]["segments"] for c in cases], default=0)
        frames = []
        for c in cases:
            t = self["cases"][c][table]
            rows = np.asarray(t["q"]).shape[0]
            data = {"case": np.full(rows, c, dtype=int)}
            frames.append(pd.DataFrame(extra(c, t, _expand_q(t, data, width))))
        frame = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
        frame.attrs["labels"] = dict(self["labels"])
        frame.attrs["units"] = self.units
        return frame

    def branches_frame(self, case=None):
        """branches.csv as a pandas DataFrame: one row per traced point, columns case, branch, point,
        parameter, Fx, Fy, Me, x, y, phi, dx, dy, min_eig (+ stiffness, frequency, input columns), q1 … qn,
        stable, negative. case: one case (0-based) or None for all. `frame.attrs["labels"]` holds the
        axis labels in the scene's units."""
        return self._frame("branches_frame", "branches", case, lambda c, t, data: data)

    def special_points_frame(self, case=None):
        """The special points as a pandas DataFrame, one row each in the order of special_points.json:
        case, index (into result['special_points']), type, field, branch, the branch columns at the point,
        q1 … qn, shape, stability_before, stability_after, note."""
        def extra(c, t, data):
            points = [self["special_points"][i] for i in np.asarray(t["index"])]
            for key in ("stability_before", "stability_after", "note"):
                data[key] = [p.get(key, "") for p in points]
            return data
        return self._frame("special_points_frame", "special_points", case, extra)

    def equilibria_frame(self, case=None):
        """equilibria.csv as a pandas DataFrame (the equilibria analysis): case, rank (1-based, ascending
        potential within its set), at (the set's path-parameter value), potential, index, stable, shape,
        branch, q1 … qn."""
        def extra(c, t, data):
            data["at"] = np.asarray(t["at"])
            data["rank"] = np.asarray(t["rank"])
            return data
        return self._frame("equilibria_frame", "equilibria", case, extra)

    def plot_spec(self, what):
        """The plot named `what` among the scene's plots, else the first of that type among them, else
        the default plot of that type (dict: type, name, title, x, y, at, cases)."""
        for spec in self["plots"]:
            if spec["name"] == what:
                return spec
        for spec in list(self["plots"]) + list(self["default_plots"]):
            if spec["type"] == what:
                return spec
        names = sorted({s["name"] for s in self["plots"]} | {s["type"] for s in self["default_plots"]})
        raise KeyError(f"no plot {what!r} in this run: the scene's plots and default plots are {', '.join(names)}")

    def plot(self, what="bifurcation", **options):
        """A matplotlib Figure of one plot: `what` is the name of one of the scene's plots
        ("force_deflection") or a type ("bifurcation", "stiffness", "shapes"), with the scene's x, y and
        at unless given in options (see plot_bifurcation, plot_stiffness, plot_shapes)."""
        if what == "force_deflection" and not any(s["name"] == what for s in self["plots"]):
            return self.plot_force_deflection(**options)
        spec = self.plot_spec(what)
        kinds = {"bifurcation": self.plot_bifurcation, "stiffness": self.plot_stiffness, "shapes": self.plot_shapes}
        if spec["type"] not in kinds:
            raise ValueError(f"RunResult.plot draws bifurcation, stiffness and shapes plots; a {spec['type']} plot is "
                             f"drawn by run_scene(..., out=DIR) as DIR/plots/{spec['name']}.png")
        if spec["type"] == "shapes":
            options.setdefault("at", spec["at"])
        else:
            options.setdefault("x", spec["x"])
            options.setdefault("y", spec["y"])
        options.setdefault("title", spec["title"] or None)
        if spec["cases"] and len(spec["cases"]) < len(self["cases"]):
            options.setdefault("case", spec["cases"])
        return kinds[spec["type"]](**options)

    def plot_bifurcation(self, x=None, y=None, case=None, ax=None, labels="auto", title=None):
        """Bifurcation diagram: column(s) y against column x (defaults: the scene's first bifurcation plot,
        else parameter and q1). Each branch is one LineCollection (gid "case C branch B"), solid where
        stable and dashed where unstable (blue / red with one case; one colour per case otherwise);
        special points marked per type (one Line2D each, gid "special TYPE") and labelled (labels: "auto"
        labels all up to 60 points, beyond that only the primary branch's branch points, as ranges of
        mode numbers, "BP 24-27"; "all"; "none"); jumps as arrows. Axis labels in the scene's units.
        Returns the Figure."""
        spec = self.plot_spec("bifurcation") if x is None or y is None else None
        return _plot.diagram(self, x if x is not None else spec["x"], y if y is not None else spec["y"], case, ax,
                             labels, title, log=False)

    def plot_force_deflection(self, case=None, ax=None, labels="auto", title=None):
        """The axial force Fx against the end shortening dx = x0 − x (plot_bifurcation(x="dx", y="Fx"))."""
        return _plot.diagram(self, "dx", "Fx", case, ax, labels, title, log=False)

    def plot_stiffness(self, x=None, y=None, case=None, ax=None, labels="auto", title=None):
        """Stiffness against x (defaults: the scene's stiffness plot, else its default), as plot_bifurcation,
        on a logarithmic axis (symmetric-log when the values change sign); the special points at the
        stiffness interpolated along their branch, a KMIN at its own located value."""
        spec = self.plot_spec("stiffness") if x is None or y is None else None
        return _plot.diagram(self, x if x is not None else spec["x"], y if y is not None else spec["y"], case, ax,
                             labels, title, log=True)

    def plot_shapes(self, at=None, case=None, title=None):
        """The chain at the stable traced point nearest to each path-parameter value in `at` (default: the
        scene's shapes plot), one panel per value and case in a grid, to the true aspect ratio, axes in
        the scene's length unit. Returns the Figure."""
        if at is None:
            shapes = [s for s in self["plots"] if s["type"] == "shapes"]
            if not shapes:
                raise ValueError("plot_shapes needs `at`, the path-parameter values to draw the chain at: the scene "
                                 "has no shapes plot to take them from")
            at = shapes[0]["at"]
        return _plot.shapes(self, np.atleast_1d(np.asarray(at, dtype=float)), case, title)

#!/usr/bin/env python3
"""Plot every CSV series of a phlex run as PNG files next to them.

Usage:
    python3 tools/plot_series.py <output_dir> [--dpi N]

Every *.csv in <output_dir> gets a PNG of the same name (energy.csv also power_balance.png). Panels are
against time t [s] unless noted; vectors are in the frame the CSV states (body, joint or inertial).

    energy.csv         -> energy.png         the energy components kinetic T, strain U and gravity potential V with
                                             the total H dashed on top (a component equal to H stays visible);
                                             the change of the total H - H0 with the supplied work W (lossless and
                                             unloaded: H - H0 is the energy error, at solver tolerance)
                       -> power_balance.png  input power P; per-step residual |H(n+1) - H(n) - dt P| (log scale);
                                             cumulative balance error H - H0 - W (the sum of the residuals, which
                                             the rounding of H in the CSV does not blur)
    modes.csv          -> modes.png          natural frequency vs mode number per body (rigid-body modes hollow),
                                             relative residual of each eigenpair (log scale); eigenvalue_rad2_s2
                                             = (2 pi f)^2 is not drawn again
    <body>_ports.csv   -> <body>_ports.png   per port: wrench input (force, moment), output (velocity, angular
                                             velocity), inertial position of the port point
    <body>_rigid.csv   -> <body>_rigid.png   a moving frame: centre of mass c (and frame origin r_P where it
                                             differs), velocity v_P and angular velocity w (body frame), quaternion,
                                             body axes e1 e2 e3 (the columns of R, inertial), changes of the linear
                                             and angular momenta P - P(0), L - L(0) (their initial values in the
                                             titles: a free body's are conserved), orthogonality |R^T R - I| (log
                                             scale); a point mass: position, velocity, force on it, P - P(0), L - L(0)
    <joint>_joint.csv  -> <joint>_joint.png  joint force and moment (joint frame e1 e2 e3), relative rotations
                                             [rad, deg on the right] and translations [m], |gap| of each constrained
                                             direction (log scale), power through the joint
    any other *.csv    -> <name>.png         every numeric column against the first column

Scales: the x, y, z components of a vector share one axes unless one that varies would fill less than a tenth
of its height; then each component gets an axes of its own, stacked in the vector's panel. A quantity that is constant (to 1e-6 of its size) is drawn
flat, not magnified down to its rounding noise; quantities that should stay at zero (residuals, gaps,
orthogonality) are drawn as absolute values on log scales. A column of a known file that this script does not
know gets an extra panel of its own (and a note on stdout), so no series is skipped silently.

Needs only numpy and matplotlib (Debian: python3-numpy python3-matplotlib, which 'make deps' installs).
Renders with the Agg backend, so no display is needed. Exit status: 0 when every plot was written,
1 when a CSV could not be read or plotted, 2 on a usage error (no directory, no CSV in it, no numpy or
matplotlib).
"""

import argparse
import csv
import math
import os
import sys
from typing import Callable, NamedTuple, Optional, Sequence, Tuple

_SYSTEM_PYTHON = "/usr/bin/python3"
_REEXEC_GUARD = "PHLEX_PLOT_SERIES_REEXEC"

CONSTANT_RTOL = 1e-6  # a series whose variation is below this fraction of its size counts as constant
SPLIT_FRACTION = 0.1  # a varying component filling less of a shared panel's height gets a panel of its own
XYZ = ("x", "y", "z")
XYZ_COLORS = ("tab:blue", "tab:orange", "tab:green")


def _import_numpy_matplotlib():
    """numpy and matplotlib (Agg); re-runs under the system python3 when the current interpreter
    (e.g. a pyenv shim first on PATH) lacks them but Debian's python3 has them."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np

        return np, plt
    except ImportError as err:
        missing = err.name or str(err)
        here = os.path.realpath(sys.executable or "")
        if (
            not os.environ.get(_REEXEC_GUARD)
            and os.path.exists(_SYSTEM_PYTHON)
            and os.path.realpath(_SYSTEM_PYTHON) != here
        ):
            os.environ[_REEXEC_GUARD] = "1"
            os.execv(_SYSTEM_PYTHON, [_SYSTEM_PYTHON] + sys.argv)
        print(
            f"plot_series: error: Python module '{missing}' is not available to {sys.executable}; "
            "install numpy and matplotlib (Debian: apt-get install python3-numpy python3-matplotlib, "
            "or 'make deps')",
            file=sys.stderr,
        )
        sys.exit(2)


class SeriesError(Exception):
    """A CSV that exists but cannot be plotted."""


class Table:
    """A CSV file: numeric columns as float arrays, the others as lists of strings.
    The plotters take columns through num(); leftover() lists the numeric ones nobody took."""

    def __init__(self, path, np):
        self.path = path
        self.name = os.path.basename(path)
        with open(path, newline="") as fp:
            rows = [row for row in csv.reader(fp) if any(cell.strip() for cell in row)]
        if not rows:
            raise SeriesError(f"{path}: empty file (no header line)")
        self.header = [name.strip() for name in rows[0]]
        body = rows[1:]
        if not body:
            raise SeriesError(f"{path}: no data rows after the header")
        for i, row in enumerate(body):
            if len(row) != len(self.header):
                raise SeriesError(f"{path}: data row {i + 1} has {len(row)} fields, the header has {len(self.header)}")
        self.numeric, self.text = {}, {}
        for j, name in enumerate(self.header):
            cells = [row[j].strip() for row in body]
            try:
                self.numeric[name] = np.array([float(c) for c in cells])
            except ValueError:
                self.text[name] = cells
        self.used = set()

    def has(self, name):
        return name in self.numeric

    def num(self, name):
        """A numeric column, marked as drawn."""
        if name not in self.header:
            raise SeriesError(f"{self.path}: no column '{name}'; header is: {','.join(self.header)}")
        if name not in self.numeric:
            bad = next(c for c in self.text[name] if not _is_number(c))
            raise SeriesError(f"{self.path}: column '{name}' is not numeric (e.g. {bad!r})")
        self.used.add(name)
        return self.numeric[name]

    def leftover(self):
        return [name for name in self.header if name in self.numeric and name not in self.used]


def _is_number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


class Line(NamedTuple):
    label: str
    y: object
    style: dict = {}


class Panel(NamedTuple):
    """One cell of a figure's grid: a title over one or more stacked axes, each (ylabel, lines) against
    the figure's x; or custom(ax) drawing anything else in a single axes."""

    title: str
    axes: Sequence[Tuple[str, Sequence[Line]]] = ()
    log: bool = False  # absolute values on a log scale (zeros left out)
    flat: bool = True  # keep a constant quantity flat instead of magnifying its rounding noise
    degrees: bool = False  # a secondary axis in degrees (the lines are angles in rad)
    custom: Optional[Callable] = None
    scale: float = 0.0  # the size against which a variation counts as rounding noise (0: the lines' own size)


def panel(title, ylabel, lines, **kw):
    """A panel of one axes."""
    return Panel(title, [(ylabel, lines)], **kw)


def _span(np, y):
    y = y[np.isfinite(y)]
    return float(y.max() - y.min()) if y.size else 0.0


def _size(np, ys):
    finite = [np.abs(y[np.isfinite(y)]) for y in ys]
    return max((float(f.max()) for f in finite if f.size), default=0.0)


def vector_panel(np, title, symbol, unit, lines, relative=False, scale=0.0):
    """The components of one vector (Lines labelled by their symbol, e.g. 'F_x') in one axes, or stacked
    one per axes when a varying one would fill less than SPLIT_FRACTION of a shared axes' height.
    relative: draw the change from the initial value, which the title gives. scale: see Panel."""
    if relative:
        initial = ", ".join(f"{line.y[0]:.6g}" for line in lines)
        title = f"{title}: Δ{symbol} = {symbol} − {symbol}(0), {symbol}(0) = ({initial})"
        lines = [line._replace(label=f"Δ{line.label}", y=line.y - line.y[0]) for line in lines]
        symbol = f"Δ{symbol}"
    ys = [line.y for line in lines]
    size = max(_size(np, ys), scale)
    height = max(float(np.nanmax(y)) for y in ys) - min(float(np.nanmin(y)) for y in ys)
    squeezed = [CONSTANT_RTOL * size < _span(np, y) < SPLIT_FRACTION * height for y in ys]
    if len(lines) > 1 and any(squeezed):
        axes = [(f"{line.label} [{unit}]", [line]) for line in lines]
    else:
        axes = [(f"{symbol} [{unit}]", lines)]
    return Panel(title, axes, flat=not relative, scale=scale)


def xyz_lines(tbl, columns, symbol):
    """Lines of the x, y, z columns that exist, labelled symbol_x .., coloured x blue, y orange, z green."""
    sep = "," if "_" in symbol else "_"
    return [Line(f"{symbol}{sep}{c}", tbl.num(col), {"color": color})
            for col, c, color in zip(columns, XYZ, XYZ_COLORS) if tbl.has(col)]


def vector(np, tbl, title, symbol, unit, columns, relative=False):
    """[the panel of a vector's columns] (empty when the file has none of them)."""
    lines = xyz_lines(tbl, columns, symbol)
    return [vector_panel(np, title, symbol, unit, lines, relative)] if lines else []


def extra_panels(tbl, style=None):
    """Panels of the numeric columns no plotter drew (lines, or as style says), with a note on stdout."""
    left = tbl.leftover()
    if left:
        print(f"plot_series: note: {tbl.path}: columns not known to plot_series.py, drawn as extra panels: "
              f"{', '.join(left)}")
    return [panel(f"column '{name}'", name, [Line(name, tbl.num(name), style or {})]) for name in left]


def _pad(panels, ncols=2):
    """Pad a group of panels to whole rows, so the next group starts on a new row."""
    return list(panels) + [None] * (-len(panels) % ncols)


def _draw_lines(np, ax, x, lines, pnl):
    drawn = 0
    for line in lines:
        y = np.asarray(line.y, dtype=float)
        if pnl.log:
            y = np.abs(y)
            keep = np.isfinite(y) & (y > 0)
            if keep.any():
                ax.semilogy(x[keep], y[keep], ".", ms=2.5, label=line.label, **line.style)
                drawn += 1
        else:
            ax.plot(x, y, label=line.label, **{"lw": 1.3, **line.style})
            drawn += 1
    if pnl.log and not drawn:
        ax.text(0.5, 0.5, "identically zero", transform=ax.transAxes, ha="center", va="center")
    if pnl.flat and not pnl.log:
        lo = min(float(np.nanmin(line.y)) for line in lines)
        hi = max(float(np.nanmax(line.y)) for line in lines)
        size = max(abs(lo), abs(hi), pnl.scale)
        if 0 < size and hi - lo <= CONSTANT_RTOL * size:
            mid, half = 0.5 * (lo + hi), 0.05 * size
            ax.set_ylim(mid - half, mid + half)
    if pnl.degrees:
        ax.secondary_yaxis("right", functions=(np.degrees, np.radians)).set_ylabel("[deg]")
    if len(lines) > 1 and ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=7.5, ncol=3 if len(lines) > 4 else 1)


def draw_figure(np, plt, x, xlabel, panels, title, path, dpi, ncols=2):
    """Lay the panels out (None: an empty cell) on a grid sharing the x axis and write the PNG.
    A row of panels has as many grid rows as its panel with the most stacked axes; a panel with fewer
    axes spreads them over those rows."""
    panels = list(panels)
    while panels and panels[-1] is None:
        panels.pop()
    ncols = min(ncols, len(panels))
    nrows = math.ceil(len(panels) / ncols)
    stacks = [max(len(p.axes) if p and not p.custom else 1 for p in panels[r * ncols:(r + 1) * ncols])
              for r in range(nrows)]
    heights = [(2.4 + 1.1 * (n - 1) + (0.6 if ncols == 1 else 0)) / n for n in stacks for _ in range(n)]
    fig = plt.figure(figsize=(6.8 * ncols if ncols > 1 else 9, sum(heights) + 0.6), dpi=dpi, layout="constrained")
    grid = fig.add_gridspec(len(heights), ncols, height_ratios=heights)
    first = [sum(stacks[:r]) for r in range(nrows)]
    x = np.asarray(x, dtype=float)
    shared = None
    for i, pnl in enumerate(panels):
        if pnl is None:
            continue
        row, col, n = first[i // ncols], i % ncols, stacks[i // ncols]
        below = i + ncols
        bottom = below >= len(panels) or panels[below] is None
        if pnl.custom:
            ax = fig.add_subplot(grid[row:row + n, col], sharex=shared)
            pnl.custom(ax)
            axes = [ax]
        else:
            k = len(pnl.axes)
            edges = [row + round(j * n / k) for j in range(k + 1)]
            axes = []
            for j, (ylabel, lines) in enumerate(pnl.axes):
                ax = fig.add_subplot(grid[edges[j]:edges[j + 1], col], sharex=shared)
                _draw_lines(np, ax, x, lines, pnl)
                ax.set_ylabel(ylabel, fontsize=9)
                axes.append(ax)
        shared = shared or axes[0]
        axes[0].set_title(pnl.title, fontsize=9.5, pad=10)
        for j, ax in enumerate(axes):
            ax.grid(True, which="both", alpha=0.3)
            last = j == len(axes) - 1
            ax.tick_params(labelbottom=last and bottom)
            if last and bottom:
                ax.set_xlabel(xlabel)
    fig.suptitle(title)
    fig.align_ylabels()
    fig.savefig(path)
    plt.close(fig)
    print(f"plot_series: wrote {path}")


def _run(dirpath):
    return os.path.basename(os.path.normpath(os.path.abspath(dirpath)))


def _png(tbl, name=None):
    return os.path.join(os.path.dirname(tbl.path), name or tbl.name[:-4] + ".png")


T_LABEL = "time t [s]"


def plot_energy(np, plt, tbl, dpi):
    t = tbl.num("time")
    tbl.num("step")  # the step index: time is the x axis
    lines = []
    for col, label, color in (("kinetic", "kinetic T", "tab:blue"), ("strain", "strain U", "tab:orange"),
                              ("potential", "gravity potential V", "tab:green")):
        if col in tbl.header:
            y = tbl.num(col)
            lines.append(Line(label + (" (identically 0)" if not np.any(y) else ""), y, {"color": color, "lw": 1.8}))
    total, work = tbl.num("total"), tbl.num("supplied_work")
    power, residual = tbl.num("input_power"), tbl.num("balance_residual")
    # the dampers' share (files of earlier versions have no such columns: nothing dissipated)
    dpower = tbl.num("dissipated_power") if tbl.has("dissipated_power") else np.zeros(t.shape)
    dwork = tbl.num("dissipated_work") if tbl.has("dissipated_work") else np.zeros(t.shape)
    lines.append(Line("total H", total, {"color": "k", "ls": "--", "lw": 1.1, "zorder": 3}))
    change = total - total[0]
    drift = np.nancumsum(residual)  # H - H0 - W + D, free of the rounding of the total in the CSV
    scale = _size(np, [line.y for line in lines])
    error = float(np.nanmax(np.abs(drift)))
    relative = f" = {error / scale:.3g} of the largest energy" if scale > 0 else ""
    change_lines = [Line("H − H0", change, {"color": "k", "ls": "--", "zorder": 3})]
    if np.any(work):
        change_lines.insert(0, Line("supplied work W", work, {"color": "tab:red", "lw": 2.5, "alpha": 0.6}))
    if np.any(dwork):
        change_lines.insert(0, Line("W − dissipated D", work - dwork, {"color": "tab:purple", "lw": 2.5, "alpha": 0.6}))
    panels = [
        panel("energy components, total H dashed on top", "energy [J]", lines),
        panel(f"change of the total energy; max |H − H0 − W{' + D' if np.any(dwork) else ''}| = {error:.3g} J{relative}", "[J]", change_lines,
              flat=False),
    ]
    run = _run(os.path.dirname(tbl.path))
    draw_figure(np, plt, t, T_LABEL, panels + extra_panels(tbl), f"Energy ({run}, {tbl.name})", _png(tbl), dpi,
                ncols=1)
    panels = [
        panel("input power of the port and frame wrenches, body forces, drives and prescribed motions",
              "P [W]", [Line("P", power)] + ([Line("dissipated D", dpower, {"color": "tab:purple"})] if np.any(dpower) else [])),
        panel(f"per-step balance residual |H(n+1) − H(n) − Δt {'(P − D)' if np.any(dpower) else 'P'}| (log scale)", "|residual| [J]",
              [Line("|residual|", residual, {"color": "tab:red"})], log=True),
        panel(f"cumulative balance error H − H0 − W{' + D' if np.any(dwork) else ''}, summed from the residuals (the CSV rounds H to 13 digits)",
              "Σ residual [J]", [Line("Σ residual", drift)], flat=False),
    ]
    draw_figure(np, plt, t, T_LABEL, panels, f"Power balance ({run}, {tbl.name})", _png(tbl, "power_balance.png"),
                dpi, ncols=1)


def plot_modes(np, plt, tbl, dpi):
    mode, freq = tbl.num("mode"), tbl.num("frequency_hz")
    tbl.num("eigenvalue_rad2_s2")  # (2 pi f)^2: the same as the frequency
    residual = tbl.num("relative_residual")
    rigid = tbl.num("rigid") > 0.5 if "rigid" in tbl.header else np.zeros(mode.shape, bool)
    bodies = np.array(tbl.text.get("body") or [""] * len(mode))
    names = list(dict.fromkeys(bodies))
    markers = "osD^v<>p"

    def frequencies(name, color):
        def draw(ax):
            sel = bodies == name
            ax.plot(mode[sel], freq[sel], "-", color="0.75")
            ax.plot(mode[sel & ~rigid], freq[sel & ~rigid], "o", color=color, label="elastic")
            if (sel & rigid).any():
                ax.plot(mode[sel & rigid], freq[sel & rigid], "o", mfc="none", color=color,
                        label="rigid-body (≈ 0 Hz)")
                ax.legend(loc="upper left", fontsize=8)
            if sel.sum() <= 40:
                for m, f in zip(mode[sel & ~rigid], freq[sel & ~rigid]):
                    ax.annotate(f"{f:.4g}", (m, f), textcoords="offset points", xytext=(4, 5), fontsize=7)
            ax.set_ylabel("f [Hz]")
            ax.margins(y=0.15)
        return draw

    def residuals(ax):
        for k, name in enumerate(names):
            sel = bodies == name
            dodge = 0.12 * (k - (len(names) - 1) / 2)
            res = np.abs(residual[sel])
            keep = res > 0
            ax.semilogy(mode[sel][keep] + dodge, res[keep], markers[k % len(markers)], color=f"C{k}",
                        label=f"body '{name}'" if name else "residual")
        if len(names) > 1:
            ax.legend(loc="best", fontsize=8)
        ax.set_ylabel("relative residual [-]")

    panels = []
    for k, name in enumerate(names):
        sel = bodies == name
        nrigid = int((sel & rigid).sum())
        who = f"body '{name}': " if name else ""
        counts = f"{int(sel.sum()) - nrigid} elastic and {nrigid} rigid-body modes"
        panels.append(Panel(f"{who}natural frequencies, {counts}", custom=frequencies(name, f"C{k}")))
    panels.append(Panel("relative residual of each eigenpair (log scale)", custom=residuals))
    title = f"Modes ({_run(os.path.dirname(tbl.path))}, {tbl.name})"
    extra = extra_panels(tbl, {"ls": "none", "marker": "o"})  # rows of several bodies: points, not a line
    draw_figure(np, plt, mode, "mode number (per body) [-]", panels + extra, title, _png(tbl), dpi, ncols=1)


_PORT_GROUPS = (
    ("F", "force input, body frame", "F", "N"),
    ("T", "moment input, body frame", "T", "N m"),
    ("v", "velocity output, body frame", "v", "m/s"),
    ("w", "angular velocity output, body frame", "ω", "rad/s"),
    ("", "position of the port point, inertial", "x", "m"),
)


def port_names(header):
    """Port names in column order, from the columns <port>_Fx ... <port>_wz, <port>_x ..."""
    suffixes = [f"_{g}{c}" for g, _, _, _ in _PORT_GROUPS for c in XYZ]
    names = []
    for col in header:
        for suffix in suffixes:
            if col.endswith(suffix) and len(col) > len(suffix):
                name = col[: -len(suffix)]
                if name not in names:
                    names.append(name)
                break
    return names


def plot_ports(np, plt, tbl, dpi):
    t = tbl.num("time")
    names = port_names(tbl.header)
    if not names:
        raise SeriesError(f"{tbl.path}: no port columns (<port>_Fx ... <port>_wz) in header: {','.join(tbl.header)}")
    panels = []
    for name in names:  # per port: force and moment, velocity and angular velocity, position
        for g, what, symbol, unit in _PORT_GROUPS:
            panels += vector(np, tbl, f"port '{name}': {what}", symbol, unit, [f"{name}_{g}{c}" for c in XYZ])
        panels = _pad(panels)
    body = tbl.name[: -len("_ports.csv")]
    title = f"Ports of body '{body}': wrench inputs and collocated outputs ({_run(os.path.dirname(tbl.path))})"
    draw_figure(np, plt, t, T_LABEL, panels + extra_panels(tbl), title, _png(tbl), dpi)


def plot_rigid(np, plt, tbl, dpi):
    """A moving frame (cx.., R.., wx.., orthogonality) or a point mass (rx.., vx.., Fx..: the force on it)."""
    t = tbl.num("time")
    body = tbl.name[: -len("_rigid.csv")]
    run = _run(os.path.dirname(tbl.path))
    momenta = (vector(np, tbl, "linear momentum, inertial", "P", "kg m/s", ("Px", "Py", "Pz"), relative=True)
               + vector(np, tbl, "angular momentum about the inertial origin", "L", "kg m²/s", ("Lx", "Ly", "Lz"),
                        relative=True))
    if "cx" not in tbl.header:
        panels = (vector(np, tbl, "position, inertial", "r", "m", ("rx", "ry", "rz"))
                  + vector(np, tbl, "velocity, inertial", "v", "m/s", ("vx", "vy", "vz"))
                  + vector(np, tbl, "force input on its port, inertial", "F", "N", ("Fx", "Fy", "Fz"))
                  + [None] + momenta)
        draw_figure(np, plt, t, T_LABEL, panels + extra_panels(tbl), f"Point mass '{body}' ({run})", _png(tbl), dpi)
        return

    centre = xyz_lines(tbl, ("cx", "cy", "cz"), "c")
    origin = xyz_lines(tbl, ("rx", "ry", "rz"), "r_P")
    scale = _size(np, [line.y for line in centre + origin])  # a position of 1e-18 m is 0 beside one of 1 m
    position = [vector_panel(np, "centre of mass, inertial", "c", "m", centre, scale=scale)]
    if any(not np.allclose(o.y, c.y, rtol=0, atol=1e-12 * (1 + scale)) for o, c in zip(origin, centre)):
        position.append(vector_panel(np, "frame origin, inertial", "r_P", "m", origin, scale=scale))
    orthogonality = []
    if tbl.has("orthogonality"):
        orthogonality.append(panel("orthogonality of R (log scale)", "‖RᵀR − I‖ [-]",
                                   [Line("‖RᵀR − I‖", tbl.num("orthogonality"))], log=True))
    if len(position) == 1:  # the orthogonality fills the row of the centre of mass
        position, orthogonality = position + orthogonality, []
    body_axes = [(f"e{j} [-]", xyz_lines(tbl, [f"R{i}{j}" for i in (1, 2, 3)], f"e{j}")) for j in (1, 2, 3)]
    panels = (_pad(position)
              + vector(np, tbl, "velocity of the frame origin, body frame", "v_P", "m/s", ("vPx", "vPy", "vPz"))
              + vector(np, tbl, "angular velocity, body frame", "ω", "rad/s", ("wx", "wy", "wz"))
              + [panel("orientation: quaternion", "q [-]", [Line(c, tbl.num(c)) for c in ("qw", "qx", "qy", "qz")]),
                 Panel("orientation: body axes e1, e2, e3 (the columns of R), inertial", body_axes)]
              + momenta + orthogonality)
    draw_figure(np, plt, t, T_LABEL, panels + extra_panels(tbl), f"Rigid motion of body '{body}' ({run})",
                _png(tbl), dpi)


_ROTATIONS = ("angle", "rot1", "rot2", "rot3")
_TRANSLATIONS = ("slide", "slide1", "slide2")


def joint_kind(header):
    """The joint type, as far as the relative-motion and gap columns tell."""
    motion = frozenset(c for c in header if c in _ROTATIONS + _TRANSLATIONS)
    kinds = {frozenset(): "fixed or prescribed", frozenset({"angle"}): "revolute", frozenset({"slide"}): "prismatic",
             frozenset({"angle", "slide"}): "cylindrical", frozenset({"slide1", "slide2", "angle"}): "planar",
             frozenset({"rot1", "rot2", "rot3"}): "universal" if "gap_cross" in header else "spherical"}
    kind = kinds.get(motion, "unknown type")
    return kind + (", driven" if "gap_drive" in header else "")


def _gap_unit(row):
    """Translation rows t1 t2 t3 in m, rotation rows r1 r2 r3 and cross in rad, a drive in either."""
    return "m" if row.startswith("t") else "rad" if row.startswith("r") or row == "cross" else "m or rad"


def plot_joint(np, plt, tbl, dpi):
    t = tbl.num("time")
    rotations = [Line(c, tbl.num(c)) for c in _ROTATIONS if c in tbl.header]
    translations = [Line(c, tbl.num(c)) for c in _TRANSLATIONS if c in tbl.header]
    gaps = [Line(f"{c[4:]} [{_gap_unit(c[4:])}]", tbl.num(c)) for c in tbl.header if c.startswith("gap_")]
    panels = (vector(np, tbl, "force on the second port's body, joint frame (x, y, z: e1, e2, e3)", "F", "N",
                     ("Fx", "Fy", "Fz"))
              + vector(np, tbl, "moment on the second port's body, joint frame", "M", "N m", ("Mx", "My", "Mz")))
    if rotations:
        panels.append(panel("relative rotation since the drawn configuration", "rotation [rad]", rotations,
                            degrees=True))
    if translations:
        panels.append(panel("relative translation since the drawn configuration", "translation [m]", translations))
    if gaps:
        panels.append(panel("position-level violation of each constrained direction (log scale)", "|gap| [m, rad]",
                            gaps, log=True))
    panels.append(panel("power through the joint (zero to solver tolerance unless driven)", "power [W]",
                        [Line("power", tbl.num("power"))], flat=False))
    joint = tbl.name[: -len("_joint.csv")]
    title = f"Joint '{joint}' ({joint_kind(tbl.header)}; {_run(os.path.dirname(tbl.path))})"
    draw_figure(np, plt, t, T_LABEL, panels + extra_panels(tbl), title, _png(tbl), dpi)


def plot_generic(np, plt, tbl, dpi):
    first = tbl.header[0]
    if first not in tbl.numeric:
        raise SeriesError(f"{tbl.path}: the first column '{first}' is not numeric, nothing to plot against")
    x = tbl.num(first)
    if not tbl.leftover():
        raise SeriesError(f"{tbl.path}: no numeric column besides '{first}'")
    skipped = [name for name in tbl.header if name in tbl.text]
    note = f"; text columns not drawn: {', '.join(skipped)}" if skipped else ""
    panels = [panel(f"'{name}'", name, [Line(name, tbl.num(name))]) for name in tbl.leftover()]
    draw_figure(np, plt, x, first, panels, f"{tbl.name} ({_run(os.path.dirname(tbl.path))}{note})", _png(tbl), dpi)


def plotter_for(name):
    """The plotter of a CSV file name: by its fixed name or suffix, else the generic one."""
    if name == "energy.csv":
        return plot_energy
    if name == "modes.csv":
        return plot_modes
    for suffix, fn in (("_ports.csv", plot_ports), ("_rigid.csv", plot_rigid), ("_joint.csv", plot_joint)):
        if name.endswith(suffix) and len(name) > len(suffix):
            return fn
    return plot_generic


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Plot every CSV series of a phlex run (energy.csv, modes.csv, <body>_ports.csv, "
        "<body>_rigid.csv, <joint>_joint.csv, any other *.csv) as PNG files in the same directory."
    )
    parser.add_argument("output_dir", help="a phlex output directory (-output_dir)")
    parser.add_argument("--dpi", type=int, default=120, help="resolution of the PNG files (default 120)")
    args = parser.parse_args(argv)

    if not os.path.isdir(args.output_dir):
        print(f"plot_series: error: '{args.output_dir}' is not a directory", file=sys.stderr)
        return 2
    names = sorted(n for n in os.listdir(args.output_dir) if n.endswith(".csv") and not n.startswith("."))
    if not names:
        print(f"plot_series: error: no CSV file in '{args.output_dir}' (is it a phlex -output_dir?)", file=sys.stderr)
        return 2

    np, plt = _import_numpy_matplotlib()
    failed = 0
    for name in names:
        path = os.path.join(args.output_dir, name)
        try:
            plotter_for(name)(np, plt, Table(path, np), args.dpi)
        except (SeriesError, OSError, UnicodeDecodeError, csv.Error) as err:
            print(f"plot_series: error: {err}", file=sys.stderr)
            failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Plot phlex's CSV time series and mode tables as PNG files next to them.

Usage:
    python3 tools/plot_series.py <output_dir> [--dpi N]

Reads whichever of these files exist in <output_dir> and writes:
    energy.csv          -> energy.png         kinetic, strain and total energy vs time
                        -> power_balance.png  |balance_residual| = |H(n+1) - H(n) - dt P| (log scale),
                                              supplied work W and H - H0 vs time
    modes.csv           -> modes.png          natural frequency vs mode number
    <body>_ports.csv    -> <body>_ports.png   force, moment, velocity and angular velocity of every port vs time
    <body>_rigid.csv    -> <body>_rigid.png   centre of mass, angular velocity, orthogonality of R vs time (a point
                                              mass: position, velocity, the force on it)
    <joint>_joint.csv   -> <joint>_joint.png  joint force and moment, relative motion, violations (log scale),
                                              power through the joint vs time

Needs only numpy and matplotlib (Debian: python3-numpy python3-matplotlib, which 'make deps' installs).
Renders with the Agg backend, so no display is needed. Exit status: 0 when every plot was written,
1 when a CSV could not be read or plotted, 2 on a usage error (no directory, no known CSV, no numpy or
matplotlib).
"""

import argparse
import csv
import os
import sys

_SYSTEM_PYTHON = "/usr/bin/python3"
_REEXEC_GUARD = "PHLEX_PLOT_SERIES_REEXEC"


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
        sys.exit(
            f"plot_series: error: Python module '{missing}' is not available to {sys.executable}; "
            "install numpy and matplotlib (Debian: apt-get install python3-numpy python3-matplotlib, "
            "or 'make deps')"
        )


class SeriesError(Exception):
    """A CSV that exists but cannot be plotted."""


def read_csv(path, np, required=()):
    """Header names and a dict name -> float array of a comma-separated file with one header line."""
    with open(path, newline="") as fp:
        rows = [row for row in csv.reader(fp) if row and any(cell.strip() for cell in row)]
    if not rows:
        raise SeriesError(f"{path}: empty file (no header line)")
    header = [name.strip() for name in rows[0]]
    missing = [name for name in required if name not in header]
    if missing:
        raise SeriesError(f"{path}: missing column(s) {', '.join(missing)}; header is: {','.join(header)}")
    body = rows[1:]
    if not body:
        raise SeriesError(f"{path}: no data rows after the header")
    data = np.full((len(body), len(header)), np.nan)
    for i, row in enumerate(body):
        if len(row) != len(header):
            raise SeriesError(f"{path}: line {i + 2} has {len(row)} fields, the header has {len(header)}")
        for j, cell in enumerate(row):
            try:
                data[i, j] = float(cell)
            except ValueError:
                raise SeriesError(f"{path}: line {i + 2}, column '{header[j]}': not a number: {cell!r}") from None
    return header, {name: data[:, j] for j, name in enumerate(header)}


def _finish(fig, plt, path, dpi):
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    print(f"plot_series: wrote {path}")


def _label(dirpath):
    return os.path.basename(os.path.normpath(os.path.abspath(dirpath)))


def plot_energy(dirpath, np, plt, dpi):
    path = os.path.join(dirpath, "energy.csv")
    cols = ("time", "kinetic", "strain", "total", "supplied_work", "balance_residual")
    _, s = read_csv(path, np, cols)
    t = s["time"]
    name = _label(dirpath)

    fig, ax = plt.subplots(figsize=(9, 5))
    ax.plot(t, s["kinetic"], label="kinetic")
    ax.plot(t, s["strain"], label="strain")
    ax.plot(t, s["total"], "k", lw=2, label="total H")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("energy [J]")
    h0 = s["total"][0]
    drift = np.nanmax(np.abs(s["total"] - h0 - s["supplied_work"])) / abs(h0) if h0 != 0 else float("nan")
    ax.set_title(f"Energy vs time ({name})\nmax |H - H0 - W| / H0 = {drift:.3g}  (W: supplied work)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    _finish(fig, plt, os.path.join(dirpath, "energy.png"), dpi)

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    res = np.abs(s["balance_residual"])
    shown = np.isfinite(res) & (res > 0)
    if shown.any():
        ax1.semilogy(t[shown], res[shown], ".-", ms=3, color="tab:red", label="|balance residual|")
        ax1.legend(loc="best")
    else:
        ax1.text(0.5, 0.5, "balance residual is identically zero", transform=ax1.transAxes, ha="center", va="center")
    ax1.set_ylabel("|H(n+1) - H(n) - Δt P| [J]")
    ax1.set_title(f"Power balance ({name})\nper-step residual |H(n+1) - H(n) - Δt P| (log scale), P: input power")
    ax1.grid(True, which="both", alpha=0.3)
    ax2.plot(t, s["supplied_work"], lw=2, label="supplied work W")
    ax2.plot(t, s["total"] - h0, "--", label="H - H0")
    ax2.set_xlabel("time t [s]")
    ax2.set_ylabel("work / energy change [J]")
    ax2.grid(True, alpha=0.3)
    ax2.legend(loc="best")
    _finish(fig, plt, os.path.join(dirpath, "power_balance.png"), dpi)


def plot_modes(dirpath, np, plt, dpi):
    path = os.path.join(dirpath, "modes.csv")
    header, s = read_csv(path, np, ("mode", "frequency_hz"))
    mode, f = s["mode"], s["frequency_hz"]
    rigid = s["rigid"] > 0.5 if "rigid" in header else np.zeros(mode.shape, bool)

    fig, ax = plt.subplots(figsize=(9, 5))
    ax.plot(mode, f, "-", color="0.7", zorder=1)
    ax.plot(mode[~rigid], f[~rigid], "o", color="tab:blue", label="elastic", zorder=2)
    if rigid.any():
        ax.plot(mode[rigid], f[rigid], "s", color="tab:orange", label="rigid body", zorder=2)
    if len(mode) <= 30:
        for m, fr in zip(mode, f):
            ax.annotate(f"{fr:.4g}", (m, fr), textcoords="offset points", xytext=(4, 6), fontsize=8)
    ax.set_xlabel("mode number [-]")
    ax.set_ylabel("natural frequency f [Hz]")
    ax.set_title(f"Natural frequencies ({_label(dirpath)}): {len(mode)} modes")
    ax.set_xticks(mode if len(mode) <= 30 else ax.get_xticks())
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left")
    _finish(fig, plt, os.path.join(dirpath, "modes.png"), dpi)


# ports.csv: time, then for every port <name>_Fx,_Fy,_Fz,_Tx,_Ty,_Tz,_vx,_vy,_vz,_wx,_wy,_wz
_PORT_GROUPS = (
    (("Fx", "Fy", "Fz"), "force", "force F [N]"),
    (("Tx", "Ty", "Tz"), "moment", "moment T [N m]"),
    (("vx", "vy", "vz"), "velocity", "velocity v [m/s]"),
    (("wx", "wy", "wz"), "angular velocity", "angular velocity ω [rad/s]"),
)
_PORT_SUFFIXES = tuple(c for group, _, _ in _PORT_GROUPS for c in group)


def port_names(header):
    """Port names in column order, from columns <name>_<suffix>."""
    names = []
    for col in header:
        for suffix in _PORT_SUFFIXES:
            if col.endswith("_" + suffix) and len(col) > len(suffix) + 1:
                name = col[: -len(suffix) - 1]
                if name not in names:
                    names.append(name)
                break
    return names


def plot_ports(dirpath, np, plt, dpi, path):
    header, s = read_csv(path, np, ("time",))
    names = port_names(header)
    if not names:
        raise SeriesError(f"{path}: no port columns (<port>_Fx ... <port>_wz) in header: {','.join(header)}")
    t = s["time"]
    fig, axes = plt.subplots(2 * len(names), 2, figsize=(11, 5.5 * len(names)), sharex=True, squeeze=False)
    for p, name in enumerate(names):
        for g, (comps, what, ylabel) in enumerate(_PORT_GROUPS):
            ax = axes[2 * p + g // 2, g % 2]
            plotted = False
            for comp in comps:
                col = f"{name}_{comp}"
                if col in s:
                    ax.plot(t, s[col], label=comp)
                    plotted = True
            if plotted:
                ax.legend(loc="best", fontsize=8)
            else:
                ax.text(0.5, 0.5, "no columns", transform=ax.transAxes, ha="center", va="center")
            ax.set_title(f"port '{name}': {what}", fontsize=10)
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time t [s]")
    fig.suptitle(f"Port inputs (force, moment) and collocated outputs (velocity) ({os.path.basename(path)})")
    _finish(fig, plt, path[:-4] + ".png", dpi)


def plot_rigid(dirpath, np, plt, dpi, path):
    """A moving frame (cx.., wx.., orthogonality) or a point mass (rx.., vx.., Fx..: the force on it)."""
    header, s = read_csv(path, np, ("time",))
    t = s["time"]
    point = "cx" not in header
    panels = (
        (("rx", "ry", "rz") if point else ("cx", "cy", "cz"), "position [m]" if point else "centre of mass [m]"),
        (("vx", "vy", "vz") if point else ("wx", "wy", "wz"), "velocity [m/s]" if point else "angular velocity ω [rad/s] (body)"),
    )
    missing = [c for cols, _ in panels for c in cols if c not in header]
    if missing:
        raise SeriesError(f"{path}: missing column(s) {', '.join(missing)}; header is: {','.join(header)}")
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for ax, (cols, ylabel) in zip(axes, panels):
        for c in cols:
            ax.plot(t, s[c], label=c)
        ax.set_ylabel(ylabel)
    if point and all(c in header for c in ("Fx", "Fy", "Fz")):
        for c in ("Fx", "Fy", "Fz"):
            axes[2].plot(t, s[c], label=c)
        axes[2].set_ylabel("force on the point [N]")
    elif "orthogonality" in header:
        o = np.abs(s["orthogonality"])
        shown = o > 0
        if shown.any():
            axes[2].semilogy(t[shown], o[shown], ".", ms=3, label="‖RᵀR − I‖")
        axes[2].set_ylabel("orthogonality of R")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time t [s]")
    fig.suptitle(f"{'Point mass' if point else 'Rigid motion'} ({os.path.basename(path)})")
    _finish(fig, plt, path[:-4] + ".png", dpi)


def plot_joint(dirpath, np, plt, dpi, path):
    header, s = read_csv(path, np, ("time", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "power"))
    t = s["time"]
    motion = [c for c in ("angle", "slide", "slide1", "slide2", "rot1", "rot2", "rot3") if c in header]
    gaps = [c for c in header if c.startswith("gap_")]
    fig, axes = plt.subplots(5, 1, figsize=(9, 14), sharex=True)
    for c in ("Fx", "Fy", "Fz"):
        axes[0].plot(t, s[c], label=c)
    axes[0].set_ylabel("force [N] (joint frame)")
    for c in ("Mx", "My", "Mz"):
        axes[1].plot(t, s[c], label=c)
    axes[1].set_ylabel("moment [N m] (joint frame)")
    for c in motion:
        axes[2].plot(t, s[c], label=c)
    axes[2].set_ylabel("relative motion [rad, m]")
    if not motion:
        axes[2].text(0.5, 0.5, "no free motion", transform=axes[2].transAxes, ha="center", va="center")
    for c in gaps:
        g = np.abs(s[c])
        shown = g > 0
        if shown.any():
            axes[3].semilogy(t[shown], g[shown], ".", ms=3, label=c[4:])
    axes[3].set_ylabel("|violation| [m, rad]")
    axes[4].plot(t, s["power"], label="power through the joint")
    axes[4].set_ylabel("power [W]")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time t [s]")
    fig.suptitle(f"Joint ({os.path.basename(path)}): wrench on the second port by the first")
    _finish(fig, plt, path[:-4] + ".png", dpi)


def _one(fn):
    """A plotter of one fixed file name, called as the per-file ones."""
    return lambda dirpath, np, plt, dpi, path: fn(dirpath, np, plt, dpi)


# (file name or suffix, plotter): fixed names, then every file ending with the suffix
PLOTTERS = (("energy.csv", _one(plot_energy)), ("modes.csv", _one(plot_modes)), ("_ports.csv", plot_ports),
            ("_rigid.csv", plot_rigid), ("_joint.csv", plot_joint))


def files_to_plot(dirpath):
    """(path, plotter) for every known CSV in dirpath."""
    names = sorted(os.listdir(dirpath))
    found = []
    for key, fn in PLOTTERS:
        for name in names:
            if (name == key) if not key.startswith("_") else (name.endswith(key) and len(name) > len(key)):
                found.append((os.path.join(dirpath, name), fn))
    return found


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Plot phlex's energy.csv, modes.csv, <body>_ports.csv, <body>_rigid.csv and <joint>_joint.csv as PNG files in the same directory."
    )
    parser.add_argument("output_dir", help="a phlex output directory (-output_dir)")
    parser.add_argument("--dpi", type=int, default=120, help="resolution of the PNG files (default 120)")
    args = parser.parse_args(argv)

    if not os.path.isdir(args.output_dir):
        print(f"plot_series: error: '{args.output_dir}' is not a directory", file=sys.stderr)
        return 2
    found = files_to_plot(args.output_dir)
    if not found:
        known = "energy.csv, modes.csv, <body>_ports.csv, <body>_rigid.csv, <joint>_joint.csv"
        print(f"plot_series: error: no known CSV ({known}) in '{args.output_dir}'", file=sys.stderr)
        return 2

    np, plt = _import_numpy_matplotlib()
    failed = 0
    for path, plotter in found:
        try:
            plotter(args.output_dir, np, plt, args.dpi, path)
        except (SeriesError, OSError) as err:
            print(f"plot_series: error: {err}", file=sys.stderr)
            failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

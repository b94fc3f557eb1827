#!/usr/bin/env python3
"""Render the XDMF fields of a phlex run as PNG images (and animations) with ParaView, without a display.

Usage:
    pvbatch tools/render.py <output_dir> [--field NAME[:COMPONENT]] [--animate] [--out DIR] [options]
    python3 tools/render.py <output_dir> ...     (when ParaView's paraview.simple is importable: python3-paraview)

Reads every <name>.xmf in <output_dir> (with the legacy XDMF reader, which keeps the time series) and writes in
--out (default: <output_dir>):
    <body>.xmf, a transient   -> <body>_<field>.png         the step where the colour field peaks (--time)
      with --animate          -> <body>_<field>_frames/     one PNG per output step (0000.png, 0001.png, ...)
                                 <body>_<field>.gif         those frames as an animated GIF (made with Pillow)
    two or more transients    -> all_bodies_<field>.png     the bodies together (and their frames and GIF)
    <body>_modes.xmf          -> <body>_modes_<k>.png       mode k, warped by its shape; its frequency from modes.csv
    two or more placed modes  -> assembly_modes_<k>.png     a linearised assembly's mode k, all bodies where they sit,
                                                            warped alike (-analysis linearized)

Colour: --field NAME, a point or cell field of the files, vectors by their magnitude; NAME:X, :Y, :Z or
:Magnitude for a vector, NAME:XX ... :XZ for the stress (components XX YY ZZ XY YZ XZ). Default: von_mises
(the von Mises stress) when the files have it, else velocity, else displacement; mode shapes: mode_shape.
The colour range is the same for every step and body of an image series (--range MIN,MAX sets it).
Shape: a fixed body is warped by its displacement, at true scale unless the largest displacement is below 1 %
of the body's size: then magnified, by a round factor written on the image, to about 10 % (--warp-scale S sets
the factor); its undeformed edges are drawn in grey. A floating body is drawn where it is: its mesh geometry is
its inertial position, rigid motion and deformation at true scale. A mode is scaled to 10 % of the body's size.

Video: the frames become an animated GIF with Pillow (python3-pil, which python3-matplotlib brings), the one
format every browser, viewer and slide program plays; without Pillow only the frames are written.

Headless: Debian's ParaView (package python3-paraview, which brings pvbatch) renders through X even with
--force-offscreen-rendering, so without a display (no DISPLAY) the script starts a private Xvfb (package xvfb)
on a free display number for its run (rather than 'xvfb-run -a', which races when renders start together and
leaves its Xvfb behind when its clean-up fails); 'xvfb-run -a pvbatch tools/render.py ...' works too, and
ParaView builds with EGL or OSMesa need no display. A python3 without ParaView (e.g. a pyenv one) hands over to
/usr/bin/python3. Exit status: 0 when every image was written, 1 when a file could not be read or rendered, 2
on a usage error (no directory, no XDMF file in it, a field that a file lacks, no ParaView, no display and no
Xvfb).
"""

import argparse
import csv
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

_SYSTEM_PYTHON = "/usr/bin/python3"
_PYTHON_GUARD = "PHLEX_RENDER_REEXEC"
_INSTALL = "install ParaView's Python module (Debian: apt-get install python3-paraview xvfb)"

FIELDS = {"displacement": ("displacement", "m"), "velocity": ("velocity", "m/s"), "stress": ("stress", "Pa"),
          "von_mises": ("von Mises stress", "Pa"), "inertial_position": ("inertial position", "m"),
          "mode_shape": ("mode shape", "-")}
DEFAULT_FIELDS = ("von_mises", "velocity", "displacement")
COMPONENTS = {"X": 0, "Y": 1, "Z": 2, "XX": 0, "YY": 1, "ZZ": 2, "XY": 3, "YZ": 4, "XZ": 5, "MAGNITUDE": -1}
MAGNIFY_BELOW = 0.01  # auto warp: magnify when the largest displacement is below this fraction of the body's size
MAGNIFY_TO = 0.1  # ... to about this fraction (also the size of a drawn mode shape)
VIEWS = {"iso": ((1.0, 0.8, 1.4), (0, 1, 0)), "x": ((1, 0, 0), (0, 1, 0)), "y": ((0, 1, 0), (0, 0, -1)),
         "z": ((0, 0, 1), (0, 1, 0))}


class RenderError(Exception):
    """A file that cannot be read or rendered (exit status 1)."""


class UsageError(Exception):
    """A wrong command line or a missing tool (exit status 2)."""


def parse_args(argv):
    p = argparse.ArgumentParser(description="Render a phlex run's XDMF fields (<body>.xmf, <body>_modes.xmf) as PNG "
                                "images and animations with ParaView, headless (see the module docstring).")
    p.add_argument("output_dir", help="a phlex output directory (-output_dir)")
    p.add_argument("--field", help="colour by this field, NAME or NAME:COMPONENT (default: von_mises, else velocity, "
                   "else displacement; modes: mode_shape)")
    p.add_argument("--animate", action="store_true", help="transients: also one PNG per output step and a GIF")
    p.add_argument("--out", help="where the images go (default: the output directory)")
    p.add_argument("--time", default="peak", help="the step of the still image: peak (where the colour field is "
                   "largest, the default), last, or a time in s (the nearest output step)")
    p.add_argument("--range", dest="crange", metavar="MIN,MAX", help="colour range (default: over all steps)")
    p.add_argument("--warp-scale", type=float, metavar="S", help="displacement factor of fixed bodies (default: auto)")
    p.add_argument("--view", choices=sorted(VIEWS), default="iso",
                   help="look from: iso (default), or along the x, y or z axis")
    p.add_argument("--size", default="1200x800", metavar="WxH", help="image size in pixels (default 1200x800)")
    p.add_argument("--fps", type=float, default=12, help="frames per second of the GIF (default 12)")
    args = p.parse_args(argv)
    try:
        args.size = [int(v) for v in args.size.lower().split("x")]
        if len(args.size) != 2 or min(args.size) < 16:
            raise ValueError
    except ValueError:
        p.error(f"--size: expected WIDTHxHEIGHT in pixels, e.g. 1200x800, got {args.size!r}")
    if args.crange:
        try:
            limits = [float(v) for v in args.crange.split(",")]
            if len(limits) != 2 or not limits[0] < limits[1]:
                raise ValueError
        except ValueError:
            p.error(f"--range: expected MIN,MAX with MIN < MAX, got {args.crange!r}")
        args.crange = limits
    if args.time not in ("peak", "last"):
        try:
            args.time = float(args.time)
        except ValueError:
            p.error(f"--time: expected peak, last or a time in s, got {args.time!r}")
    if args.warp_scale is not None and args.warp_scale < 0:
        p.error("--warp-scale: must be >= 0")
    if args.fps <= 0:
        p.error("--fps: must be > 0")
    if args.field:
        name, _, comp = args.field.partition(":")
        if comp and comp.upper() not in COMPONENTS and not comp.isdigit():
            p.error(f"--field {args.field}: unknown component '{comp}' (X, Y, Z, Magnitude, XX YY ZZ XY YZ XZ or "
                    "an index)")
        index = COMPONENTS.get(comp.upper(), int(comp) if comp.isdigit() else -1) if comp else -1
        args.field = (name, index, comp if index >= 0 else "")
    return args


# --------------------------------------------------------------------------
# ParaView and a display
# --------------------------------------------------------------------------


def import_paraview():
    """paraview.simple; re-runs under the system python3 when this interpreter (e.g. a pyenv shim) lacks it."""
    try:
        from paraview import simple
        return simple
    except ImportError as err:
        here = os.path.realpath(sys.executable or "")
        if (not os.environ.get(_PYTHON_GUARD) and os.path.exists(_SYSTEM_PYTHON)
                and os.path.realpath(_SYSTEM_PYTHON) != here):
            os.environ[_PYTHON_GUARD] = "1"
            os.execv(_SYSTEM_PYTHON, [_SYSTEM_PYTHON] + sys.argv)
        raise UsageError(f"ParaView's Python module paraview.simple is not available to {sys.executable} ({err}): "
                         f"{_INSTALL}, then run 'pvbatch tools/render.py ...' or 'python3 tools/render.py ...'")


def start_display():
    """Rendering needs an X display unless ParaView was built for EGL or OSMesa. Without one (no DISPLAY),
    start a private Xvfb on a free display number (-displayfd: no race between renders started together) and
    return it, to be stopped at the end."""
    from paraview.modules.vtkRemotingViews import vtkPVRenderingCapabilitiesInformation as caps

    if caps.GetLocalCapabilities() & (caps.HEADLESS_RENDERING | caps.ONSCREEN_RENDERING):
        return None
    xvfb = shutil.which("Xvfb")
    if not xvfb:
        raise UsageError("this ParaView renders through X and there is no display (DISPLAY is not set): install "
                         "xvfb (Debian: apt-get install xvfb), or run under a display or 'xvfb-run -a'")
    read_fd, write_fd = os.pipe()
    log = tempfile.TemporaryFile()
    server = subprocess.Popen([xvfb, "-displayfd", str(write_fd), "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
                              pass_fds=(write_fd,), stdin=subprocess.DEVNULL, stdout=log, stderr=log)
    os.close(write_fd)
    with os.fdopen(read_fd) as fp:
        number = fp.readline().strip()  # written when the server is ready; nothing if it died
    if not number:
        server.wait()
        log.seek(0)
        message = log.read().decode(errors="replace").strip().splitlines()
        raise UsageError(f"Xvfb did not start: {message[-1] if message else 'no message'}")
    os.environ["DISPLAY"] = f":{number}"
    return server


# --------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------


def xdmf_files(dirpath):
    return sorted(n for n in os.listdir(dirpath) if n.endswith(".xmf") and not n.startswith("."))


def check_heavy_data(path):
    """The HDF5 files an XDMF file refers to must exist (ParaView would only print a warning)."""
    with open(path, errors="replace") as fp:
        text = fp.read()
    if "<Xdmf" not in text:
        raise RenderError(f"{path}: not an XDMF file")
    for h5 in sorted(set(re.findall(r">\s*([^<>:\s]+\.h5):", text))):
        if not os.path.isfile(os.path.join(os.path.dirname(path), h5)):
            raise RenderError(f"{path}: refers to {h5}, which is missing")


def mode_table(dirpath):
    """(body, mode) -> (frequency [Hz], rigid) from modes.csv, when there is one."""
    path = os.path.join(dirpath, "modes.csv")
    table = {}
    if os.path.isfile(path):
        with open(path, newline="") as fp:
            for row in csv.DictReader(fp):
                try:
                    table[(row["body"], int(row["mode"]))] = (float(row["frequency_hz"]), row["rigid"].strip() == "1")
                except (KeyError, ValueError):
                    raise RenderError(f"{path}: unexpected row {row} (want mode, frequency_hz, rigid, body)") from None
    return table


class Body:
    """One XDMF file in the pipeline: its reader, the shape drawn (warped or not) and its fields."""

    def __init__(self, pv, path):
        check_heavy_data(path)
        self.path = path
        self.name = os.path.basename(path)[: -len(".xmf")]
        self.reader = pv.XDMFReader(registrationName=self.name, FileNames=[path])
        self.reader.UpdatePipelineInformation()
        self.times = list(self.reader.TimestepValues) or [0.0]
        self.reader.UpdatePipeline(self.times[0])
        info = self.reader.GetDataInformation()
        if info.GetNumberOfPoints() == 0:
            raise RenderError(f"{path}: ParaView read no mesh from it")
        self.points = list(self.reader.PointData.keys())
        self.cells = list(self.reader.CellData.keys())
        self.modes = "mode_shape" in self.points
        self.floating = "inertial_position" in self.points
        self.shape = self.reader
        self.ghost = None

    def association(self, field):
        if field in self.points:
            return "POINTS"
        if field in self.cells:
            return "CELLS"
        raise UsageError(f"field '{field}' is not in {self.path}; its fields: {', '.join(self.points + self.cells)}")

    def array(self, field):
        return (self.shape.PointData if field in self.points else self.shape.CellData)[field]

    def range_at(self, time, field, comp):
        self.shape.UpdatePipeline(time)
        return self.array(field).GetRange(comp)

    def bounds_at(self, time):
        self.shape.UpdatePipeline(time)
        return self.shape.GetDataInformation().GetBounds()


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _unit(a):
    norm = math.sqrt(_dot(a, a))
    return [x / norm for x in a]


def union(boxes):
    """The bounding box (xmin, xmax, ymin, ymax, zmin, zmax) of boxes."""
    return [(max if i % 2 else min)(b[i] for b in boxes) for i in range(6)]


def size_of(box):
    return math.sqrt(sum((box[2 * i + 1] - box[2 * i]) ** 2 for i in range(3)))


def round_factor(x):
    """The round number (1, 2 or 5 times a power of 10) nearest below x."""
    p = 10 ** math.floor(math.log10(x))
    return max(m * p for m in (1, 2, 5) if m * p <= x)


# --------------------------------------------------------------------------
# Drawing
# --------------------------------------------------------------------------


class Scene:
    """A render view with a shared colour map, a scalar bar and two text annotations."""

    def __init__(self, pv, args):
        self.pv = pv
        self.args = args
        self.view = pv.CreateView("RenderView")
        self.view.ViewSize = args.size
        self.view.OrientationAxesVisibility = 1
        if hasattr(self.view, "UseColorPaletteForBackground"):
            self.view.UseColorPaletteForBackground = 0
        self.view.Background = [1, 1, 1]
        self.view.OrientationAxesLabelColor = [0, 0, 0]
        self.title = self.text("Upper Left Corner", self.font(15))
        self.status = self.text("Lower Left Corner", self.font(15))
        self.displays = {}

    def font(self, size):
        """A font size for 800-pixel high images, scaled to the image's height."""
        return max(9, round(size * self.args.size[1] / 800))

    def text(self, where, size):
        source = self.pv.Text(Text="")
        display = self.pv.Show(source, self.view)
        display.WindowLocation = where
        display.FontSize = size
        display.Color = [0, 0, 0]
        return source

    def show(self, body, field, comp):
        """Show a body coloured by field (its ghost, the undeformed edges, in grey when it has one)."""
        pv = self.pv
        display = pv.Show(body.shape, self.view)
        # the mesh's edges, unless the image is so small that they would blacken the body
        display.Representation = "Surface With Edges" if min(self.args.size) >= 600 else "Surface"
        display.EdgeColor = [0.25, 0.25, 0.25]
        pv.ColorBy(display, (body.association(field), field))
        lut = pv.GetColorTransferFunction(field)
        lut.AutomaticRescaleRangeMode = "Never"
        if comp >= 0:
            lut.VectorMode, lut.VectorComponent = "Component", comp
        else:
            lut.VectorMode = "Magnitude"
        bar = pv.GetScalarBar(lut, self.view)
        component = "" if comp < 0 and body.array(field).GetNumberOfComponents() == 1 else (
            " (magnitude)" if comp < 0 else f" ({body.array(field).GetComponentName(comp) or comp})")
        label, unit = FIELDS.get(field, (field, "?"))
        bar.Title = f"{label}{component} [{unit}]"
        bar.ComponentTitle = ""
        bar.TitleColor = bar.LabelColor = [0, 0, 0]
        bar.TitleFontSize, bar.LabelFontSize = self.font(15), self.font(13)
        bar.AutomaticLabelFormat = 0
        bar.LabelFormat = bar.RangeLabelFormat = "%-#.3g"
        bar.ScalarBarLength = 0.5
        display.SetScalarBarVisibility(self.view, True)
        ghost = None
        if body.ghost is not None:
            ghost = pv.Show(body.ghost, self.view)
            ghost.Representation = "Feature Edges"
            ghost.AmbientColor = ghost.DiffuseColor = [0.55, 0.55, 0.55]
            ghost.ColorArrayName = ["POINTS", ""]
        self.displays[body.name] = (display, ghost)

    def only(self, bodies):
        names = {b.name for b in bodies}
        for name, (display, ghost) in self.displays.items():
            display.Visibility = name in names
            if ghost is not None:
                ghost.Visibility = name in names

    def set_range(self, field, lo, hi):
        """Colours over [lo, hi]: from 0 for a non-negative quantity (a magnitude), symmetric about 0 with a
        diverging map for a signed one (a component)."""
        lut = self.pv.GetColorTransferFunction(field)
        if lo < 0 < hi and not self.args.crange:
            lo, hi = -max(-lo, hi), max(-lo, hi)
        elif lo >= 0 and not self.args.crange:
            lo = 0.0
        lut.ApplyPreset("Cool to Warm" if lo < 0 < hi else "Turbo", True)
        lut.RescaleTransferFunction(lo, hi if hi > lo else lo + 1e-30)

    def aim(self, box):
        """Look at box (xmin, xmax, ymin, ymax, zmin, zmax) from the chosen direction, so that its corners fill
        the image but the scalar bar's strip on the right."""
        direction, up = VIEWS[self.args.view]
        back = _unit(direction)
        upward = _unit([u - _dot(up, back) * b for u, b in zip(up, back)])
        right = [upward[1] * back[2] - upward[2] * back[1], upward[2] * back[0] - upward[0] * back[2],
                 upward[0] * back[1] - upward[1] * back[0]]
        centre = [0.5 * (box[2 * i] + box[2 * i + 1]) for i in range(3)]
        corners = [[box[2 * i + (k >> i & 1)] - centre[i] for i in range(3)] for k in range(8)]
        tan_v = math.tan(math.radians(self.view.CameraViewAngle / 2))
        tan_h = 0.8 * tan_v * self.args.size[0] / self.args.size[1]
        fit = max(max(abs(_dot(c, right)) for c in corners) / tan_h, max(abs(_dot(c, upward)) for c in corners) / tan_v)
        distance = max(_dot(c, back) for c in corners) + 1.1 * (fit or 1.0)
        self.view.CameraFocalPoint = centre
        self.view.CameraPosition = [c + distance * b for c, b in zip(centre, back)]
        self.view.CameraViewUp = upward
        self.view.CenterOfRotation = centre

    def save(self, time, path, title, status):
        self.view.ViewTime = time
        self.title.Text = title
        self.status.Text = status
        self.pv.Render(self.view)
        self.pv.SaveScreenshot(path, self.view, ImageResolution=self.args.size)


def field_of(bodies, args, default=DEFAULT_FIELDS):
    """(field, component index or -1, component name or ''): --field, or the first default field that every
    body has."""
    if args.field:
        field, comp, _ = args.field
        for body in bodies:
            body.association(field)
            n = body.array(field).GetNumberOfComponents()
            if comp >= n:
                raise UsageError(f"--field {field}:{args.field[2]}: {field} has {n} component(s) in {body.path}")
        return args.field
    for field in default:
        if all(field in body.points + body.cells for body in bodies):
            return field, -1, ""
    names = ", ".join(sorted({f for b in bodies for f in b.points + b.cells}))
    raise UsageError(f"none of {', '.join(default)} is in every file; choose with --field (fields: {names})")


def warp_fixed(pv, bodies, args):
    """Warp the fixed bodies by their displacement with one factor (auto or --warp-scale); the text to write."""
    fixed = [b for b in bodies if not b.floating and "displacement" in b.points]
    if not fixed:
        return ""
    largest = max(abs(b.range_at(t, "displacement", -1)[1]) for b in fixed for t in b.times)
    size = size_of(union([b.bounds_at(b.times[0]) for b in fixed]))
    factor = args.warp_scale
    if factor is None:
        factor = 1.0 if largest == 0 or largest >= MAGNIFY_BELOW * size else round_factor(MAGNIFY_TO * size / largest)
    for body in fixed:
        body.ghost = body.reader
        body.shape = pv.WarpByVector(Input=body.reader, Vectors=["POINTS", "displacement"], ScaleFactor=factor)
    return "displacement at true scale" if factor == 1 else f"displacement × {factor:g}"


def render_transients(pv, bodies, args, out, run):
    """The last step of each body (and of all together), with --animate every step and a GIF."""
    field, comp, comp_name = field_of(bodies, args)
    shape = warp_fixed(pv, bodies, args)
    scene = Scene(pv, args)
    for body in bodies:
        scene.show(body, field, comp)
    ranges = {(body.name, t): body.range_at(t, field, comp) for body in bodies for t in body.times}
    lo, hi = min(r[0] for r in ranges.values()), max(r[1] for r in ranges.values())
    scene.set_range(field, *(args.crange or (lo, hi)))
    tag = f"{field}_{comp_name}" if comp_name else field
    groups = [([body], body.name) for body in bodies]
    if len(bodies) > 1:
        groups.append((bodies, "all_bodies"))
    for group, name in groups:
        times = sorted({t for body in group for t in body.times})
        scene.only(group)
        scene.aim(union([body.bounds_at(t) for body in group for t in body.times]))
        title = f"run '{run}': " + ", ".join(f"body '{body.name}'" for body in group)
        notes = [shape] if shape and not all(b.floating for b in group) else []
        if any(b.floating for b in group):
            notes.append("floating: inertial position, true scale")
        note = "".join(f"; {n}" for n in notes)
        if args.time == "peak":
            def peak(t):
                return max(max(abs(v) for v in ranges[(b.name, t)]) for b in group if (b.name, t) in ranges)
            still = max(times, key=peak)
            when = f" (peak of {field}{':' + comp_name if comp_name else ''})"
        else:
            still = times[-1] if args.time == "last" else min(times, key=lambda t: abs(t - args.time))
            when = ""
        png = os.path.join(out, f"{name}_{tag}.png")
        scene.save(still, png, title, f"t = {still:.6g} s{when}{note}")
        print(f"render: wrote {png}")
        if args.animate and len(times) > 1:
            frames = os.path.join(out, f"{name}_{tag}_frames")
            os.makedirs(frames, exist_ok=True)
            paths = []
            for k, t in enumerate(times):
                paths.append(os.path.join(frames, f"{k:04d}.png"))
                scene.save(t, paths[-1], title, f"t = {t:.6g} s{note}")
            print(f"render: wrote {len(paths)} frames in {frames}/")
            write_gif(paths, os.path.join(out, f"{name}_{tag}.gif"), args.fps)


def render_modes(pv, body, args, out, run, table):
    """One image per mode, warped by the mode shape to MAGNIFY_TO of the body's size."""
    field, comp, _ = field_of([body], args, default=("mode_shape",))
    size = size_of(body.bounds_at(body.times[0]))
    warp = pv.WarpByVector(Input=body.reader, Vectors=["POINTS", "mode_shape"])
    body.ghost, body.shape = body.reader, warp
    scene = Scene(pv, args)
    scene.show(body, field, comp)
    name = body.name[: -len("_modes")] if body.name.endswith("_modes") else body.name
    for t in body.times:
        k = int(round(t))
        body.reader.UpdatePipeline(t)
        largest = body.reader.PointData["mode_shape"].GetRange(-1)[1]
        warp.ScaleFactor = MAGNIFY_TO * size / largest if largest > 0 else 0
        scene.set_range(field, *(args.crange or body.range_at(t, field, comp)))
        scene.aim(union([body.bounds_at(t), body.reader.GetDataInformation().GetBounds()]))
        freq, rigid = table.get((name, k), (None, False))
        what = f"mode {k}" + (", rigid-body" if rigid else f": {freq:.6g} Hz" if freq is not None else "")
        png = os.path.join(out, f"{body.name}_{k:02d}.png")
        scene.save(t, png, f"run '{run}': body '{name}'", f"{what}; largest displacement drawn at "
                   f"{MAGNIFY_TO:.0%} of the body's size")
        print(f"render: wrote {png}")


def assembly_frequencies(dirpath):
    """mode -> (frequency [Hz], kind) from linearized_modes.csv when it holds one configuration (else {})."""
    path = os.path.join(dirpath, "linearized_modes.csv")
    table, configs = {}, set()
    if os.path.isfile(path):
        with open(path, newline="") as fp:
            for row in csv.DictReader(fp):
                try:
                    configs.add(row["configuration"])
                    table[int(row["mode"])] = (float(row["frequency_hz"]), row["kind"])
                except (KeyError, ValueError):
                    raise RenderError(f"{path}: unexpected row {row}") from None
    return table if len(configs) == 1 else {}


def render_assembly_modes(pv, bodies, args, out, run):
    """The modes of a linearised assembly: every body placed where it sits, all warped by one factor."""
    field, comp, _ = field_of(bodies, args, default=("mode_shape",))
    size = size_of(union([b.bounds_at(b.times[0]) for b in bodies]))
    warps = []
    for body in bodies:
        warp = pv.WarpByVector(Input=body.reader, Vectors=["POINTS", "mode_shape"])
        body.ghost, body.shape = body.reader, warp
        warps.append(warp)
    scene = Scene(pv, args)
    for body in bodies:
        scene.show(body, field, comp)
    table = assembly_frequencies(args.output_dir)
    for t in sorted({t for b in bodies for t in b.times}):
        k = int(round(t))
        largest = 0.0
        for body in bodies:
            body.reader.UpdatePipeline(t)
            largest = max(largest, body.reader.PointData["mode_shape"].GetRange(-1)[1])
        for warp in warps:
            warp.ScaleFactor = MAGNIFY_TO * size / largest if largest > 0 else 0
        lo = min(b.range_at(t, field, comp)[0] for b in bodies)
        hi = max(b.range_at(t, field, comp)[1] for b in bodies)
        scene.set_range(field, *(args.crange or (lo, hi)))
        scene.aim(union([b.bounds_at(t) for b in bodies] + [b.reader.GetDataInformation().GetBounds() for b in bodies]))
        freq, kind = table.get(k, (None, ""))
        what = f"mode {k}" + (", mechanism" if kind == "mechanism" else f": {freq:.6g} Hz" if freq is not None else "")
        png = os.path.join(out, f"assembly_modes_{k:02d}.png")
        scene.save(t, png, f"run '{run}': the assembly ({', '.join(b.name[:-len('_modes')] for b in bodies)})",
                   f"{what}; largest displacement drawn at {MAGNIFY_TO:.0%} of the assembly's size")
        print(f"render: wrote {png}")


def write_gif(frames, path, fps):
    """An animated GIF of the PNG frames (at most 800 pixels wide), with Pillow."""
    try:
        from PIL import Image
    except ImportError:
        print(f"render: note: no GIF ({path}): Pillow is missing (Debian: python3-pil); the frames are written")
        return
    images = []
    for frame in frames:
        with Image.open(frame) as image:
            scale = min(1.0, 800 / image.width)
            image = image.convert("RGB").resize((round(image.width * scale), round(image.height * scale)))
            images.append(image.quantize(colors=255))
    images[0].save(path, save_all=True, append_images=images[1:], duration=round(1000 / fps), loop=0)
    print(f"render: wrote {path}")


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        return render(args)
    except UsageError as err:
        print(f"render: error: {err}", file=sys.stderr)
        return 2


def render(args):
    if not os.path.isdir(args.output_dir):
        raise UsageError(f"'{args.output_dir}' is not a directory")
    names = xdmf_files(args.output_dir)
    if not names:
        raise UsageError(f"no XDMF file (<body>.xmf) in '{args.output_dir}' (a run with -output_fields 0 or without "
                         "flexible bodies writes none)")
    out = args.out or args.output_dir
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as err:
        raise UsageError(f"cannot create --out directory '{out}': {err.strerror}") from None
    pv = import_paraview()
    server = start_display()
    try:
        return render_all(pv, args, names, out)
    finally:
        if server:
            server.terminate()
            server.wait()


def render_all(pv, args, names, out):
    """Render the XDMF files names of the output directory; the exit status."""
    run = os.path.basename(os.path.normpath(os.path.abspath(args.output_dir)))
    failed = 0
    transients, modes = [], []
    for name in names:
        try:
            body = Body(pv, os.path.join(args.output_dir, name))
        except (RenderError, OSError) as err:
            print(f"render: error: {err}", file=sys.stderr)
            failed += 1
            continue
        (modes if body.modes else transients).append(body)
    try:
        table = mode_table(args.output_dir) if modes else {}
        for body in modes:
            render_modes(pv, body, args, out, run, table)
        placed = [b for b in modes if b.floating]
        if len(placed) > 1:
            for body in placed:
                body.shape = body.reader
            render_assembly_modes(pv, [Body(pv, b.path) for b in placed], args, out, run)
        if transients:
            render_transients(pv, transients, args, out, run)
    except (RenderError, OSError) as err:
        print(f"render: error: {err}", file=sys.stderr)
        failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    status = main()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)  # not sys.exit: pvbatch crashes in its finalisation after a sys.exit once it has rendered

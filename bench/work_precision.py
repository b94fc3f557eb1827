#!/usr/bin/env python3
"""Work-precision of phlex: error against wall time, per point its DOFs, ranks and peak memory.

  transient  the tip-loaded cantilever (options/cantilever_tip_load.yaml) on one mesh, integrators x time steps; the
             error is that of the tip port's velocity (vx vy vz wx wy wz) at the end time against a run of the
             implicit midpoint rule with a step --ref-factor times smaller than the smallest, relative to its norm
  modes      the steel bar free-free and clamped at x = 0 (the cantilever), P1 and P2 on a sequence of meshes; the
             error is the largest relative error of the first 10 elastic frequencies against the finest P2 mesh (or
             --reference) with the same support
  mechanism  the paper's crank-slider (options/crankslider.yaml: rigid crank at 150 rad/s, flexible coupler on mean
             axes, slider), coupler meshes x time steps over 8 rad of crank angle; the error is the largest deviation
             of the coupler's midpoint deflection u_y/L from the converged FFRF model
             (validation/reference/crankslider_midpoint_ffrf_check.csv, tools/crankslider_midpoint.py), and the cost
             is also given per simulated second; --coupler-models full,reduced5,reduced10 adds the coupler as a
             reduced body (issue 41; the wall time includes building the reduced model, transient_s is the
             time-stepping stage of -log_view alone)

Writes bench/results/work_precision_<case>.csv and, when matplotlib is installed, .png beside them.

Dimensions beyond the discretisation (each a comma-separated list; every point is run for each value):
  --np        ranks (mpiexec -n)
  --presets   transient and mechanism: solver presets options/solver/<name>.opts (default: the scene's own)
  --eps-types modes: eigensolvers (-modes_eps_type: phlexblock, krylovschur, ...)
  --supports  modes: free (the free-free bar, 6 rigid modes) and clamped (the cantilever, frame patch "clamp")

usage: bench/work_precision.py [--cases transient,modes,mechanism] [--mesh meshes/bench/bar_h0.02.msh]
                               [--meshes meshes/bar_h0.05.msh,meshes/bench/bar_h0.02.msh,meshes/bench/bar_h0.01.msh]
                               [--coupler-cells 8,16,32] [--mechanism-dts 4e-5,2e-5,1e-5] [--np 1,2]
                               [--coupler-models full,reduced5,reduced10,reduced20,reduced40]
                               [--presets exact,iterative] [--eps-types phlexblock,krylovschur] [--supports free,clamped]
                               [--phlex bin/phlex]
"""
import argparse
import csv
import math
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "bench", "results")

# integrator: phlex options (the preset is the scene's default one)
SCHEMES = {
    "midpoint": [],
    "cn": ["-ts_type", "cn"],
    "bdf2": ["-ts_type", "bdf", "-ts_bdf_order", "2", "-ts_adapt_type", "none"],
    "alpha0.8": ["-ts_type", "alpha", "-ts_alpha_radius", "0.8"],
}


def run(cmd):
    """cmd under /usr/bin/time -v: (output, wall seconds, peak RSS GiB)"""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        p = subprocess.run(["/usr/bin/time", "-v", "-o", tf.name] + cmd, cwd=ROOT, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True)
        t = tf.read()
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout[-3000:]))
    m = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", t)
    wall = int(m.group(1) or 0) * 3600 + int(m.group(2)) * 60 + float(m.group(3))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 2**20
    return p.stdout, wall, rss


def launcher(np_):
    return ["mpiexec", "-n", str(np_)] if np_ > 1 else []


def preset_options(preset):
    """the options of a solver preset ("" or "default": the scene's own)"""
    if preset in ("", "default"):
        return []
    path = os.path.join("options", "solver", preset + ".opts")
    if not os.path.exists(os.path.join(ROOT, path)):
        sys.exit("no solver preset %s" % path)
    return ["-solver_options_file", path]


def last_row(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows[-1]


def transient(a, out):
    tend = a.tend
    dts = [float(x) for x in a.dts.split(",")]
    outdir = tempfile.mkdtemp(prefix="phlex_wp_")

    def one(scheme, dt, np_=1, preset=""):
        cmd = launcher(np_) + [a.phlex, "-options_file", "options/cantilever_tip_load.yaml", "-body0_dm_plex_filename",
                               a.mesh, "-ts_dt", repr(dt), "-ts_max_time", repr(tend), "-ts_max_steps", "100000000",
                               "-output_fields", "0", "-output_dir", outdir, "-progress", "0"] + SCHEMES[scheme] \
            + preset_options(preset)
        log, wall, rss = run(cmd)
        dofs = int(re.search(r"velocity P\d \((\d+) dofs\)", log).group(1))
        r = last_row(os.path.join(outdir, "cantilever_ports.csv"))
        assert abs(float(r["time"]) - tend) < 1e-9 * tend, "the run did not end at %g" % tend
        y = [float(r[k]) for k in ("tip_vx", "tip_vy", "tip_vz", "tip_wx", "tip_wy", "tip_wz")]
        return y, wall, rss, dofs

    dtref = min(dts) / a.ref_factor
    yref, wall, rss, dofs = one("midpoint", dtref)
    print("reference: midpoint, dt %g, %.1f s" % (dtref, wall), flush=True)
    nref = math.sqrt(sum(v * v for v in yref))
    rows = []
    for np_ in a.nps:
        for preset in a.preset_list:
            for scheme in a.scheme_list:
                for dt in dts:
                    y, wall, rss, dofs = one(scheme, dt, np_, preset)
                    err = math.sqrt(sum((u - v) ** 2 for u, v in zip(y, yref))) / nref
                    rows.append(dict(scheme=scheme, dt=dt, steps=round(tend / dt), error=err, wall_s=wall,
                                     peak_rss_gib=rss, dofs=dofs, ranks=np_, preset=preset or "default", mesh=a.mesh,
                                     variant="%s %s np%d" % (scheme, preset or "default", np_)))
                    print("%-9s %-9s np %d dt %-8g error %.3e  %.1f s" % (scheme, preset or "default", np_, dt, err,
                                                                        wall), flush=True)
    write(out, rows)
    return rows


SUPPORTS = {"free": [], "clamped": ["-body0_frame_patch", "clamp"]}


def modes(a, out):
    outdir = tempfile.mkdtemp(prefix="phlex_wp_")
    meshes = a.meshes.split(",")

    def one(mesh, degree, support, np_=1, eps_type=""):
        cmd = launcher(np_) + [a.phlex, "-analysis", "modes", "-body0_dm_plex_filename", mesh,
                               "-body0_youngs_modulus", "2.1e11", "-body0_poissons_ratio", "0.3", "-body0_density",
                               "7800", "-body0_petscspace_degree", str(degree), "-modes_nev", "10",
                               "-modes_eps_tol", a.tol, "-output_dir", outdir, "-output_fields", "0", "-progress", "0"] \
            + SUPPORTS[support] + (["-modes_eps_type", eps_type] if eps_type else [])
        log, wall, rss = run(cmd)
        dofs = int(re.search(r"velocity P\d \((\d+) dofs\)", log).group(1))
        with open(os.path.join(outdir, "modes.csv")) as f:
            rows = [r for r in csv.DictReader(f)]
        elastic = [float(r["frequency_hz"]) for r in rows if r["rigid"] == "0"]
        assert len(elastic) >= 10, "%s: %d elastic modes" % (" ".join(cmd), len(elastic))
        return elastic[:10], wall, rss, dofs

    rows = []
    for support in a.support_list:
        ref, wall, _, dofs = one(a.reference or meshes[-1], 2, support)
        print("reference (%s): P2 %s, %d DOFs, %.1f s" % (support, a.reference or meshes[-1], dofs, wall), flush=True)
        for np_ in a.nps:
            for eps_type in a.eps_list:
                for degree in (1, 2):
                    for mesh in meshes:
                        if degree == 2 and mesh == (a.reference or meshes[-1]):
                            continue  # the reference itself
                        f, wall, rss, dofs = one(mesh, degree, support, np_, eps_type)
                        err = max(abs(x - y) / y for x, y in zip(f, ref))
                        rows.append(dict(support=support, degree=degree, mesh=mesh, error=err, wall_s=wall,
                                         peak_rss_gib=rss, dofs=dofs, ranks=np_, eps_type=eps_type or "default",
                                         tol=a.tol, variant="P%d %s np%d" % (degree, eps_type or "default", np_)))
                        print("%-7s P%d %-32s %-11s np %d %8d DOFs error %.3e  %.1f s  %.2f GiB"
                              % (support, degree, mesh, eps_type or "default", np_, dofs, err, wall, rss), flush=True)
    write(out, rows)
    return rows


def mechanism(a, out):
    outdir = tempfile.mkdtemp(prefix="phlex_wp_")
    tend = 8.0 / 150.0  # 8 rad of crank angle

    def one(cells, dt, np_=1, preset="", model="full"):
        extra = []
        if model.startswith("reduced"):
            if not model[len("reduced"):].isdigit():
                sys.exit("coupler model %s: reduced<N>, N the number of normal modes (reduced10)" % model)
            extra = ["-body1_type", "reduced", "-body1_reduction_modes", model[len("reduced"):]]
        elif model != "full":
            sys.exit("unknown coupler model %s (full, reduced<N>)" % model)
        cmd = launcher(np_) + [a.phlex, "-options_file", "options/crankslider.yaml", "-body1_dm_plex_filename",
                               "meshes/crankslider_coupler_nx%d.msh" % cells, "-ts_dt", repr(dt), "-ts_max_time",
                               repr(tend), "-output_fields", "0", "-output_dir", outdir, "-progress", "0",
                               "-log_view"] + extra + preset_options(preset)
        log, wall, rss = run(cmd)
        dofs = int(re.search(r"velocity P\d \((\d+) dofs\)", log).group(1))
        coords = re.search(r"(\d+) coordinates\)", log)
        stage = re.search(r"Phlex Transient: ([0-9.e+-]+)", log)
        check = subprocess.run([sys.executable, "tools/crankslider_midpoint.py", outdir], cwd=ROOT,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True).stdout
        m = re.search(r"max deviation ([0-9.e+-]+)", check)
        if not m:
            sys.exit("no deviation in the check's output:\n" + check)
        return (float(m.group(1)), wall, rss, dofs, int(coords.group(1)) if coords else 0,
                float(stage.group(1)) if stage else float("nan"))

    rows = []
    for np_ in a.nps:
        for preset in a.preset_list:
            for model in a.coupler_models.split(","):
                for cells in [int(x) for x in a.coupler_cells.split(",")]:
                    for dt in [float(x) for x in a.mechanism_dts.split(",")]:
                        err, wall, rss, dofs, coords, transient_s = one(cells, dt, np_, preset, model)
                        rows.append(dict(model=model, cells=cells, dt=dt, steps=round(tend / dt), error=err,
                                         wall_s=wall, transient_s=transient_s,
                                         wall_per_simulated_s=wall / tend, peak_rss_gib=rss, dofs=dofs,
                                         coordinates=coords, ranks=np_, preset=preset or "default",
                                         variant="%s %d cells %s np%d" % (model, cells, preset or "default", np_)))
                        print("coupler %-9s %2d cells (%5d DOFs, %3d coordinates) %-9s np %d dt %-6g deviation "
                              "%.2e  %.2f s (transient %.2f s; %.1f s per simulated s)" % (
                                  model, cells, dofs, coords, preset or "default", np_, dt, err, wall,
                                  transient_s, wall / tend), flush=True)
    write(out, rows)
    return rows


def write(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("wrote", os.path.relpath(path, ROOT))


def plot(path, rows, group, title, ylabel="relative error"):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no", os.path.relpath(path, ROOT))
        return
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for g in sorted({r[group] for r in rows}, key=lambda v: (str(type(v)), v)):
        pts = [(r["wall_s"], r["error"]) for r in rows if r[group] == g and r["error"] > 0]
        if pts:
            ax.loglog(*zip(*pts), "o-", label=str(g))
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print("wrote", os.path.relpath(path, ROOT))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cases", default="transient,modes,mechanism")
    p.add_argument("--phlex", default="bin/phlex")
    p.add_argument("--np", default="1", help="ranks, a list: 1,2")
    p.add_argument("--presets", default="", help="transient, mechanism: solver presets (options/solver/<name>.opts)")
    p.add_argument("--eps-types", default="", help="modes: eigensolvers (-modes_eps_type)")
    p.add_argument("--schemes", default=",".join(SCHEMES), help="transient: integrators (%s)" % ", ".join(SCHEMES))
    p.add_argument("--reference", default="", help="modes: the P2 mesh of the reference (default: the last of --meshes)")
    p.add_argument("--supports", default="free,clamped", help="modes: free (free-free bar), clamped (cantilever)")
    p.add_argument("--mesh", default="meshes/bench/bar_h0.02.msh")
    p.add_argument("--dts", default="4.8e-4,2.4e-4,1.2e-4,6e-5")
    p.add_argument("--tend", type=float, default=0.00576)
    p.add_argument("--ref-factor", type=float, default=8.0)
    p.add_argument("--meshes", default="meshes/bar_h0.05.msh,meshes/bench/bar_h0.02.msh,meshes/bench/bar_h0.01.msh")
    p.add_argument("--tol", default="1e-10")
    p.add_argument("--coupler-cells", default="8,16,32")
    p.add_argument("--mechanism-dts", default="4e-5,2e-5,1e-5")
    p.add_argument("--coupler-models", default="full",
                   help="mechanism: the coupler, full and/or reduced<N> (a reduced body of N normal modes): full,reduced10")
    a = p.parse_args()
    a.nps = [int(x) for x in a.np.split(",")]
    a.preset_list = a.presets.split(",")
    a.eps_list = a.eps_types.split(",")
    a.scheme_list = a.schemes.split(",")
    a.support_list = a.supports.split(",")
    for sp in a.support_list:
        if sp not in SUPPORTS:
            sys.exit("unknown support %s (%s)" % (sp, ", ".join(SUPPORTS)))
    for sc in a.scheme_list:
        if sc not in SCHEMES:
            sys.exit("unknown scheme %s (%s)" % (sc, ", ".join(SCHEMES)))
    os.makedirs(RESULTS, exist_ok=True)
    if max(a.nps) > 1:
        os.environ.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for case in a.cases.split(","):
        base = os.path.join(RESULTS, "work_precision_%s" % case)
        if case == "transient":
            rows = transient(a, base + ".csv")
            plot(base + ".png", rows, "variant", "cantilever tip velocity at t = %g s, %d DOFs" % (a.tend, rows[0]["dofs"]))
        elif case == "modes":
            rows = modes(a, base + ".csv")
            for sp in a.support_list:
                plot("%s_%s.png" % (base, sp), [r for r in rows if r["support"] == sp], "variant",
                     "%s bar, first 10 elastic frequencies" % ("free-free" if sp == "free" else "cantilever"))
        elif case == "mechanism":
            rows = mechanism(a, base + ".csv")
            plot(base + ".png", rows, "variant", "crank-slider midpoint deflection over 8 rad, against FFRF",
                 "max |u_y/L - FFRF|")
        else:
            sys.exit("unknown case %s" % case)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Side by side with Exudyn's Craig-Bampton pendulum (../shared/peers/exudyn_pendulum.py; issue 41 item 6): the same
steel bar on the peer's own mesh (bar_h<H>.msh of the peer's make_meshes.py), the same number of elastic coordinates,
runs interleaved (phlex, peer, phlex, peer, ...) so that the machine's drift over the sitting hits both.

  phlex  bench/pendulum_exudyn.yaml with the bar a reduced body: --modes normal modes clamped at the hinged face plus
         the tip port's 6 attachment modes (the tip is a port for its output; the frame carries the rigid motion);
         time per step = the "Phlex Transient" stage of -log_view (Newton, monitor, series) / steps
  peer   ObjectFFRFreducedOrder with Hurty-Craig-Bampton modes: the hinge face's 6 static (RBE2) modes plus --modes
         fixed-interface eigenmodes; its own ms_per_step (SolveDynamic's wall time / steps)
Both take 16 elastic coordinates with --modes 10. The reference of both tips is phlex's full body on the same mesh
(P1, every node, run once): the tip face's mean position at the end time and the lowest tip z over the run.

usage: bench/side_by_side_exudyn.py --peer-python PEERDIR/.venv/bin/python [--peer-dir ../shared/peers]
                                    [--h 0.02] [--modes 10] [--repeat 3] [--phlex bin/phlex] [--tend 1.0]
Appends every run to bench/results/side_by_side_exudyn.csv and prints the ratio of the medians.
"""
import argparse
import csv
import datetime
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1",
           OPENBLAS_NUM_THREADS="1")


def sh(cmd, cwd=ROOT):
    p = subprocess.run(cmd, cwd=cwd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout[-3000:]))
    return p.stdout


def phlex(a, mesh, model):
    out = tempfile.mkdtemp(prefix="phlex_exu_")
    cmd = [a.phlex, "-options_file", "bench/pendulum_exudyn.yaml", "-body0_dm_plex_filename", mesh, "-output_dir",
           out, "-progress", "0", "-ts_max_time", repr(a.tend), "-log_view"]
    if model == "reduced":
        cmd += ["-body0_type", "reduced", "-body0_reduction_modes", str(a.modes)]
    log = sh(cmd)
    stage = float(re.search(r"^\s*\d+:\s+Phlex Transient: ([\d.e+-]+)", log, re.M).group(1))
    steps = int(re.search(r"Transient: (\d+) steps", log).group(1))
    with open(os.path.join(out, "bar_ports.csv")) as f:
        rows = list(csv.DictReader(f))
    shutil.rmtree(out)
    tip = [[float(r["tip_%s" % c]) for c in "xyz"] for r in rows]
    return dict(ms_per_step=1e3 * stage / steps, tip_final=tip[-1], tip_min_z=min(t[2] for t in tip), steps=steps)


def peer(a, mesh):
    line = sh([a.peer_python, os.path.join(a.peer_dir, "exudyn_pendulum.py"), mesh, "--modes", str(a.modes), "--tend",
               repr(a.tend), "--h", "1e-3"], cwd=a.peer_dir)
    j = json.loads([l for l in line.splitlines() if l.startswith("{")][-1])
    return dict(ms_per_step=j["ms_per_step"], tip_final=j["tip_final"], tip_min_z=j["tip_min_z"], steps=j["steps"])


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--peer-python", required=True)
    p.add_argument("--peer-dir", default=os.path.join(ROOT, "..", "shared", "peers"))
    p.add_argument("--h", default="0.02")
    p.add_argument("--modes", type=int, default=10)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--tend", type=float, default=1.0)
    p.add_argument("--phlex", default="bin/phlex")
    p.add_argument("--meshdir", default=os.path.join(tempfile.gettempdir(), "phlex_peer_meshes"))
    p.add_argument("--csv", default=os.path.join(ROOT, "bench", "results", "side_by_side_exudyn.csv"))
    a = p.parse_args()
    a.peer_dir = os.path.abspath(a.peer_dir)
    os.makedirs(a.meshdir, exist_ok=True)
    mesh = os.path.join(a.meshdir, "bar_h%s.msh" % a.h)
    if not os.path.exists(mesh):
        sh([a.peer_python, os.path.join(a.peer_dir, "make_meshes.py"), a.meshdir, a.h])
    ref = phlex(a, mesh, "full")
    print("phlex full body (reference): %.3f ms per step, tip at %.1f s %s, lowest tip z %.7f" % (ref["ms_per_step"], a.tend, ["%.6f" % x for x in ref["tip_final"]], ref["tip_min_z"]), flush=True)
    runs = {"phlex": [], "exudyn": []}
    for _ in range(a.repeat):
        for who in ("phlex", "exudyn"):
            r = phlex(a, mesh, "reduced") if who == "phlex" else peer(a, mesh)
            err = max(abs(x - y) for x, y in zip(r["tip_final"], ref["tip_final"]))
            r.update(tip_error=err, min_z_error=abs(r["tip_min_z"] - ref["tip_min_z"]))
            runs[who].append(r)
            print("%-6s %.4f ms per step; tip at %.1f s off the full body's by %.2e m, lowest z by %.2e m" % (who, r["ms_per_step"], a.tend, err, r["min_z_error"]), flush=True)
            new = not os.path.exists(a.csv)
            os.makedirs(os.path.dirname(a.csv), exist_ok=True)
            with open(a.csv, "a", newline="") as f:
                w = csv.writer(f)
                if new:
                    w.writerow(["date", "code", "mesh", "modes", "steps", "ms_per_step", "tip_error_m", "min_z_error_m", "full_ms_per_step"])
                w.writerow([datetime.datetime.now().isoformat(timespec="seconds"), who, os.path.basename(mesh), a.modes, r["steps"], "%.4f" % r["ms_per_step"], "%.3e" % err, "%.3e" % r["min_z_error"], "%.3f" % ref["ms_per_step"]])
    mp = statistics.median(r["ms_per_step"] for r in runs["phlex"])
    me = statistics.median(r["ms_per_step"] for r in runs["exudyn"])
    print("median ms per step: phlex %.4f, exudyn %.4f; exudyn / phlex = %.2f" % (mp, me, me / mp))


if __name__ == "__main__":
    main()

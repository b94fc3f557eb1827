#!/usr/bin/env python3
"""Side by side with the peer (DOLFINx + SLEPc, ../shared/peers): the same bar mesh, the same case, runs interleaved
(phlex, peer, phlex, peer, ...) so that the machine's drift over the sitting hits both; prints the ratios and appends
every run to bench/results/side_by_side.csv.

Cases (both codes: P2 velocity/displacement, 1 rank unless --np):
  transient  the clamped bar, implicit midpoint, factorization reused; time per step with its energy monitor
             (phlex: the "Phlex Transient" stage less its PCSetUp and PhlexCondSetUp, of a long and a short run,
             differenced, so that the factorization, the set-up and the first solve drop out; the peer: its loop
             time per step, factorization done before the loop)
  modes      free-free, 26 eigenpairs (6 rigid + 20 elastic), shift-and-invert Krylov-Schur, tolerance --tol
             (phlex: --phlex-tol when given, to compare at equal accuracy rather than equal tolerance); wall time of
             the whole run and peak memory, and the largest relative difference of the 20 elastic frequencies
             between the two codes (the peer prints them to 1e-6 Hz: about 2e-9 of the first)

usage: bench/side_by_side.py --peer-python PEERDIR/.venv/bin/python [--peer-dir DIR] [--mesh MSH] [--repeat N]
                             [--cases transient,modes] [--phlex bin/phlex] [--np 1] [--extra "phlex options"]
                             [--tol 1e-8] [--phlex-tol 1e-5]
"""
import argparse
import csv
import datetime
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def timed(cmd, env=None):
    """run cmd under /usr/bin/time -v: (stdout+stderr text, wall seconds, peak RSS GiB)"""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        p = subprocess.run(["/usr/bin/time", "-v", "-o", tf.name] + cmd, cwd=ROOT, env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        t = tf.read()
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout[-3000:]))
    wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", t)
    secs = (int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3)))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 2**20
    return p.stdout, secs, rss


def stage_time(log, name):
    m = re.search(r"^\s*\d+:\s+%s: ([\d.e+-]+)" % re.escape(name), log, re.M)
    return float(m.group(1)) if m else float("nan")


def event_time(log, stage, event):
    """the time of an event within a -log_view stage (0 if the stage does not log it)"""
    blocks = log.split("--- Event Stage ")
    for b in blocks[1:]:
        if b.split("\n", 1)[0].split(": ", 1)[-1].strip() == stage:
            m = re.search(r"^%s\s+\d+\s+[\d.]+\s+([\d.e+-]+)" % re.escape(event), b, re.M)
            return float(m.group(1)) if m else 0.0
    return 0.0


def stepping_time(log):
    """the transient stage without the one-time factorization and set-up inside its first step"""
    st = "Phlex Transient"
    return stage_time(log, st) - event_time(log, st, "PCSetUp") - event_time(log, st, "PhlexCondSetUp")


def mpi(np_, cmd, launcher="mpiexec"):
    return ([launcher, "-n", str(np_)] if np_ > 1 else []) + cmd


def peer_launcher(python):
    """the peer's own MPI launcher: its wheels bring MPICH, which Open MPI's mpiexec cannot start"""
    own = os.path.join(os.path.dirname(python), "mpiexec")
    return own if os.path.exists(own) else "mpiexec"


def phlex_transient(a, steps):
    cmd = mpi(a.np, [a.phlex, "-options_file", "options/cantilever.yaml", "-body0_dm_plex_filename", a.mesh,
                     "-body0_ic_velocity_type", "beam", "-body0_ic_velocity_direction", "0,0,1", "-ts_dt", "1e-4",
                     "-ts_max_steps", str(steps), "-output_fields", "0", "-output_dir", a.out + "/tr", "-log_view"]
              + a.extra.split())
    log, wall, rss = timed(cmd)
    dofs = int(re.search(r"velocity P2 \((\d+) dofs\)", log).group(1))
    return stepping_time(log), wall, rss, dofs


def peer_env(python):
    """one thread per process; the MPI library of the peer's wheels (MPICH, in the virtual environment's lib/) found
    without activating the environment"""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    lib = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(python))), "lib")
    if os.path.exists(os.path.join(lib, "libmpi.so.12")):
        env["LD_LIBRARY_PATH"] = lib + (":" + env["LD_LIBRARY_PATH"] if env.get("LD_LIBRARY_PATH") else "")
    return env


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--peer-python", required=True)
    p.add_argument("--peer-dir", default=os.path.join(ROOT, "..", "shared", "peers"))
    p.add_argument("--mesh", default="meshes/bench/bar_h0.01.msh")
    p.add_argument("--repeat", type=int, default=2)
    p.add_argument("--cases", default="transient,modes")
    p.add_argument("--phlex", default="bin/phlex")
    p.add_argument("--np", type=int, default=1)
    p.add_argument("--short", type=int, default=10, help="phlex transient: steps of the short run")
    p.add_argument("--long", type=int, default=30, help="phlex transient: steps of the long run")
    p.add_argument("--tol", default="1e-8")
    p.add_argument("--phlex-tol", default="", help="modes: phlex's tolerance (default --tol)")
    p.add_argument("--extra", default="", help="options added to every phlex run")
    p.add_argument("--csv", default=os.path.join(ROOT, "bench", "results", "side_by_side.csv"))
    a = p.parse_args()
    a.out = tempfile.mkdtemp(prefix="phlex_sbs_")
    os.makedirs(os.path.dirname(a.csv), exist_ok=True)
    new = not os.path.exists(a.csv)
    out = open(a.csv, "a", newline="")
    w = csv.writer(out)
    if new:
        w.writerow(["date", "case", "mesh", "ranks", "code", "run", "dofs", "per_step_s", "wall_s", "peak_rss_gib", "loadavg", "extra"])
    stamp = datetime.datetime.now().isoformat(timespec="seconds")
    mesh = os.path.abspath(os.path.join(ROOT, a.mesh))
    peer = os.path.abspath(a.peer_dir)
    res = {}
    for case in a.cases.split(","):
        for r in range(a.repeat):
            load = open("/proc/loadavg").read().split()[0]
            if case == "transient":
                t1, _, _, dofs = phlex_transient(a, a.short)
                t2, wall, rss, dofs = phlex_transient(a, a.long)
                ph = (t2 - t1) / (a.long - a.short)
                w.writerow([stamp, case, a.mesh, a.np, "phlex", r, dofs, "%.4f" % ph, "%.2f" % wall, "%.3f" % rss, load, a.extra])
                cmd = mpi(a.np, [a.peer_python, os.path.join(peer, "transient_bar.py"), mesh, "--degree", "2",
                                 "--solver", "mumps", "--steps", "20"], peer_launcher(a.peer_python))
                log, wall, rss = timed(cmd, peer_env(a.peer_python))
                j = json.loads([l for l in log.splitlines() if l.startswith("{")][-1])
                pe = j["per_step_ms"] / 1e3
                w.writerow([stamp, case, a.mesh, a.np, "peer", r, j["ndofs"], "%.4f" % pe, "%.2f" % wall, "%.3f" % rss, load, ""])
                res.setdefault(case, []).append((ph, pe, dofs, j["ndofs"]))
                print("transient run %d: phlex %.3f s/step (%d DOFs), peer %.3f s/step (%d DOFs): peer/phlex %.2f"
                      % (r, ph, dofs, pe, j["ndofs"], pe / ph), flush=True)
            elif case == "modes":
                cmd = mpi(a.np, [a.phlex, "-analysis", "modes", "-body0_dm_plex_filename", a.mesh,
                                 "-body0_youngs_modulus", "2.1e11", "-body0_poissons_ratio", "0.3", "-body0_density",
                                 "7800", "-body0_petscspace_degree", "2", "-modes_nev", "20", "-modes_eps_tol", a.phlex_tol or a.tol,
                                 "-output_dir", a.out + "/modes", "-output_fields", "0"] + a.extra.split())
                log, wph, rph = timed(cmd)
                dofs = int(re.search(r"velocity P2 \((\d+) dofs\)", log).group(1))
                w.writerow([stamp, case, a.mesh, a.np, "phlex", r, dofs, "", "%.2f" % wph, "%.3f" % rph, load,
                            (a.extra + " -modes_eps_tol " + a.phlex_tol).strip() if a.phlex_tol else a.extra])
                cmd = mpi(a.np, [a.peer_python, os.path.join(peer, "modal_bar.py"), mesh, "--degree", "2", "--bc",
                                 "free", "--nev", "26", "--tol", a.tol], peer_launcher(a.peer_python))
                log, wpe, rpe = timed(cmd, peer_env(a.peer_python))
                j = json.loads([l for l in log.splitlines() if l.startswith("{")][-1])
                ndofs = j.get("ndofs", 0)
                w.writerow([stamp, case, a.mesh, a.np, "peer", r, ndofs, "", "%.2f" % wpe, "%.3f" % rpe, load, ""])
                res.setdefault(case, []).append((wph, wpe, rph, rpe))
                with open(os.path.join(a.out, "modes", "modes.csv")) as f:
                    fph = [float(x["frequency_hz"]) for x in csv.DictReader(f) if x["rigid"] == "0"][:20]
                fpe = sorted(j["freqs_Hz"])[6:26]
                diff = max(abs(x - y) / x for x, y in zip(fph, fpe))
                print("modes run %d: phlex %.1f s %.2f GiB, peer %.1f s %.2f GiB: peer/phlex time %.2f, memory phlex/peer %.2f;"
                      " elastic frequencies differ by %.1e at most" % (r, wph, rph, wpe, rpe, wpe / wph, rph / rpe, diff),
                      flush=True)
            out.flush()
    for case, v in res.items():
        ratios = [x[1] / x[0] for x in v]
        print("%s: peer/phlex %s, median %.2f" % (case, " ".join("%.2f" % x for x in ratios), statistics.median(ratios)))
    print("runs appended to", os.path.relpath(a.csv, ROOT))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Summarise the logs of bench/run.sh into markdown tables.

    python3 bench/summarize.py [RESULTS_DIR]        (default bench/results)

For every case it takes the run with the smallest wall time (of the REPEAT runs) and reports its phase times
from -log_view; the other runs' wall times are listed so that a contended run is visible.
Modal frequencies are compared with the finest free-free mesh present (modes_h<smallest h>).
Transient per-step times come from pairs of runs with 20 and 40 steps: (TSStep(40) - TSStep(20)) / 20.
"""
import csv
import glob
import os
import re
import sys
from collections import defaultdict

RESULTS = sys.argv[1] if len(sys.argv) > 1 else "bench/results"

EVENTS = ["PhlexBodySetUp", "PhlexBodyAssem", "PhlexModesSolve", "EPSSolve", "EPSSetUp", "STSetUp", "MatSolve",
          "TSStep", "KSPSolve", "PCSetUp", "PCApply", "PhlexSysIFunc", "PhlexSysIJac", "PhlexMonEnergy",
          "MatCholFctrSym", "MatCholFctrNum", "MatLUFactorSym", "MatLUFactorNum", "MatMult", "SNESSolve",
          "KSPSolve_FS_Schu", "KSPSolve_FS_0", "KSPSolve_FS_1", "KSPSolve_FS_Low", "MatAXPY", "PCApply",
          "BVOrthogonalizeV", "BVDotVec", "BVMatMultVec", "STApply", "MatConvert", "MatTranspose",
          "DMPlexCreateGmsh", "DMPlexDistribute", "PCSetUp_GAMG+", "KSPSolve", "PhlexFloatResid", "PhlexFloatJac",
          "PhlexBordBasis", "PhlexBordSetUp"]


def parse(path):
    r = {"path": path, "events": defaultdict(lambda: {"count": 0, "time": 0.0}), "stages": {}, "ranks": []}
    stage = None
    with open(path, errors="replace") as f:
        for line in f:
            m = re.match(r"# (\w[\w ]*?): (.*)", line)
            if m and line.startswith("# "):
                r.setdefault("hdr_" + m.group(1).replace(" ", "_"), m.group(2).strip())
            m = re.search(r"velocity P(\d) \((\d+) dofs\), stress P\d discontinuous \((\d+) dofs\)", line)
            if m:
                r["degree"], r["vdofs"], r["sdofs"] = int(m.group(1)), int(m.group(2)), int(m.group(3))
            m = re.search(r"(\d+) tetrahedra", line)
            if m and "cells" not in r:
                r["cells"] = int(m.group(1))
            m = re.match(r"\s*\d+: +([\w ]+?): +([\d.e+-]+) +([\d.]+)%", line)
            if m:
                r["stages"][m.group(1).strip()] = float(m.group(2))
            m = re.match(r"--- Event Stage \d+: (.*)", line)
            if m:
                stage = m.group(1).strip()
            m = re.match(r"(\S+) +(\d+) +[\d.]+ +([\d.e+-]+) +[\d.]+ +[\d.e+-]+", line)
            if m and stage is not None and not line.startswith("#"):
                name = m.group(1)
                ev = r["events"][name]
                ev["count"] += int(m.group(2))
                ev["time"] += float(m.group(3))
                r["events"][stage + "/" + name] = {"count": int(m.group(2)), "time": float(m.group(3))}
            m = re.match(r"\s*Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (.*)", line)
            if m:
                parts = [float(x) for x in m.group(1).split(":")]
                w = 0.0
                for p in parts:
                    w = 60 * w + p
                r["wall"] = w
            m = re.match(r"\s*Maximum resident set size \(kbytes\): (\d+)", line)
            if m:
                r["rss_kb"] = int(m.group(1))
            m = re.match(r"\s*User time \(seconds\): ([\d.]+)", line)
            if m:
                r["user"] = float(m.group(1))
            m = re.match(r"\s*System time \(seconds\): ([\d.]+)", line)
            if m:
                r["sys"] = float(m.group(1))
            m = re.match(r"\s*Percent of CPU this job got: (\d+)%", line)
            if m:
                r["cpu_pct"] = int(m.group(1))
            m = re.match(r"phlex-rank (\d+) maxrss_kb (\d+) wall_s ([\d.]+)", line)
            if m:
                r["ranks"].append((int(m.group(1)), int(m.group(2)), float(m.group(3))))
            m = re.match(r"# loadavg during: ([\d.]+)", line)
            if m:
                r["load_max"] = max(r.get("load_max", 0.0), float(m.group(1)))
            m = re.match(r"# machine busy CPU during the run: ([\d.]+) s", line)
            if m:
                r["busy"] = float(m.group(1))
            m = re.match(r"\s*(R?INFOG\(\d+\)) \(.*\): *(\S+)\s*$", line)
            if m:
                try:
                    r.setdefault("mumps", {})[m.group(1)] = float(m.group(2))
                except ValueError:
                    pass
            m = re.match(r"# exit status: (\d+)", line)
            if m:
                r["status"] = int(m.group(1))
            m = re.match(r"Modes of body \S+ \((\w+)\): (\d+) computed(?:, (\d+) rigid)?", line)
            if m:
                r["nconv"], r["nrigid"] = int(m.group(2)), int(m.group(3) or 0)
            m = re.match(r"Transient: (\d+) steps", line)
            if m:
                r["steps"] = int(m.group(1))
            m = re.search(r"max \|H - H0\| / H0 = ([\d.e+-]+)", line)
            if m:
                r["drift"] = float(m.group(1))
    mcsv = path[:-4] + ".modes.csv"
    if os.path.exists(mcsv):
        with open(mcsv) as f:
            rows = list(csv.DictReader(f))
        r["freqs"] = [float(x["frequency_hz"]) for x in rows if x["rigid"] == "0"]
        r["resid_max"] = max(float(x["relative_residual"]) for x in rows if x["rigid"] == "0")
    return r


def load():
    runs = defaultdict(list)
    for p in sorted(glob.glob(os.path.join(RESULTS, "*.r[0-9]*.log"))):
        name = re.sub(r"\.r\d+\.log$", "", os.path.basename(p))
        runs[name].append(parse(p))
    return runs


def best(rs):
    ok = [r for r in rs if r.get("status", 1) == 0 and "wall" in r]
    return min(ok, key=lambda r: r["wall"]) if ok else None


def ev(r, name, key="time"):
    e = r["events"].get(name)
    return e[key] if e else None


def f(x, fmt="{:.2f}"):
    return "–" if x is None else fmt.format(x)


def gib(kb):
    return kb / 1024.0 / 1024.0


def others(r):
    """CPU seconds used by other processes during the run (machine busy time minus this run's user + system)."""
    if "busy" not in r or "user" not in r:
        return None
    return max(0.0, r["busy"] - r["user"] - r.get("sys", 0.0))


def walls(rs):
    return " / ".join(f(r.get("wall"), "{:.1f}") for r in rs)


def modes_table(runs, names, title):
    print(f"\n### {title}\n")
    print("EPSSolve includes STSetUp (SLEPc sets up inside EPSSolve); 'iterations' = EPSSolve - STSetUp; "
          "'after EPSSolve' = PhlexModesSolve - EPSSolve (eigenvector extraction, purification solves, residuals).\n")
    print("| case | ranks | velocity DOFs | wall [s] (runs) | Phlex Setup [s] | PhlexBodyAssem [s] | STSetUp (factorization) [s] "
          "| MatCholFctrSym / Num [s] | EPSSolve [s] | iterations [s] | after EPSSolve [s] | MatSolve count | per MatSolve [s] | Phlex Modes stage [s] | peak RSS [GiB] | max load | other CPU [s] | modes conv. | max rel. residual |")
    print("|" + "---|" * 19)
    for n in names:
        rs = runs.get(n)
        if not rs:
            continue
        r = best(rs)
        if r is None:
            print(f"| {n} | failed |" + " |" * 17)
            continue
        ms = ev(r, "MatSolve")
        mc = ev(r, "MatSolve", "count")
        np_ = int(r.get("hdr_np", "1"))
        rss = f(gib(r["rss_kb"]), "{:.2f}")
        if r["ranks"]:
            rss = "max " + f(gib(max(x[1] for x in r["ranks"])), "{:.2f}") + ", sum " + f(gib(sum(x[1] for x in r["ranks"])), "{:.2f}")
        print(f"| {n} | {np_} | {r.get('vdofs')} | {f(r['wall'], '{:.1f}')} ({walls(rs)}) | {f(r['stages'].get('Phlex Setup'))} "
              f"| {f(ev(r, 'PhlexBodyAssem'))} | {f(ev(r, 'STSetUp'))} | {f(ev(r, 'MatCholFctrSym'))} / {f(ev(r, 'MatCholFctrNum'))} "
              f"| {f(ev(r, 'EPSSolve'))} | {f(ev(r, 'EPSSolve') - ev(r, 'STSetUp'))} | {f(ev(r, 'PhlexModesSolve') - ev(r, 'EPSSolve'))} | {mc} | {f(ms / mc if ms and mc else None, '{:.3f}')} | {f(r['stages'].get('Phlex Modes'))} "
              f"| {rss} | {f(r.get('load_max'), '{:.1f}')} | {f(others(r), '{:.0f}')} | {r.get('nconv')} ({r.get('nrigid')} rigid) | {f(r.get('resid_max'), '{:.0e}')} |")


def freq_errors(runs):
    free = [n for n in runs if re.fullmatch(r"modes_h[\d.]+", n)]
    if not free:
        return
    free.sort(key=lambda n: float(n[7:]))
    ref_name = free[0]
    ref = best(runs[ref_name])
    if ref is None or "freqs" not in ref:
        return
    print(f"\n### Frequency error against {ref_name} ({ref.get('vdofs')} velocity DOFs), elastic modes 1..20\n")
    print("| mesh | velocity DOFs | max rel. error | mean rel. error | first mode [Hz] | 20th mode [Hz] |")
    print("|---|---|---|---|---|---|")
    for n in sorted(free, key=lambda n: -float(n[7:])):
        r = best(runs[n])
        if r is None or "freqs" not in r:
            continue
        k = min(20, len(r["freqs"]), len(ref["freqs"]))
        errs = [abs(r["freqs"][i] - ref["freqs"][i]) / ref["freqs"][i] for i in range(k)]
        print(f"| {n} | {r.get('vdofs')} | {max(errs):.2e} | {sum(errs) / k:.2e} | {r['freqs'][0]:.4f} | {r['freqs'][k - 1]:.4f} |")
    order = sorted(free, key=lambda n: -float(n[7:]))
    print(f"\nFrequencies [Hz] and relative error against {ref_name}:\n")
    head = []
    for n in order:
        head += [n] if n == ref_name else [n, "rel. error"]
    print("| mode | " + " | ".join(head) + " |")
    print("|---|" + "---|" * len(head))
    for i in range(20):
        row = []
        for n in order:
            r = best(runs[n])
            ok = r and "freqs" in r and i < len(r["freqs"])
            row.append(f"{r['freqs'][i]:.4f}" if ok else "–")
            if n != ref_name:
                row.append(f"{abs(r['freqs'][i] - ref['freqs'][i]) / ref['freqs'][i]:.1e}" if ok else "–")
        print(f"| {i + 1} | " + " | ".join(row) + " |")


def compare_freqs(runs, a, b):
    ra, rb = best(runs.get(a, [])), best(runs.get(b, []))
    if not ra or not rb or "freqs" not in ra or "freqs" not in rb:
        return
    k = min(20, len(ra["freqs"]), len(rb["freqs"]))
    d = max(abs(ra["freqs"][i] - rb["freqs"][i]) / rb["freqs"][i] for i in range(k))
    print(f"- max relative frequency difference {a} vs {b}: {d:.1e}")


def mumps_table(runs):
    rows = [(n, best(rs)) for n, rs in sorted(runs.items())]
    rows = [(n, r) for n, r in rows if r and r.get("mumps")]
    if not rows:
        return
    print("\n### MUMPS factor statistics (runs with -modes_eps_view)\n")
    print("| case | ordering used INFOG(7) | entries in factor INFOG(29) | factorization flops RINFOG(3) | MUMPS memory INFOG(18) [MB] | STSetUp [s] | per MatSolve [s] | wall [s] |")
    print("|---|---|---|---|---|---|---|---|")
    names = {0: "AMD", 1: "user", 2: "AMF", 3: "SCOTCH", 4: "PORD", 5: "METIS", 6: "QAMD"}
    for n, r in rows:
        mu = r["mumps"]
        o = mu.get("INFOG(7)")
        ms, mc = ev(r, "MatSolve"), ev(r, "MatSolve", "count")
        print(f"| {n} | {names.get(int(o), o) if o is not None else '–'} | {f(mu.get('INFOG(29)'), '{:.3g}')} | {f(mu.get('RINFOG(3)'), '{:.3g}')} "
              f"| {f(mu.get('INFOG(18)'), '{:.0f}')} | {f(ev(r, 'STSetUp'))} | {f(ms / mc if ms and mc else None, '{:.3f}')} | {f(r['wall'], '{:.1f}')} |")


def transient_table(runs):
    groups = defaultdict(dict)
    for n in runs:
        m = re.fullmatch(r"(tr_\w+?_h[\d.]+)_s(\d+)(_np2)?(_refblas)?", n)
        if m:
            groups[m.group(1) + (m.group(3) or "") + (m.group(4) or "")][int(m.group(2))] = n
    if not groups:
        return
    print("\n### Transient (clamped cantilever, implicit midpoint)\n")
    print("Per step = ((TSStep - PCSetUp)(b) - (TSStep - PCSetUp)(a)) / (b - a) for the runs with a and b steps; first step = TSStep(a) - (a - 1) x per step.\n")
    print("| case | ranks | velocity DOFs | steps a / b | wall a / b [s] (runs) | Phlex Setup [s] | Main Stage (system set-up) [s] "
          "| TSStep a / b [s] | per step, reused factorization [ms] | first step [s] | PCSetUp [s] | MatCholFctrSym / Num [s] "
          "| MatSolve per step [ms] | PhlexSysIFunc per step [ms] | PhlexMonEnergy per step [ms] | MatMult calls per step | peak RSS (b) [GiB] | other CPU a / b [s] | energy drift (b) |")
    print("|" + "---|" * 19)
    for g in sorted(groups):
        d = groups[g]
        a, b = min(d), max(d)
        ra, rb = best(runs[d[a]]), best(runs[d[b]])
        if len(d) == 1 and rb is not None:
            # one step count only: per step = (TSStep - PCSetUp) / steps (includes the first step's extra work)
            t, p = ev(rb, "TSStep"), ev(rb, "PCSetUp") or 0.0
            per = (t - p) / b
            print(f"| {g} | {int(rb.get('hdr_np', '1'))} | {rb.get('vdofs')} | {b} only | {f(rb['wall'], '{:.1f}')} ({walls(runs[d[b]])}) "
                  f"| {f(rb['stages'].get('Phlex Setup'))} | {f(rb['stages'].get('Main Stage'))} | {f(t)} | {per * 1000:.0f} (TSStep - PCSetUp) / {b} "
                  f"| – | {f(p)} | – | – | {f(ev(rb, 'PhlexSysIFunc') / b * 1000, '{:.0f}')} | {f(ev(rb, 'PhlexMonEnergy') / b * 1000, '{:.0f}')} | – "
                  f"| {f(gib(rb['rss_kb']), '{:.2f}')} | {f(others(rb), '{:.0f}')} | {f(rb.get('drift'), '{:.1e}')} |")
            continue
        if ra is None or rb is None:
            print(f"| {g} | failed |" + " |" * 17)
            continue

        def step(name, key="time"):
            x, y = ev(ra, name, key), ev(rb, name, key)
            return None if x is None or y is None else (y - x) / (b - a)

        ta, tb = ev(ra, "TSStep"), ev(rb, "TSStep")
        # the set-up of the preconditioner (factorization) happens once, in the first step: take it out of the
        # difference so that its run-to-run noise does not leak into the per-step time
        pa, pb = ev(ra, "PCSetUp") or 0.0, ev(rb, "PCSetUp") or 0.0
        per = ((tb - pb) - (ta - pa)) / (b - a)
        first = ta - (a - 1) * per
        ms_per, ifn, mon, mm = step("MatSolve"), step("PhlexSysIFunc"), step("PhlexMonEnergy"), step("MatMult", "count")
        np_ = int(rb.get("hdr_np", "1"))
        rss = f(gib(rb["rss_kb"]), "{:.2f}")
        if rb["ranks"]:
            rss = "max " + f(gib(max(x[1] for x in rb["ranks"])), "{:.2f}") + ", sum " + f(gib(sum(x[1] for x in rb["ranks"])), "{:.2f}")
        ms = lambda x: f(x * 1000 if x is not None else None, "{:.0f}")
        print(f"| {g} | {np_} | {rb.get('vdofs')} | {a} / {b} | {f(ra['wall'], '{:.1f}')} / {f(rb['wall'], '{:.1f}')} ({walls(runs[d[a]])}; {walls(runs[d[b]])}) "
              f"| {f(rb['stages'].get('Phlex Setup'))} | {f(rb['stages'].get('Main Stage'))} | {f(ta)} / {f(tb)} | {per * 1000:.0f} | {f(first)} "
              f"| {f(ev(rb, 'PCSetUp'))} | {f(ev(rb, 'MatCholFctrSym'))} / {f(ev(rb, 'MatCholFctrNum'))} | {ms(ms_per)} "
              f"| {ms(ifn)} | {ms(mon)} | {f(mm, '{:.0f}')} | {rss} | {f(others(ra), '{:.0f}')} / {f(others(rb), '{:.0f}')} | {f(rb.get('drift'), '{:.1e}')} |")


def floating_table(runs):
    """Floating body against the same body clamped (fl_<variant>_h<h>_s<a>, _s<b>): per-step cost with the set-up
    (factorization, bordered basis) taken out, and the share of the rigid coupling."""
    groups = defaultdict(dict)
    for n in runs:
        m = re.fullmatch(r"fl_(\w+?)_h([\d.]+)_s(\d+)", n)
        if m:
            groups[(m.group(2), m.group(1))][int(m.group(3))] = n
    if not groups:
        return
    print("\n### Floating body against the clamped body (transient, dt = 2e-4 s)\n")
    print("Per step = (X(b) - X(a)) / (b - a) for the runs with a and b steps, X = TSStep - PCSetUp (set-up of the "
          "factorization and of the bordered basis taken out); Newton its = Jacobian evaluations per step; "
          "Schur solves = KSPSolve_FS_Schu calls per step: one per outer Krylov iteration (solves with the velocity (+ rigid) Schur block); rigid coupling = PhlexFloatResid + PhlexFloatJac "
          "+ PhlexBordSetUp per step (the dense 18-column borders, the 18 x 18 Schur complement and the rigid "
          "residual rows); the once-per-shift bordered basis (PhlexBordBasis) is listed apart.\n")
    print("| h | case | velocity DOFs | steps a / b | wall a / b [s] | per step [ms] | vs clamped | Newton its | Schur solves "
          "| MatSolve per step [ms] | residual per step [ms] | Jacobian per step [ms] | monitor per step [ms] "
          "| rigid coupling per step [ms] | PCSetUp [s] | bordered basis [s] | peak RSS (b) [GiB] | other CPU a / b [s] |")
    print("|" + "---|" * 18)
    order = ["clamped_exact", "frozen", "full", "clamped_iterative", "frozen_iterative", "full_iterative"]
    for (h, variant) in sorted(groups, key=lambda k: (-float(k[0]), order.index(k[1]) if k[1] in order else 99, k[1])):
        d = groups[(h, variant)]
        a, b = min(d), max(d)
        ra, rb = best(runs[d[a]]), best(runs[d[b]])
        if ra is None or rb is None:
            print(f"| {h} | {variant} | failed |" + " |" * 15)
            continue

        def per_step(r):
            return ev(r, "TSStep") - (ev(r, "PCSetUp") or 0.0)

        def per_step_pair(ra, rb, a, b):
            # one step count only (a large mesh): (TSStep - PCSetUp) / b, which keeps the first step's extra work
            return per_step(rb) / b if a == b else (per_step(rb) - per_step(ra)) / (b - a)

        def step(name, key="time"):
            x, y = ev(ra, name, key), ev(rb, name, key)
            if y is None:
                return None
            return y / b if a == b else None if x is None else (y - x) / (b - a)

        per = per_step_pair(ra, rb, a, b)
        base = None
        ref = groups.get((h, "clamped_iterative" if variant.endswith("iterative") else "clamped_exact"))
        if ref:
            ca, cb = best(runs[ref[min(ref)]]), best(runs[ref[max(ref)]])
            if ca is not None and cb is not None:
                base = per_step_pair(ca, cb, min(ref), max(ref))
        rigid = [step(e) for e in ("PhlexFloatResid", "PhlexFloatJac", "PhlexBordSetUp")]
        rigid = sum(x for x in rigid if x is not None) if any(x is not None for x in rigid) else None
        ms = lambda x: f(x * 1000 if x is not None else None, "{:.0f}")
        print(f"| {h} | {variant} | {rb.get('vdofs')} | {a} / {b} | {f(ra['wall'], '{:.1f}')} / {f(rb['wall'], '{:.1f}')} "
              f"| {per * 1000:.0f} | {f(per / base if base else None, '{:.1f}')} x | {f(step('PhlexSysIJac', 'count'), '{:.1f}')} "
              f"| {f(step('KSPSolve_FS_Schu', 'count'), '{:.1f}')} | {ms(step('MatSolve'))} | {ms(step('PhlexSysIFunc'))} "
              f"| {ms(step('PhlexSysIJac'))} | {ms(step('PhlexMonEnergy'))} | {ms(rigid)} | {f(ev(rb, 'PCSetUp'))} "
              f"| {f(ev(rb, 'PhlexBordBasis'))} | {f(gib(rb['rss_kb']), '{:.2f}')} | {f(others(ra), '{:.0f}')} / {f(others(rb), '{:.0f}')} |")


def main():
    runs = load()
    if not runs:
        sys.exit(f"no logs in {RESULTS}")
    modes = sorted([n for n in runs if n.startswith("modes_")],
                   key=lambda n: (("_refblas" in n), -float(re.match(r"modes_h([\d.]+)", n).group(1)), n))
    modes_table(runs, modes, "Modal analysis (20 elastic modes)")
    freq_errors(runs)
    print()
    for n in modes:
        if n != "modes_h0.01" and n.startswith("modes_h0.01") and "clamp" not in n:
            compare_freqs(runs, n, "modes_h0.01")
        if n.endswith("_refblas"):
            compare_freqs(runs, n, n[: -len("_refblas")])
    mumps_table(runs)
    transient_table(runs)
    floating_table(runs)


if __name__ == "__main__":
    main()

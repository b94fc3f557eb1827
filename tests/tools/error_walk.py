#!/usr/bin/env python3
"""Walks phlex's error paths (issue 43 item 2): finds the error sites in the sources, runs inputs that trigger
them, and checks each run against README's exit-code table.

  python3 tests/tools/error_walk.py [--bin bin/phlex] [--work DIR] [-j 2] [--list-sites] [--untriggered] [--min-triggered N]
                                    [--only GLOB] [--inputs FILE]

Error sites: every SETERRQ(comm, PETSC_ERR_X, "format", ...) and PetscCheck(cond, comm, PETSC_ERR_X, "format", ...)
in src/ (the format's adjacent literals joined, PetscInt_FMT and the like read as a conversion). A site's format is
turned into a regular expression (conversions match anything), which identifies the site that printed a run's
one-line "phlex: error: ..." message.

Inputs: the runs of the specs in tests/cases/*.test that expect an error exit (2, 3, 4 or 5) on one process and need
no setup command (their args, args2, ...), and the extra inputs in tests/tools/error_inputs.txt (one argument line
each, "{outdir}" and "{root}" as in specs: paths the specs do not reach). Each run gets an output directory of its
own under --work.

Each run must
  - end with a code of README's table (0, 1, 2, 3, 4, 5, 130, 143), and, when its message came from a known site,
    with the code of that site's kind (PETSC_ERR_USER_INPUT, _FILE_OPEN/_READ/_UNEXPECTED, _SUP, _ARG_*: 2;
    _FILE_WRITE: 4; _NOT_CONVERGED, _CONV_FAILED, _FP: 3; _USER: 5; others: 1);
  - with code 2, 3 or 4 print exactly one "phlex: error:" line and no PETSc traceback ("[0]PETSC ERROR");
  - with code 2 leave its output directory empty (or not made); with code 3 nothing but failed/.
Messages that name neither an option (-name), a quoted value or file, nor a body or joint are listed (not failures).

The report: the runs, the failures, "sites triggered: N of M" (M: sites of the codes phlex exits 2 for), and with
--untriggered the sites no input reached. Exit status 1 when a run failed a check, else 0.
"""
import argparse
import concurrent.futures
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TABLE = {0, 1, 2, 3, 4, 5, 130, 143}  # README.md, "Exit codes"
TIMES = {}
# specs left out for their time (the walk is meant to take about a minute): their error runs come after long runs
SLOW = {"stress_high_spin_fieldsplit_newton_fails"}  # 46 s: Newton fails after a spin-up
KIND = {
    "PETSC_ERR_USER_INPUT": 2, "PETSC_ERR_FILE_OPEN": 2, "PETSC_ERR_FILE_READ": 2, "PETSC_ERR_FILE_UNEXPECTED": 2,
    "PETSC_ERR_SUP": 2, "PETSC_ERR_ARG_WRONG": 2, "PETSC_ERR_ARG_OUTOFRANGE": 2,
    "PETSC_ERR_FILE_WRITE": 4,
    "PETSC_ERR_NOT_CONVERGED": 3, "PETSC_ERR_CONV_FAILED": 3, "PETSC_ERR_FP": 3,
    "PETSC_ERR_USER": 5,
}

CALL = re.compile(r"\b(SETERRQ|PetscCheck)\s*\(")
# the scene reader prints its errors itself and returns PHLEX_EXIT_INPUT (before PETSc's options exist)
PRINTED = re.compile(r'fprintf\(\s*stderr\s*,\s*"phlex: error: ')
# messages formatted into a buffer that an error call passes on ("%s", msg): matched, not counted as sites
BUFFERED = re.compile(r"\b(PetscSNPrintf|snprintf)\s*\(")
STRING = re.compile(r'"((?:[^"\\]|\\.)*)"')
CONV = re.compile(r"%[-+ #0]*(\*|\d+)?(\.(\*|\d+))?(hh|h|ll|l|L|z|j|t)?[diouxXeEfgGcsp%]")


# input-error sites that no input reaches, each (file, a piece of its format's text, why): internal checks of
# PETSC_ERR_USER_INPUT's kind, and checks that an earlier one always pre-empts. The walk fails if an input triggers one.
UNREACHABLE = [
    ("src/analysis/eps_block.c", "is written for real scalars",
     "PETSc and SLEPc here are built for real scalars (the Makefile links petsc_real)"),
    ("src/parts/flexible_ic.c", "is not available for the stress",
     "-<body>ic_stress_type's list offers zero and uniform only: PETSc refuses rigid, beam, mode first"),
    ("src/parts/flexible_ic.c", "ic_stress_type must be zero or uniform",
     "-<body>ic_stress_type's list offers zero and uniform only: PETSc refuses the others first"),
    ("src/parts/flexible_spin.c", "has no prescribed spin",
     "the spin sweep sets the rate of the one spinning body it found (SpinningPart); a scene without one is refused "
     "before (bad_spin_sweep_without_spin)"),
    ("src/parts/flexible_spin.c", "is not a finite number",
     "-linearized_spin_sweep* refuses a rate that is not finite and >= 0 first (linearized.c, bad_spin_sweep_negative)"),
    ("src/analysis/transient_checkpoint.c", "discrete unknowns, this scene",
     "the checkpoint's scene signature (each part's and joint's discrete unknowns) is compared first: 'written for "
     "another scene'"),
    ("src/fe/mesh.c", "a distributed mesh with overlap",
     "-<body>dm_distribute_overlap and -<body>dm_distribute are refused before the mesh is set from options, and "
     "phlex's own distribution has no overlap"),
    ("src/fe/partition_metis.c", "partitions a mesh held by one rank",
     "phlex reads each mesh on one rank and partitions it once (a second distribution is refused)"),
    ("src/fe/partition_metis.c", "too large for METIS",
     "a cell graph of 2^31 entries (about 5e8 cells): no test input"),
    ("src/parts/flexible_fe.c", "element with",
     "the basis of P1 or P2 tetrahedra only: -petscspace_degree 1 or 2 and other cells are refused at input"),
    ("src/parts/flexible_stress_maps.c", "the cell-by-cell stress maps take at most 4",
     "the stress is P0 or P1 (-petscspace_degree 1 or 2 is checked at input): at most 4 stress nodes per cell"),
    ("src/parts/flexible_stress_maps.c", "the strain energy takes at most 4",
     "the stress is P0 or P1 (-petscspace_degree 1 or 2 is checked at input): at most 4 stress nodes per cell"),
    ("src/parts/flexible_port.c", "is not a triangle",
     "the boundary of a tetrahedral mesh (other cells are refused when the mesh is read)"),
    ("src/parts/flexible_port.c", "too many basis functions",
     "an internal bound of a P1/P2 triangle's nodes"),
    ("src/io/fields.c", "too many vertex fields", "the fields are registered by the code, not by input"),
    ("src/io/fields.c", "too many cell fields", "the fields are registered by the code, not by input"),
    ("src/system/layout.c", "too many fields", "the layout's fields are those of the part types, not of input"),
    # internal checks of the linearised pencil: the linearisation point is built at rest (the initial velocities
    # are not part of it: a floating body at 10 rad/s, a moving reduced body and a moving point mass were analysed
    # about rest) and gravity, port, frame and body loads, preloaded springs and moving rests are refused before
    ("src/analysis/linearized.c", "the velocity equations have terms in v",
     "internal check of the pencil at rest (the linearisation point has no velocity; a spin is handled apart)"),
    ("src/analysis/linearized.c", "the displacement acts on the velocity equations",
     "internal check of the pencil at rest (loads and preloads are refused before: the equilibrium check)"),
    ("src/analysis/linearized.c", "the elastic coordinates' rows are not",
     "internal check of the pencil at rest (the linearisation point has no velocity)"),
    ("src/analysis/linearized.c", "the discrete velocities' equations are not symmetric",
     "internal check of the pencil at rest (the linearisation point has no velocity)"),
    ("src/analysis/linearized.c", "couples the frames' positions or velocities",
     "internal check of the pencil at rest (gravity, loads and preloads are refused before)"),
    ("src/analysis/linearized.c", "the frames' velocities or positions act on the field",
     "internal check of the pencil at rest (gravity, loads and preloads are refused before)"),
    ("src/analysis/linearized_damped.c", "a force element's rows are not those of a spring-damper at rest",
     "internal check of the pencil at rest (a spring off its rest is refused before: 'holds a force at the "
     "linearisation point')"),
]


def unreachable_reason(site):
    f = site["where"].split(":")[0]
    for uf, piece, why in UNREACHABLE:
        if uf == f and piece in site["text"]:
            return why
    return None


def call_text(src, start):
    """the text of a call from its opening parenthesis to the matching one (strings and chars skipped)"""
    depth, i, n = 0, start, len(src)
    while i < n:
        c = src[i]
        if c == '"' or c == "'":
            j = i + 1
            while j < n and src[j] != c:
                j += 2 if src[j] == "\\" else 1
            i = j + 1
            continue
        if c == "(":
            depth += 1
        elif c == ")":
            depth -= 1
            if depth == 0:
                return src[start:i + 1]
        i += 1
    return src[start:]


def format_of(text):
    """the format string of a call: its first run of adjacent literals, with the PETSc format macros between them
    read as a conversion"""
    m = STRING.search(text)
    if not m:
        return None
    parts, pos = [m.group(1)], m.end()
    while True:
        rest = text[pos:]
        g = re.match(r'\s*(?:(PetscInt_FMT|PetscInt64_FMT|PetscCount_FMT|PETSC_[A-Z_]*FMT)\s*)?"((?:[^"\\]|\\.)*)"', rest)
        if not g:
            break
        parts.append(("d" if g.group(1) else "") + g.group(2))
        pos += g.end()
    if re.match(r"\s*(PetscInt_FMT|PetscInt64_FMT|PetscCount_FMT|PETSC_[A-Z_]*FMT)\b", text[pos:]):
        parts.append("d")  # a format ending in a conversion macro: "got %" PetscInt_FMT
    return "".join(parts)


def sites(root):
    out = []
    for path in sorted(glob.glob(os.path.join(root, "src", "**", "*.c"), recursive=True)):
        src = open(path, encoding="utf-8", errors="replace").read()
        for m in CALL.finditer(src):
            text = call_text(src, m.end() - 1)
            code = re.search(r"\bPETSC_ERR_[A-Z_]+", text)
            # the format follows the error code (a PetscCheck's condition may hold literals of its own)
            fmt = format_of(text[code.end():] if code else text)
            if fmt is None:
                continue
            line = src.count("\n", 0, m.start()) + 1
            if not CONV.sub("", fmt):
                # SETERRQ(comm, code, "%s", msg): the message was formatted before, by the nearest PetscSNPrintf(msg, ...)
                arg = re.search(r'"\s*,\s*(\w+)', text)
                if arg:
                    prev = [p for p in re.finditer(r"PetscSNPrintf\(\s*%s\s*," % re.escape(arg.group(1)), src[:m.start()])]
                    if prev:
                        fmt = format_of(call_text(src, prev[-1].end() - len(prev[-1].group(0)) + prev[-1].group(0).index("(")))
                        fmt = fmt if fmt is not None else ""
            if not CONV.sub("", fmt):
                continue  # a wrapper that passes a message on: not a site of its own
            pieces = CONV.split(fmt)
            # CONV has 4 groups: split returns literal, g1, g2, g3, g4, literal, ...
            literals = pieces[0::5]
            lit = [bytes(p, "utf-8").decode("unicode_escape", errors="replace") for p in literals]
            rx = ".*?".join(re.escape(p) for p in lit)
            out.append({"where": "%s:%d" % (os.path.relpath(path, root), line), "code": code.group(0) if code else "?",
                        "text": "".join(lit),
                        "rx": re.compile("^" + rx + "$", re.S), "fixed": sum(len(p) for p in lit), "hits": 0})
        for kind, pat in (("PRINTED", PRINTED), ("BUFFERED", BUFFERED)):
            for m in pat.finditer(src):
                text = call_text(src, src.index("(", m.start()))
                fmt = format_of(text)
                if fmt is None:
                    continue
                if kind == "PRINTED":
                    fmt = fmt[len("phlex: error: "):]
                    if fmt.endswith("\\n"):
                        fmt = fmt[:-2]
                if kind == "PRINTED" and not CONV.sub("", fmt):
                    continue  # the error handler printing a message of another site
                if not fmt.startswith("phlex: ") and len(CONV.sub("", fmt)) >= 20 or kind == "PRINTED":
                    line = src.count("\n", 0, m.start()) + 1
                    lit = [bytes(p, "utf-8").decode("unicode_escape", errors="replace") for p in CONV.split(fmt)[0::5]]
                    out.append({"where": "%s:%d" % (os.path.relpath(path, root), line),
                                "code": "PETSC_ERR_USER_INPUT" if kind == "PRINTED" else "BUFFERED",
                                "text": "".join(lit),
                                "rx": re.compile("^" + ".*?".join(re.escape(p) for p in lit) + "$", re.S),
                                "fixed": sum(len(p) for p in lit), "hits": 0})
    return out


def spec_runs(root, inputs=None):
    """the specs with an error run, each a list of its runs in order: (name, args, expected exit, checked); a later
    run may use an earlier one's files (a restart, a reduced body), so all the spec's runs go, in one directory"""
    specs = []
    for path in sorted(glob.glob(os.path.join(root, "tests", "cases", "*.test"))):
        name = os.path.basename(path)[:-5]
        keys, last = {}, None
        for raw in open(path, encoding="utf-8"):
            if raw.strip().startswith("#") or not raw.strip():
                continue
            if raw[0] in " \t" and last:
                keys[last] += " " + raw.strip()
                continue
            if ":" in raw:
                k, v = raw.split(":", 1)
                last = k.strip()
                keys[last] = v.strip()
        if "setup" in keys or name in SLOW:
            continue
        runs, k, errors = [], 1, 0
        while True:
            a = keys.get("args" if k == 1 else "args%d" % k)
            if a is None:
                break
            e = keys.get("exit" if k == 1 else "exit%d" % k, "0")
            n = keys.get("nsize%d" % k, keys.get("nsize", "1"))
            if n != "1" or "{stdout" in a or "{stderr" in a:
                runs = None
                break
            err = e in ("2", "3", "4", "5", "nonzero")
            errors += err
            runs.append(("%s#%d" % (name, k), a, None if e == "nonzero" else int(e), err))
            k += 1
        if runs and errors:
            specs.append((name, runs))
    extra = inputs or os.path.join(root, "tests", "tools", "error_inputs.txt")
    if os.path.exists(extra):
        for i, raw in enumerate(open(extra, encoding="utf-8")):
            s = raw.strip()
            if s and not s.startswith("#"):
                nm = "error_inputs.txt:%d" % (i + 1)
                # "run ;; run ;; ... ;; refused run": the earlier runs (a checkpoint, a reduced body) must end
                # normally, in the same output directory; the last is the refused one
                parts = [p.strip() for p in s.split(" ;; ")]
                runs = [("%s#%d" % (nm, k + 1), a, 0, False) for k, a in enumerate(parts[:-1])]
                specs.append((nm, runs + [(nm, parts[-1], -1, True)]))  # -1: any error exit
    return specs


def results_in(d):
    if not os.path.isdir(d):
        return []
    found = []
    for base, dirs, files in os.walk(d):
        for f in files:
            found.append(os.path.relpath(os.path.join(base, f), d))
    return found


def run_spec(spec, args):
    """runs a spec's runs in order in one output directory; returns per checked run (name, expected, code, stdout,
    stderr, files it left), and the broken chain's message if an unchecked run did not end as its spec says"""
    sname, runs = spec
    outdir = os.path.join(args.work, re.sub(r"[^A-Za-z0-9_.-]", "_", sname))
    shutil.rmtree(outdir, ignore_errors=True)
    os.makedirs(outdir)
    tmp = outdir + ".ompi"
    out = []
    t0 = time.time()
    for name, argline, expected, checked in runs:
        argv = [a.replace("{outdir}", outdir).replace("{root}", ROOT) for a in shlex.split(argline)]
        os.makedirs(tmp, exist_ok=True)
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                   OMPI_MCA_ess_singleton_isolated="1", OMPI_MCA_rmaps_base_oversubscribe="1",
                   OMPI_MCA_orte_tmpdir_base=tmp)
        before = set(results_in(outdir))
        try:
            p = subprocess.run([args.bin] + argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               timeout=args.timeout)
            code, sout, err = p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
        except subprocess.TimeoutExpired:
            code, sout, err = None, "", ""
        shutil.rmtree(tmp, ignore_errors=True)
        left = sorted(set(results_in(outdir)) - before)
        if checked:
            out.append((name, expected, code, sout, err, left))
        elif code != expected:
            out.append((name, expected, code, sout, err, None))
            break
        if checked and expected is not None and expected >= 0 and code != expected:
            break
    TIMES[sname] = time.time() - t0
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "phlex"))
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "error_walk"))
    ap.add_argument("-j", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--list-sites", action="store_true")
    ap.add_argument("--untriggered", action="store_true")
    ap.add_argument("--only", help="the specs (names, error_inputs.txt:<line>) matching this glob pattern")
    ap.add_argument("--inputs", help="another file of extra inputs than tests/tools/error_inputs.txt")
    ap.add_argument("--min-triggered", type=int, default=0,
                    help="fail when fewer reachable input-error sites are triggered (a coverage floor for the test)")
    args = ap.parse_args()
    args.work = os.path.abspath(args.work)
    ss = sites(ROOT)
    if args.list_sites:
        for s in ss:
            print(s["where"], s["code"], s["rx"].pattern[:100])
        return 0
    specs = spec_runs(ROOT, args.inputs)
    if args.only:
        import fnmatch
        specs = [sp for sp in specs if fnmatch.fnmatch(sp[0], args.only)]
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    failures, unnamed, unmatched, nchecked = [], [], [], 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.j) as ex:
        results = [r for rs in ex.map(lambda sp: run_spec(sp, args), specs) for r in rs]
    for name, expected, code, sout, err, left in results:
        bad = []
        if left is None:
            failures.append("%s: exit code %s, its spec expects %s (a run the error runs need)" % (name, code, expected))
            continue
        nchecked += 1
        if code is None:
            failures.append("%s: timed out" % name)
            continue
        if code < 0:
            bad.append("killed by signal %d" % -code)
        elif code not in TABLE:
            bad.append("exit code %d is not in README's table" % code)
        if expected == -1 and code == 0:
            bad.append("exit code 0: the input was accepted (error_inputs.txt lists inputs that must be refused)")
        elif expected is not None and expected >= 0 and code != expected:
            bad.append("exit code %d, its spec expects %d" % (code, expected))
        lines = [l for l in err.splitlines() if l.startswith("phlex: error: ")]
        msg = lines[0][len("phlex: error: "):] if lines else None
        usage = code == 2 and not lines and sout.startswith("Usage:")  # bin/phlex without arguments
        if code in (2, 3, 4) and not usage:
            if len(lines) != 1:
                bad.append("%d 'phlex: error:' lines" % len(lines))
            if "PETSC ERROR" in err:
                bad.append("a PETSc traceback")
        if code == 2 and left:
            bad.append("left in its output directory: %s" % ", ".join(left[:3]))
        if code == 3 and [f for f in left if not f.startswith("failed" + os.sep)]:
            bad.append("results left beside failed/")
        if msg is not None:
            # the most specific site whose format matches (the most fixed text)
            best = None
            for s in ss:
                if s["rx"].match(msg) and (best is None or s["fixed"] > best["fixed"]):
                    best = s
            if best:
                best["hits"] += 1
                want = KIND.get(best["code"], 1)
                if best["code"] != "BUFFERED" and code != want:
                    bad.append("site %s (%s) exits %d, its kind %d" % (best["where"], best["code"], code, want))
            else:
                unmatched.append("%s: %s" % (name, msg[:120]))
            if not re.search(r"(^|[\s(,'\"])-[A-Za-z]|'[^']+'|\bbody\b|\bjoint\b|\bscene\b|\boption", msg):
                unnamed.append("%s: %s" % (name, msg[:120]))
        if bad:
            failures.append("%s: %s" % (name, "; ".join(bad)))
    ss = [s for s in ss if s["code"] != "BUFFERED"]
    # sites with the same format print the same message: which of them did cannot be told, so they count as one
    # (the first in the sources; a hit is a hit of the group)
    groups = {}
    for s in ss:
        g = groups.setdefault((s["rx"].pattern, s["code"]), s)
        if g is not s:
            g["hits"] += s["hits"]
            g.setdefault("same", []).append(s["where"])
    ss = list(groups.values())
    for s in ss:
        s["unreachable"] = unreachable_reason(s)
        if s["unreachable"] and s["hits"]:
            failures.append("%s: marked unreachable in UNREACHABLE (%s) but an input triggered it" % (
                s["where"], s["unreachable"]))
    input_sites = [s for s in ss if KIND.get(s["code"]) == 2]
    unreachable = [s for s in input_sites if s["unreachable"]]
    reachable = [s for s in input_sites if not s["unreachable"]]
    hit_input = [s for s in input_sites if s["hits"]]
    hit_all = [s for s in ss if s["hits"]]
    print("error runs checked: %d, of %d specs and inputs (%d lines of error_inputs.txt)" % (
        nchecked, len(specs), sum(1 for sp in specs if sp[0].startswith("error_inputs.txt"))))
    print("error sites in src/: %d (sites of one format counted once); input-error sites (exit 2): %d, of which %d "
          "no input reaches (UNREACHABLE)" % (len(ss), len(input_sites), len(unreachable)))
    print("sites triggered: %d of %d reachable input-error sites (%d of all %d)" % (
        len(hit_input), len(reachable), len(hit_all), len(ss)))
    print("messages from no site in src/ (PETSc's option parsing, the error handler's rewording): %d" % len(unmatched))
    if args.untriggered:
        for u in unmatched:
            print("from no site: " + u)
    for u in unnamed:
        print("names no option, value or file: " + u)
    if args.untriggered:
        for s in reachable:
            if not s["hits"]:
                print("untriggered: %s %s" % (s["where"], s["code"]))
        for s in unreachable:
            print("unreachable: %s %s: %s" % (s["where"], s["code"], s["unreachable"]))
    if args.untriggered:
        for n, t in sorted(TIMES.items(), key=lambda x: -x[1])[:8]:
            print("slowest: %s %.1f s" % (n, t))
    if len(hit_input) < args.min_triggered:
        failures.append("coverage: %d reachable input-error sites triggered, fewer than --min-triggered %d (an input no "
                        "longer reaches its site: --untriggered lists them)" % (len(hit_input), args.min_triggered))
    for f in failures:
        print("FAIL " + f)
    print("%d runs failed a check" % len(failures))
    if not failures:
        print("error walk: every error run exits with a code of README's table and its site's kind, one message, "
              "nothing written")
    shutil.rmtree(args.work, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

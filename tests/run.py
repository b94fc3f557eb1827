#!/usr/bin/env python3
"""Tolerance-aware regression test runner for phlex.

Each test is described by a spec file ``tests/cases/<name>.test``; the runner
runs ``bin/phlex`` (directly, or under ``mpiexec`` when ``nsize`` > 1),
filters its stdout, and compares it token by token with
``tests/output/<name>.out``, and produced CSV series column by column with
``tests/ref/``.  Numbers are compared with relative/absolute/zero tolerances,
everything else exactly.  Results are printed as TAP-like lines followed by a
summary line ``N passed, N failed[, N skipped]``.

Python 3 standard library only.  See tests/README.md for the spec format.
"""

import argparse
import concurrent.futures
import csv
import fnmatch
import functools
import io
import math
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from typing import Dict, List, NamedTuple, Optional, Sequence, Tuple

TESTS_DIR = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(TESTS_DIR)

MAX_DIFFS = 5          # differences listed per compared file
TAIL_LINES = 40        # stdout/stderr lines shown on failure in verbose mode
SHORT_TAIL_LINES = 10  # stderr lines shown on exit-status failures otherwise (the first and the last as many)
REASON_WIDTH = 160     # maximum width of the reason on a "not ok" line

# --------------------------------------------------------------------------
# Tokenizing and numeric comparison
# --------------------------------------------------------------------------

_NUM_CORE = r"""[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|nan|inf(?:inity)?)"""

# A number inside a line: not glued to a preceding word character or '.',
# not followed by a word character or by '.<digit>' (so "body0.h5", "x86_64",
# "1.2.3", "info" and "banana" stay words, while "f=83.68," splits).
NUMBER_RE = re.compile(r"(?<![\w.])" + _NUM_CORE + r"(?!\w|\.\d)", re.IGNORECASE)
NUMBER_FULL_RE = re.compile(_NUM_CORE, re.IGNORECASE)
INTEGER_RE = re.compile(r"[+-]?\d+")


class Token(NamedTuple):
    """One token of a line: kind is 'word', 'int' or 'float'."""

    kind: str
    text: str
    value: Optional[float] = None


class Tol(NamedTuple):
    """Numeric tolerances: |a-b| <= atol + rtol*|b|, or both |x| < ztol."""

    rtol: float = 1e-8
    atol: float = 0.0
    ztol: float = 0.0


def number_token(text: str) -> Token:
    """Make an 'int' or 'float' token from text that is known to be a number."""
    if INTEGER_RE.fullmatch(text):
        return Token("int", text, float(text))
    return Token("float", text, float(text))


def tokenize(line: str) -> List[Token]:
    """Split a line into word and number tokens.

    The line is split at whitespace; inside each piece numbers are split off
    from surrounding punctuation, e.g. ``f=83.68,`` -> ``f=``, ``83.68``, ``,``.
    """
    tokens: List[Token] = []
    for piece in line.split():
        pos = 0
        for match in NUMBER_RE.finditer(piece):
            if match.start() > pos:
                tokens.append(Token("word", piece[pos:match.start()]))
            tokens.append(number_token(match.group()))
            pos = match.end()
        if pos < len(piece):
            tokens.append(Token("word", piece[pos:]))
    return tokens


def parse_cell(cell: str) -> Token:
    """Classify one CSV cell (already stripped) as a number or a word."""
    if NUMBER_FULL_RE.fullmatch(cell):
        return number_token(cell)
    return Token("word", cell)


def numbers_close(expected: float, got: float, tol: Tol) -> bool:
    """Tolerance rule: both NaN; equal infinities; both below ztol; or
    |got - expected| <= atol + rtol*|expected|."""
    if math.isnan(expected) or math.isnan(got):
        return math.isnan(expected) and math.isnan(got)
    if math.isinf(expected) or math.isinf(got):
        return expected == got
    if abs(expected) < tol.ztol and abs(got) < tol.ztol:
        return True
    return abs(got - expected) <= tol.atol + tol.rtol * abs(expected)


def tokens_match(expected: Token, got: Token, tol: Tol) -> bool:
    """Compare two tokens: words exactly, two integers exactly, otherwise
    numbers (float vs float, or integer vs float) with the tolerance rule."""
    if expected.kind == "word" or got.kind == "word":
        return expected.kind == got.kind and expected.text == got.text
    if expected.kind == "int" and got.kind == "int":
        return int(expected.text) == int(got.text)
    return numbers_close(expected.value, got.value, tol)


def relative_error(expected: float, got: float) -> float:
    """|got-expected| / |expected| (absolute error when expected is 0)."""
    if math.isnan(expected) or math.isnan(got):
        return 0.0 if math.isnan(expected) and math.isnan(got) else math.inf
    if math.isinf(expected) or math.isinf(got):
        return 0.0 if expected == got else math.inf
    err = abs(got - expected)
    return err / abs(expected) if expected != 0 else err


def error_note(expected: Token, got: Token) -> str:
    """A ' (abs err .., rel err ..)' note for two numeric tokens, else ''."""
    if expected.kind == "word" or got.kind == "word":
        return ""
    if math.isnan(expected.value) or math.isnan(got.value):
        return ""
    if math.isinf(expected.value) or math.isinf(got.value):
        return ""
    if expected.kind == "int" and got.kind == "int":
        return ""
    err = abs(got.value - expected.value)
    note = f" (abs err {err:.3g}"
    if expected.value != 0:
        note += f", rel err {err / abs(expected.value):.3g}"
    return note + ")"


def shorten(text: str, width: int = 100) -> str:
    """Truncate text to width characters, marking the cut with '...'."""
    return text if len(text) <= width else text[: width - 3] + "..."


# --------------------------------------------------------------------------
# Text (stdout) comparison
# --------------------------------------------------------------------------


class Diff(NamedTuple):
    """One reported difference: a one-line summary plus detail lines."""

    summary: str
    details: Tuple[str, ...] = ()


def compare_line(lineno: int, expected: str, got: str, tol: Tol) -> Optional[Diff]:
    """Compare one line token by token; return a Diff or None if equal."""
    etoks, gtoks = tokenize(expected), tokenize(got)
    details = (f"  expected: {shorten(expected.strip(), 200)}",
               f"       got: {shorten(got.strip(), 200)}")
    if len(etoks) != len(gtoks):
        return Diff(f"line {lineno}: expected {len(etoks)} tokens, got {len(gtoks)}", details)
    for etok, gtok in zip(etoks, gtoks):
        if not tokens_match(etok, gtok, tol):
            return Diff(f"line {lineno}: expected {shorten(etok.text, 40)} "
                        f"got {shorten(gtok.text, 40)}{error_note(etok, gtok)}", details)
    return None


def compare_text(expected: str, got: str, tol: Tol, max_diffs: int = MAX_DIFFS) -> List[Diff]:
    """Compare two texts line by line with token-wise tolerances.

    Returns the differences (empty when the texts match).  A line-count
    mismatch is reported first, followed by the first differing lines of the
    common part, up to max_diffs in all.
    """
    elines, glines = expected.splitlines(), got.splitlines()
    diffs: List[Diff] = []
    if len(elines) != len(glines):
        diffs.append(Diff(f"expected {len(elines)} lines, got {len(glines)}"))
    for lineno, (eline, gline) in enumerate(zip(elines, glines), start=1):
        if len(diffs) >= max_diffs:
            break
        diff = compare_line(lineno, eline, gline, tol)
        if diff:
            diffs.append(diff)
    if len(elines) != len(glines) and len(diffs) < max_diffs:
        n = min(len(elines), len(glines)) + 1
        extra = elines if len(elines) > len(glines) else glines
        which = "expected" if len(elines) > len(glines) else "got"
        diffs.append(Diff(f"line {n}: only in {which}: {shorten(extra[n - 1].strip())}"))
    return diffs


# --------------------------------------------------------------------------
# CSV comparison
# --------------------------------------------------------------------------


class CsvTable(NamedTuple):
    """A parsed CSV file: header names and data rows (stripped cells)."""

    header: List[str]
    rows: List[List[str]]


class CsvResult(NamedTuple):
    """Outcome of comparing two CSV tables."""

    diffs: List[Diff]
    notes: List[str]  # informational lines for verbose mode


def parse_csv(text: str) -> CsvTable:
    """Parse CSV text: first non-blank row is the header; blank rows are skipped."""
    rows = [[cell.strip() for cell in row]
            for row in csv.reader(io.StringIO(text))
            if any(cell.strip() for cell in row)]
    if not rows:
        return CsvTable([], [])
    return CsvTable(rows[0], rows[1:])


def column_errors(ref: CsvTable, out: CsvTable, name: str) -> Tuple[float, int]:
    """Max relative error (and its 1-based row) over the numeric cells of a column."""
    ri, oi = ref.header.index(name), out.header.index(name)
    worst, worst_row = 0.0, 0
    for row, (rrow, orow) in enumerate(zip(ref.rows, out.rows), start=1):
        if ri >= len(rrow) or oi >= len(orow):
            continue
        rtok, otok = parse_cell(rrow[ri]), parse_cell(orow[oi])
        if rtok.kind != "word" and otok.kind != "word":
            err = relative_error(rtok.value, otok.value)
            if err > worst:
                worst, worst_row = err, row
    return worst, worst_row


def compare_csv(expected: str, got: str, tol: Tol, columns: Optional[Sequence[str]] = None,
                label: str = "csv", max_diffs: int = MAX_DIFFS,
                column_atol: Optional[Dict[str, float]] = None) -> CsvResult:
    """Compare produced CSV text (got) with reference CSV text (expected).

    Only the reference's columns (or the given subset) are compared; extra
    produced columns are allowed and mentioned in the notes.  Rows are
    numbered from 1 for the first data row after the header.
    """
    ref, out = parse_csv(expected), parse_csv(got)
    diffs: List[Diff] = []
    notes: List[str] = []
    wanted = list(columns) if columns else list(ref.header)
    for name in wanted:
        if name not in ref.header:
            diffs.append(Diff(f"{label}: column {name} not in the reference"))
    missing = [n for n in wanted if n in ref.header and n not in out.header]
    if missing:
        diffs.append(Diff(f"{label}: missing column{'s' if len(missing) > 1 else ''} "
                          f"{', '.join(missing)}",
                          (f"  produced columns: {', '.join(out.header)}",)))
    extra = [n for n in out.header if n not in ref.header]
    if extra:
        notes.append(f"{label}: extra produced columns (not compared): {', '.join(extra)}")
    if len(ref.rows) != len(out.rows):
        diffs.append(Diff(f"{label}: expected {len(ref.rows)} rows, got {len(out.rows)}"))
    common = [n for n in wanted if n in ref.header and n in out.header]
    diffs.extend(compare_cells(ref, out, common, tol, label, max_diffs - len(diffs), column_atol))
    for name in common:
        worst, row = column_errors(ref, out, name)
        notes.append(f"{label}: column {name}: max rel err {worst:.3g}"
                     + (f" (row {row})" if row else ""))
    return CsvResult(diffs[: max(max_diffs, 1)], notes)


def compare_cells(ref: CsvTable, out: CsvTable, names: Sequence[str], tol: Tol,
                  label: str, limit: int, column_atol: Optional[Dict[str, float]] = None) -> List[Diff]:
    """Compare the named columns cell by cell over the common rows (a column of column_atol with its own
    absolute tolerance)."""
    diffs: List[Diff] = []
    indices = [(n, ref.header.index(n), out.header.index(n)) for n in names]
    tols = {n: Tol(tol.rtol, column_atol[n], tol.ztol) if column_atol and n in column_atol else tol for n in names}
    for row, (rrow, orow) in enumerate(zip(ref.rows, out.rows), start=1):
        for name, ri, oi in indices:
            if len(diffs) >= limit:
                return diffs
            rcell = rrow[ri] if ri < len(rrow) else None
            ocell = orow[oi] if oi < len(orow) else None
            if rcell is None or ocell is None:
                if rcell != ocell:
                    diffs.append(Diff(f"{label} column {name} row {row}: expected "
                                      f"{rcell if rcell is not None else '(missing cell)'} got "
                                      f"{ocell if ocell is not None else '(missing cell)'}"))
                continue
            rtok, otok = parse_cell(rcell), parse_cell(ocell)
            if not tokens_match(rtok, otok, tols[name]):
                diffs.append(Diff(f"{label} column {name} row {row}: expected {shorten(rcell, 40)} "
                                  f"got {shorten(ocell, 40)}{error_note(rtok, otok)}"))
    return diffs


# --------------------------------------------------------------------------
# Spec files
# --------------------------------------------------------------------------

KNOWN_KEYS = {
    "description", "args", "nsize", "requires", "filter", "output", "csv", "columns",
    "rtol", "atol", "ztol", "csv_rtol", "csv_atol", "csv_ztol", "csv_column_atol", "timeout", "exit",
    "stderr", "files_absent", "files_present", "ref_source", "setup", "post",
}

# the keys of one run; a test of several runs numbers them from the second on: args2, exit2, stderr2, nsize2, filter2
RUN_KEYS = ("args", "nsize", "exit", "stderr", "filter")
RUN_KEY_RE = re.compile(r"(" + "|".join(RUN_KEYS) + r")([2-9]|[1-9][0-9]+)")

# requirement -> petscconf.h macro (None: always available)
FEATURES = {
    "mumps": "PETSC_HAVE_MUMPS",
    "hdf5": "PETSC_HAVE_HDF5",
    "superlu": "PETSC_HAVE_SUPERLU",
    "superlu_dist": "PETSC_HAVE_SUPERLU_DIST",
    "cholmod": "PETSC_HAVE_SUITESPARSE",
    "suitesparse": "PETSC_HAVE_SUITESPARSE",
    "ptscotch": "PETSC_HAVE_PTSCOTCH",
    "hypre": "PETSC_HAVE_HYPRE",
    "mpi2": None,
}

# requirement -> a program that must be on PATH (a tool a test's filter runs besides phlex)
TOOLS = {
    "paraview": "pvbatch",
    "xvfb": "Xvfb",
    "h5dump": "h5dump",  # Debian's hdf5-tools: tests/tools/compare_fields.py reads field files with it
}

NAME_RE = re.compile(r"[A-Za-z0-9_.+-]+")


class SpecError(Exception):
    """A malformed test spec."""


class Run(NamedTuple):
    """One run of bin/phlex in a test: its arguments and what the runner checks of it."""

    args: List[str]
    nsize: int
    exit: str                      # "0", "nonzero" or an integer as text
    stderr: Optional["re.Pattern[str]"]
    filter: Optional[str]          # shell command its stdout is piped through; None: compared whole
    compared: bool = True          # False (filter: none): its stdout is not compared


class Spec(NamedTuple):
    """A parsed test spec (see tests/README.md). args, nsize, exit, stderr and filter are the first run's; runs
    holds every run, the first one first."""

    name: str
    description: str
    args: List[str]
    nsize: int
    requires: List[str]
    filter: Optional[str]
    output: Optional[str]          # file name under the expected dir, or None
    csv: List[Tuple[str, str]]     # (produced rel. to outdir, reference rel. to ref dir)
    columns: Optional[List[str]]
    tol: Tol
    csv_tol: Tol
    timeout: float
    exit: str                      # "0", "nonzero" or an integer as text
    stderr: Optional["re.Pattern[str]"]
    files_absent: List[str]
    files_present: List[str]
    ref_source: Optional[str] = None  # how the reference CSVs were made (not phlex): --update leaves them alone
    column_atol: Optional[Dict[str, float]] = None  # CSV columns with their own absolute tolerance
    runs: Tuple[Run, ...] = ()     # every run (empty: the one run of args, nsize, exit, stderr, filter)
    setup: Optional[str] = None    # shell command before the first run
    post: Optional[str] = None     # shell command after the last run; its stdout is compared after the runs'

    def all_runs(self) -> Tuple[Run, ...]:
        """The runs of the test (a spec built without runs: its one run)."""
        if self.runs:
            return self.runs
        filt = self.filter
        return (Run(self.args, self.nsize, self.exit, self.stderr, None if filt == "none" else filt, filt != "none"),)

    def max_nsize(self) -> int:
        """The largest number of MPI ranks of any run (a test with more than one runs alone)."""
        return max(r.nsize for r in self.all_runs())


def parse_column_atol(text: str) -> Dict[str, float]:
    """``name=value`` pairs (whitespace separated): CSV columns with their own absolute tolerance."""
    out: Dict[str, float] = {}
    for item in text.split():
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise SpecError(f"csv_column_atol: expected name=value, got {item!r}")
        try:
            out[name] = float(value)
        except ValueError:
            raise SpecError(f"csv_column_atol: {name}: not a number: {value!r}") from None
        if out[name] < 0:
            raise SpecError(f"csv_column_atol: {name}: must be >= 0, got {value}")
    return out


def read_spec_lines(text: str) -> Dict[str, str]:
    """Read ``key: value`` lines into a dict.

    Lines whose first non-blank character is '#' are comments, blank lines are
    ignored, and lines starting with whitespace continue the previous value
    (joined with a single space).
    """
    values: Dict[str, str] = {}
    key = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        if raw[0].isspace():
            if key is None:
                raise SpecError(f"line {lineno}: continuation line before any key")
            values[key] = (values[key] + " " + stripped).strip()
            continue
        key, sep, value = raw.partition(":")
        key = key.strip()
        if not sep or not key:
            raise SpecError(f"line {lineno}: expected 'key: value', got {shorten(stripped, 60)!r}")
        if key not in KNOWN_KEYS and not RUN_KEY_RE.fullmatch(key):
            raise SpecError(f"line {lineno}: unknown key {key!r}")
        if key in values:
            raise SpecError(f"line {lineno}: duplicate key {key!r}")
        values[key] = value.strip()
    return values


def split_list(value: str) -> List[str]:
    """Split a space- and/or comma-separated list."""
    return [item for item in re.split(r"[\s,]+", value) if item]


def parse_float(values: Dict[str, str], key: str, default: float) -> float:
    """Read a non-negative float option."""
    if key not in values:
        return default
    try:
        number = float(values[key])
    except ValueError:
        raise SpecError(f"{key}: not a number: {values[key]!r}") from None
    if not number >= 0:
        raise SpecError(f"{key}: must be >= 0, got {values[key]!r}")
    return number


def parse_timeout(values: Dict[str, str]) -> float:
    """The timeout in seconds (default 300, must be > 0)."""
    timeout = parse_float(values, "timeout", 300.0)
    if timeout == 0:
        raise SpecError("timeout: must be > 0")
    return timeout


def parse_tolerances(values: Dict[str, str]) -> Tuple[Tol, Tol]:
    """Stdout tolerances and CSV tolerances (csv_* override each one)."""
    tol = Tol(parse_float(values, "rtol", 1e-8), parse_float(values, "atol", 0.0),
              parse_float(values, "ztol", 0.0))
    csv_tol = Tol(parse_float(values, "csv_rtol", tol.rtol), parse_float(values, "csv_atol", tol.atol),
                  parse_float(values, "csv_ztol", tol.ztol))
    return tol, csv_tol


def parse_csv_pairs(value: str) -> List[Tuple[str, str]]:
    """Parse ``produced:reference`` pairs separated by whitespace."""
    pairs = []
    for item in value.split():
        produced, sep, reference = item.partition(":")
        if not sep or not produced or not reference:
            raise SpecError(f"csv: expected produced:reference, got {item!r}")
        pairs.append((produced, reference))
    return pairs


def parse_exit(value: str, key: str = "exit") -> str:
    """Validate the 'exit' key (or exit<k>): 0, nonzero or an integer."""
    if value == "nonzero" or re.fullmatch(r"[+-]?\d+", value):
        return value if value == "nonzero" else str(int(value))
    raise SpecError(f"{key}: expected 0, nonzero or an integer, got {value!r}")


def parse_nsize(values: Dict[str, str], key: str, default: int) -> int:
    """A number of MPI ranks (>= 1)."""
    try:
        nsize = int(values.get(key, str(default)))
    except ValueError:
        raise SpecError(f"{key}: not an integer: {values[key]!r}") from None
    if nsize < 1:
        raise SpecError(f"{key}: must be >= 1, got {nsize}")
    return nsize


def parse_run(values: Dict[str, str], k: int, nsize: int) -> Run:
    """The keys of run k (1: args, exit, ...; k >= 2: args<k>, exit<k>, ...; nsize<k> defaults to nsize)."""
    suffix = "" if k == 1 else str(k)
    try:
        args = shlex.split(values["args" + suffix])
    except ValueError as err:
        raise SpecError(f"args{suffix}: {err}") from None
    stderr = None
    if "stderr" + suffix in values:
        try:
            stderr = re.compile(values["stderr" + suffix], re.DOTALL)
        except re.error as err:
            raise SpecError(f"stderr{suffix}: bad regular expression: {err}") from None
    exit_value = parse_exit(values.get("exit" + suffix, "0"), "exit" + suffix)
    filt = values.get("filter" + suffix) or None
    return Run(args=args, nsize=parse_nsize(values, "nsize" + suffix, nsize) if k > 1 else nsize, exit=exit_value,
               stderr=stderr, filter=None if filt == "none" else filt, compared=filt != "none")


def parse_runs(values: Dict[str, str], nsize: int) -> Tuple[Run, ...]:
    """Run 1 and the numbered runs 2, 3, ... (their args<k> consecutive; no other key of a run without args)."""
    numbers = sorted({int(m.group(2)) for m in map(RUN_KEY_RE.fullmatch, values) if m})
    count = 1
    while f"args{count + 1}" in values:
        count += 1
    for k in numbers:
        if k > count:
            key = next(key for key in values if RUN_KEY_RE.fullmatch(key) and int(RUN_KEY_RE.fullmatch(key).group(2)) == k)
            if key.startswith("args"):
                raise SpecError(f"{key} without args{count + 1}: number the runs 2, 3, ... without a gap")
            raise SpecError(f"{key} without args{k}")
    return tuple(parse_run(values, k, nsize) for k in range(1, count + 1))


def parse_spec(name: str, text: str) -> Spec:
    """Parse the text of ``<name>.test`` into a Spec, raising SpecError."""
    values = read_spec_lines(text)
    if "args" not in values:
        raise SpecError("missing required key 'args'")
    nsize = parse_nsize(values, "nsize", 1)
    requires = [r.lower() for r in split_list(values.get("requires", ""))]
    for feature in requires:
        if feature not in FEATURES and feature not in TOOLS and feature not in PROBES:
            raise SpecError(f"requires: unknown feature {feature!r} "
                            f"(known: {', '.join(sorted({**FEATURES, **TOOLS, **PROBES}))})")
    output = values.get("output", f"{name}.out")
    runs = parse_runs(values, nsize)
    tol, csv_tol = parse_tolerances(values)
    columns = split_list(values["columns"]) if "columns" in values else None
    first = runs[0]
    return Spec(
        name=name,
        description=values.get("description", ""),
        args=first.args,
        nsize=nsize,
        requires=requires,
        filter=values.get("filter") or None,
        output=None if output.lower() == "none" else output,
        csv=parse_csv_pairs(values.get("csv", "")),
        columns=columns or None,
        tol=tol,
        csv_tol=csv_tol,
        timeout=parse_timeout(values),
        exit=first.exit,
        stderr=first.stderr,
        files_absent=values.get("files_absent", "").split(),
        files_present=values.get("files_present", "").split(),
        ref_source=values.get("ref_source") or None,
        column_atol=parse_column_atol(values.get("csv_column_atol", "")) or None,
        runs=runs,
        setup=values.get("setup") or None,
        post=values.get("post") or None,
    )


# --------------------------------------------------------------------------
# PETSc features
# --------------------------------------------------------------------------


def petscconf_candidates() -> List[str]:
    """Possible locations of petscconf.h: pkg-config first, then PETSC_DIR."""
    paths = []
    try:
        incdir = subprocess.run(["pkg-config", "--variable=includedir", "petsc"],
                                capture_output=True, text=True, timeout=30).stdout.strip()
        if incdir:
            paths.append(os.path.join(incdir, "petscconf.h"))
    except (OSError, subprocess.SubprocessError):
        pass
    petsc_dir = os.environ.get("PETSC_DIR")
    if petsc_dir:
        arch = os.environ.get("PETSC_ARCH", "")
        if arch:
            paths.append(os.path.join(petsc_dir, arch, "include", "petscconf.h"))
        paths.append(os.path.join(petsc_dir, "include", "petscconf.h"))
    return paths


def petsc_macros() -> Optional[set]:
    """The PETSC_HAVE_* macros defined to 1 in petscconf.h (None if not found)."""
    for path in petscconf_candidates():
        try:
            with open(path, encoding="utf-8", errors="replace") as fh:
                text = fh.read()
        except OSError:
            continue
        return set(re.findall(r"^\s*#\s*define\s+(PETSC_HAVE_\w+)\s+1\b", text, re.MULTILINE))
    return None


@functools.lru_cache(maxsize=None)
def openblas_available() -> bool:
    """The BLAS phlex links (-lblas: the system's libblas.so.3) is OpenBLAS with kernels for several x86-64 processors
    (Debian's, which make deps installs): the tests of -openblas_coretype need it."""
    import ctypes
    import platform
    if platform.machine() not in ("x86_64", "AMD64"):
        return False
    try:
        lib = ctypes.CDLL("libblas.so.3")
    except OSError:
        return False
    return all(hasattr(lib, f) for f in ("openblas_get_corename", "gotoblas_dynamic_init"))


# requirement -> a probe of this machine (neither a PETSc macro nor a program)
PROBES = {
    "openblas": openblas_available,
}


def missing_features(requires: Sequence[str], macros: Optional[set]) -> List[str]:
    """The required features that this PETSc installation lacks, and the tools not on PATH
    (named 'feature (program not on PATH)')."""
    missing = []
    for feature in requires:
        if feature in TOOLS:
            if shutil.which(TOOLS[feature]) is None:
                missing.append(f"{feature} ({TOOLS[feature]} not on PATH)")
            continue
        if feature in PROBES:
            if not PROBES[feature]():
                missing.append(f"{feature} (not on this machine)")
            continue
        macro = FEATURES[feature]
        if macro is not None and (macros is None or macro not in macros):
            missing.append(feature)
    return missing


# --------------------------------------------------------------------------
# Running a test
# --------------------------------------------------------------------------


class Config(NamedTuple):
    """Runner-wide settings from the command line."""

    binary: str
    mpiexec: List[str]
    cases: str
    ref: str
    expected: str
    work: str
    verbose: bool
    update: bool


class RunOutput(NamedTuple):
    """What a finished (or timed-out) process left behind."""

    returncode: Optional[int]   # None on timeout
    stdout: str
    stderr: str
    timed_out: bool


class Result(NamedTuple):
    """The outcome of one test, ready to print."""

    name: str
    status: str                 # "ok", "fail" or "skip"
    reason: str = ""
    elapsed: Optional[float] = None
    diagnostics: Tuple[str, ...] = ()


_ACTIVE: set = set()
_ACTIVE_LOCK = threading.Lock()


def kill_group(proc: subprocess.Popen) -> None:
    """Kill a process and everything in its process group."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        try:
            proc.kill()
        except ProcessLookupError:
            pass


def kill_active() -> None:
    """Kill every test process still running (used on Ctrl-C)."""
    with _ACTIVE_LOCK:
        procs = list(_ACTIVE)
    for proc in procs:
        kill_group(proc)


def run_process(cmd: List[str], env: Dict[str, str], timeout: float,
                stdin_data: Optional[bytes] = None) -> RunOutput:
    """Run cmd in its own process group from the repo root, with a timeout."""
    proc = subprocess.Popen(cmd, cwd=ROOT, env=env, start_new_session=True,
                            stdin=subprocess.PIPE if stdin_data is not None else subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    with _ACTIVE_LOCK:
        _ACTIVE.add(proc)
    try:
        try:
            out, err = proc.communicate(stdin_data, timeout=timeout)
            timed_out = False
        except subprocess.TimeoutExpired:
            kill_group(proc)
            try:
                out, err = proc.communicate(timeout=10)
            except subprocess.TimeoutExpired:
                out, err = b"", b""
            timed_out = True
    finally:
        with _ACTIVE_LOCK:
            _ACTIVE.discard(proc)
    return RunOutput(None if timed_out else proc.returncode,
                     out.decode("utf-8", "replace"), err.decode("utf-8", "replace"), timed_out)


def test_env(session_base: Optional[str] = None) -> Dict[str, str]:
    """The environment for test processes: ours plus OpenMPI settings.

    OMPI_MCA_ess_singleton_isolated: a process started without mpiexec does not spawn an
    orted (which costs seconds on some machines, e.g. a fresh chroot).
    OMPI_MCA_orte_tmpdir_base: each run's own Open MPI session directory (session_base, made and removed by the
    runner). Isolated singletons otherwise share one, /tmp/ompi.<host>.<uid>/jf.0/1: two starting at once can fail
    in its mkdir ('File exists', exit 1: log_view_stages once), and MPI-IO's shared-file-pointer component makes a
    file there named after the file opened, where two runs writing checkpoint.h5 at once collided ('unable to open
    file for mmap' on stderr)."""
    env = dict(os.environ)
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", OMPI_MCA_ess_singleton_isolated="1")
    if session_base:
        env["OMPI_MCA_orte_tmpdir_base"] = session_base
    return env


def outdir_paths(spec: Spec, cfg: Config) -> Tuple[str, str]:
    """(absolute outdir, outdir as substituted into args: relative to root if inside it)."""
    absdir = os.path.join(cfg.work, spec.name)
    rel = os.path.relpath(absdir, ROOT)
    return absdir, (absdir if rel.startswith("..") else rel)


LOG_RE = re.compile(r"\{(stdout|stderr)([1-9][0-9]*)\}")


def substitute(text: str, outdir: str, logdir: Optional[str] = None) -> str:
    """Replace the {outdir} and {root} placeholders, and {stdout<k>} / {stderr<k>} (the files holding run k's
    output, under logdir) when logdir is given."""
    text = text.replace("{outdir}", outdir).replace("{root}", ROOT)
    if logdir is not None:
        text = LOG_RE.sub(lambda m: os.path.join(logdir, f"run{m.group(2)}.{m.group(1)}"), text)
    return text


def build_command(run: Run, cfg: Config, outdir: str, logdir: Optional[str] = None) -> List[str]:
    """The command line of a run: the binary, under mpiexec if its nsize > 1."""
    args = [substitute(a, outdir, logdir) for a in run.args]
    if run.nsize > 1:
        return cfg.mpiexec + ["--oversubscribe", "-n", str(run.nsize), cfg.binary] + args
    return [cfg.binary] + args


def describe_exit(code: Optional[int]) -> str:
    """Human-readable process status."""
    if code is not None and code < 0:
        try:
            return f"killed by signal {-code} ({signal.Signals(-code).name})"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit status {code}"


def exit_ok(expected: str, code: int) -> bool:
    """Does the exit code satisfy the spec's 'exit' value?

    'nonzero' means a normal exit with non-zero status: death by a signal
    (negative return code) does not count as a clean error exit.
    """
    if expected == "nonzero":
        return code > 0
    return code == int(expected)


CRASH_RE = re.compile(r"Segmentation|SEGV|Caught signal|exited on signal|terminated with signal"
                      r"|killed by signal")

# an option given to a run that ended normally and never read it: phlex's end-of-run warning, PETSc's -options_left
# report (an option of the scene file or of a solver preset that is for another analysis is not one: phlex warns
# about those by design)
UNUSED_RE = re.compile(r"^.*(?:was never used \(misspelt\?\)|There are options you set that were not used"
                       r"|^Option left: name:).*$", re.MULTILINE)


def tail(text: str, n: int) -> List[str]:
    """The last n lines of text."""
    return text.splitlines()[-n:]


def head_and_tail(text: str, n: int) -> List[str]:
    """The first and the last n lines of text (a failed run's cause is often at the top, e.g. a library's message
    before PETSc's trace, whose configure line and call stack fill the end)."""
    lines = text.splitlines()
    if len(lines) <= 2 * n:
        return lines
    return lines[:n] + [f"... ({len(lines) - 2 * n} lines)"] + lines[-n:]


class Checker:
    """Collects the problems found while checking one test run."""

    def __init__(self) -> None:
        self.problems: List[Diff] = []
        self.notes: List[str] = []

    def fail(self, summary: str, details: Sequence[str] = ()) -> None:
        """Record one problem."""
        self.problems.append(Diff(summary, tuple(details)))

    def extend(self, prefix: str, diffs: Sequence[Diff]) -> None:
        """Record comparison differences, prefixing their summaries."""
        for diff in diffs:
            self.fail(f"{prefix}{diff.summary}", diff.details)


def shell_env() -> Dict[str, str]:
    """The environment of a filter, a setup or a post command."""
    # a filter may start phlex itself with mpiexec, which refuses root without OMPI_ALLOW_RUN_AS_ROOT; not the other
    # settings of test_env(): singletons isolated from an orted share one session directory, and two filters' runs
    # writing checkpoint.h5 at once then collide in Open MPI's shared-file-pointer files
    env = os.environ.copy()
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def apply_filter(command: Optional[str], stdin_text: str, outdir: str, logdir: Optional[str], timeout: float,
                 chk: Checker, what: str = "filter") -> Optional[str]:
    """Pipe stdin_text through a shell command (sh -c): a run's filter, or the post command (stdin empty); the
    command's stdout, or None when it failed. No command: stdin_text itself.

    Exit status 1 is accepted (grep matching nothing); higher ones are errors.
    """
    if not command:
        return stdin_text
    res = run_process(["sh", "-c", substitute(command, outdir, logdir)], shell_env(), timeout,
                      stdin_data=stdin_text.encode("utf-8"))
    if res.timed_out or res.returncode not in (0, 1):
        chk.fail(f"{what} failed ({'timeout' if res.timed_out else describe_exit(res.returncode)})",
                 [f"  {what}: {command}"] + ["  " + l for l in tail(res.stderr, 5)])
        return None
    return res.stdout


def read_text(path: str) -> Optional[str]:
    """A file's text, or None if it cannot be read."""
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            return fh.read()
    except OSError:
        return None


def write_if_changed(path: str, data: bytes) -> bool:
    """Write data to path unless it already holds exactly that; True if written."""
    try:
        with open(path, "rb") as fh:
            if fh.read() == data:
                return False
    except OSError:
        pass
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "wb") as fh:
        fh.write(data)
    return True


def rel(path: str) -> str:
    """A path relative to the repo root when inside it, for messages."""
    r = os.path.relpath(path, ROOT)
    return path if r.startswith("..") else r


def check_stdout(spec: Spec, cfg: Config, filtered: str, chk: Checker) -> None:
    """Compare (or, with --update, store) the filtered stdout."""
    path = os.path.join(cfg.expected, spec.output)
    if cfg.update:
        if write_if_changed(path, filtered.encode("utf-8")):
            chk.notes.append(f"updated {rel(path)}")
        return
    expected = read_text(path)
    if expected is None:
        chk.fail(f"missing expected output {rel(path)} (create it with --update)")
        return
    chk.extend("stdout ", compare_text(expected, filtered, spec.tol))


def check_csvs(spec: Spec, cfg: Config, absdir: str, chk: Checker) -> None:
    """Compare (or, with --update, copy over) each produced CSV with its reference."""
    seen_columns: set = set()
    compared = False
    for produced, reference in spec.csv:
        ppath, rpath = os.path.join(absdir, produced), os.path.join(cfg.ref, reference)
        got = read_text(ppath)
        if got is None:
            chk.fail(f"{produced} was not produced")
            continue
        if cfg.update and spec.ref_source:
            chk.notes.append(f"{rel(rpath)} not updated: it comes from {spec.ref_source}")
        elif cfg.update:
            with open(ppath, "rb") as fh:
                if write_if_changed(rpath, fh.read()):
                    chk.notes.append(f"updated {rel(rpath)}")
            continue
        expected = read_text(rpath)
        if expected is None:
            chk.fail(f"missing reference {rel(rpath)} (create it with --update)")
            continue
        seen_columns.update(parse_csv(expected).header)
        compared = True
        result = compare_csv(expected, got, spec.csv_tol, spec.columns, label=produced, column_atol=spec.column_atol)
        chk.extend("", result.diffs)
        if cfg.verbose:
            chk.notes.extend(result.notes)
    unknown = sorted(set(spec.column_atol or {}) - seen_columns)
    if compared and unknown:
        chk.fail(f"csv_column_atol names column{'s' if len(unknown) > 1 else ''} in no compared reference: "
                 f"{', '.join(unknown)}")


def check_files(spec: Spec, absdir: str, chk: Checker) -> None:
    """files_absent / files_present checks relative to the outdir."""
    for item in spec.files_absent:
        if item == "outdir-empty":
            if os.path.isdir(absdir) and os.listdir(absdir):
                chk.fail("outdir not empty", ["  left behind: " + ", ".join(sorted(os.listdir(absdir)))])
        elif item == "outdir-no-results":
            # a numerical failure: nothing but the series so far, apart in failed/
            left = sorted(set(os.listdir(absdir)) - {"failed"}) if os.path.isdir(absdir) else []
            if left:
                chk.fail("outdir holds results", ["  left behind: " + ", ".join(left)])
        elif os.path.lexists(os.path.join(absdir, item)):
            chk.fail(f"{item} exists but should not")
    for item in spec.files_present:
        if not os.path.exists(os.path.join(absdir, item)):
            chk.fail(f"{item} was not produced")


def stderr_pattern(pattern: "re.Pattern[str]", outdir: str) -> "re.Pattern[str]":
    """A stderr regex with {outdir} and {root} replaced by the paths, escaped."""
    if "{outdir}" not in pattern.pattern and "{root}" not in pattern.pattern:
        return pattern
    text = pattern.pattern.replace("{outdir}", re.escape(outdir)).replace("{root}", re.escape(ROOT))
    return re.compile(text, pattern.flags)


def check_stderr(run: Run, out: RunOutput, chk: Checker, prefix: str = "", outdir: str = "") -> None:
    """A run's stderr regex and, for error-path runs, the crash markers; for a run that must end normally and whose
    stderr the spec leaves free, no option that went unused."""
    if run.stderr is not None or run.exit == "nonzero":
        crash = CRASH_RE.search(out.stdout + "\n" + out.stderr)
        if crash:
            chk.fail(f"{prefix}crash marker {crash.group()!r} in output")
    if run.stderr is not None and not stderr_pattern(run.stderr, outdir).search(out.stderr):
        chk.fail(f"{prefix}stderr does not match /{shorten(run.stderr.pattern, 60)}/",
                 ["  stderr: " + l for l in tail(out.stderr, SHORT_TAIL_LINES)] or ["  stderr: (empty)"])
    if run.stderr is None and run.exit == "0":
        unused = UNUSED_RE.findall(out.stderr) + UNUSED_RE.findall(out.stdout)
        if unused:
            chk.fail(f"{prefix}an option went unused: {shorten(unused[0].strip(), 100)}", ["  " + l for l in unused])


def prepare_outdir(absdir: str) -> None:
    """Delete and re-create the test's output directory."""
    shutil.rmtree(absdir, ignore_errors=True)
    os.makedirs(absdir, exist_ok=True)


def write_logs(logdir_abs: str, k: int, out: RunOutput) -> None:
    """Keep run k's stdout and stderr in <work>/<name>.runs/run<k>.stdout and .stderr (for {stdout<k>},
    {stderr<k>} and for reading after a failure)."""
    for kind, text in (("stdout", out.stdout), ("stderr", out.stderr)):
        with open(os.path.join(logdir_abs, f"run{k}.{kind}"), "w", encoding="utf-8") as fh:
            fh.write(text)


def join_texts(texts: Sequence[str]) -> str:
    """The compared text of several runs: their filtered stdouts and the post command's, each ending a line."""
    if len(texts) == 1:
        return texts[0]
    return "".join(t if not t or t.endswith("\n") else t + "\n" for t in texts)


def run_test(spec: Spec, cfg: Config) -> Result:
    """Run one (non-skipped) test: its setup, its runs in order, its post command, and check everything its spec
    asks for. A run that times out or ends with another exit status than expected stops the test."""
    absdir, outdir = outdir_paths(spec, cfg)
    logdir_abs, logdir = absdir + ".runs", outdir + ".runs"
    runs = spec.all_runs()
    diag: List[str] = []
    prepare_outdir(absdir)
    prepare_outdir(logdir_abs)
    chk = Checker()
    start = time.monotonic()
    last: Optional[RunOutput] = None
    if spec.setup:
        if cfg.verbose:
            diag.append(f"$ (setup) {substitute(spec.setup, outdir, logdir)}")
        res = run_process(["sh", "-c", substitute(spec.setup, outdir, logdir)], shell_env(), spec.timeout)
        if res.timed_out or res.returncode != 0:
            chk.fail(f"setup failed ({'timeout' if res.timed_out else describe_exit(res.returncode)})",
                     [f"  setup: {spec.setup}"] + ["  " + l for l in tail(res.stderr, 5)])
            return make_result(spec, cfg, chk, res, time.monotonic() - start, diag)
    texts: List[str] = []
    compare = spec.output is not None
    for k, run in enumerate(runs, start=1):
        prefix = f"run {k}: " if len(runs) > 1 else ""
        cmd = build_command(run, cfg, outdir, logdir)
        if cfg.verbose:
            diag.append(f"$ {shlex.join(cmd)}")
        session_base = tempfile.mkdtemp(prefix="phlex-test-ompi-")
        try:
            out = run_process(cmd, test_env(session_base), spec.timeout)
        except OSError as err:
            return Result(spec.name, "fail", f"{prefix}cannot run {cmd[0]}: {err}", time.monotonic() - start,
                          tuple(diag))
        finally:
            shutil.rmtree(session_base, ignore_errors=True)
        write_logs(logdir_abs, k, out)
        last = out
        if out.timed_out:
            chk.fail(f"{prefix}timeout", [f"  no exit after {spec.timeout:g} s"])
            return make_result(spec, cfg, chk, out, time.monotonic() - start, diag)
        if not exit_ok(run.exit, out.returncode):
            expected = "a nonzero exit status" if run.exit == "nonzero" else f"exit status {run.exit}"
            chk.fail(f"{prefix}{describe_exit(out.returncode)}, expected {expected}",
                     [] if cfg.verbose else ["  stderr: " + l for l in head_and_tail(out.stderr, SHORT_TAIL_LINES)])
            return make_result(spec, cfg, chk, out, time.monotonic() - start, diag)
        check_stderr(run, out, chk, prefix, outdir)
        if compare and run.compared:
            filtered = apply_filter(run.filter, out.stdout, outdir, logdir, spec.timeout, chk,
                                    "filter" if k == 1 else f"filter{k}")
            if filtered is None:
                compare = False
            else:
                texts.append(filtered)
    if compare and spec.post:
        posted = apply_filter(spec.post, "", outdir, logdir, spec.timeout, chk, "post")
        if posted is None:
            compare = False
        else:
            texts.append(posted)
    if compare:
        check_stdout(spec, cfg, join_texts(texts) if texts else "", chk)
    check_csvs(spec, cfg, absdir, chk)
    check_files(spec, absdir, chk)
    return make_result(spec, cfg, chk, last, time.monotonic() - start, diag)


def make_result(spec: Spec, cfg: Config, chk: Checker, run: Optional[RunOutput], elapsed: float,
                diag: List[str]) -> Result:
    """Turn the collected problems and notes into a Result."""
    if not chk.problems:
        return Result(spec.name, "ok", "", elapsed, tuple(diag + chk.notes))
    for problem in chk.problems:
        diag.append(problem.summary)
        diag.extend(problem.details)
    diag.extend(chk.notes)
    if cfg.verbose and run is not None:
        for label, text in (("stdout", run.stdout), ("stderr", run.stderr)):
            lines = tail(text, TAIL_LINES)
            diag.append(f"--- last {len(lines)} lines of {label} ---" if lines else f"--- {label}: empty ---")
            diag.extend("  " + l for l in lines)
    return Result(spec.name, "fail", chk.problems[0].summary, elapsed, tuple(diag))


# --------------------------------------------------------------------------
# Test selection and scheduling
# --------------------------------------------------------------------------


class Case(NamedTuple):
    """A selected test: its spec, or why it cannot run."""

    name: str
    spec: Optional[Spec]
    error: Optional[str]   # spec error / unknown test
    skip: Optional[str]    # skip reason


def all_test_names(cases_dir: str) -> List[str]:
    """Names of all tests in the cases directory, sorted."""
    try:
        files = os.listdir(cases_dir)
    except OSError:
        return []
    return sorted(f[: -len(".test")] for f in files if f.endswith(".test"))


def select_names(patterns: Sequence[str], available: Sequence[str]) -> List[Tuple[str, bool]]:
    """Resolve names/glob patterns to (name, exists) pairs, sorted, without duplicates.

    A pattern that matches nothing yields (pattern, False) so it can be
    reported as a failing test.
    """
    if not patterns:
        return [(n, True) for n in available]
    chosen, unknown = set(), []
    for pattern in patterns:
        pattern = os.path.basename(pattern)
        if pattern.endswith(".test"):
            pattern = pattern[: -len(".test")]
        matches = fnmatch.filter(available, pattern)
        if matches:
            chosen.update(matches)
        else:
            unknown.append(pattern)
    return sorted([(n, True) for n in chosen] + [(n, False) for n in dict.fromkeys(unknown)])


def load_case(name: str, exists: bool, cases_dir: str, macros: Optional[set]) -> Case:
    """Read and parse one test spec, deciding whether it must be skipped."""
    if not exists:
        return Case(name, None, f"no test named {name!r} in {rel(cases_dir)}", None)
    if not NAME_RE.fullmatch(name):
        return Case(name, None, "bad test name (use letters, digits, _ . + -)", None)
    text = read_text(os.path.join(cases_dir, name + ".test"))
    if text is None:
        return Case(name, None, "cannot read spec", None)
    try:
        spec = parse_spec(name, text)
    except SpecError as err:
        return Case(name, None, f"bad spec: {err}", None)
    missing = missing_features(spec.requires, macros)
    return Case(name, spec, None, f"missing {', '.join(missing)}" if missing else None)


class Reporter:
    """Prints results in test order as they become available, and counts them."""

    def __init__(self, total: int) -> None:
        self.results: List[Optional[Result]] = [None] * total
        self.next = 0
        self.counts = {"ok": 0, "fail": 0, "skip": 0}
        self.lock = threading.Lock()

    def add(self, index: int, result: Result) -> None:
        """Store a result and print all results that are now in order."""
        with self.lock:
            self.results[index] = result
            while self.next < len(self.results) and self.results[self.next] is not None:
                self.emit(self.next + 1, self.results[self.next])
                self.next += 1

    def emit(self, number: int, result: Result) -> None:
        """Print one TAP line plus its '#' diagnostics."""
        self.counts[result.status] += 1
        timing = f" ({result.elapsed:.1f} s)" if result.elapsed is not None else ""
        if result.status == "skip":
            line = f"ok {number} - {result.name} # SKIP {result.reason}"
        elif result.status == "ok":
            line = f"ok {number} - {result.name}{timing}"
        else:
            line = f"not ok {number} - {result.name}{timing}: {shorten(result.reason, REASON_WIDTH)}"
        print(line)
        for diag in result.diagnostics:
            print(f"# {diag}")
        sys.stdout.flush()

    def summary(self) -> str:
        """The final 'N passed, N failed[, N skipped]' line."""
        text = f"{self.counts['ok']} passed, {self.counts['fail']} failed"
        if self.counts["skip"]:
            text += f", {self.counts['skip']} skipped"
        return text


def run_one(case: Case, cfg: Config) -> Result:
    """Run a case, turning unexpected runner errors into a failure."""
    try:
        return run_test(case.spec, cfg)
    except Exception as err:  # keep the suite going; report the error on this test
        return Result(case.name, "fail", f"runner error: {type(err).__name__}: {err}", 0.0)


def run_cases(cases: Sequence[Case], cfg: Config, jobs: int, reporter: Reporter) -> None:
    """Run the cases with up to `jobs` at once; nsize > 1 tests run alone."""
    runnable = []
    for index, case in enumerate(cases):
        if case.error:
            reporter.add(index, Result(case.name, "fail", case.error))
        elif case.skip:
            reporter.add(index, Result(case.name, "skip", case.skip))
        else:
            runnable.append((index, case))
    jobs = max(jobs, 1)
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=jobs)
    pending: set = set()

    def submit(index: int, case: Case) -> concurrent.futures.Future:
        fut = pool.submit(run_one, case, cfg)
        fut.add_done_callback(lambda f, i=index: reporter.add(i, f.result()))
        return fut

    try:
        for index, case in runnable:
            if case.spec.max_nsize() > 1:
                concurrent.futures.wait(pending)
                pending.clear()
                concurrent.futures.wait([submit(index, case)])
                continue
            while len(pending) >= jobs:
                done, _ = concurrent.futures.wait(pending, return_when=concurrent.futures.FIRST_COMPLETED)
                pending -= done
            pending.add(submit(index, case))
        concurrent.futures.wait(pending)
    except KeyboardInterrupt:
        kill_active()  # before shutdown(), which waits for the running tests
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


# --------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------


def parse_args(argv: Sequence[str]) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(
        description="Run phlex regression tests (TAP-like output, tolerance-aware comparisons).")
    p.add_argument("names", nargs="*", help="test names or glob patterns (default: all tests)")
    p.add_argument("-v", "--verbose", action="store_true",
                   help="print command lines, CSV column errors, and output tails on failure")
    p.add_argument("--update", action="store_true",
                   help="store outputs/CSVs as the new expected results instead of comparing")
    p.add_argument("-j", "--jobs", type=int, default=1, metavar="N",
                   help="run up to N tests at once (tests with nsize > 1 run alone)")
    p.add_argument("--bin", default=os.path.join(ROOT, "bin", "phlex"), metavar="PATH",
                   help="binary under test (default: bin/phlex)")
    p.add_argument("--mpiexec", default="mpiexec", metavar="CMD",
                   help="MPI launcher command, may include options (default: mpiexec)")
    p.add_argument("--cases", default=os.path.join(TESTS_DIR, "cases"), metavar="DIR",
                   help="directory of <name>.test specs (default: tests/cases)")
    p.add_argument("--ref", default=os.path.join(TESTS_DIR, "ref"), metavar="DIR",
                   help="directory of reference CSVs (default: tests/ref)")
    p.add_argument("--expected", default=os.path.join(TESTS_DIR, "output"), metavar="DIR",
                   help="directory of expected stdout files (default: tests/output)")
    p.add_argument("--work", default=os.path.join(ROOT, "build", "tests"), metavar="DIR",
                   help="where per-test output directories are created (default: build/tests)")
    p.add_argument("--list", action="store_true", help="list the tests with their descriptions")
    return p.parse_args(argv)


def list_tests(names: Sequence[Tuple[str, bool]], cases_dir: str) -> int:
    """Print test names with descriptions; 1 if some name was unknown or broken."""
    status = 0
    width = max((len(n) for n, _ in names), default=0)
    for name, exists in names:
        case = load_case(name, exists, cases_dir, macros=set())
        if case.error:
            status = 1
            print(f"{name:<{width}}  ({case.error})")
        else:
            runs = case.spec.all_runs()
            extra = f" [nsize {case.spec.max_nsize()}]" if case.spec.max_nsize() > 1 else ""
            extra += f" [{len(runs)} runs]" if len(runs) > 1 else ""
            req = f" [requires {' '.join(case.spec.requires)}]" if case.spec.requires else ""
            print(f"{name:<{width}}  {case.spec.description}{extra}{req}")
    return status


def make_config(opts: argparse.Namespace) -> Config:
    """Build the runner configuration from parsed options."""
    return Config(binary=os.path.abspath(opts.bin), mpiexec=shlex.split(opts.mpiexec),
                  cases=os.path.abspath(opts.cases), ref=os.path.abspath(opts.ref),
                  expected=os.path.abspath(opts.expected), work=os.path.abspath(opts.work),
                  verbose=opts.verbose, update=opts.update)


def main(argv: Sequence[str]) -> int:
    """Entry point: select, run and report tests; return the exit status."""
    opts = parse_args(argv)
    cfg = make_config(opts)
    names = select_names(opts.names, all_test_names(cfg.cases))
    if opts.list:
        return list_tests(names, cfg.cases)
    reporter = Reporter(len(names))
    print(f"1..{len(names)}")
    if not (os.path.isfile(cfg.binary) and os.access(cfg.binary, os.X_OK)):
        print(f"# error: {rel(cfg.binary)} does not exist or is not executable; build it with 'make'")
        for index, (name, _) in enumerate(names):
            reporter.add(index, Result(name, "fail", f"{rel(cfg.binary)} not found"))
        print(reporter.summary())
        return 1
    macros = petsc_macros()
    cases = [load_case(name, exists, cfg.cases, macros) for name, exists in names]
    if macros is None and any(c.spec and any(FEATURES.get(f) for f in c.spec.requires) for c in cases):
        print("# warning: petscconf.h not found (pkg-config petsc); optional features count as missing")
    if cfg.update:
        print("# --update: storing outputs as the new expected results")
    try:
        run_cases(cases, cfg, opts.jobs, reporter)
    except KeyboardInterrupt:
        kill_active()
        print("# interrupted")
        print(reporter.summary())
        return 130
    print(reporter.summary())
    return 0 if reporter.counts["fail"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

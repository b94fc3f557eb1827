#!/usr/bin/env python3
"""Self-test for the comparison and spec-parsing functions of tests/run.py.

Run with:  python3 tests/test_runner_selftest.py
"""

import os
import sys
import unittest
from unittest import mock

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import run  # noqa: E402  (tests/run.py)
from run import Tol, Token  # noqa: E402


def kinds_and_texts(line):
    """Tokenize a line into (kind, text) pairs."""
    return [(t.kind, t.text) for t in run.tokenize(line)]


class TokenizeTest(unittest.TestCase):
    def test_number_split_from_punctuation(self):
        self.assertEqual(kinds_and_texts("f=83.68,"),
                         [("word", "f="), ("float", "83.68"), ("word", ",")])

    def test_exponents_and_signs(self):
        self.assertEqual(kinds_and_texts("1e-10 -3.2E+05 +7"),
                         [("float", "1e-10"), ("float", "-3.2E+05"), ("int", "+7")])
        self.assertEqual(run.tokenize("-3.2E+05")[0].value, -3.2e5)

    def test_nan_and_inf(self):
        self.assertEqual(kinds_and_texts("nan -inf NaN Infinity"),
                         [("float", "nan"), ("float", "-inf"), ("float", "NaN"), ("float", "Infinity")])

    def test_words_containing_digits_or_nan_stay_words(self):
        self.assertEqual(kinds_and_texts("body0.h5 x86_64 info banana 1.2.3 3x"),
                         [("word", w) for w in ["body0.h5", "x86_64", "info", "banana", "1.2.3", "3x"]])

    def test_parentheses_percent_colon(self):
        self.assertEqual(kinds_and_texts("(1.5) 50% t:0.25 x=-2"),
                         [("word", "("), ("float", "1.5"), ("word", ")"), ("int", "50"), ("word", "%"),
                          ("word", "t:"), ("float", "0.25"), ("word", "x="), ("int", "-2")])

    def test_sentence_final_period(self):
        self.assertEqual(kinds_and_texts("took 1.5."), [("word", "took"), ("float", "1.5"), ("word", ".")])

    def test_integer_vs_float_kind(self):
        self.assertEqual([t.kind for t in run.tokenize("12 12.0 1e3 5.")], ["int", "float", "float", "float"])


class ToleranceTest(unittest.TestCase):
    def test_rtol(self):
        tol = Tol(rtol=1e-3)
        self.assertTrue(run.numbers_close(100.0, 100.09, tol))
        self.assertFalse(run.numbers_close(100.0, 100.2, tol))

    def test_rtol_is_relative_to_expected(self):
        tol = Tol(rtol=0.1)
        self.assertTrue(run.numbers_close(10.0, 11.0, tol))      # 1 <= 0.1*10
        self.assertFalse(run.numbers_close(11.0, 9.8, tol))      # 1.2 > 0.1*11

    def test_atol(self):
        tol = Tol(rtol=0.0, atol=1e-6)
        self.assertTrue(run.numbers_close(0.0, 5e-7, tol))
        self.assertFalse(run.numbers_close(0.0, 2e-6, tol))

    def test_ztol(self):
        tol = Tol(rtol=1e-8, atol=0.0, ztol=1e-10)
        self.assertTrue(run.numbers_close(3e-12, -8e-11, tol))   # both "zero"
        self.assertFalse(run.numbers_close(3e-12, 2e-10, tol))   # one is not below ztol
        self.assertFalse(run.numbers_close(0.0, 1e-12, Tol(rtol=1e-8)))  # ztol 0: no zero rule

    def test_default_rtol(self):
        self.assertTrue(run.numbers_close(1.0, 1.0 + 5e-9, Tol()))
        self.assertFalse(run.numbers_close(1.0, 1.0 + 5e-8, Tol()))

    def test_nan_equals_only_nan(self):
        big = Tol(rtol=1e9, atol=1e9, ztol=1e9)
        self.assertTrue(run.numbers_close(float("nan"), float("nan"), Tol()))
        self.assertFalse(run.numbers_close(float("nan"), 1.0, big))
        self.assertFalse(run.numbers_close(0.0, float("nan"), big))

    def test_inf(self):
        self.assertTrue(run.numbers_close(float("inf"), float("inf"), Tol()))
        self.assertFalse(run.numbers_close(float("inf"), float("-inf"), Tol(rtol=10)))
        self.assertFalse(run.numbers_close(float("inf"), 1e308, Tol(rtol=10)))


class TokenMatchTest(unittest.TestCase):
    def test_integers_exact_despite_tolerance(self):
        loose = Tol(rtol=0.5, atol=10)
        self.assertFalse(run.tokens_match(run.tokenize("12")[0], run.tokenize("13")[0], loose))
        self.assertTrue(run.tokens_match(run.tokenize("12")[0], run.tokenize("+12")[0], loose))

    def test_int_vs_float_uses_tolerance(self):
        tol = Tol(rtol=1e-5)
        self.assertTrue(run.tokens_match(run.tokenize("1")[0], run.tokenize("0.999999")[0], tol))
        self.assertFalse(run.tokens_match(run.tokenize("1")[0], run.tokenize("1.1")[0], tol))

    def test_word_vs_number(self):
        self.assertFalse(run.tokens_match(Token("word", "x"), run.tokenize("1")[0], Tol()))


class CompareTextTest(unittest.TestCase):
    def test_equal_within_tolerance(self):
        exp = "step 1 f=83.68, err 1e-10\nPASS\n"
        got = "step 1 f=83.680001, err 1.00001e-10\nPASS\n"
        self.assertEqual(run.compare_text(exp, got, Tol(rtol=1e-4)), [])

    def test_whitespace_insensitive(self):
        self.assertEqual(run.compare_text("a   1.0  b\n", "a 1.0 b   \n", Tol()), [])

    def test_float_mismatch_reports_line(self):
        diffs = run.compare_text("x\nf=83.68,\n", "x\nf=83.70,\n", Tol(rtol=1e-6))
        self.assertEqual(len(diffs), 1)
        self.assertTrue(diffs[0].summary.startswith("line 2: expected 83.68 got 83.70"), diffs[0].summary)

    def test_integer_mismatch(self):
        diffs = run.compare_text("iterations 12\n", "iterations 13\n", Tol(rtol=1.0))
        self.assertEqual(diffs[0].summary, "line 1: expected 12 got 13")

    def test_word_mismatch(self):
        diffs = run.compare_text("converged PASS\n", "converged FAIL\n", Tol())
        self.assertEqual(diffs[0].summary, "line 1: expected PASS got FAIL")

    def test_token_count_mismatch(self):
        diffs = run.compare_text("a 1 2\n", "a 1 2 3\n", Tol())
        self.assertIn("expected 3 tokens, got 4", diffs[0].summary)

    def test_line_count_mismatch(self):
        diffs = run.compare_text("a\nb\n", "a\nb\nc\n", Tol())
        self.assertEqual(diffs[0].summary, "expected 2 lines, got 3")
        self.assertIn("only in got: c", diffs[-1].summary)

    def test_max_diffs(self):
        exp = "".join(f"v {i}\n" for i in range(20))
        got = "".join(f"v {i + 1}\n" for i in range(20))
        self.assertEqual(len(run.compare_text(exp, got, Tol(), max_diffs=3)), 3)


class CompareCsvTest(unittest.TestCase):
    REF = "time, kinetic, potential\n0, 1.0e-3, 2.0\n0.1, 1.1e-3, 1.9\n"

    def test_equal_with_extra_column_and_spacing(self):
        got = "time,kinetic,potential,total\n0,0.0010000001,2.0,2.001\n0.1,1.1e-3,1.9,1.9011\n"
        result = run.compare_csv(self.REF, got, Tol(rtol=1e-6))
        self.assertEqual(result.diffs, [])
        self.assertTrue(any("extra produced columns" in n and "total" in n for n in result.notes))
        self.assertTrue(any("column kinetic: max rel err" in n for n in result.notes))

    def test_value_mismatch_reports_column_and_row(self):
        got = "time,kinetic,potential\n0,1.0e-3,2.0\n0.1,1.2e-3,1.9\n"
        diffs = run.compare_csv(self.REF, got, Tol(), label="energy.csv").diffs
        self.assertEqual(len(diffs), 1)
        self.assertTrue(diffs[0].summary.startswith(
            "energy.csv column kinetic row 2: expected 1.1e-3 got 1.2e-3"), diffs[0].summary)

    def test_missing_column(self):
        got = "time,potential\n0,2.0\n0.1,1.9\n"
        diffs = run.compare_csv(self.REF, got, Tol(), label="e.csv").diffs
        self.assertEqual(diffs[0].summary, "e.csv: missing column kinetic")

    def test_row_count_mismatch(self):
        got = "time,kinetic,potential\n0,1.0e-3,2.0\n"
        diffs = run.compare_csv(self.REF, got, Tol(), label="e.csv").diffs
        self.assertEqual([d.summary for d in diffs], ["e.csv: expected 2 rows, got 1"])

    def test_selected_columns_only(self):
        got = "time,kinetic,potential\n0,1.0e-3,999\n0.1,1.1e-3,999\n"
        self.assertEqual(run.compare_csv(self.REF, got, Tol(), columns=["time", "kinetic"]).diffs, [])
        diffs = run.compare_csv(self.REF, got, Tol(), columns=["nosuch"]).diffs
        self.assertIn("not in the reference", diffs[0].summary)

    def test_nonnumeric_cells_exact(self):
        ref = "name,value\nbeam,1\n"
        self.assertEqual(run.compare_csv(ref, "name,value\nbeam,1\n", Tol()).diffs, [])
        self.assertEqual(len(run.compare_csv(ref, "name,value\nBeam,1\n", Tol()).diffs), 1)

    def test_ztol_in_csv(self):
        ref = "t,v\n0,1e-14\n"
        got = "t,v\n0,-3e-13\n"
        self.assertEqual(len(run.compare_csv(ref, got, Tol()).diffs), 1)
        self.assertEqual(run.compare_csv(ref, got, Tol(ztol=1e-12)).diffs, [])


class SpecTest(unittest.TestCase):
    def test_parse_full_spec(self):
        text = """# a comment
description: lossless cantilever,
  midpoint rule
args: -options_file options/x.yaml -output_dir {outdir}
   -ts_max_steps 10
nsize: 2
requires: mumps, hdf5
filter: grep -E "frequency|PASS"
csv: energy.csv:cantilever_energy.csv
columns: time kinetic
rtol: 1e-6
csv_atol: 1e-12
exit: nonzero
stderr: Error.*mesh
files_absent: energy.csv outdir-empty
"""
        spec = run.parse_spec("demo", text)
        self.assertEqual(spec.description, "lossless cantilever, midpoint rule")
        self.assertEqual(spec.args[-3:], ["{outdir}", "-ts_max_steps", "10"])
        self.assertEqual(spec.nsize, 2)
        self.assertEqual(spec.requires, ["mumps", "hdf5"])
        self.assertEqual(spec.filter, 'grep -E "frequency|PASS"')
        self.assertEqual(spec.output, "demo.out")
        self.assertEqual(spec.csv, [("energy.csv", "cantilever_energy.csv")])
        self.assertEqual(spec.columns, ["time", "kinetic"])
        self.assertEqual(spec.tol, Tol(1e-6, 0.0, 0.0))
        self.assertEqual(spec.csv_tol, Tol(1e-6, 1e-12, 0.0))
        self.assertEqual(spec.exit, "nonzero")
        self.assertTrue(spec.stderr.search("Error:\nbad mesh"))
        self.assertEqual(spec.files_absent, ["energy.csv", "outdir-empty"])

    def test_output_none(self):
        self.assertIsNone(run.parse_spec("t", "args: -x\noutput: none\n").output)

    def test_errors(self):
        for text in ["description: no args\n", "args: a\nbogus: 1\n", "args: a\nargs: b\n",
                     "  continuation first\n", "args: a\nrequires: fortran\n", "args: a\nexit: maybe\n",
                     "args: a\ncsv: nocolon.csv\n", "args: a\nstderr: (\n", "args: 'unterminated\n"]:
            with self.assertRaises(run.SpecError, msg=text):
                run.parse_spec("t", text)

    def test_missing_features(self):
        self.assertEqual(run.missing_features(["mumps", "mpi2", "hypre"], {"PETSC_HAVE_MUMPS"}), ["hypre"])
        self.assertEqual(run.missing_features(["cholmod"], None), ["cholmod"])

    def test_missing_tools(self):
        tools = {"shell": "sh", "nothing": "phlex-selftest-no-such-program"}
        with mock.patch.dict(run.TOOLS, tools):
            self.assertEqual(run.missing_features(["shell", "nothing", "mpi2"], set()),
                             ["nothing (phlex-selftest-no-such-program not on PATH)"])
            self.assertEqual(run.parse_spec("t", "args: a\nrequires: shell\n").requires, ["shell"])


class MultiRunSpecTest(unittest.TestCase):
    def test_numbered_runs(self):
        text = """args: -a {outdir}
nsize: 2
exit: 2
stderr: first
filter: grep A
args2: -b
exit2: nonzero
stderr2: second
filter2: none
args3: -c
nsize3: 1
filter3: grep C
setup: mkdir -p {outdir}/x
post: echo done
"""
        spec = run.parse_spec("t", text)
        runs = spec.all_runs()
        self.assertEqual(len(runs), 3)
        self.assertEqual((spec.args, spec.nsize, spec.exit), (["-a", "{outdir}"], 2, "2"))
        self.assertEqual([r.args for r in runs], [["-a", "{outdir}"], ["-b"], ["-c"]])
        self.assertEqual([r.nsize for r in runs], [2, 2, 1])   # nsize is inherited, the others are per run
        self.assertEqual([r.exit for r in runs], ["2", "nonzero", "0"])
        self.assertEqual([r.stderr.pattern if r.stderr else None for r in runs], ["first", "second", None])
        self.assertEqual([(r.filter, r.compared) for r in runs], [("grep A", True), (None, False), ("grep C", True)])
        self.assertEqual((spec.setup, spec.post), ("mkdir -p {outdir}/x", "echo done"))
        self.assertEqual(spec.max_nsize(), 2)

    def test_one_run(self):
        spec = run.parse_spec("t", "args: -x\nfilter: none\n")
        self.assertEqual(len(spec.all_runs()), 1)
        self.assertFalse(spec.all_runs()[0].compared)

    def test_errors(self):
        for text in ["args: a\nargs3: b\n", "args: a\nexit2: 1\n", "args: a\nargs2: b\nstderr3: x\n",
                     "args: a\nargs2: b\nexit2: maybe\n", "args: a\nargs2: b\nnsize2: 0\n",
                     "args: a\nargs2: b\nstderr2: (\n", "args: a\nargs1: b\n", "args: a\nargs02: b\n",
                     "args: a\nargs2: b\nargs2: c\n", "args: a\noutput2: x\n"]:
            with self.assertRaises(run.SpecError, msg=text):
                run.parse_spec("t", text)

    def test_substitute_logs(self):
        text = run.substitute("{outdir}/a {stdout2} {stderr10}", "out/t", "out/t.runs")
        self.assertEqual(text, "out/t/a out/t.runs/run2.stdout out/t.runs/run10.stderr")


FAKE_PHLEX = """#!/bin/sh
# a stand-in for bin/phlex: out=TEXT (stdout), err=TEXT (stderr), touch=FILE, sleep=S, exit=N
code=0
for a in "$@"; do
  case "$a" in
    out=*) echo "${a#out=}" ;;
    err=*) echo "${a#err=}" >&2 ;;
    touch=*) : > "${a#touch=}" ;;
    sleep=*) sleep "${a#sleep=}" ;;
    exit=*) code="${a#exit=}" ;;
  esac
done
exit $code
"""


class MultiRunTest(unittest.TestCase):
    """run_test on a stand-in binary: each run checked, the texts joined, the post command's output last."""

    def setUp(self):
        import tempfile
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.binary = os.path.join(self.dir, "fake_phlex")
        with open(self.binary, "w") as fh:
            fh.write(FAKE_PHLEX)
        os.chmod(self.binary, 0o755)
        self.cfg = run.Config(binary=self.binary, mpiexec=["mpiexec"], cases=self.dir, ref=self.dir,
                              expected=self.dir, work=os.path.join(self.dir, "work"), verbose=False, update=False)

    def tearDown(self):
        self.tmp.cleanup()

    def run_spec(self, text, expected=None):
        if expected is not None:
            with open(os.path.join(self.dir, "t.out"), "w") as fh:
                fh.write(expected)
        return run.run_test(run.parse_spec("t", text), self.cfg)

    def test_runs_filters_post(self):
        text = """args: out=one out=skip touch={outdir}/a
filter: grep one
args2: out=two err=refused exit=2
exit2: 2
stderr2: refused
args3: out=three
filter3: none
post: cat {stderr2}; ls {outdir}; cat {stdout3}
"""
        result = self.run_spec(text, "one\ntwo\nrefused\na\nthree\n")
        self.assertEqual(result.status, "ok", result.diagnostics)
        with open(os.path.join(self.cfg.work, "t.runs", "run2.stderr")) as fh:
            self.assertEqual(fh.read(), "refused\n")

    def test_compared_text_differs(self):
        result = self.run_spec("args: out=one\nargs2: out=two\n", "one\nTWO\n")
        self.assertEqual(result.status, "fail")
        self.assertIn("line 2: expected TWO got two", result.reason)

    def test_exit_of_a_later_run_stops_the_test(self):
        text = "args: out=one\nargs2: exit=3\nargs3: touch={outdir}/third\noutput: none\n"
        result = self.run_spec(text)
        self.assertEqual(result.status, "fail")
        self.assertEqual(result.reason, "run 2: exit status 3, expected exit status 0")
        self.assertFalse(os.path.exists(os.path.join(self.cfg.work, "t", "third")))

    def test_one_run_messages_unchanged(self):
        result = self.run_spec("args: exit=3\noutput: none\n")
        self.assertEqual(result.reason, "exit status 3, expected exit status 0")

    def test_timeout_per_run(self):
        result = self.run_spec("args: out=a\nargs2: sleep=5\ntimeout: 0.5\noutput: none\n")
        self.assertEqual(result.reason, "run 2: timeout")

    def test_stderr_and_crash_markers_per_run(self):
        result = self.run_spec("args: out=a\nargs2: err=other exit=1\nexit2: 1\nstderr2: refused\noutput: none\n")
        self.assertTrue(result.reason.startswith("run 2: stderr does not match /refused/"), result.reason)
        result = self.run_spec("args: out=a\nargs2: err=Segmentation exit=1\nexit2: nonzero\noutput: none\n")
        self.assertEqual(result.reason, "run 2: crash marker 'Segmentation' in output")

    def test_unused_option(self):
        warning = "err='phlex: warning: option -foo 1 was never used (misspelt?)'"
        result = self.run_spec(f"args: out=a\nargs2: {warning}\noutput: none\n")
        self.assertEqual(result.status, "fail")
        self.assertTrue(result.reason.startswith("run 2: an option went unused: phlex: warning: option -foo 1"),
                        result.reason)
        result = self.run_spec(f"args: out=a\nargs2: {warning}\nstderr2: never used\noutput: none\n")
        self.assertEqual(result.status, "ok", result.diagnostics)   # a stderr the spec states is its own check
        result = self.run_spec("args: out='Option left: name:-foo value: 1'\noutput: none\n")
        self.assertTrue(result.reason.startswith("an option went unused: Option left"), result.reason)

    def test_stderr_names_outdir(self):
        text = "args: err={outdir}/x.h5 exit=2\nexit: 2\nstderr: ^{outdir}/x\\.h5$\noutput: none\n"
        self.assertEqual(self.run_spec(text).status, "ok")
        text = "args: err=elsewhere/x.h5 exit=2\nexit: 2\nstderr: {outdir}/x\\.h5\noutput: none\n"
        self.assertTrue(self.run_spec(text).reason.startswith("stderr does not match"))

    def test_setup(self):
        text = "setup: mkdir {outdir}/made\nargs: touch={outdir}/made/x\noutput: none\nfiles_present: made/x\n"
        self.assertEqual(self.run_spec(text).status, "ok")
        result = self.run_spec("setup: exit 3\nargs: touch={outdir}/x\noutput: none\nfiles_absent: outdir-empty\n")
        self.assertEqual(result.reason, "setup failed (exit status 3)")

    def test_post_failure(self):
        result = self.run_spec("args: out=a\npost: exit 2\n", "a\n")
        self.assertEqual(result.reason, "post failed (exit status 2)")


class SelectTest(unittest.TestCase):
    def test_select(self):
        avail = ["a_1", "a_2", "b"]
        self.assertEqual(run.select_names([], avail), [("a_1", True), ("a_2", True), ("b", True)])
        self.assertEqual(run.select_names(["b.test", "a_*"], avail), [("a_1", True), ("a_2", True), ("b", True)])
        self.assertEqual(run.select_names(["zz"], avail), [("zz", False)])


if __name__ == "__main__":
    unittest.main()

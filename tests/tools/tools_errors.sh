#!/bin/sh
# Usage errors (exit status 2) and unreadable CSV files (exit status 1) of tools/plot_series.py and tools/render.py,
# for the test tools_errors. $1: the output directory of a short pendulum run. Prints each case's exit status, its
# stderr, then its stdout, with $1 written as OUTDIR.
dir=$1
run() {
  label=$1
  shift
  "$@" > "$dir/stdout.txt" 2> "$dir/stderr.txt"
  echo "== $label: exit status $?"
  grep -v '^ ' "$dir/stderr.txt" | grep -v '^usage:' | sed "s|$dir|OUTDIR|g"
  sed "s|$dir|OUTDIR|g" "$dir/stdout.txt"
}

mkdir -p "$dir/empty" "$dir/broken"
cp "$dir/bob_rigid.csv" "$dir/broken/"
head -n 3 "$dir/energy.csv" > "$dir/broken/energy.csv"
echo "3,0.003,1" >> "$dir/broken/energy.csv"
sed '2s/[^,]*$/oops/' "$dir/hinge_joint.csv" > "$dir/broken/hinge_joint.csv"
: > "$dir/broken/empty.csv"

run "plot_series.py without a directory" python3 tools/plot_series.py
run "plot_series.py on a missing directory" python3 tools/plot_series.py "$dir/missing"
run "plot_series.py on a directory without CSV" python3 tools/plot_series.py "$dir/empty"
run "plot_series.py on broken CSV files" python3 tools/plot_series.py "$dir/broken"
run "render.py on a missing directory" python3 tools/render.py "$dir/missing"
run "render.py on a directory without XDMF" python3 tools/render.py "$dir"
run "render.py with a bad component" python3 tools/render.py "$dir" --field velocity:W
run "render.py with a bad range" python3 tools/render.py "$dir" --range 1,0

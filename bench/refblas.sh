#!/bin/sh
# Time cases with the reference BLAS/LAPACK (Debian libblas3/liblapack3) instead of OpenBLAS, then restore.
#
#   bench/refblas.sh [CASE ...]        default: modes_h0.02 modes_h0.01
#
# Needs root: it switches the system-wide alternatives libblas.so.3 and liblapack.so.3, which every program on
# the machine uses while the runs last. On exit (also on error or Ctrl-C) both alternatives go back to auto mode,
# which selects OpenBLAS (priority 90), and the script checks that they point to openblas-serial again.
# The logs are bench/results/<case>_refblas.r<i>.log; the environment of bench/run.sh (PHLEX, REPEAT, ...) applies.
set -eu

ARCH=x86_64-linux-gnu
LIB=/usr/lib/$ARCH

restore() {
  update-alternatives --quiet --auto libblas.so.3-$ARCH
  update-alternatives --quiet --auto liblapack.so.3-$ARCH
  b=$(readlink -f $LIB/libblas.so.3)
  l=$(readlink -f $LIB/liblapack.so.3)
  echo "restored: libblas.so.3 -> $b; liblapack.so.3 -> $l" >&2
  case $b$l in
  *openblas*openblas*) ;;
  *) echo "WARNING: BLAS/LAPACK do not point to OpenBLAS; check update-alternatives --display libblas.so.3-$ARCH" >&2 ;;
  esac
}
trap restore EXIT
trap 'exit 130' INT TERM

[ -f $LIB/blas/libblas.so.3 ] && [ -f $LIB/lapack/liblapack.so.3 ] || { echo "reference BLAS/LAPACK not installed (apt-get install libblas3 liblapack3)" >&2; exit 2; }
update-alternatives --quiet --set libblas.so.3-$ARCH $LIB/blas/libblas.so.3
update-alternatives --quiet --set liblapack.so.3-$ARCH $LIB/lapack/liblapack.so.3
echo "using: libblas.so.3 -> $(readlink -f $LIB/libblas.so.3); liblapack.so.3 -> $(readlink -f $LIB/liblapack.so.3)" >&2

[ $# -ge 1 ] || set -- modes_h0.02 modes_h0.01
TAG=_refblas "$(dirname "$0")/run.sh" "$@"

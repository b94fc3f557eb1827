#!/bin/sh
# Install, with apt, the Debian bookworm packages phlex needs that are not yet installed.
# Called by 'make deps' (and by 'make run' / 'make check' when PETSc, SLEPc, gmsh or mpiexec is missing).
set -eu

packages="petsc-dev slepc-dev libyaml-dev gmsh libmetis-dev libopenblas0-serial openmpi-bin pkg-config make python3 python3-numpy python3-matplotlib hdf5-tools"

missing=""
for p in $packages; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done

if [ -z "$missing" ]; then
  echo "deps: all required packages are installed"
  exit 0
fi

echo "deps: installing:$missing"
if [ "$(id -u)" -eq 0 ]; then
  sudo=""
elif command -v sudo >/dev/null 2>&1; then
  sudo="sudo"
else
  echo "deps: need root (or sudo) to install:$missing" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
# shellcheck disable=SC2086
$sudo apt-get install -y -q --no-install-recommends $missing

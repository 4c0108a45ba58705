#!/usr/bin/env bash
# femcod set-up: installs only what is missing, builds femcod, installs it and runs the main
# job on the default deck. Idempotent and quiet: a re-run that finds everything installed
# spends its time in the build check and the run only. Two ways to find what it needs:
# - Debian with root (or sudo without a password): the missing Debian packages are installed;
# - otherwise (a cluster: no root, libraries from `module load`): nothing is installed; the
#   compilers on PATH and the libraries pkg-config, $HDF5_ROOT, $FFTW_ROOT, $OPENBLAS_ROOT
#   (or _DIR, _HOME, EBROOT...) and the library paths show are used, and what is missing is
#   named with the module or package to look for (doc/cluster.md, "Building on a cluster").
#   bash setup.sh                 install + build + install femcod + run input/sphere_d1.deck
#   bash setup.sh --no-run        the same without the run (CI)
#   bash setup.sh --prefix DIR    install femcod into DIR/bin (default: /usr/local as root,
#                                 ~/.local otherwise)
#   bash setup.sh --modules       use the environment's compilers and libraries even as root
#   bash setup.sh --mpi           also femcod-mpi (mpi/, doc/cluster.md) next to femcod, with
#                                 OpenMPI, FFTW-MPI and the OpenMPI HDF5 (Debian) or the
#                                 mpifort, FFTW-MPI and parallel HDF5 found; tests: bash mpi/test.sh
#   bash setup.sh --python        also the Python package (python/, doc/python.md) in its own
#                                 virtual environment PREFIX/lib/femcod-python, with numpy, h5py, xarray,
#                                 matplotlib and pytest; its interpreter is PREFIX/bin/femcod-python
#   bash setup.sh --wheel         build dist/femcod-VERSION-py3-none-manylinux_*.whl: the Python
#                                 package with the femcod program, libfemcod.so and the shared
#                                 libraries they need inside (doc/install.md); installs nothing
# Every set-up also installs the C library: PREFIX/lib/libfemcod.so, PREFIX/include/femcod.h
# (and the Fortran modules in PREFIX/include/femcod).
# fpm comes from PyPI into its own virtual environment (Debian's pip refuses system
# installs, PEP 668), linked into PREFIX/bin.
set -euo pipefail
cd "$(dirname "$0")"

run_main=1
mpi=0
python=0
wheel=0
modules=0
if [ "$(id -u)" -eq 0 ]; then prefix=/usr/local; else prefix="$HOME/.local"; fi
while [ $# -gt 0 ]; do
  case "$1" in
    --no-run) run_main=0; shift ;;
    --mpi) mpi=1; shift ;;
    --python) python=1; shift ;;
    --wheel) wheel=1; shift ;;
    --modules) modules=1; shift ;;
    --prefix) [ $# -ge 2 ] || { echo "setup: --prefix needs a directory" >&2; exit 2; }; prefix=$2; shift 2 ;;
    -h|--help) sed -n '2,30p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "setup: unknown argument $1 (setup.sh --help)" >&2; exit 2 ;;
  esac
done
if [ "$wheel" -eq 1 ] && { [ "$mpi" -eq 1 ] || [ "$python" -eq 1 ]; }; then
  echo "setup: --wheel builds the wheel only; run it on its own (then pip install dist/femcod-*.whl)" >&2; exit 2
fi
mkdir -p "$prefix/bin"
prefix=$(cd "$prefix" && pwd)

# Debian packages when this user may install them; the environment's libraries otherwise.
if [ "$modules" -eq 0 ] && command -v dpkg-query >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1 &&
   { [ "$(id -u)" -eq 0 ] || sudo -n true 2>/dev/null; }; then
  source ./packaging/debian.sh
else
  source ./packaging/environment.sh
fi

if ! command -v fpm >/dev/null 2>&1; then
  venv="$prefix/lib/femcod-fpm"
  echo "setup: installing fpm 0.12.0 from PyPI into $venv"
  python3 -m venv "$venv"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check fpm==0.12.0
  fpm_bin=$("$venv/bin/python" -c 'import fpm,os;print(os.path.join(os.path.dirname(fpm.__file__),"fpm"))')
  ln -sf "$fpm_bin" "$prefix/bin/fpm"
  export PATH="$prefix/bin:$PATH"
fi
if [ "$wheel" -eq 1 ]; then
  run_main=0
  prefix="$PWD/build/wheel/stage"
  rm -rf build/wheel
  mkdir -p "$prefix/bin"
fi

fpm build --profile release >/dev/null 2>build.log || { cat build.log >&2; exit 1; }
rm -f build.log
fpm install --profile release --prefix "$prefix" --includedir include/femcod >/dev/null 2>&1 ||
  { echo "setup: fpm install into $prefix failed" >&2; exit 1; }
# The C library: fpm installs the static archive (fpm.toml [install] library = true); one
# link makes the shared library of it, with the libraries fpm.toml links (written to a
# temporary name, then renamed, so a program using the old one keeps it).
if [ ! "$prefix/lib/libfemcod.so" -nt "$prefix/lib/libfemcod.a" ]; then
  link_libraries=$(sed -n 's/^link *= *\[\(.*\)\]/\1/p' fpm.toml | tr -d '"' | tr ',' '\n' | sed 's/^ */-l/' | tr '\n' ' ')
  # shellcheck disable=SC2046,SC2086
  "${FPM_FC:-gfortran}" -shared -o "$prefix/lib/libfemcod.so.tmp" -Wl,--whole-archive "$prefix/lib/libfemcod.a" \
    -Wl,--no-whole-archive ${FPM_LDFLAGS:-} $(pkg-config --libs hdf5) -lhdf5_fortran $link_libraries -fopenmp ||
    { echo "setup: linking libfemcod.so failed" >&2; exit 1; }
  mv -f "$prefix/lib/libfemcod.so.tmp" "$prefix/lib/libfemcod.so"
  if [ "$(id -u)" -eq 0 ] && [ "$wheel" -eq 0 ]; then ldconfig; fi
fi
mkdir -p "$prefix/include"
cmp -s src/capi/femcod.h "$prefix/include/femcod.h" || cp src/capi/femcod.h "$prefix/include/femcod.h"
# What the installed benchmarks need besides the program: the peers' script (--peers).
mkdir -p "$prefix/share/femcod"
cmp -s app/femcod_peers.py "$prefix/share/femcod/femcod_peers.py" || cp app/femcod_peers.py "$prefix/share/femcod/"
case ":$(printenv PATH):$wheel" in
  *":$prefix/bin:"*|*:1) ;;
  *) echo "setup: femcod is installed in $prefix/bin; add it to PATH (export PATH=\"$prefix/bin:\$PATH\")" ;;
esac
if [ "$mpi" -eq 1 ]; then
  (cd mpi && source ./environment.sh &&
    fpm build --profile release --flag "$FEMCOD_MPI_FLAGS" >/dev/null 2>build.log &&
    fpm install --profile release --flag "$FEMCOD_MPI_FLAGS" --prefix "$prefix" >/dev/null 2>>build.log) ||
    { cat mpi/build.log >&2; echo "setup: the MPI build failed" >&2; exit 1; }
  rm -f mpi/build.log
fi
if [ "$python" -eq 1 ]; then
  venv="$prefix/lib/femcod-python"
  [ -x "$venv/bin/python" ] || python3 -m venv "$venv"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check "./python[test]" ||
    { echo "setup: pip install ./python failed" >&2; exit 1; }
  # A script, not a link: Python finds its virtual environment from the path it was started by.
  rm -f "$prefix/bin/femcod-python"
  printf '#!/bin/sh\nexec "%s/bin/python" "$@"\n' "$venv" > "$prefix/bin/femcod-python"
  chmod +x "$prefix/bin/femcod-python"
fi
if [ "$run_main" -eq 1 ]; then
  mkdir -p out
  "$prefix/bin/femcod" run input/sphere_d1.deck -o out/sphere_d1 --loads 100,1000,5000 --force
fi
if [ "$wheel" -eq 1 ]; then
  bash packaging/wheel.sh "$prefix"
fi

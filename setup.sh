#!/usr/bin/env bash
# femcod set-up for a fresh Debian 12 machine (reaches Debian's packages and PyPI).
# Installs only what is missing, builds femcod, installs it onto PATH and runs the main
# job on the default deck. Idempotent and quiet: a re-run that finds everything installed
# spends its time in the build check and the run only.
#   bash setup.sh                 install + build + install femcod + run input/sphere_d1.deck
#   bash setup.sh --no-run        the same without the run (CI)
#   bash setup.sh --prefix DIR    install femcod into DIR/bin (default: /usr/local as root,
#                                 ~/.local otherwise)
#   bash setup.sh --mpi           also OpenMPI, FFTW-MPI and the OpenMPI HDF5, and femcod-mpi
#                                 (mpi/, doc/cluster.md) next to femcod; tests: bash mpi/test.sh
#   bash setup.sh --python        also the Python package (python/, doc/python.md) in its own
#                                 virtual environment PREFIX/lib/femcod-python, with numpy, h5py, xarray,
#                                 matplotlib and pytest; its interpreter is PREFIX/bin/femcod-python
# Every set-up also installs the C library: PREFIX/lib/libfemcod.so, PREFIX/include/femcod.h
# (and the Fortran modules in PREFIX/include/femcod).
# fpm comes from PyPI into its own virtual environment (Debian's pip refuses system
# installs, PEP 668), linked into PREFIX/bin.
set -euo pipefail
cd "$(dirname "$0")"

run_main=1
mpi=0
python=0
if [ "$(id -u)" -eq 0 ]; then prefix=/usr/local; else prefix="$HOME/.local"; fi
while [ $# -gt 0 ]; do
  case "$1" in
    --no-run) run_main=0; shift ;;
    --mpi) mpi=1; shift ;;
    --python) python=1; shift ;;
    --prefix) [ $# -ge 2 ] || { echo "setup: --prefix needs a directory" >&2; exit 2; }; prefix=$2; shift 2 ;;
    -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "setup: unknown argument $1 (setup.sh --help)" >&2; exit 2 ;;
  esac
done
mkdir -p "$prefix/bin"
prefix=$(cd "$prefix" && pwd)

sudo_if_needed() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

debian_packages=(gfortran liblapack-dev libopenblas-dev libhdf5-dev libfftw3-dev pkg-config hdf5-tools zlib1g-dev libssl-dev
  python3-venv)
if [ "$mpi" -eq 1 ]; then debian_packages+=(libopenmpi-dev openmpi-bin libfftw3-mpi-dev libhdf5-openmpi-dev); fi
missing=()
for p in "${debian_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  sudo_if_needed apt-get update -qq >/dev/null
  sudo_if_needed apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The serial build takes HDF5 from pkg-config's hdf5.pc. Installing libhdf5-openmpi-dev
# switches that alternative to the MPI HDF5, which the serial build would then pick up
# silently: point it back at the serial one (femcod-mpi finds its own, mpi/environment.sh).
pc_dir=$(pkg-config --variable=pcfiledir hdf5-serial)
if [ -e "$pc_dir/hdf5.pc" ] && [ "$(readlink -f "$pc_dir/hdf5.pc")" != "$(readlink -f "$pc_dir/hdf5-serial.pc")" ]; then
  sudo_if_needed update-alternatives --set hdf5.pc "$pc_dir/hdf5-serial.pc" >/dev/null
  echo "setup: hdf5.pc pointed at $(readlink -f "$pc_dir/hdf5.pc"); set back to the serial HDF5"
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

fpm build --profile release >/dev/null 2>build.log || { cat build.log >&2; exit 1; }
rm -f build.log
fpm install --profile release --prefix "$prefix" --includedir include/femcod >/dev/null 2>&1 ||
  { echo "setup: fpm install into $prefix failed" >&2; exit 1; }
# The C library: fpm installs the static archive (fpm.toml [install] library = true); one
# link makes the shared library of it, with the libraries fpm.toml links (written to a
# temporary name, then renamed, so a program using the old one keeps it).
if [ ! "$prefix/lib/libfemcod.so" -nt "$prefix/lib/libfemcod.a" ]; then
  link_libraries=$(python3 -c 'import tomllib; print(" ".join("-l" + l for l in tomllib.load(open("fpm.toml", "rb"))["build"]["link"]))')
  # shellcheck disable=SC2046,SC2086
  gfortran -shared -o "$prefix/lib/libfemcod.so.tmp" -Wl,--whole-archive "$prefix/lib/libfemcod.a" \
    -Wl,--no-whole-archive $(pkg-config --libs hdf5) -lhdf5_fortran $link_libraries -fopenmp ||
    { echo "setup: linking libfemcod.so failed" >&2; exit 1; }
  mv -f "$prefix/lib/libfemcod.so.tmp" "$prefix/lib/libfemcod.so"
  if [ "$(id -u)" -eq 0 ]; then ldconfig; fi
fi
mkdir -p "$prefix/include"
cmp -s src/capi/femcod.h "$prefix/include/femcod.h" || cp src/capi/femcod.h "$prefix/include/femcod.h"
# What the installed benchmarks need besides the program: the peers' script (--peers).
mkdir -p "$prefix/share/femcod"
cmp -s app/femcod_peers.py "$prefix/share/femcod/femcod_peers.py" || cp app/femcod_peers.py "$prefix/share/femcod/"
case ":$(printenv PATH):" in
  *":$prefix/bin:"*) ;;
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

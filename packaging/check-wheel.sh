#!/usr/bin/env bash
# The wheel on a machine with python3 and nothing else (a developer's check; needs root,
# debootstrap or an existing Debian 12 root in $FRESH_ROOT, and PyPI for numpy and h5py):
# a minimal Debian 12 (python3; python3-venv added, since Debian alone splits venv out of
# python3), no compilers, no HDF5, FFTW or BLAS; a user who is not root installs
# dist/femcod-*.whl into a virtual environment, runs the main job and femcod-python's tests
# from a source tarball (git archive), and solves the decks of input/ for
# packaging/compare_builds.py, whose table against this machine's femcod it prints.
#   sudo bash packaging/check-wheel.sh [FEMCOD_OF_THIS_MACHINE]
set -euo pipefail
cd "$(dirname "$0")/.."
reference=${1:-$(command -v femcod || true)}
wheel=$(ls dist/femcod-*.whl 2>/dev/null | head -1)
[ -n "$wheel" ] || { echo "check-wheel: no dist/femcod-*.whl (bash setup.sh --wheel)" >&2; exit 2; }
base=${FRESH_ROOT:-/tmp/fresh-debian}
if [ ! -x "$base/bin/bash" ]; then
  mirror=$( (grep -rhoE '(https?://[^ ]+/debian)( |$)' /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null || true) | head -1 | tr -d ' ')
  debootstrap --variant=minbase bookworm "$base" "$mirror" >/tmp/debootstrap.log 2>&1
  cp /etc/resolv.conf "$base/etc/resolv.conf"
  mkdir -p "$base/usr/local/share/ca-certificates"
  cp /usr/local/share/ca-certificates/*.crt "$base/usr/local/share/ca-certificates/" 2>/dev/null || true
  chroot "$base" bash -c "apt-get update -qq && apt-get install -y -qq python3 ca-certificates >/dev/null && update-ca-certificates >/dev/null"
fi
root=/tmp/femcod-wheel-check
rm -rf "$root"; cp -a "$base" "$root"
for m in proc sys dev; do mount --bind /$m "$root/$m"; done
trap 'for m in proc sys dev; do umount "$root/$m" 2>/dev/null || true; done' EXIT
chroot "$root" bash -c "apt-get install -y -qq python3-venv >/dev/null && useradd -m femuser"
# the checkout with its tracked changes (git stash create; HEAD when there are none)
tree=$(git stash create); tree=${tree:-HEAD}
git archive --prefix=femcod/ "$tree" | tar -x -C "$root/home/femuser"
cp "$wheel" "$root/home/femuser/"
chroot "$root" chown -R femuser: /home/femuser
certs="SSL_CERT_FILE=/etc/ssl/certs/ca-certificates.crt PIP_CERT=/etc/ssl/certs/ca-certificates.crt"
as_user() { chroot "$root" env -i HOME=/home/femuser PATH=/usr/bin:/bin $certs su -s /bin/bash femuser -c "cd /home/femuser && export $certs && $1"; }
echo "== what the machine has: $(as_user 'for c in gfortran gcc cc pkg-config h5dump; do command -v $c >/dev/null && printf "%s " $c; done; echo "(none of gfortran gcc cc pkg-config h5dump is expected)"')"
echo "== libraries: $(as_user 'ldconfig -p 2>/dev/null | grep -cE "hdf5|fftw|blas|lapack|gfortran|gomp" || true') of hdf5/fftw/blas/lapack/gfortran/gomp known to the loader"
start=$(date +%s)
as_user "python3 -m venv env && env/bin/pip install -q --disable-pip-version-check $(basename "$wheel")'[test]'"
echo "== pip install of $(basename "$wheel") with its dependencies: $(( $(date +%s) - start )) s"
as_user 'export PATH=$HOME/env/bin:$PATH && id -un && command -v femcod && femcod --version && cd femcod &&
  femcod run input/sphere_d1.deck -o out/sphere_d1 --loads 100,1000,5000 --force | tail -4 &&
  python -c "import femcod; print(\"import femcod:\", femcod.__version__, femcod._library.library_path())"'
as_user 'cd femcod && FEMCOD_ENV=$HOME/env OUTDIR=$HOME/job bash doc/cluster/wheel.sbatch input/sphere_d2.deck --loads 100,500 &&
  ls $HOME/job && echo "== doc/cluster/wheel.sbatch: results written"'
start=$(date +%s)
as_user 'export PATH=$HOME/env/bin:$PATH && cd femcod && python -m pytest -q -p no:cacheprovider python/tests 2>&1 | tail -4'
echo "== pytest: $(( $(date +%s) - start )) s"
as_user 'export PATH=$HOME/env/bin:$PATH && cd femcod && python packaging/compare_builds.py run femcod /home/femuser/wheel-results'
if [ -n "$reference" ]; then
  python_with_femcod=$(command -v femcod-python || echo "$root/home/femuser/env/bin/python")
  rm -rf /tmp/femcod-reference-results
  "$python_with_femcod" packaging/compare_builds.py run "$reference" /tmp/femcod-reference-results
  "$python_with_femcod" packaging/compare_builds.py compare /tmp/femcod-reference-results "$root/home/femuser/wheel-results"
fi

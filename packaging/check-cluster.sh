#!/usr/bin/env bash
# setup.sh on a cluster-like machine (a developer's check; needs root, a Debian 12 root in
# $FRESH_ROOT or debootstrap, and Debian's package registry):
# - the system has what a cluster's operating system has: gcc/gfortran, pkg-config, python3
#   with venv, zlib and OpenSSL, and the run-time libraries the scientific libraries need;
# - HDF5 (the OpenMPI build, with Fortran), FFTW (with MPI), OpenBLAS and OpenMPI are not in
#   /usr: their Debian packages are unpacked under /opt/sw (dpkg -x, pkg-config files and
#   OpenMPI's wrapper data pointed there) and reached only through a module-like
#   environment (PATH, LD_LIBRARY_PATH, PKG_CONFIG_PATH, CPATH, OPAL_PREFIX);
# - a user who is not root (no sudo) runs README's cluster lines: setup.sh --mpi --no-run,
#   the main job, and femcod-mpi on 2 ranks. (OpenMPI's OMPIO fails MPI_File_open in this
#   unpacked, relocated OpenMPI, "MPI_ERR_OTHER", where Debian's installed one works: the
#   run asks for ROMIO, --mca io romio321.)
#   sudo bash packaging/check-cluster.sh
set -euo pipefail
cd "$(dirname "$0")/.."
base=${FRESH_ROOT:-/tmp/fresh-debian}
[ -x "$base/bin/bash" ] || { echo "check-cluster: no Debian root at $base (run packaging/check-wheel.sh once, or set FRESH_ROOT)" >&2; exit 2; }
root=/tmp/femcod-cluster-check
rm -rf "$root"; cp -a "$base" "$root"
for m in proc sys dev dev/pts; do mkdir -p "$root/$m"; mount --bind /$m "$root/$m"; done
trap 'for m in dev/pts proc sys dev; do umount "$root/$m" 2>/dev/null || true; done' EXIT
# The scientific libraries' packages, and the rest (their run-time dependencies) as the system's.
sw_packages="libhdf5-openmpi-dev libhdf5-openmpi-103-1 libhdf5-openmpi-fortran-102 libhdf5-openmpi-hl-100
  libhdf5-openmpi-hl-fortran-100 libhdf5-openmpi-cpp-103-1 libhdf5-openmpi-hl-cpp-100 libfftw3-dev libfftw3-double3
  libfftw3-single3 libfftw3-long3 libfftw3-quad3 libfftw3-bin libfftw3-mpi3 libfftw3-mpi-dev libopenblas-dev
  libopenblas-pthread-dev libopenblas0-pthread libopenblas0 libopenmpi-dev libopenmpi3 openmpi-bin openmpi-common
  libsz2 libaec0 libaec-dev"
sw_packages=$(echo $sw_packages)
chroot "$root" bash -c "export DEBIAN_FRONTEND=noninteractive; apt-get update -qq && \
  apt-get install -y -qq --no-install-recommends gfortran gcc pkg-config python3-venv zlib1g-dev libssl-dev \
    $sw_packages >/dev/null 2>&1 && \
  mkdir -p /tmp/debs && cd /tmp/debs && apt-get download -qq $sw_packages >/dev/null 2>&1 && \
  dpkg --purge --force-depends $sw_packages >/dev/null 2>&1; \
  for f in /tmp/debs/*.deb; do dpkg -x \$f /opt/sw; done"
sw=/opt/sw/usr
# The module's work: names the alternatives would have made, pkg-config files and OpenMPI's
# data pointed at /opt/sw.
chroot "$root" bash -c "set -e; cd $sw/bin && ln -sf mpifort.openmpi mpifort && ln -sf mpirun.openmpi mpirun
  cd $sw/lib/x86_64-linux-gnu
  ln -sf openblas-pthread/libopenblas.so libopenblas.so && ln -sf openmpi/lib/libmpi.so libmpi.so
  for f in \$(find $sw/lib/x86_64-linux-gnu/pkgconfig -name '*.pc'); do sed -i 's#^prefix=/usr#prefix=$sw#' \$f; done
  sed -i 's#/usr/#$sw/#g' $sw/share/openmpi/*-wrapper-data.txt 2>/dev/null || true"
hdf5=$sw/lib/x86_64-linux-gnu/hdf5/openmpi
module_env="export PATH=$sw/bin:\$PATH
export LD_LIBRARY_PATH=$sw/lib/x86_64-linux-gnu:$sw/lib/x86_64-linux-gnu/openblas-pthread:$sw/lib/x86_64-linux-gnu/openmpi/lib:$hdf5
export PKG_CONFIG_PATH=$sw/lib/x86_64-linux-gnu/pkgconfig:$hdf5/pkgconfig
export CPATH=$sw/include:$sw/include/hdf5/openmpi
export HDF5_ROOT=$sw HDF5_DIR=$hdf5 FFTW_ROOT=$sw OPENBLAS_ROOT=$sw/lib/x86_64-linux-gnu/openblas-pthread
export OPAL_PREFIX=$sw"
chroot "$root" bash -c "useradd -m femuser && printf '%s\n' '$module_env' > /etc/femcod-modules.sh"
tree=$(git stash create); tree=${tree:-HEAD}
git archive --prefix=femcod/ "$tree" | tar -x -C "$root/home/femuser"
chroot "$root" chown -R femuser: /home/femuser
as_user() { chroot "$root" env -i HOME=/home/femuser PATH=/usr/bin:/bin su -s /bin/bash femuser -c \
  "cd /home/femuser && source /etc/femcod-modules.sh && $1"; }
echo "== in /usr: $(chroot "$root" bash -c 'ls /usr/lib/x86_64-linux-gnu | grep -cE "hdf5|fftw|openblas|libmpi|libblas|liblapack"' || true) hdf5/fftw/openblas/mpi/blas/lapack files; under /opt/sw: $(chroot "$root" bash -c 'find /opt/sw -name "*.so*" | grep -cE "hdf5|fftw|openblas|libmpi"')"
echo "== sudo: $(as_user 'command -v sudo || echo none'); user: $(as_user 'id -un')"
start=$(date +%s)
as_user 'cd femcod && bash setup.sh --mpi --no-run' 2>&1 | tail -25
echo "== setup.sh --mpi --no-run: $(( $(date +%s) - start )) s"
as_user 'export PATH=$HOME/.local/bin:$PATH && cd femcod && femcod run input/sphere_d1.deck -o out/sphere_d1 --loads 100,1000,5000 --force | tail -3 &&
  ldd $(command -v femcod) | grep -E "hdf5|fftw|blas|lapack" &&
  mpirun --oversubscribe --mca io romio321 -np 2 femcod-mpi input/sphere_d1.deck --loads 100,1000 -o out/sphere_mpi --force | tail -3'

# The MPI build's environment, sourced (from mpi/) by setup.sh --mpi, test.sh and the
# doc/cluster scripts. The serial build never reads it.
# - mpifort as the compiler (fpm 0.12's `mpi` metapackage crashes, fpm issue 1207);
# - on Debian, pkg-config's hdf5 resolved to the OpenMPI HDF5 for this build only
#   (build/pkgconfig comes first; the system's hdf5.pc stays the serial one, setup.sh --mpi
#   sees to it), and -I/usr/include for fftw3-mpi.f03's own `include 'fftw3.f03'`;
# - where setup.sh used the environment's libraries (../build/environment.sh), its flags;
# - mpirun's flags for this machine: --oversubscribe (more ranks than cores in the tests),
#   ranks yield when idle (oversubscribed ranks would spin), and as root
#   --allow-run-as-root (containers, CI).
if [ -f ../build/environment.sh ]; then
  # setup.sh found the libraries in the environment (a cluster's modules): the same flags,
  # with the parallel HDF5 it checked for.
  source ../build/environment.sh
  export FEMCOD_MPI_FLAGS="$FPM_FFLAGS"
else
  mkdir -p build/pkgconfig
  ln -sf "$(pkg-config --variable=pcfiledir hdf5-openmpi)/hdf5-openmpi.pc" build/pkgconfig/hdf5.pc
  export PKG_CONFIG_PATH="$PWD/build/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
  export FEMCOD_MPI_FLAGS="-I/usr/include"
fi
export FPM_FC=mpifort
FEMCOD_MPIRUN_FLAGS="--oversubscribe --mca mpi_yield_when_idle 1"
if [ "$(id -u)" -eq 0 ]; then FEMCOD_MPIRUN_FLAGS="$FEMCOD_MPIRUN_FLAGS --allow-run-as-root"; fi
export FEMCOD_MPIRUN_FLAGS

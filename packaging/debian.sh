# Sourced by setup.sh on Debian when this user may install packages (root, or sudo without
# a password): installs the missing Debian packages. Reads $mpi; sets nothing else.
rm -f build/environment.sh   # a former environment-mode build's flags (mpi/environment.sh reads it)
sudo_if_needed() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo -n "$@"; fi; }

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

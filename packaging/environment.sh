# Sourced by setup.sh where it may not install packages (a cluster: no root, no sudo; or
# --modules): finds the compilers and libraries the environment offers (`module load gcc
# hdf5 fftw openblas` and the like) and tells fpm where they are. Installs nothing.
# Reads $mpi. Exports FPM_FC, FPM_CC, FPM_FFLAGS, FPM_CFLAGS, FPM_LDFLAGS and PKG_CONFIG_PATH,
# and writes them to build/environment.sh, which `fpm test` needs sourced in a new shell.
# Where each library is looked for, in order: pkg-config; the roots module systems set
# (NAME_ROOT, NAME_DIR, NAME_HOME, EBROOTNAME); LIBRARY_PATH, LD_LIBRARY_PATH, CPATH; the
# system's directories. A library found outside the system's directories is linked with an
# rpath, so the installed femcod runs without the modules loaded.
echo "setup: no package installation here (not root, no sudo without a password, or --modules);"
echo "setup: using the compilers and libraries of this environment"
missing=()
link_dirs=()
include_dirs=()
system_dirs=" /usr/lib64 /usr/lib/x86_64-linux-gnu /usr/lib /lib64 /lib/x86_64-linux-gnu /lib "

# The directories to search (one a line) for a library (KIND lib) or a header (KIND
# include): pkg-config's for the given modules (pc1,pc2), the roots of the given variables,
# then the paths the compilers read and the system's.
candidate_dirs() {
  local kind=$1 pcs=$2; shift 2
  local pc v r d flag subdirs paths
  if [ "$kind" = lib ]; then
    flag=L; subdirs="lib64 lib lib/x86_64-linux-gnu"; paths="${LIBRARY_PATH:-}:${LD_LIBRARY_PATH:-}"
  else
    flag=I; subdirs="include include/hdf5/serial include/hdf5/openmpi"; paths="${CPATH:-}:${FPATH:-}:${C_INCLUDE_PATH:-}"
  fi
  for pc in ${pcs//,/ }; do
    pkg-config --exists "$pc" 2>/dev/null || continue
    if [ "$kind" = lib ]; then pkg-config --libs-only-L "$pc"; else pkg-config --cflags-only-I "$pc"; fi |
      tr ' ' '\n' | sed -n "s/^-$flag//p"
    pkg-config --variable="${kind}dir" "$pc"
  done
  for v in "$@"; do
    r=${!v:-}
    if [ -n "$r" ]; then for d in $subdirs; do printf '%s\n' "$r/$d"; done; printf '%s\n' "$r"; fi
  done
  tr ':' '\n' <<< "$paths"
  if [ "$kind" = lib ]; then tr ' ' '\n' <<< "$system_dirs"; else printf '%s\n' /usr/include /usr/local/include /usr/include/hdf5/serial; fi
}
candidate_library_dirs() { candidate_dirs lib "$@"; }
candidate_include_dirs() { candidate_dirs include "$@"; }
# first_with FILE < dirs: the first directory holding FILE (reads all its input: under
# pipefail, a writer cut short would fail the pipeline)
first_with() {
  local d found=""
  while read -r d; do [ -z "$found" ] && [ -n "$d" ] && [ -e "$d/$1" ] && found=$d; done
  [ -n "$found" ] && echo "$found"
}
add_link_dir() {
  case "$system_dirs" in *" $1 "*) return ;; esac
  case " ${link_dirs[*]:-} " in *" $1 "*) return ;; esac
  link_dirs+=("$1")
}
add_include_dir() {
  case " ${include_dirs[*]:-} /usr/include " in *" $1 "*) return ;; esac
  include_dirs+=("$1")
}
# need KIND FILE WHAT PCS VARS...: find FILE, a library (KIND lib) or a header (KIND
# include); WHAT names it for the message.
need() {
  local kind=$1 file=$2 what=$3 pcs=$4; shift 4
  local d
  if d=$(candidate_dirs "$kind" "$pcs" "$@" | first_with "$file"); then
    if [ "$kind" = lib ]; then add_link_dir "$d"; else add_include_dir "$d"; fi
    echo "setup:   found $file in $d"; return 0
  fi
  missing+=("$file ($what)"); return 1
}
need_library() { local name=$1; shift; need lib "lib$name.so" "$@"; }
need_header() { need include "$@"; }

fpm_fc=${FPM_FC:-gfortran}
if [ "$mpi" -eq 1 ]; then
  command -v mpifort >/dev/null 2>&1 && echo "setup:   found mpifort: $(command -v mpifort)" ||
    missing+=("mpifort (module openmpi or mpich; packages openmpi-devel / libopenmpi-dev)")
fi
if command -v "$fpm_fc" >/dev/null 2>&1; then
  echo "setup:   found $fpm_fc: $("$fpm_fc" --version | head -1)"
else
  missing+=("$fpm_fc, the Fortran compiler (module gcc; packages gcc-gfortran / gfortran)")
fi
command -v "${FPM_CC:-gcc}" >/dev/null 2>&1 || missing+=("${FPM_CC:-gcc}, the C compiler (module gcc)")
command -v pkg-config >/dev/null 2>&1 || missing+=("pkg-config (packages pkgconf / pkg-config)")
python3 -c 'import venv, ensurepip' 2>/dev/null ||
  missing+=("python3 with venv and ensurepip (module python; packages python3 / python3-venv)")

fftw_vars=(FFTW_ROOT FFTW_DIR FFTW_HOME FFTW3_ROOT FFTW3_DIR EBROOTFFTW)
hdf5_vars=(HDF5_ROOT HDF5_DIR HDF5_HOME EBROOTHDF5)
blas_vars=(OPENBLAS_ROOT OPENBLAS_DIR OPENBLAS_HOME EBROOTOPENBLAS LAPACK_ROOT BLAS_ROOT)
for lib in fftw3 fftw3f fftw3_omp; do need_library "$lib" "FFTW 3 with float and OpenMP (module fftw)" fftw3 "${fftw_vars[@]}" || true; done
need_header fftw3.f03 "FFTW's Fortran 2003 interface (module fftw)" fftw3 "${fftw_vars[@]}" || true
if [ "$mpi" -eq 1 ]; then
  for lib in fftw3_mpi fftw3f_mpi fftw3f_omp; do
    need_library "$lib" "FFTW built with MPI (module fftw of the MPI toolchain)" fftw3 "${fftw_vars[@]}" || true
  done
  need_header fftw3-mpi.f03 "FFTW's MPI interface (module fftw of the MPI toolchain)" fftw3 "${fftw_vars[@]}" || true
fi
# BLAS and LAPACK: -llapack -lblas (fpm.toml); an OpenBLAS without those names gets them as
# links in build/link (OpenBLAS holds both).
blas_dir=$(candidate_library_dirs "lapack,blas,openblas" "${blas_vars[@]}" | first_with liblapack.so) &&
  blas_dir2=$(candidate_library_dirs "lapack,blas,openblas" "${blas_vars[@]}" | first_with libblas.so) || blas_dir=""
if [ -n "$blas_dir" ]; then
  add_link_dir "$blas_dir"; add_link_dir "$blas_dir2"; echo "setup:   found liblapack.so in $blas_dir, libblas.so in $blas_dir2"
elif openblas_dir=$(candidate_library_dirs "openblas" "${blas_vars[@]}" | first_with libopenblas.so); then
  mkdir -p build/link
  ln -sf "$openblas_dir/libopenblas.so" build/link/liblapack.so
  ln -sf "$openblas_dir/libopenblas.so" build/link/libblas.so
  add_link_dir "$openblas_dir"; add_link_dir "$PWD/build/link"
  echo "setup:   found libopenblas.so in $openblas_dir (linked as -llapack -lblas through build/link)"
else
  missing+=("liblapack.so and libblas.so, or libopenblas.so (module openblas; packages openblas-devel / libopenblas-dev)")
fi
need_library z "zlib (module zlib; packages zlib-devel / zlib1g-dev)" zlib ZLIB_ROOT EBROOTZLIB || true
need_library crypto "OpenSSL's libcrypto, for SHA-256 (module openssl; packages openssl-devel / libssl-dev)" \
  libcrypto OPENSSL_ROOT EBROOTOPENSSL || true

# HDF5 with its Fortran library and modules. fpm finds HDF5 by pkg-config's hdf5; where the
# module gives none, one is written into build/pkgconfig from the root found.
hdf5_fortran=hdf5_fortran
if hdf5_lib=$(candidate_library_dirs "hdf5" "${hdf5_vars[@]}" | first_with libhdf5_fortran.so); then
  echo "setup:   found libhdf5_fortran.so in $hdf5_lib"
else
  missing+=("libhdf5_fortran.so (HDF5 with Fortran; module hdf5; packages hdf5-devel / libhdf5-dev)")
fi
if hdf5_inc=$(candidate_include_dirs "hdf5" "${hdf5_vars[@]}" | first_with hdf5.mod); then
  echo "setup:   found hdf5.mod in $hdf5_inc"
else
  missing+=("hdf5.mod (HDF5 built with Fortran, by the same compiler; module hdf5)")
fi
if [ ${#missing[@]} -eq 0 ]; then
  hdf5_parallel=$(grep -c '^#define H5_HAVE_PARALLEL 1' "$hdf5_inc/H5pubconf.h" 2>/dev/null || true)
  if [ "$mpi" -eq 1 ] && [ "${hdf5_parallel:-0}" -eq 0 ]; then
    missing+=("a parallel HDF5 for femcod-mpi ($hdf5_inc/H5pubconf.h has no H5_HAVE_PARALLEL; module hdf5 of the MPI toolchain)")
  fi
  add_link_dir "$hdf5_lib"; add_include_dir "$hdf5_inc"
  if ! pkg-config --exists hdf5 2>/dev/null || [ "$(pkg-config --variable=libdir hdf5 2>/dev/null)" != "$hdf5_lib" ]; then
    hdf5_version=$(sed -n 's/^#define H5_VERSION "\(.*\)"/\1/p' "$hdf5_inc/H5pubconf.h" 2>/dev/null | head -1)
    mkdir -p build/pkgconfig
    printf 'libdir=%s\nincludedir=%s\n\nName: hdf5\nDescription: HDF5 (written by femcod setup.sh from the library found)\nVersion: %s\nCflags: -I${includedir}\nLibs: -L${libdir} -lhdf5\n' \
      "$hdf5_lib" "$hdf5_inc" "${hdf5_version:-1.10}" > build/pkgconfig/hdf5.pc
    export PKG_CONFIG_PATH="$PWD/build/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
    echo "setup:   wrote build/pkgconfig/hdf5.pc for HDF5 ${hdf5_version:-} (no pkg-config file named that one)"
  fi
fi

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: missing from this environment (load the modules that provide them, or set NAME_ROOT):" >&2
  printf 'setup:   %s\n' "${missing[@]}" >&2
  exit 3
fi
flags_I=""; for d in "${include_dirs[@]}"; do flags_I+=" -I$d"; done
flags_L=""; for d in "${link_dirs[@]}"; do flags_L+=" -L$d -Wl,-rpath,$d"; done
export FPM_FC=$fpm_fc FPM_CC=${FPM_CC:-gcc}
export FPM_FFLAGS="${FPM_FFLAGS:-}$flags_I" FPM_CFLAGS="${FPM_CFLAGS:-}$flags_I" FPM_LDFLAGS="${FPM_LDFLAGS:-}$flags_L"
mkdir -p build
{
  echo "# written by setup.sh: the environment femcod was built in; source it, then fpm test --profile debug"
  for v in FPM_FC FPM_CC FPM_FFLAGS FPM_CFLAGS FPM_LDFLAGS PKG_CONFIG_PATH; do printf 'export %s=%q\n' "$v" "${!v:-}"; done
} > build/environment.sh
echo "setup: build flags in build/environment.sh (source it, then fpm test --profile debug)"

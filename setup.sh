#!/usr/bin/env bash
# femcod set-up for a fresh Debian 12 machine (root; reaches Debian's packages and PyPI).
# Installs only what is missing, builds femcod, and runs the main job on the default deck.
# Idempotent and quiet: a re-run that finds everything installed spends its time in the
# build check and the run only.
#   bash setup.sh            install + build + run input/sphere_d1.deck
#   bash setup.sh --no-run   install + build only (used by .ci/run)
set -euo pipefail
cd "$(dirname "$0")"

run_main=1
[ "${1:-}" = "--no-run" ] && run_main=0

sudo_if_needed() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

debian_packages=(gfortran liblapack-dev libopenblas-dev libhdf5-dev libfftw3-dev pkg-config hdf5-tools)
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

if ! command -v fpm >/dev/null 2>&1; then
  echo "setup: installing fpm 0.12.0 from PyPI"
  python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore fpm==0.12.0
  fpm_bin=$(python3 -c 'import fpm,os;print(os.path.join(os.path.dirname(fpm.__file__),"fpm"))')
  sudo_if_needed ln -sf "$fpm_bin" /usr/local/bin/fpm
fi

fpm build --profile release >/dev/null 2>build.log || { cat build.log >&2; exit 1; }
rm -f build.log
if [ "$run_main" -eq 1 ]; then
  mkdir -p out
  fpm run --profile release femcod -- run input/sphere_d1.deck -o out/sphere_d1 --loads 100,1000,5000 --force
fi

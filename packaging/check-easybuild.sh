#!/usr/bin/env bash
# The EasyBuild easyconfig installed offline (a developer's check; needs root to make the
# user): EasyBuild 5.4.1 from PyPI and Lmod (Debian's lmod) on this machine, the source
# tarball from this checkout (git archive HEAD), the system's libraries as OS dependencies,
# fpm on PATH. A user who is not root (EasyBuild refuses root) runs eb, then loads the
# module and runs the main job.
#   sudo bash packaging/check-easybuild.sh
set -euo pipefail
cd "$(dirname "$0")/.."
version=$(sed -n 's/^version = "\(.*\)"/\1/p' fpm.toml)
user=femcod-eb
id "$user" >/dev/null 2>&1 || useradd -m "$user"
home=$(getent passwd "$user" | cut -d: -f6)
command -v lmod >/dev/null 2>&1 || [ -f /usr/share/lmod/lmod/init/bash ] ||
  { DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lmod >/dev/null; }
venv=/opt/femcod-easybuild
[ -x "$venv/bin/eb" ] || { /usr/bin/python3 -m venv "$venv" && "$venv/bin/pip" install -q easybuild==5.4.1; }
rm -rf "$home/eb" "$home/eb-sources"
mkdir -p "$home/eb-sources/f/femcod"
git archive --prefix="femcod-$version/" -o "$home/eb-sources/f/femcod/femcod-$version.tar.gz" HEAD
cp "packaging/easybuild/femcod-$version.eb" "$home/"
chown -R "$user": "$home"
fpm_dir=$(dirname "$(command -v fpm)")
su -s /bin/bash "$user" -c "cd && source /usr/share/lmod/lmod/init/bash &&
  export EB_PYTHON=$venv/bin/python PATH=$venv/bin:$fpm_dir:/usr/bin:/bin &&
  eb --prefix=\$HOME/eb --sourcepath=\$HOME/eb-sources --modules-tool=Lmod --module-syntax=Lua femcod-$version.eb 2>&1 |
    grep -E '^== (COMPLETED|FAILED)|Build succeeded|ERROR|>> result' &&
  module use \$HOME/eb/modules/all && module load femcod/$version && command -v femcod && femcod --version &&
  d=\$(mktemp -d) && femcod run \$EBROOTFEMCOD/share/femcod/input/sphere_d1.deck -o \$d/sphere_d1 --loads 100,1000,5000 | tail -3"

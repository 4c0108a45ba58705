"""One version: fpm.toml's `version` is the one place it is written; the femcod program, the
C library, the Python distribution (python/setup.py reads fpm.toml), femcod-mpi's manifest
and a result set's /run femcod_version all say the same."""
import os
import re

import h5py

import femcod
from conftest import REPO, run_femcod


def manifest_version(path):
    with open(path) as f:
        return re.search(r'^version\s*=\s*"([^"]+)"', f.read(), re.M).group(1)


def test_every_version_is_fpm_toml_s(tmp_path):
    expected = manifest_version(os.path.join(REPO, "fpm.toml"))
    assert re.fullmatch(r"\d+\.\d+\.\d+", expected)
    assert manifest_version(os.path.join(REPO, "mpi", "fpm.toml")) == expected
    assert run_femcod("--version").stdout.split() == ["femcod", expected]
    assert femcod.version() == expected
    assert femcod.__version__ == expected
    run_femcod("run", os.path.join(REPO, "input", "sphere_d1.deck"), "-o", tmp_path / "v", "--loads", "100", "-q",
               "--figures", "none")
    with h5py.File(tmp_path / "v.h5") as f:
        assert f["run"].attrs["femcod_version"] == expected


def test_changelog_names_the_version():
    expected = manifest_version(os.path.join(REPO, "fpm.toml"))
    with open(os.path.join(REPO, "CHANGELOG.md")) as f:
        assert re.search(rf"^## \[?{re.escape(expected)}\]?", f.read(), re.M)
    with open(os.path.join(REPO, "CITATION.cff")) as f:
        assert re.search(rf"^version: \"?{re.escape(expected)}\"?$", f.read(), re.M)

"""One version: fpm.toml's `version` is the one place it is written; the femcod program, the
C library, the Python distribution (python/setup.py reads fpm.toml), femcod-mpi's manifest
and a result set's /run femcod_version all say the same."""
import os
import re
import shutil
import subprocess

import h5py
import pytest

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


def test_source_tarball_holds_no_build_output():
    """`git archive HEAD` is the source tarball: nothing generated is tracked (the build
    directories, objects, modules, wheels, Python build files)."""
    if shutil.which("git") is None or not os.path.isdir(os.path.join(REPO, ".git")):
        pytest.skip("not a git checkout (a source tarball or the wheel's check)")
    tracked = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True, check=True).stdout.split()
    generated = re.compile(r"(^|/)(build|dist|__pycache__|\.pytest_cache)/|\.(o|mod|smod|a|so|whl|pyc)$|\.egg-info/")
    assert [f for f in tracked if generated.search(f)] == []
    assert len(tracked) > 100

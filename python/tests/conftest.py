"""Shared pieces of the Python tests (run by .ci/run after fpm test: femcod-python -m pytest python/tests).

They use the installed femcod program and libfemcod.so (bash setup.sh --python): the
command line's answers are the references the library's must equal to the last bit.
"""
import os
import shutil
import subprocess

import pytest

import femcod._library

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), os.pardir, os.pardir))


def femcod_program():
    program = shutil.which("femcod")
    if program is None:
        pytest.fail("the femcod program is not on PATH: bash setup.sh installs it")
    return program


def run_femcod(*args, cwd=None, check=True):
    """The femcod command with these arguments; its completed process."""
    p = subprocess.run([femcod_program(), *map(str, args)], cwd=cwd, capture_output=True, text=True)
    if check and p.returncode != 0:
        pytest.fail(f"femcod {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}")
    return p


def library_dirs():
    """PREFIX/lib and PREFIX/include of the installed library."""
    lib = os.path.dirname(os.path.abspath(femcod._library.library_path()))
    return lib, os.path.join(os.path.dirname(lib), "include")

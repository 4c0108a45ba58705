"""Build script of femcod's Python package (the metadata is in pyproject.toml).

Two things need code, not configuration:
- the version comes from the one place it is written, the repository's fpm.toml (the
  femcod program, libfemcod.so and PREFIX.h5's femcod_version print the same; test
  test_version checks they agree);
- a wheel that carries the native femcod (femcod/_native: the program, libfemcod.so and
  femcod.h, staged by setup.sh --wheel) is tagged for the platform, py3-none-linux_x86_64,
  not as pure Python: the program and library do not depend on the Python ABI (ctypes).
  auditwheel then copies in the shared libraries they need (doc/install.md).
"""
import os
import re

from setuptools import Distribution, setup

HERE = os.path.dirname(os.path.abspath(__file__))


def fpm_version():
    """The `version = "X.Y.Z"` line of ../fpm.toml (the repository's; setup.sh --wheel keeps the layout)."""
    with open(os.path.join(HERE, os.pardir, "fpm.toml")) as f:
        for line in f:
            found = re.match(r'\s*version\s*=\s*"([^"]+)"', line)
            if found:
                return found.group(1)
    raise RuntimeError("fpm.toml has no version line")


def native_files():
    """The staged native files under femcod/_native, relative to the package; [] for the pure package."""
    root = os.path.join(HERE, "femcod")
    found = []
    for directory, _, names in os.walk(os.path.join(root, "_native")):
        found += [os.path.relpath(os.path.join(directory, n), root) for n in names]
    return sorted(found)


commands = {}
options = {}
if native_files():
    try:
        from setuptools.command.bdist_wheel import bdist_wheel
    except ImportError:  # setuptools < 70.1
        from wheel.bdist_wheel import bdist_wheel

    class PlatformWheel(bdist_wheel):
        """A wheel for this platform that any Python 3 can install (no extension module)."""

        def get_tag(self):
            return ("py3", "none") + tuple(super().get_tag()[2:])

    class NativeDistribution(Distribution):
        """Native files inside: installed into platlib, the wheel not pure (auditwheel needs both)."""

        def has_ext_modules(self):
            return True

    commands["bdist_wheel"] = PlatformWheel
    options["distclass"] = NativeDistribution

setup(version=fpm_version(), package_data={"femcod": native_files()}, cmdclass=commands,
      py_modules=["femcod_program"] if native_files() else [],
      entry_points={"console_scripts": ["femcod = femcod_program:main"]} if native_files() else {},
      **options)

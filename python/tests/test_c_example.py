"""doc/femcod_example.c, compiled against the installed libfemcod.so and femcod.h and run.

Its answer is checked against Hertz's closed forms computed here (Johnson, Contact
Mechanics, eqs. 4.22-4.23), independently of the example's own printout of them.
"""
import csv
import io
import math
import os
import shutil
import subprocess

import pytest

from conftest import REPO, library_dirs


def test_c_example_compiles_runs_and_gives_hertz(tmp_path):
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        # setup.sh installs gfortran, which brings gcc; a machine with only the wheel may have none.
        pytest.skip("no C compiler on this machine")
    lib, include = library_dirs()
    exe = tmp_path / "example"
    subprocess.run([cc, os.path.join(REPO, "doc", "femcod_example.c"), f"-I{include}", f"-L{lib}", "-lfemcod",
                    f"-Wl,-rpath,{lib}", "-lm", "-o", str(exe)], check=True)
    p = subprocess.run([str(exe)], capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr
    rows = {r[0]: r[1:] for r in csv.reader(io.StringIO(p.stdout)) if r}
    # Hertz: P = 1000 nN, R = 200 nm, E = 200 GPa, nu = 0.25 against a rigid flat.
    P, R, E, nu = 1000.0, 200.0, 200.0, 0.25
    a = (3 * P * R / (4 * E / (1 - nu ** 2))) ** (1 / 3)
    area, approach, p0 = math.pi * a ** 2, a ** 2 / R, 3 * P / (2 * math.pi * a ** 2)
    # The grid's area counts whole 1 nm pixels: within 4 % of pi a^2 (a = 8.9 nm, 250 pixels).
    assert float(rows["area_nm2"][0]) == pytest.approx(area, rel=0.04)
    assert float(rows["approach_nm"][0]) == pytest.approx(approach, rel=0.01)
    assert float(rows["max_pressure_GPa"][0]) == pytest.approx(p0, rel=0.02)
    assert int(rows["progress_calls"][0]) >= 1
    # The refused combination: status 2 with run's own message.
    assert rows["refused"][0] == "2" and "--approach" in rows["refused"][1]

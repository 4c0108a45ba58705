"""doc/python_walkthrough.py, the doc's walk-through from an AFM file to a load-area
figure, run as a user runs it on a scan the test makes: a self-affine surface (Hurst 0.8)
written as a Gwyddion ASCII export in micrometres.

The check is the field's law for rough contact at small nominal pressures: the real area
grows in proportion to the load (Persson, J. Chem. Phys. 115 (2001) 3840; Hyun et al.,
Phys. Rev. E 70 (2004) 026117: A/A0 = kappa p / (E* h'rms)), so the fitted exponent is
near 1 and the fraction rises with every load."""
import os
import subprocess
import sys

import numpy as np

from conftest import REPO


def gwyddion_export(path, n=128, side_um=1.0, hurst=0.8, rms_nm=3.0, seed=3):
    rng = np.random.default_rng(seed)
    k = np.fft.fftfreq(n)
    q = np.hypot(*np.meshgrid(k, k, indexing="ij"))
    q[0, 0] = np.inf
    h = np.real(np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * q ** -(1 + hurst)))
    h *= rms_nm / h.std() / 1000  # um
    with open(path, "w") as f:
        f.write(f"# Channel: Height\n# Width: {side_um} um\n# Height: {side_um} um\n# Value units: um\n")
        for row in h:
            f.write("\t".join(repr(float(v)) for v in row) + "\n")


def test_walkthrough_runs_and_draws_the_load_area_curve(tmp_path):
    scan = tmp_path / "scan.txt"
    figure = tmp_path / "figure.png"
    gwyddion_export(scan)
    p = subprocess.run([sys.executable, os.path.join(REPO, "doc", "python_walkthrough.py"), str(scan), "-o",
                        str(figure), "--states", "6"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "128 x 128 pixels of 7.8125 nm" in p.stdout
    rows = [line.split(",") for line in p.stdout.splitlines()[2:8]]
    fraction = [float(r[3]) for r in rows]
    assert all(b > a for a, b in zip(fraction, fraction[1:])) and 0 < fraction[0] and fraction[-1] < 1
    exponent = float(p.stdout.split("area_load_exponent,")[1].split()[0])
    assert 0.8 < exponent < 1.2
    with open(figure, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"

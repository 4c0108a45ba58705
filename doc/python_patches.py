"""femcod's contact patches against tamaas' cluster analysis, on the same contact maps
(doc/results.md, "Contact patches").

    PYTHON doc/python_patches.py [--np 512]

PYTHON is an environment with femcod (pip install ./python) and tamaas (never a femcod
dependency). A self-affine surface (Hurst 0.8, rms 3 nm, pixel 2 nm) is solved as a
periodic cell by `femcod run --solver cg --boundary periodic` at loads from 0.3 to 30 %
contact; each state's contact map (pressure > 0) is handed to tamaas.FloodFill.getClusters
(which treats the grid as periodic), 4- and 8-connected. Printed: the patch statistics
against load, and whether femcod's patches (count, and every patch's area and perimeter)
equal tamaas' clusters.
"""
import argparse
import os
import shutil
import subprocess
import tempfile

import h5py
import numpy as np

import femcod


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--np", type=int, default=512)
    args = parser.parse_args()
    import tamaas as tm
    program = shutil.which("femcod")
    with tempfile.TemporaryDirectory() as d:
        deck = os.path.join(d, "rough.h5")
        subprocess.run([program, "mkdeck", "self-affine", "--np", str(args.np), "--pixel", "2", "--hurst", "0.8",
                        "--rms", "3", "--shape-on", "lower", "-o", deck], check=True, capture_output=True)
        h = femcod.read_deck(deck).lower
        gy, gx = np.gradient(h, 2.0)
        slope = np.sqrt(np.mean(gx ** 2 + gy ** 2))
        estar = 200 / (1 - 0.25 ** 2)
        side = args.np * 2.0
        loads = [float(f"{f * estar * slope / 2 * side ** 2:.3g}") for f in (0.003, 0.01, 0.03, 0.1, 0.3)]
        prefix = os.path.join(d, "r")
        subprocess.run([program, "run", deck, "--solver", "cg", "--boundary", "periodic", "--loads",
                        ",".join(repr(x) for x in loads), "-o", prefix, "-q"], check=True)
        print(f"NP = {args.np}, pixel 2 nm, Hurst 0.8, rms 3 nm, periodic; femcod run --solver cg")
        print("| load (nN) | contact | patches 4 | patches 8 | mean patch (px, 8) | largest (px) | perimeter ~ area^e |"
              " tamaas 4 / 8 | every patch equal |")
        print("|---|---|---|---|---|---|---|---|---|")
        with h5py.File(prefix + ".h5") as f:
            for k in range(len(loads)):
                g = f["loads"][f"{k + 1:03d}"]
                contact = g["pressure"][()] > 0
                mine = {c: sorted(zip(g[f"patch_area_{c}"][()], g[f"patch_perimeter_{c}"][()])) for c in (4, 8)}
                theirs = {c: sorted((cl.area, cl.perimeter) for cl in tm.FloodFill.getClusters(contact, c == 8))
                          for c in (4, 8)}
                same = all(mine[c] == theirs[c] for c in (4, 8))
                areas8 = np.array([a for a, _ in mine[8]])
                print(f"| {g.attrs['load_nN']:.4g} | {contact.mean():.4f} | {g.attrs['patches_4']} | "
                      f"{g.attrs['patches_8']} | {areas8.mean():.2f} | {areas8.max()} | "
                      f"{g.attrs['patch_perimeter_exponent']:.3f} | {len(theirs[4])} / {len(theirs[8])} | "
                      f"{'yes' if same else 'NO'} |")


if __name__ == "__main__":
    main()

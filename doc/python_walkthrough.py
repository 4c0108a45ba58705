"""From an AFM height file to a load-area figure, in Python (doc/python.md).

    femcod-python doc/python_walkthrough.py SCAN [--pixel D] [-o FIGURE.png]

SCAN is what `femcod run --lower` reads: a Gwyddion ASCII export (with its units and
width), an ASCII matrix (give --pixel), FILE.h5:/DATASET or a NanoScope file. The scan
is levelled (its mean plane removed), put on an elastic body (200 GPa, 0.25) against a
rigid flat, and solved by the cg solver at nominal pressures from 1e-4 to 3e-2 E*; the
figure shows the scan, the real area fraction against the load (log-log, with its
power-law fit) and the pressure map at the middle load. The table goes to standard
output. The tests run this script on a surface they make (python/tests).
"""
import argparse
import time

import matplotlib
import numpy as np

import femcod

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the back end is chosen)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scan")
    parser.add_argument("--pixel", type=float, help="pixel size in nm, when the file does not give it")
    parser.add_argument("-o", "--figure", default="walkthrough.png")
    parser.add_argument("--states", type=int, default=8, help="loads on the curve")
    args = parser.parse_args()

    # 1. The scan, as `femcod run --lower SCAN --remove-plane` reads it (heights in nm, from the lowest point).
    deck = femcod.read_heights(args.scan, pixel=args.pixel, remove_plane=True)
    n, d = deck.np, deck.pixel
    side = n * d
    estar = deck.young[0] / (1 - deck.poisson[0] ** 2)

    # 2. Loads from nominal pressures p/E* = 1e-4 .. 3e-2 over the scan's area.
    loads = side ** 2 * estar * np.logspace(-4, np.log10(3e-2), args.states)
    t0 = time.perf_counter()
    result = femcod.solve(deck, loads=loads, solver="cg")
    seconds = time.perf_counter() - t0

    # 3. The table and the power law area ~ load^m over the curve.
    fraction = result.column("area_fraction")
    m, c = np.polyfit(np.log(result.loads), np.log(fraction), 1)
    print(f"scan: {args.scan}, {n} x {n} pixels of {d:.6g} nm; E* = {estar:.6g} GPa; solved in {seconds:.3f} s")
    print("load_nN,nominal_pressure_over_estar,approach_nm,area_fraction,max_pressure_GPa")
    for s in result.states:
        print(f"{s.load:.6g},{s.load / side ** 2 / estar:.6g},{s.approach:.6g},{s.area_fraction:.6g},"
              f"{s.max_pressure:.6g}")
    print(f"area_load_exponent,{m:.4f}")

    # 4. The figure.
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    extent = (0, side, side, 0)  # row i down the page, column j across: femcod's [i, j]
    im = ax[0].imshow(deck.lower, extent=extent, cmap="viridis")
    fig.colorbar(im, ax=ax[0], label="height (nm)")
    ax[0].set(title="scan, levelled", xlabel="x (nm)", ylabel="y (nm)")
    ax[1].loglog(result.loads, fraction, "o-", label="femcod cg")
    ax[1].loglog(result.loads, np.exp(c) * result.loads ** m, "--", label=f"fit: area ~ load^{m:.2f}")
    ax[1].set(title="real contact area", xlabel="load (nN)", ylabel="area fraction")
    ax[1].legend()
    middle = result.states[len(result.states) // 2]
    im = ax[2].imshow(np.ma.masked_equal(middle.pressure, 0), extent=extent, cmap="inferno")
    fig.colorbar(im, ax=ax[2], label="pressure (GPa)")
    ax[2].set(title=f"pressure at {middle.load:.3g} nN", xlabel="x (nm)")
    fig.tight_layout()
    fig.savefig(args.figure, dpi=90)
    print(f"figure,{args.figure}")


if __name__ == "__main__":
    main()

"""What calling femcod from Python costs, against the same solve inside `femcod run`.

    femcod-python python/benchmarks/overhead.py [--np 1024] [--repeats 7] [--fraction 0.02]

A self-affine surface (Hurst 0.8, rms 3 nm, pixel 2 nm; `femcod mkdeck`, an HDF5 deck)
is solved by the cg solver at one load, `--repeats` times each way, alternating:

- `femcod run DECK --solver cg --loads L`, the whole command (reading the deck, writing
  the result set) and, from its summary.json, the solve and the maps alone (timings_s);
- `femcod.solve(deck, loads=[L])` on the deck already in memory: the call as a notebook
  user makes it, the arrays' conversion, the library's copy of the heights, the solve, the
  maps and their copies into numpy included.

The table gives the medians and the ratio of the Python call to the command's solve and
maps; the answers are checked to be the same doubles. Copies a call makes: none of an
input array that is already C-ordered float64 (one conversion otherwise), one of each
height map into the library's problem, one of each result map into a new numpy array.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time

import numpy as np

import femcod


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--np", type=int, default=1024)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--fraction", type=float, default=0.02, help="about this contact fraction")
    args = parser.parse_args()
    program = shutil.which("femcod")
    if program is None:
        raise SystemExit("overhead: the femcod program is not on PATH (bash setup.sh)")
    with tempfile.TemporaryDirectory() as d:
        deck_path = os.path.join(d, "surface.h5")
        subprocess.run([program, "mkdeck", "self-affine", "--np", str(args.np), "--pixel", "2", "--hurst", "0.8",
                        "--rms", "3", "--shape-on", "lower", "-o", deck_path], check=True, capture_output=True)
        deck = femcod.read_deck(deck_path)
        # The load for about the fraction asked: p = f E* h'rms / 2 over the grid.
        slope = np.sqrt(np.mean(np.gradient(deck.lower, deck.pixel)[0] ** 2 +
                                np.gradient(deck.lower, deck.pixel)[1] ** 2))
        estar = deck.young[0] / (1 - deck.poisson[0] ** 2)
        load = float(f"{args.fraction * estar * slope / 2 * (args.np * deck.pixel) ** 2:.3g}")
        command, inside, python = [], [], []
        for _ in range(args.repeats):
            prefix = os.path.join(d, "run")
            t0 = time.perf_counter()
            subprocess.run([program, "run", deck_path, "--solver", "cg", "--loads", repr(load), "-o", prefix, "-q",
                            "--force"], check=True)
            command.append(time.perf_counter() - t0)
            with open(prefix + ".summary.json") as f:
                timings = json.load(f)["timings_s"]
            inside.append(timings["solve"] + timings["maps"])
            t0 = time.perf_counter()
            r = femcod.solve(deck, loads=[load], solver="cg")
            python.append(time.perf_counter() - t0)
        cli = femcod.load(prefix + ".h5")
        same = all(np.array_equal(cli.states[0].maps[k], r.states[0].maps[k]) for k in ("pressure", "gap")) and \
            cli.states[0].approach == r.states[0].approach
        med = statistics.median
        print(f"femcod from Python against femcod run: NP = {args.np}, cg at {load:g} nN "
              f"({r.states[0].area_fraction:.4f} contact, {int(r.states[0].cg_iterations)} iterations), "
              f"medians of {args.repeats}, threads as OMP_NUM_THREADS (default all)")
        print("| measure | seconds | over the command's solve + maps |")
        print("|---|---|---|")
        print(f"| femcod run, the whole command | {med(command):.4f} | {med(command) / med(inside):.3f} |")
        print(f"| femcod run, solve + maps (summary.json) | {med(inside):.4f} | 1 |")
        print(f"| femcod.solve from Python | {med(python):.4f} | {med(python) / med(inside):.3f} |")
        print(f"answers equal to the last bit: {'yes' if same else 'NO'}")
        print(f"spread (min-max): command {min(command):.4f}-{max(command):.4f}, solve + maps "
              f"{min(inside):.4f}-{max(inside):.4f}, Python {min(python):.4f}-{max(python):.4f} s")


if __name__ == "__main__":
    main()

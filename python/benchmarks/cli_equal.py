"""The table of doc/python.md, "The same answer as the command line, bit for bit".

    femcod-python python/benchmarks/cli_equal.py

For every deck of input/ and every solver (at 5, 15 and 30 % of the load where the deck's
full incremental history ends, as python/tests/test_cli_equal.py), `femcod run` and
femcod.solve: how many doubles were compared (state values, map entries, history entries)
and how many differ in any bit.
"""
import glob
import os
import shutil
import subprocess
import tempfile

import numpy as np

import femcod

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), os.pardir, os.pardir))


def bits(x):
    return np.atleast_1d(np.asarray(x, dtype=np.float64)).view(np.uint64)


def compare(cli, py):
    compared = differ = 0
    reached = [s for s in py.states if s.reached]
    for c, p in zip(cli.states, reached):
        for name, value in c.values.items():
            if name in p.values:
                compared += 1
                differ += int(np.count_nonzero(bits(value) != bits(p.values[name])))
        for name in c.maps:
            compared += c.maps[name].size
            differ += int(np.count_nonzero(bits(c.maps[name]) != bits(p.maps[name])))
    for name, column in cli.history.items():
        if name in py.history:
            compared += column.size
            differ += int(np.count_nonzero(bits(column) != bits(py.history[name])))
    return len(reached), compared, differ


def main():
    program = shutil.which("femcod")
    print("| deck | NP | solver | states | doubles compared | differing |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        for deck_path in sorted(glob.glob(os.path.join(REPO, "input", "*.deck"))):
            deck = femcod.read_deck(deck_path)
            subprocess.run([program, "run", deck_path, "-o", f"{d}/full", "-q", "--force"], check=True)
            top = float(femcod.load(f"{d}/full.h5").history["load_nN"].max())
            loads = [0.05 * top, 0.15 * top, 0.3 * top]
            for solver in ("incremental", "legacy", "cg"):
                subprocess.run([program, "run", deck_path, "-o", f"{d}/x", "--solver", solver, "--loads",
                                ",".join(repr(x) for x in loads), "-q", "--force"], check=True)
                states, compared, differ = compare(femcod.load(f"{d}/x.h5"),
                                                   femcod.solve(deck, loads=loads, solver=solver))
                print(f"| {os.path.basename(deck_path)} | {deck.np} | {solver} | {states} | {compared} | {differ} |")


if __name__ == "__main__":
    main()
